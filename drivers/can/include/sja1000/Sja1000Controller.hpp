// One SJA1000 CAN channel as a DCOS device (seed 7.3.2, 7.13).
//
// The controller is the part every bus front end shares: the ISA card
// (sja1000/IsaSja1000Channel.hpp) and, later, the PCI card of the
// dual-Pentium board only say where the chip's registers are and which
// interrupt line it raises. A super-user task installs it, and every task
// reaches it through the system agent by id:
//
//     static sja1000::IsaSja1000Channel can0("can0", 0x280, 10);
//     iobus::IsaConflict conflict;
//     Result<ObjectId> id = can0.install("can0", Visibility::Regional, &conflict);
//
//     systemAgent.Open(id.value());          // starts the chip on the bus
//     systemAgent.Write(id.value(), 0, &frame, sizeof frame);
//
// Read and Write move whole can::CanFrame objects (channel 0 only):
// - Write queues frames for sending and returns the bytes of the frames it
//   took; a full queue takes fewer. The queue is ordered by identifier, as
//   the bus arbitrates, and keeps the order of frames with one identifier;
//   a frame waiting in the chip's single transmit buffer is aborted when a
//   more urgent one is queued, so the node's own priority order holds on
//   the bus (seed 6.4: task priority is bus priority).
// - Read hands out received frames, oldest first, and returns 0 bytes when
//   none is waiting: a driver never waits (dcos/Device.hpp). A task waits
//   for the receive event it asked for with kSetNotification.
// - Channel 1 (kTimedChannel) moves the same frames with timestamps: Read
//   gives TimedFrame objects, each with the uptime read when the interrupt
//   that took it from the chip began, and a frame written on channel 1
//   comes back through channel 1's Read once it has gone, flagged as an
//   echo and stamped with its transmit interrupt (as SocketCAN loops back
//   a sent frame with its timestamp). On the bus a frame ends for every
//   node at once, so the sender's echo and the receivers' frames carry the
//   same moment (the global time base, docs/protocols/time.md). Channel
//   0's Read skips echoes.
//
// Errors: the interrupt service routine follows the chip's error counters
// and reports every change of state (error-active, warning, passive,
// bus-off) to the task registered with kSetNotification. After bus-off the
// chip is restarted at once (it then waits the 128 x 11 recessive bits the
// standard asks for) unless the policy says to wait for kRestart. A node
// alone on the bus gets no acknowledgement and would repeat its frame for
// ever, filling the bus with retries: after kLoneNodeAttempts acknowledge
// errors in a row the controller aborts the frame, reports NoAcknowledge
// and holds its queue until it hears another node or is written to again.
//
// The interrupt service routine handles at most kInterruptLoopBound
// interrupt causes per call, as Linux's driver bounds its loop, so a chip
// that keeps its line asserted cannot hold the processor for ever.
#pragma once

#include <sja1000/BitTiming.hpp>
#include <sja1000/Sja1000Chip.hpp>

#include <can/CanFrame.hpp>
#include <dcos/Device.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sja1000 {

/// What the bus looks like from this channel (kGetState).
struct BusState {
    ErrorState errorState = ErrorState::Active;
    uint8_t receiveErrors = 0;   ///< RXERR.
    uint8_t transmitErrors = 0;  ///< TXERR.
    uint8_t started = 0;         ///< 1 while the chip is on the bus.
    uint8_t noAcknowledge = 0;   ///< 1 while the queue is held for want of an acknowledge.
    uint32_t bitRate = 0;        ///< The bit rate in use.
    uint16_t samplePointPermille = 0;
    uint16_t queued = 0;         ///< Frames waiting to be sent, the one in the chip included.
};

/// Counters from the install on (kGetStatistics).
struct ChannelStatistics {
    uint32_t framesSent = 0;
    uint32_t framesReceived = 0;
    uint32_t receiveQueueOverruns = 0; ///< Frames lost because no task read them in time.
    uint32_t chipOverruns = 0;         ///< Frames lost in the chip's FIFO (DOI).
    uint32_t malformedFrames = 0;      ///< Received frames with a data length code above 8, dropped.
    uint32_t badIdentifiers = 0;       ///< Received frames of a format the filter excludes, dropped.
    uint32_t busErrors = 0;            ///< BEI: every error the chip saw on the bus.
    uint32_t acknowledgeErrors = 0;    ///< Bus errors in the acknowledge slot of our own frames.
    uint32_t arbitrationLost = 0;      ///< ALI.
    uint32_t errorWarnings = 0;        ///< Entries into the warning state.
    uint32_t errorPassives = 0;        ///< Entries into error-passive.
    uint32_t busOffs = 0;
    uint32_t restarts = 0;             ///< Recoveries begun by the policy after bus-off, and every kRestart.
    uint32_t recoveries = 0;           ///< Recoveries from bus-off completed: back on the bus, error-active.
    uint32_t errorActives = 0;         ///< Returns to error-active from warning, passive or bus-off.
    uint32_t stateChangesLost = 0;     ///< State changes the owner had not read when the log was full.
    uint32_t aborts = 0;               ///< Frames taken back from the chip for a more urgent one.
    uint32_t loneNodeHolds = 0;        ///< Times the queue was held for want of an acknowledge.
    uint32_t interrupts = 0;           ///< Calls of the interrupt service routine.
    uint32_t interruptLoopLimits = 0;  ///< Calls that stopped at kInterruptLoopBound.
    /// Instructions of the last call of the interrupt service routine that
    /// received one frame and saw no other cause, from its first statement
    /// to its last; 0 in an image without an instruction counter
    /// (arch_x86/InstructionCounter.hpp).
    uint32_t receiveInterruptInstructions = 0;
};

/// A frame with its time, as channel 1 (kTimedChannel) reads it.
struct TimedFrame {
    /// flags: the frame is this channel's own, sent after a write on channel 1.
    static constexpr uint32_t kEcho = 1u << 0;

    can::CanFrame frame{};
    uint32_t flags = 0;
    /// TimerAgent::Uptime at the start of the interrupt that received the
    /// frame, or for an echo, that saw its transmission complete.
    uint64_t timeNs = 0;
    /// The instruction counter (arch_x86::instructionCount) at the start of
    /// the same interrupt; 0 in an image without one, where nothing writes it.
    uint64_t instructionStamp = 0;
};

/// Whom the channel tells, and with which events (kSetNotification).
struct Notification {
    dcos::ObjectId task{};      ///< Null: nobody.
    uint32_t receiveEvent = 0;  ///< Posted when a frame is received (0: not posted).
    uint32_t stateEvent = 0;    ///< Posted when the error state or the acknowledge hold changes.
    uint32_t sentEvent = 0;     ///< Posted when a frame has been sent.
};

/// One change of the error state or of the lone-node hold, as the driver
/// saw it (kReadStateChanges): what the owner of the channel learns.
struct StateChange {
    ErrorState from = ErrorState::Active;
    ErrorState to = ErrorState::Active; ///< Equal to from when only the hold changed.
    uint8_t receiveErrors = 0;  ///< RXERR when the change was seen.
    uint8_t transmitErrors = 0; ///< TXERR when the change was seen.
    uint8_t holdChanged = 0;    ///< 1: this entry is the lone-node hold beginning or ending.
    uint8_t noAcknowledge = 0;  ///< 1 while the queue is held for want of an acknowledge, after this change.
};

/// The state changes not yet read, oldest first (kReadStateChanges); reading
/// them empties the channel's log.
struct StateChanges {
    static constexpr size_t kCapacity = 16;
    uint32_t count = 0;   ///< Entries of changes filled in.
    uint32_t lost = 0;    ///< Older changes overwritten since the last read.
    StateChange changes[kCapacity]{};
};

/// After bus-off (kSetBusOffPolicy).
enum class BusOffPolicy : uint32_t {
    RestartAtOnce = 0, ///< Leave reset mode at once; the chip waits 128 x 11 recessive bits.
    WaitForRestart = 1, ///< Stay off the bus until Control kRestart, then recover as the chip does.
};

class Sja1000Controller : public dcos::Device {
public:
    /// Control commands; each names its argument type and length.
    enum Command : uint32_t {
        kSetBitRate = 1,       ///< uint32_t bit/s: one of the rates BitTimingCalculator gives exactly. Restarts the chip.
        kSetFilter = 2,        ///< AcceptanceFilter. Restarts the chip.
        kSetBusMode = 3,       ///< BusMode (uint32_t). Restarts the chip.
        kGetState = 4,         ///< BusState, filled in.
        kGetStatistics = 5,    ///< ChannelStatistics, filled in.
        kSetNotification = 6,  ///< Notification.
        kSetBusOffPolicy = 7,  ///< BusOffPolicy (uint32_t).
        kRestart = 8,          ///< No argument: after bus-off begins the chip's recovery; else restarts it, counters cleared.
        kFlushTransmit = 9,    ///< No argument: drops every queued frame, the one in the chip too.
        kReadStateChanges = 10, ///< StateChanges: the error-state changes since the last read, oldest first.
    };

    /// Read and Write plain can::CanFrame objects.
    static constexpr uint32_t kFrameChannel = 0;
    /// Read TimedFrame objects; Write frames that come back as echoes.
    static constexpr uint32_t kTimedChannel = 1;
    /// Frames the transmit queue holds, the one in the chip included.
    static constexpr size_t kTransmitQueueLength = 16;
    /// Frames received and not yet read that the channel keeps.
    static constexpr size_t kReceiveQueueLength = 64;
    /// Interrupt causes handled per call of the interrupt service routine.
    static constexpr unsigned kInterruptLoopBound = 20;
    /// Acknowledge errors in a row after which a frame is aborted and the queue held.
    static constexpr unsigned kLoneNodeAttempts = 16;
    /// The bit rate after install.
    static constexpr uint32_t kDefaultBitRate = 125'000;

    /// A channel called @p claimant (static storage) whose chip is behind
    /// @p window and raises @p irq, on a card with @p oscillatorHz.
    constexpr Sja1000Controller(const char* claimant, arch_x86::IoWindow window, uint8_t irq,
                                uint32_t oscillatorHz = kDefaultOscillatorHz)
        : claimant_(claimant), chip_(window), irq_(irq), oscillatorHz_(oscillatorHz)
    {
    }

    /// Installs the interrupt service routine and the driver under @p name.
    /// Privileged. The front end has reserved the chip's resources first.
    dcos::Result<dcos::ObjectId> installController(const char* name, dcos::Visibility visibility);

    /// Deletes the device and removes the routine; Busy while open.
    dcos::Status uninstallController();

    bool installed() const { return !id().isNull(); }
    const char* claimant() const { return claimant_; }
    uint8_t irq() const { return irq_; }

    /// The interrupt service routine's body; InstallISR calls it through a
    /// trampoline, and host tests call it directly.
    void handleInterrupt();

    /// The arbitration order of two frames on the bus: true when @p a wins
    /// over @p b (ISO 11898-1: the lower identifier; with equal base
    /// identifiers a standard frame before an extended one, and a data
    /// frame before a remote one).
    static bool winsArbitration(const can::CanFrame& a, const can::CanFrame& b);

protected:
    ~Sja1000Controller() = default;

private:
    dcos::Status Probe() override;
    dcos::Status Open() override;
    dcos::Status Close() override;
    dcos::Result<size_t> Read(uint32_t channel, void* buffer, size_t length) override;
    dcos::Result<size_t> Write(uint32_t channel, const void* buffer, size_t length) override;
    dcos::Status Control(uint32_t command, void* argument, size_t length) override;

    static void interruptTrampoline(void* context);

    dcos::Status startChip();
    void stopChip();
    // A frame waiting to be sent, and whether it comes back as an echo.
    struct Outgoing {
        can::CanFrame frame{};
        bool echo = false;
    };

    bool enqueue(const can::CanFrame& frame, bool echo);
    void settleHead();
    void takeBackFromChip();
    void removeHead();
    void loadNext();
    void onTransmitDone(uint64_t now);
    void onReceive(uint64_t now);
    bool keep(const can::CanFrame& frame, uint32_t flags, uint64_t now);
    void onBusError();
    void onStateChange();
    void notify(uint32_t events);
    void finishCountedInterrupt(uint8_t seen);
    void releaseHold();
    void recordStateChange(ErrorState from, ErrorState to, bool holdChanged = false);

    const char* claimant_;
    Sja1000Chip chip_;
    uint8_t irq_;
    uint32_t oscillatorHz_;
    bool isrInstalled_ = false;
    uint32_t opens_ = 0;

    BitTiming timing_{};
    AcceptanceFilter filter_ = AcceptanceFilter::all();
    BusMode busMode_ = BusMode::Normal;
    BusOffPolicy busOffPolicy_ = BusOffPolicy::RestartAtOnce;
    Notification notification_{};

    // In an image with an instruction counter only: the counter at the
    // start of the current call of the interrupt service routine, the stamp
    // of the frames it keeps, and the receive ring's count then.
    uint64_t countStart_ = 0;
    size_t countKeptBefore_ = 0;
    // Shared with the interrupt service routine; changed with interrupts disabled.
    bool started_ = false;
    bool noAcknowledge_ = false;
    ErrorState errorState_ = ErrorState::Active;
    unsigned acknowledgeErrorsInARow_ = 0;
    // The transmit queue, sorted by winsArbitration, stable: transmit_[0] is
    // the next to send; inChip_ says it is already in the chip's buffer.
    Outgoing transmit_[kTransmitQueueLength];
    size_t transmitCount_ = 0;
    bool inChip_ = false;
    bool abortRequested_ = false; // An abort for a more urgent frame is under way.
    bool dropInChip_ = false;     // The frame in the chip was flushed: drop it when TI comes.
    // The receive ring, echoes included.
    TimedFrame receive_[kReceiveQueueLength];
    size_t receiveHead_ = 0;
    size_t receiveCount_ = 0;
    ChannelStatistics statistics_{};
    // The state changes the owner has not read yet: a ring that keeps the
    // newest, since the present state matters more than the oldest history.
    StateChange stateLog_[StateChanges::kCapacity];
    size_t stateLogHead_ = 0;
    size_t stateLogCount_ = 0;
    uint32_t stateLogLost_ = 0;
};

} // namespace sja1000
