// The multi-function ISA I/O board as a DCOS device (seed 7.3.2, 9.4).
//
// A super-user task configures one MfioBoard object per board and installs
// it; every task then reaches it through the system agent by id:
//
//     static iobus::MfioBoard board("mfio0", 0x300, 5);
//     iobus::IsaConflict conflict;
//     Result<ObjectId> id = board.install("mfio0", Visibility::Regional, &conflict);
//
//     systemAgent.Open(id.value());                 // any task
//     iobus::readAnalogInput(id.value(), 3, 0);     // iobus/MfioClient.hpp
//
// Channels (Read and Write through the system agent; docs/iobus/driver.md):
//
//     channel  name      Read (2 bytes, uint16_t)              Write (2 bytes, uint16_t)
//     0-7      AI0-AI7   converts: the `ADC_DATA` word          NotSupported
//     8-15     AO0-AO7   the DAC code read back                 the DAC code, 0..4095
//     16       DI        the 16 digital inputs                  NotSupported
//     17       DO        the digital outputs read back          the 16 digital outputs
//
// An analog input reads as the board's `ADC_DATA` word: bits 11:0 the code,
// bits 14:12 the channel, bit 15 the overrange flag (iobus/AnalogScaling.hpp
// turns it into microvolts). Conversions are interrupt driven by default:
// a Read starts one and returns 0 bytes; the interrupt service routine
// latches the result and posts the conversion event to the task that
// started it, which reads again. In polled mode a Read converts and returns
// the result at once, polling `STATUS` for at most kPollBoundNs. When no
// interrupt arrives within the interrupt bound, the next Read collects the
// result by polling, counts a missed interrupt and (unless disabled) falls
// back to polled mode for good, printing a diagnostic.
//
// Every function runs in bounded time and never waits on a kernel object,
// as dcos/Device.hpp requires; MfioClient does the waiting for a task.
#pragma once

#include <iobus/AnalogScaling.hpp>
#include <iobus/IsaResourceManager.hpp>
#include <iobus/MfioChip.hpp>

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/Device.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/Visibility.hpp>
#include <runtime/Format.hpp>

#include <stddef.h>
#include <stdint.h>

namespace iobus {

/// The channel numbers of MfioBoard's Read and Write.
namespace channel {
constexpr uint32_t kAnalogInput0 = 0;    ///< AI0; AIn is kAnalogInput0 + n (n = 0..7).
constexpr uint32_t kAnalogOutput0 = 8;   ///< AO0; AOn is kAnalogOutput0 + n (n = 0..7).
constexpr uint32_t kDigitalInputs = 16;  ///< DI, the 16 inputs as one word.
constexpr uint32_t kDigitalOutputs = 17; ///< DO, the 16 outputs as one word.
constexpr uint32_t kCount = 18;          ///< Channels 0 to kCount - 1 exist.
} // namespace channel

// An application's Modbus register map is checked against the board's points
// by the kernel's configuration rules, which cannot include this driver.
static_assert(dcos::app::kModbusAnalogInputPoints == mfio::kAnalogInputs, "the map's analog inputs are the board's");
static_assert(dcos::app::kModbusDigitalOutputPoints == mfio::kDigitalBits, "the map's digital outputs are the board's");

/// How conversions complete (Control kSetMode / kGetMode).
enum class ConversionMode : uint32_t {
    Interrupt = 0, ///< The conversion-complete interrupt delivers results.
    Polled = 1,    ///< Read polls `STATUS` until the result is ready.
};

/// The argument of kSetGain and kGetGain.
struct GainSetting {
    uint32_t channel; ///< The analog input, 0-7.
    uint32_t gain;    ///< The factor: 1, 10, 100 or 1000 (filled in by kGetGain).
};

/// What kGetInfo reports.
struct BoardInfo {
    uint16_t base;     ///< The base port.
    uint8_t irq;       ///< The interrupt line.
    uint8_t present;   ///< 1 when the last probe found the board.
    uint16_t id;       ///< `ID` as last read.
    uint16_t revision; ///< `REVISION` as last read.
};

/// Counters of the driver (kGetStatistics), from the board's install on.
struct BoardStatistics {
    uint32_t conversions;        ///< Results delivered to Read.
    uint32_t interrupts;         ///< Calls of the interrupt service routine.
    uint32_t spuriousInterrupts; ///< Interrupts that found no result waiting.
    uint32_t missedInterrupts;   ///< Conversions whose interrupt did not come within the bound.
    uint32_t fallbacks;          ///< Automatic switches to polled mode.
    uint32_t overranges;         ///< Results with the overrange flag.
    uint32_t timeouts;           ///< Conversions that never completed.
    uint32_t reserved;           ///< Zero; keeps the 64-bit fields aligned.
    uint64_t lastStartNs;        ///< Uptime when the last conversion was started.
    uint64_t lastInterruptNs;    ///< Uptime when the interrupt service routine last latched a result.
};

/// The multi-function I/O board driver.
class MfioBoard final : public dcos::Device {
public:
    /// Control commands; each names its argument type and length.
    enum Command : uint32_t {
        kSetGain = 1,              ///< GainSetting: sets an analog input's amplifier.
        kGetGain = 2,              ///< GainSetting: fills in .gain for .channel.
        kSetMode = 3,              ///< ConversionMode (uint32_t).
        kGetMode = 4,              ///< ConversionMode (uint32_t), filled in.
        kGetStatistics = 5,        ///< BoardStatistics, filled in.
        kGetInfo = 6,              ///< BoardInfo, filled in.
        kSetConversionEvent = 7,   ///< uint32_t: the event set posted when a result is latched (non-zero).
        kSetInterruptBound = 8,    ///< uint32_t: nanoseconds to wait for the interrupt before falling back.
        kSetAutomaticFallback = 9, ///< uint32_t: 1 falls back to polling on a missed interrupt, 0 never does.
        kResetBoard = 10,          ///< No argument: resets the board and reapplies the gains.
    };

    /// The event MfioBoard posts by default when a conversion completes.
    static constexpr uint32_t kDefaultConversionEvent = 1u << 28;
    /// The default time the interrupt has to arrive.
    static constexpr uint32_t kDefaultInterruptBoundNs = 2000000;
    /// The longest a polled conversion is waited for.
    static constexpr uint64_t kPollBoundNs = 2000000;
    /// The most `STATUS` reads of one polled conversion, a bound independent of the clock.
    static constexpr uint32_t kPollLimit = 20000;

    /// A board called @p claimant (for the ISA resource manager, at most 15
    /// characters, static storage) at @p base and interrupt line @p irq.
    constexpr MfioBoard(const char* claimant, uint16_t base = mfio::kDefaultBase, uint8_t irq = mfio::kDefaultIrq)
        : claimant_(claimant), base_(base), irq_(irq), chip_(arch_x86::IoWindow::ports(base, mfio::kWindowSize))
    {
    }

    /// Moves the board to other switch settings. Only while not installed (Busy otherwise).
    dcos::Status configure(uint16_t base, uint8_t irq);

    /// Reserves the ports and the line, installs the interrupt service
    /// routine and installs the driver with systemAgent.Create under
    /// @p name. Privileged. The calling task owns the device (see
    /// SystemAgent::XferOwnership). Fails with AlreadyExists and fills
    /// @p conflict when the resource manager refuses the ports or the line,
    /// with the status of InstallISR or Create otherwise; nothing stays
    /// reserved or installed after a failure.
    dcos::Result<dcos::ObjectId> install(const char* name, dcos::Visibility visibility, IsaConflict* conflict);

    /// Undoes install: deletes the device, removes the routine and releases
    /// the resources. Fails with Busy while the device is open.
    dcos::Status uninstall();

    /// True between a successful install and uninstall.
    bool installed() const { return !id().isNull(); }

    /// The base port and interrupt line.
    uint16_t base() const { return base_; }
    uint8_t irq() const { return irq_; }

    /// The claimant name given to the constructor.
    const char* claimant() const { return claimant_; }

    /// Where the driver prints diagnostics (the automatic fallback); null for none.
    void setDiagnosticSink(runtime::CharacterSink* sink) { diagnostics_ = sink; }

    /// The interrupt service routine's body; InstallISR calls it through a
    /// trampoline, and host tests call it directly.
    void handleInterrupt();

private:
    dcos::Status Probe() override;
    dcos::Status Open() override;
    dcos::Status Close() override;
    dcos::Result<size_t> Read(uint32_t channel, void* buffer, size_t length) override;
    dcos::Result<size_t> Write(uint32_t channel, const void* buffer, size_t length) override;
    dcos::Status Control(uint32_t command, void* argument, size_t length) override;

    static void interruptTrampoline(void* context);

    dcos::Result<size_t> readAnalogInput(unsigned input, uint16_t& word);
    dcos::Result<size_t> convertPolled(unsigned input, uint16_t& word);
    dcos::Result<size_t> collectMissedInterrupt(unsigned input, uint16_t& word);
    void deliver(uint16_t word);
    void applyControl();
    void initialiseBoard();

    const char* claimant_;
    uint16_t base_;
    uint8_t irq_;
    MfioChip chip_;
    runtime::CharacterSink* diagnostics_ = nullptr;

    MfioIdentity identity_{0, 0};
    bool present_ = false;
    bool isrInstalled_ = false;
    bool boardInitialised_ = false;
    uint32_t opens_ = 0;
    uint16_t gains_ = mfio::kResetGain;
    ConversionMode mode_ = ConversionMode::Interrupt;
    bool automaticFallback_ = true;
    uint32_t conversionEvent_ = kDefaultConversionEvent;
    uint32_t interruptBoundNs_ = kDefaultInterruptBoundNs;

    // Shared with the interrupt service routine; changed with interrupts disabled.
    volatile int8_t pendingInput_ = -1;     // The input being converted, or -1.
    dcos::ObjectId pendingWaiter_{};        // The task that started it.
    volatile uint64_t pendingStartNs_ = 0;  // When it was started.
    volatile uint8_t latched_ = 0;          // Bit n: results_[n] waits for a Read of AIn.
    volatile uint16_t results_[mfio::kAnalogInputs] = {};
    BoardStatistics statistics_{};
};

} // namespace iobus
