#include <sja1000/Sja1000Controller.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/InstructionCounter.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

#include <string.h>

namespace sja1000 {

using dcos::Result;
using dcos::Status;

namespace {

// The interrupts the controller works with: every one but wake-up, which
// only a sleeping chip raises and the controller never puts the chip to sleep.
constexpr uint8_t kEnabledInterrupts = reg::kInterruptReceive | reg::kInterruptTransmit |
                                       reg::kInterruptErrorWarning | reg::kInterruptDataOverrun |
                                       reg::kInterruptErrorPassive | reg::kInterruptArbitrationLost |
                                       reg::kInterruptBusError;

// The most messages the 64-byte receive FIFO holds (3 bytes each at the
// least, DS 6.4.14): a bound for draining it in one interrupt.
constexpr unsigned kReceiveFifoMessages = 21;

template <class T>
T* argumentAs(void* argument, size_t length)
{
    return length == sizeof(T) && argument != nullptr ? static_cast<T*>(argument) : nullptr;
}

// A frame as a task handed it over: copied, then rebuilt through the
// factories, so that a frame whose bytes were not made by them (an
// identifier too wide, a length above 8, data past the length) is refused
// instead of reaching the chip.
bool rebuild(const void* bytes, can::CanFrame& out)
{
    can::CanFrame raw;
    memcpy(static_cast<void*>(&raw), bytes, sizeof raw);
    const can::LinkResult<can::CanFrame> rebuilt =
        raw.isRemote() ? can::CanFrame::makeRemote(raw.id(), raw.format(), raw.length())
                       : can::CanFrame::makeData(raw.id(), raw.format(), raw.data(),
                                                 raw.length() <= can::CanFrame::kMaxDataLength ? raw.length() : 0xFF);
    if (!rebuilt.ok() || (raw.format() != can::IdFormat::Standard && raw.format() != can::IdFormat::Extended)) {
        return false;
    }
    out = rebuilt.value();
    return true;
}

// The identifier field of a frame as the bus sends it, most significant bit
// first, padded to compare frames of both formats: base identifier, then
// for a standard frame its RTR bit and a dominant IDE; for an extended one
// the recessive SRR and IDE, the 18 identifier extension bits and RTR.
uint64_t arbitrationField(const can::CanFrame& frame)
{
    if (frame.isExtended()) {
        const uint64_t base = frame.id() >> 18;
        const uint64_t extension = frame.id() & 0x3FFFF;
        return (base << 21) | (uint64_t{1} << 20) | (uint64_t{1} << 19) | (extension << 1) |
               (frame.isRemote() ? 1u : 0u);
    }
    return (uint64_t{frame.id()} << 21) | (uint64_t{frame.isRemote() ? 1u : 0u} << 20);
}

} // namespace

bool Sja1000Controller::winsArbitration(const can::CanFrame& a, const can::CanFrame& b)
{
    return arbitrationField(a) < arbitrationField(b);
}

Result<dcos::ObjectId> Sja1000Controller::installController(const char* name, dcos::Visibility visibility)
{
    if (installed()) {
        return Status::AlreadyExists;
    }
    const Result<BitTiming> timing = BitTimingCalculator::forBitRate(kDefaultBitRate, oscillatorHz_);
    if (!timing.ok()) {
        return timing.status();
    }
    const Status isr = dcos::systemAgent.InstallISR(irq_, interruptTrampoline, this);
    if (isr != Status::Ok) {
        return isr;
    }
    isrInstalled_ = true;
    const Result<dcos::ObjectId> created = dcos::systemAgent.Create(*this, name, visibility);
    if (!created.ok()) {
        (void)dcos::systemAgent.RemoveISR(irq_);
        isrInstalled_ = false;
        return created.status();
    }
    // Everything below describes this installation only.
    timing_ = timing.value();
    filter_ = AcceptanceFilter::all();
    busMode_ = BusMode::Normal;
    busOffPolicy_ = BusOffPolicy::RestartAtOnce;
    notification_ = Notification{};
    statistics_ = ChannelStatistics{};
    transmitCount_ = 0;
    inChip_ = false;
    abortRequested_ = false;
    receiveHead_ = 0;
    receiveCount_ = 0;
    noAcknowledge_ = false;
    acknowledgeErrorsInARow_ = 0;
    errorState_ = ErrorState::Active;
    stateLogHead_ = 0;
    stateLogCount_ = 0;
    stateLogLost_ = 0;
    return created;
}

Status Sja1000Controller::uninstallController()
{
    if (!installed()) {
        return Status::NotFound;
    }
    const Status deleted = dcos::systemAgent.Delete(id());
    if (deleted != Status::Ok) {
        return deleted;
    }
    if (isrInstalled_) {
        (void)dcos::systemAgent.RemoveISR(irq_);
        isrInstalled_ = false;
    }
    return Status::Ok;
}

void Sja1000Controller::interruptTrampoline(void* context)
{
    static_cast<Sja1000Controller*>(context)->handleInterrupt();
}

Status Sja1000Controller::Probe() { return chip_.probe(); }

Status Sja1000Controller::Open()
{
    if (opens_ == 0) {
        const Status probed = chip_.probe();
        if (probed != Status::Ok) {
            return probed;
        }
        const Status started = startChip();
        if (started != Status::Ok) {
            return started;
        }
    }
    ++opens_;
    return Status::Ok;
}

Status Sja1000Controller::Close()
{
    if (opens_ == 0) {
        return Status::NotOpen;
    }
    if (--opens_ == 0) {
        // Off the bus while nobody uses the channel; what was queued is dropped.
        stopChip();
        arch_x86::InterruptGuard guard;
        transmitCount_ = 0;
        inChip_ = false;
        abortRequested_ = false;
    }
    return Status::Ok;
}

Status Sja1000Controller::startChip()
{
    if (chip_.enterReset() != Status::Ok) {
        return Status::Busy;
    }
    arch_x86::InterruptGuard guard;
    started_ = false;
    const Status configured = chip_.configure(timing_, filter_, kEnabledInterrupts);
    if (configured != Status::Ok) {
        return configured;
    }
    takeBackFromChip();
    const Status started = chip_.start(busMode_);
    if (started != Status::Ok) {
        return started;
    }
    started_ = true;
    acknowledgeErrorsInARow_ = 0;
    // The counters were cleared: a channel that was not error-active is
    // again, and its owner learns of it as of any other change.
    const ErrorState previous = errorState_;
    errorState_ = ErrorState::Active;
    if (previous != ErrorState::Active) {
        recordStateChange(previous, ErrorState::Active);
        ++statistics_.errorActives;
        if (previous == ErrorState::BusOff) {
            ++statistics_.recoveries;
        }
        notify(notification_.stateEvent);
    }
    loadNext();
    return Status::Ok;
}

void Sja1000Controller::stopChip()
{
    (void)chip_.enterReset(); // A chip that does not follow is off the bus for us all the same.
    arch_x86::InterruptGuard guard;
    started_ = false;
}

Result<size_t> Sja1000Controller::Read(uint32_t channel, void* buffer, size_t length)
{
    const bool timed = channel == kTimedChannel;
    const size_t size = timed ? sizeof(TimedFrame) : sizeof(can::CanFrame);
    if ((channel != kFrameChannel && !timed) || length % size != 0) {
        return Status::InvalidArgument;
    }
    auto* out = static_cast<uint8_t*>(buffer);
    size_t copied = 0;
    const size_t wanted = length / size;
    arch_x86::InterruptGuard guard;
    while (copied < wanted && receiveCount_ != 0) {
        const TimedFrame& entry = receive_[receiveHead_];
        receiveHead_ = (receiveHead_ + 1) % kReceiveQueueLength;
        --receiveCount_;
        if (timed) {
            memcpy(out + copied * size, static_cast<const void*>(&entry), size);
        } else if ((entry.flags & TimedFrame::kEcho) == 0) {
            memcpy(out + copied * size, static_cast<const void*>(&entry.frame), size);
        } else {
            continue; // An echo is only for the timed channel's reader.
        }
        ++copied;
    }
    return copied * size;
}

Result<size_t> Sja1000Controller::Write(uint32_t channel, const void* buffer, size_t length)
{
    if ((channel != kFrameChannel && channel != kTimedChannel) || length % sizeof(can::CanFrame) != 0) {
        return Status::InvalidArgument;
    }
    const auto* in = static_cast<const uint8_t*>(buffer);
    const size_t count = length / sizeof(can::CanFrame);
    // Every frame is checked before any is queued: a bad one refuses the
    // whole write, so the caller never has to find out which were sent.
    for (size_t i = 0; i < count; ++i) {
        can::CanFrame frame;
        if (!rebuild(in + i * sizeof(can::CanFrame), frame)) {
            return Status::InvalidArgument;
        }
    }
    size_t taken = 0;
    arch_x86::InterruptGuard guard;
    for (; taken < count; ++taken) {
        can::CanFrame frame;
        (void)rebuild(in + taken * sizeof(can::CanFrame), frame); // Checked above.
        if (!enqueue(frame, channel == kTimedChannel)) {
            break;
        }
    }
    // Writing again is how a task says it wants another try after the
    // lone-node hold.
    if (noAcknowledge_) {
        releaseHold();
    }
    loadNext();
    return taken * sizeof(can::CanFrame);
}

bool Sja1000Controller::enqueue(const can::CanFrame& frame, bool echo)
{
    if (transmitCount_ == kTransmitQueueLength) {
        return false;
    }
    // After every frame that wins over it or ties with it: the queue stays
    // in arbitration order and frames with one identifier keep their order.
    // The frame in the chip (index 0) is never moved behind.
    size_t position = transmitCount_;
    while (position > (inChip_ ? 1u : 0u) && winsArbitration(frame, transmit_[position - 1].frame)) {
        transmit_[position] = transmit_[position - 1];
        --position;
    }
    transmit_[position] = {frame, echo};
    ++transmitCount_;
    // A more urgent frame than the one in the chip takes its place on the
    // bus: the chip aborts a frame not yet under way and raises TI.
    if (inChip_ && !abortRequested_ && position == 1 && winsArbitration(frame, transmit_[0].frame)) {
        chip_.abortTransmission();
        abortRequested_ = true;
    }
    return true;
}

// Moves the next frame into the chip when its transmit buffer is free and
// nothing holds the queue. Runs with interrupts disabled.
void Sja1000Controller::loadNext()
{
    if (!started_ || inChip_ || transmitCount_ == 0 || noAcknowledge_ || errorState_ == ErrorState::BusOff ||
        busMode_ == BusMode::ListenOnly) {
        return;
    }
    if ((chip_.status() & reg::kStatusTransmitBuffer) == 0) {
        return; // Still busy with an earlier request; TI will call again.
    }
    chip_.writeTransmitBuffer(transmit_[0].frame);
    chip_.transmit();
    inChip_ = true;
}

// Moves the head of the queue behind every frame that wins over it, so a
// frame taken back from the chip stays first among its equals only.
void Sja1000Controller::settleHead()
{
    for (size_t i = 0; i + 1 < transmitCount_ && winsArbitration(transmit_[i + 1].frame, transmit_[i].frame); ++i) {
        const Outgoing displaced = transmit_[i];
        transmit_[i] = transmit_[i + 1];
        transmit_[i + 1] = displaced;
    }
}

// After a reset the chip's transmit buffer is empty: a frame that was in it
// stays in the queue, in its place by identifier, unless it was flushed.
void Sja1000Controller::takeBackFromChip()
{
    if (!inChip_) {
        return;
    }
    inChip_ = false;
    abortRequested_ = false;
    if (dropInChip_) {
        dropInChip_ = false;
        removeHead();
    }
    settleHead();
}

void Sja1000Controller::removeHead()
{
    for (size_t i = 1; i < transmitCount_; ++i) {
        transmit_[i - 1] = transmit_[i];
    }
    --transmitCount_;
}

void Sja1000Controller::onTransmitDone(uint64_t now)
{
    if (!inChip_) {
        return;
    }
    const bool completed = (chip_.status() & reg::kStatusTransmitComplete) != 0;
    const bool displaced = abortRequested_;
    inChip_ = false;
    abortRequested_ = false;
    if (completed) {
        dropInChip_ = false;
        acknowledgeErrorsInARow_ = 0;
        const Outgoing sent = transmit_[0];
        removeHead();
        ++statistics_.framesSent;
        notify(notification_.sentEvent);
        if (sent.echo && keep(sent.frame, TimedFrame::kEcho, now)) {
            notify(notification_.receiveEvent);
        }
        return;
    }
    if (dropInChip_) {
        dropInChip_ = false; // Flushed while in the chip, and the abort took it back.
        removeHead();
        return;
    }
    if (displaced) {
        // Taken back for a more urgent frame, which goes first now.
        ++statistics_.aborts;
        settleHead();
    }
    // Otherwise aborted for the lone-node hold: it stays first in the queue.
}

// Puts a frame into the receive ring; false when the ring is full (the
// newest is lost: the readers have the older ones in order).
bool Sja1000Controller::keep(const can::CanFrame& frame, uint32_t flags, uint64_t now)
{
    if (receiveCount_ == kReceiveQueueLength) {
        ++statistics_.receiveQueueOverruns;
        return false;
    }
    TimedFrame& entry = receive_[(receiveHead_ + receiveCount_) % kReceiveQueueLength];
    entry.frame = frame;
    entry.flags = flags;
    entry.timeNs = now;
    ++receiveCount_;
    return true;
}

void Sja1000Controller::onReceive(uint64_t now)
{
    bool received = false;
    for (unsigned n = 0; n < kReceiveFifoMessages && (chip_.status() & reg::kStatusReceiveBuffer) != 0; ++n) {
        const can::LinkResult<can::CanFrame> frame = chip_.readReceiveBuffer();
        if (!frame.ok()) {
            ++statistics_.malformedFrames;
            continue;
        }
        if (!filter_.takesFormat(frame.value().isExtended())) {
            // The chip's filter cannot tell the formats apart (AcceptanceFilter).
            ++statistics_.badIdentifiers;
            continue;
        }
        ++statistics_.framesReceived;
        received = true;
        (void)keep(frame.value(), 0, now);
    }
    if (received) {
        // Another node is on the bus: a held queue may try again.
        if (noAcknowledge_) {
            releaseHold();
        }
        notify(notification_.receiveEvent);
    }
}

void Sja1000Controller::onBusError()
{
    const uint8_t code = chip_.errorCode();
    ++statistics_.busErrors;
    const bool transmitting = (code & reg::kEccDirectionReceive) == 0;
    if (!transmitting || (code & reg::kEccSegmentMask) != reg::kEccSegmentAckSlot) {
        return;
    }
    ++statistics_.acknowledgeErrors;
    if (++acknowledgeErrorsInARow_ >= kLoneNodeAttempts && inChip_ && !noAcknowledge_) {
        // Nobody takes our frames: stop repeating them before they fill the bus.
        noAcknowledge_ = true;
        ++statistics_.loneNodeHolds;
        if (!abortRequested_) {
            chip_.abortTransmission();
        }
        recordStateChange(errorState_, errorState_, true);
        notify(notification_.stateEvent);
    }
}

void Sja1000Controller::onStateChange()
{
    const ErrorState state = chip_.errorState();
    if (state == errorState_) {
        return;
    }
    const ErrorState previous = errorState_;
    errorState_ = state;
    recordStateChange(previous, state);
    if (previous == ErrorState::BusOff) {
        // The chip counted its 128 bus-free signals: it is on the bus again.
        ++statistics_.recoveries;
    }
    if (state == ErrorState::Active) {
        ++statistics_.errorActives;
    } else if (state == ErrorState::Warning) {
        ++statistics_.errorWarnings;
    } else if (state == ErrorState::Passive) {
        ++statistics_.errorPassives;
    } else if (state == ErrorState::BusOff) {
        ++statistics_.busOffs;
        // The chip has gone to reset mode and emptied its transmit buffer.
        takeBackFromChip();
        if (busOffPolicy_ == BusOffPolicy::RestartAtOnce && chip_.start(busMode_) == Status::Ok) {
            ++statistics_.restarts;
            // Error-active again only after the 128 x 11 recessive bits; the
            // chip reports it with EI, and the queue waits until then.
        }
    }
    notify(notification_.stateEvent);
}

void Sja1000Controller::recordStateChange(ErrorState from, ErrorState to, bool holdChanged)
{
    const ErrorCounters counters = chip_.errorCounters();
    if (stateLogCount_ == StateChanges::kCapacity) {
        // The owner has not read for a while: the oldest change goes, and it is counted.
        stateLogHead_ = (stateLogHead_ + 1) % StateChanges::kCapacity;
        --stateLogCount_;
        ++stateLogLost_;
        ++statistics_.stateChangesLost;
    }
    stateLog_[(stateLogHead_ + stateLogCount_) % StateChanges::kCapacity] =
        StateChange{from, to, counters.receive, counters.transmit, static_cast<uint8_t>(holdChanged ? 1 : 0),
                    static_cast<uint8_t>(noAcknowledge_ ? 1 : 0)};
    ++stateLogCount_;
}

void Sja1000Controller::releaseHold()
{
    noAcknowledge_ = false;
    acknowledgeErrorsInARow_ = 0;
    recordStateChange(errorState_, errorState_, true);
    notify(notification_.stateEvent);
}

void Sja1000Controller::notify(uint32_t events)
{
    if (events != 0 && !notification_.task.isNull()) {
        // A task that has gone away simply is not told.
        (void)dcos::taskAgent.PostEvent(notification_.task, events);
    }
}

void Sja1000Controller::handleInterrupt()
{
    // In an image with an instruction counter (the remote bench's,
    // docs/performance.md), the counter is read before anything else, so
    // that the routine's own count and the stamp of the frames it keeps
    // cover all of it. Every other image pays a compare and a branch here
    // and at the end, and one OR per cause.
    if (arch_x86::hasInstructionCounter()) {
        countStart_ = dcosInstructionCount();
        countKeptBefore_ = receiveCount_;
    }
    // First, before the chip is even read: the closer to the frame's end on
    // the bus, the closer two nodes' stamps of it (docs/protocols/time.md).
    const uint64_t now = dcos::TimerAgent::Uptime();
    ++statistics_.interrupts;
    uint8_t seen = 0;
    unsigned handled = 0;
    for (; handled < kInterruptLoopBound; ++handled) {
        const uint8_t causes = chip_.interrupts();
        if ((causes & kEnabledInterrupts) == 0) {
            break;
        }
        seen |= causes;
        if ((causes & reg::kInterruptDataOverrun) != 0) {
            ++statistics_.chipOverruns;
            chip_.clearOverrun();
        }
        if ((causes & reg::kInterruptReceive) != 0) {
            onReceive(now);
        }
        if ((causes & reg::kInterruptArbitrationLost) != 0) {
            (void)chip_.arbitrationLostBit(); // Frees ALC for the next loss.
            ++statistics_.arbitrationLost;
        }
        // The state first: a bus error that begins the lone-node hold is
        // then logged for the owner with the state it brought about.
        if ((causes & (reg::kInterruptErrorWarning | reg::kInterruptErrorPassive)) != 0) {
            onStateChange();
        }
        if ((causes & reg::kInterruptBusError) != 0) {
            onBusError();
        }
        if ((causes & reg::kInterruptTransmit) != 0) {
            onTransmitDone(now);
        }
        loadNext();
    }
    if (handled == kInterruptLoopBound) {
        ++statistics_.interruptLoopLimits;
    }
    if (arch_x86::hasInstructionCounter()) {
        finishCountedInterrupt(seen);
    }
}

void Sja1000Controller::finishCountedInterrupt(uint8_t seen)
{
    // The routine's count is read first, so that this bookkeeping, which
    // only a counting image does, stays out of it.
    const uint64_t end = arch_x86::instructionCount();
    if (countStart_ == 0) {
        return; // The processor has no time-stamp counter.
    }
    // One received frame and nothing else: the figure the remote bench
    // reports beside a transaction's.
    if ((seen & kEnabledInterrupts) == reg::kInterruptReceive && receiveCount_ - countKeptBefore_ == 1) {
        statistics_.receiveInterruptInstructions = static_cast<uint32_t>(end - countStart_);
    }
    // The frames kept carry the routine's start, from which the remote
    // agent counts a transaction's work on this node; moved on by what this
    // bookkeeping has cost so far, so that a transaction's count leaves it
    // out as the routine's does, and counts about what a production image
    // runs.
    const uint64_t stamp = countStart_ + (arch_x86::instructionCount() - end);
    for (size_t i = countKeptBefore_; i < receiveCount_; ++i) {
        receive_[(receiveHead_ + i) % kReceiveQueueLength].instructionStamp = stamp;
    }
}

Status Sja1000Controller::Control(uint32_t command, void* argument, size_t length)
{
    switch (command) {
    case kSetBitRate: {
        const uint32_t* rate = argumentAs<uint32_t>(argument, length);
        if (rate == nullptr) {
            return Status::InvalidArgument;
        }
        const Result<BitTiming> timing = BitTimingCalculator::forBitRate(*rate, oscillatorHz_);
        if (!timing.ok()) {
            return Status::InvalidArgument;
        }
        timing_ = timing.value();
        return started_ ? startChip() : Status::Ok;
    }
    case kSetFilter: {
        const AcceptanceFilter* filter = argumentAs<AcceptanceFilter>(argument, length);
        if (filter == nullptr || static_cast<uint8_t>(filter->formats) > static_cast<uint8_t>(FrameFormats::Standard)) {
            return Status::InvalidArgument;
        }
        filter_ = *filter;
        return started_ ? startChip() : Status::Ok;
    }
    case kSetBusMode: {
        const uint32_t* mode = argumentAs<uint32_t>(argument, length);
        if (mode == nullptr || *mode > static_cast<uint32_t>(BusMode::SelfTest)) {
            return Status::InvalidArgument;
        }
        busMode_ = static_cast<BusMode>(*mode);
        return started_ ? startChip() : Status::Ok;
    }
    case kGetState: {
        BusState* out = argumentAs<BusState>(argument, length);
        if (out == nullptr) {
            return Status::InvalidArgument;
        }
        const ErrorCounters counters = chip_.errorCounters();
        arch_x86::InterruptGuard guard;
        out->errorState = errorState_;
        out->receiveErrors = counters.receive;
        out->transmitErrors = counters.transmit;
        out->started = started_ ? 1 : 0;
        out->noAcknowledge = noAcknowledge_ ? 1 : 0;
        out->bitRate = timing_.bitRate;
        out->samplePointPermille = timing_.samplePointPermille;
        out->queued = static_cast<uint16_t>(transmitCount_);
        return Status::Ok;
    }
    case kGetStatistics: {
        ChannelStatistics* out = argumentAs<ChannelStatistics>(argument, length);
        if (out == nullptr) {
            return Status::InvalidArgument;
        }
        arch_x86::InterruptGuard guard;
        *out = statistics_;
        return Status::Ok;
    }
    case kSetNotification: {
        const Notification* wanted = argumentAs<Notification>(argument, length);
        if (wanted == nullptr) {
            return Status::InvalidArgument;
        }
        arch_x86::InterruptGuard guard;
        notification_ = *wanted;
        return Status::Ok;
    }
    case kSetBusOffPolicy: {
        const uint32_t* policy = argumentAs<uint32_t>(argument, length);
        if (policy == nullptr || *policy > static_cast<uint32_t>(BusOffPolicy::WaitForRestart)) {
            return Status::InvalidArgument;
        }
        busOffPolicy_ = static_cast<BusOffPolicy>(*policy);
        return Status::Ok;
    }
    case kRestart: {
        if (length != 0) {
            return Status::InvalidArgument;
        }
        arch_x86::InterruptGuard guard;
        if (noAcknowledge_) {
            releaseHold();
        }
        ++statistics_.restarts;
        if (started_ && errorState_ == ErrorState::BusOff && chip_.inReset()) {
            // Leaving reset mode with the counters as the chip left them
            // begins its own recovery: ISO 11898-1 lets a bus-off node back
            // only after 128 times 11 recessive bits, and writing the
            // counters now would cut that short (DS 6.4.11). The chip
            // reports the end of it with EI, and the queue waits until then.
            return chip_.start(busMode_);
        }
        return startChip();
    }
    case kReadStateChanges: {
        StateChanges* out = argumentAs<StateChanges>(argument, length);
        if (out == nullptr) {
            return Status::InvalidArgument;
        }
        arch_x86::InterruptGuard guard;
        out->count = static_cast<uint32_t>(stateLogCount_);
        out->lost = stateLogLost_;
        for (size_t i = 0; i < stateLogCount_; ++i) {
            out->changes[i] = stateLog_[(stateLogHead_ + i) % StateChanges::kCapacity];
        }
        stateLogHead_ = 0;
        stateLogCount_ = 0;
        stateLogLost_ = 0;
        return Status::Ok;
    }
    case kFlushTransmit: {
        if (length != 0) {
            return Status::InvalidArgument;
        }
        arch_x86::InterruptGuard guard;
        if (inChip_ && !abortRequested_) {
            chip_.abortTransmission();
            abortRequested_ = true;
        }
        // The frame in the chip, if any, stays until TI says whether it went.
        transmitCount_ = inChip_ ? 1 : 0;
        dropInChip_ = inChip_;
        return Status::Ok;
    }
    default:
        return Status::NotSupported;
    }
}

} // namespace sja1000
