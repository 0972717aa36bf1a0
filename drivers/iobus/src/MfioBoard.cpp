#include <iobus/MfioBoard.hpp>

#include <arch_x86/Cpu.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace iobus {

using dcos::Result;
using dcos::Status;
using namespace mfio;

namespace {

// Every Read and Write of this driver moves one 16-bit word.
constexpr size_t kWordLength = sizeof(uint16_t);

bool isAnalogInput(uint32_t number) { return number < channel::kAnalogInput0 + kAnalogInputs; }

bool isAnalogOutput(uint32_t number)
{
    return number >= channel::kAnalogOutput0 && number < channel::kAnalogOutput0 + kAnalogOutputs;
}

void storeWord(void* buffer, uint16_t word) { *static_cast<uint16_t*>(buffer) = word; }

uint16_t loadWord(const void* buffer) { return *static_cast<const uint16_t*>(buffer); }

// Time elapsed since @p start. The fine uptime is read from the tick timer
// and can step back by less than a tick when the tick's interrupt is still
// pending; such a reading counts as no time passed, never as a huge one.
uint64_t elapsedSince(uint64_t start)
{
    const uint64_t now = dcos::timerAgent.Uptime();
    return now > start ? now - start : 0;
}

template <typename T>
T* argumentAs(void* argument, size_t length)
{
    return length == sizeof(T) && argument != nullptr ? static_cast<T*>(argument) : nullptr;
}

} // namespace

Status MfioBoard::configure(uint16_t base, uint8_t irq)
{
    if (installed()) {
        return Status::Busy;
    }
    if (irq >= IsaResourceManager::kLineCount || uint32_t{base} + kWindowSize > 0x10000u || (base & 1u) != 0) {
        return Status::InvalidArgument;
    }
    base_ = base;
    irq_ = irq;
    chip_ = MfioChip(arch_x86::IoWindow::ports(base, kWindowSize));
    present_ = false;
    boardInitialised_ = false;
    return Status::Ok;
}

Result<dcos::ObjectId> MfioBoard::install(const char* name, dcos::Visibility visibility, IsaConflict* conflict)
{
    if (installed()) {
        return Status::AlreadyExists;
    }
    IsaResourceManager& resources = isaResources();
    const Status reserved = resources.reserve(claimant_, base_, kWindowSize, irq_, conflict);
    if (reserved != Status::Ok) {
        return reserved;
    }
    const Status isr = dcos::systemAgent.InstallISR(irq_, interruptTrampoline, this);
    if (isr != Status::Ok) {
        resources.release(claimant_);
        return isr;
    }
    isrInstalled_ = true;
    const Result<dcos::ObjectId> created = dcos::systemAgent.Create(*this, name, visibility);
    if (!created.ok()) {
        (void)dcos::systemAgent.RemoveISR(irq_);
        isrInstalled_ = false;
        resources.release(claimant_);
        return created.status();
    }
    boardInitialised_ = false;
    // The counters describe this installation: a board object installed
    // again (the console's, a test's) does not carry an earlier one's.
    statistics_ = BoardStatistics{};
    return created;
}

Status MfioBoard::uninstall()
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
    isaResources().release(claimant_);
    return Status::Ok;
}

void MfioBoard::interruptTrampoline(void* context) { static_cast<MfioBoard*>(context)->handleInterrupt(); }

void MfioBoard::handleInterrupt()
{
    ++statistics_.interrupts;
    const uint16_t status = chip_.status();
    if ((status & (kStatusDone | kStatusIrqPending)) == 0) {
        // Not ours, or already collected by a polling Read.
        ++statistics_.spuriousInterrupts;
        return;
    }
    const uint16_t word = chip_.data();
    chip_.acknowledge();
    statistics_.lastInterruptNs = dcos::timerAgent.Uptime();
    deliver(word);
}

// Latches a result and wakes the task that started its conversion. Runs in
// the interrupt service routine or with interrupts disabled.
void MfioBoard::deliver(uint16_t word)
{
    const unsigned input = (word >> kAdcDataChannelShift) & kAdcDataChannelMask;
    results_[input] = word;
    latched_ = static_cast<uint8_t>(latched_ | (1u << input));
    if (pendingInput_ == static_cast<int8_t>(input)) {
        pendingInput_ = -1;
        if (!pendingWaiter_.isNull()) {
            (void)dcos::taskAgent.PostEvent(pendingWaiter_, conversionEvent_);
        }
    }
}

Status MfioBoard::Probe()
{
    const Status status = chip_.probe(identity_);
    present_ = status == Status::Ok;
    return status;
}

void MfioBoard::applyControl()
{
    chip_.setControl(mode_ == ConversionMode::Interrupt && isrInstalled_ && opens_ != 0);
}

void MfioBoard::initialiseBoard()
{
    chip_.reset();
    chip_.writeGains(gains_);
    arch_x86::InterruptGuard guard;
    pendingInput_ = -1;
    latched_ = 0;
}

Status MfioBoard::Open()
{
    if (opens_ == 0) {
        const Status probed = Probe();
        if (probed != Status::Ok) {
            return probed;
        }
        // Only the first open after install resets the board: a reopen
        // must not make the outputs that drive the process jump.
        if (!boardInitialised_) {
            initialiseBoard();
            boardInitialised_ = true;
        }
    }
    ++opens_;
    applyControl();
    return Status::Ok;
}

Status MfioBoard::Close()
{
    if (opens_ == 0) {
        return Status::NotOpen;
    }
    --opens_;
    if (opens_ == 0) {
        applyControl(); // Interrupts off while nobody listens.
        arch_x86::InterruptGuard guard;
        pendingInput_ = -1;
    }
    return Status::Ok;
}

Result<size_t> MfioBoard::Read(uint32_t number, void* buffer, size_t length)
{
    if (number >= channel::kCount) {
        return Status::InvalidArgument;
    }
    if (length != kWordLength) {
        return Status::InvalidArgument;
    }
    uint16_t word = 0;
    if (isAnalogInput(number)) {
        const Result<size_t> read = readAnalogInput(number - channel::kAnalogInput0, word);
        if (!read.ok() || read.value() == 0) {
            return read;
        }
    } else if (isAnalogOutput(number)) {
        word = chip_.dac(number - channel::kAnalogOutput0);
    } else if (number == channel::kDigitalInputs) {
        word = chip_.digitalInputs();
    } else {
        word = chip_.digitalOutputs();
    }
    storeWord(buffer, word);
    return kWordLength;
}

Result<size_t> MfioBoard::readAnalogInput(unsigned input, uint16_t& word)
{
    const uint8_t bit = static_cast<uint8_t>(1u << input);
    {
        arch_x86::InterruptGuard guard;
        if ((latched_ & bit) != 0) {
            latched_ = static_cast<uint8_t>(latched_ & ~bit);
            word = results_[input];
            ++statistics_.conversions;
            statistics_.overranges += (word & kAdcDataOverrange) != 0 ? 1u : 0u;
            return kWordLength;
        }
    }
    if (mode_ == ConversionMode::Polled || !isrInstalled_) {
        return convertPolled(input, word);
    }
    const dcos::ObjectId self = dcos::taskAgent.IdOfSelf();
    {
        arch_x86::InterruptGuard guard;
        const uint64_t now = dcos::timerAgent.Uptime();
        if (pendingInput_ >= 0) {
            if (pendingInput_ != static_cast<int8_t>(input) || pendingWaiter_ != self) {
                return Status::Busy; // Another conversion is on its way.
            }
            if (now <= pendingStartNs_ || now - pendingStartNs_ < interruptBoundNs_) {
                return size_t{0}; // Still converting: wait for the event.
            }
        } else {
            pendingInput_ = static_cast<int8_t>(input);
            pendingWaiter_ = self;
            pendingStartNs_ = now;
            statistics_.lastStartNs = now;
            chip_.startConversion(input);
            return size_t{0};
        }
    }
    return collectMissedInterrupt(input, word);
}

// The interrupt did not come within the bound: fetch the result by polling,
// and fall back to polled mode unless the caller disabled that.
Result<size_t> MfioBoard::collectMissedInterrupt(unsigned input, uint16_t& word)
{
    ++statistics_.missedInterrupts;
    if (automaticFallback_) {
        mode_ = ConversionMode::Polled;
        ++statistics_.fallbacks;
        applyControl();
        if (diagnostics_ != nullptr) {
            runtime::format(*diagnostics_,
                            "iobus: %s: no interrupt on IRQ %u within %lu us; conversions are polled from now on\r\n",
                            claimant_, static_cast<unsigned>(irq_),
                            static_cast<unsigned long>(interruptBoundNs_ / 1000u));
        }
    }
    uint16_t status = 0;
    for (uint32_t poll = 0; poll < kPollLimit; ++poll) {
        status = chip_.status();
        if ((status & kStatusBusy) == 0) {
            break;
        }
    }
    {
        arch_x86::InterruptGuard guard;
        pendingInput_ = -1;
    }
    const uint16_t data = (status & kStatusDone) != 0 ? chip_.data() : 0;
    if ((status & kStatusDone) != 0 && ((data >> kAdcDataChannelShift) & kAdcDataChannelMask) == input) {
        word = data;
        chip_.acknowledge();
        ++statistics_.conversions;
        statistics_.overranges += (word & kAdcDataOverrange) != 0 ? 1u : 0u;
        return kWordLength;
    }
    // No result at all: convert again by polling.
    return convertPolled(input, word);
}

Result<size_t> MfioBoard::convertPolled(unsigned input, uint16_t& word)
{
    const uint64_t start = dcos::timerAgent.Uptime();
    statistics_.lastStartNs = start;
    // A conversion still running (started in interrupt mode) would make the
    // board ignore the start; let it finish first.
    uint32_t poll = 0;
    uint16_t status = chip_.status();
    for (; poll < kPollLimit && (status & kStatusBusy) != 0; ++poll) {
        status = chip_.status();
    }
    if ((status & kStatusBusy) != 0) {
        ++statistics_.timeouts; // The board never finishes: do not even start.
        return Status::Timeout;
    }
    if ((status & kStatusDone) != 0) {
        // A result nobody collected (a conversion that outlived its wait)
        // would be taken for this one: discard it.
        chip_.acknowledge();
    }
    chip_.startConversion(input);
    for (; poll < kPollLimit; ++poll) {
        if ((chip_.status() & kStatusDone) != 0) {
            word = chip_.data();
            chip_.acknowledge();
            ++statistics_.conversions;
            statistics_.overranges += (word & kAdcDataOverrange) != 0 ? 1u : 0u;
            return kWordLength;
        }
        if (elapsedSince(start) > kPollBoundNs) {
            break;
        }
    }
    ++statistics_.timeouts;
    return Status::Timeout;
}

Result<size_t> MfioBoard::Write(uint32_t number, const void* buffer, size_t length)
{
    if (number >= channel::kCount) {
        return Status::InvalidArgument;
    }
    if (isAnalogInput(number) || number == channel::kDigitalInputs) {
        return Status::NotSupported;
    }
    if (length != kWordLength) {
        return Status::InvalidArgument;
    }
    const uint16_t word = loadWord(buffer);
    if (isAnalogOutput(number)) {
        if (word > kCodeMaximum) {
            return Status::InvalidArgument;
        }
        chip_.writeDac(number - channel::kAnalogOutput0, word);
    } else {
        chip_.writeDigitalOutputs(word);
    }
    return kWordLength;
}

Status MfioBoard::Control(uint32_t command, void* argument, size_t length)
{
    switch (command) {
    case kSetGain: {
        GainSetting* setting = argumentAs<GainSetting>(argument, length);
        if (setting == nullptr || setting->channel >= kAnalogInputs) {
            return Status::InvalidArgument;
        }
        const Result<Gain> gain = AnalogScaling::fromFactor(setting->gain);
        if (!gain.ok()) {
            return gain.status();
        }
        const unsigned shift = gainShift(setting->channel);
        gains_ = static_cast<uint16_t>((gains_ & ~(kGainFieldMask << shift)) |
                                       (static_cast<uint16_t>(gain.value()) << shift));
        chip_.writeGains(gains_);
        return Status::Ok;
    }
    case kGetGain: {
        GainSetting* setting = argumentAs<GainSetting>(argument, length);
        if (setting == nullptr || setting->channel >= kAnalogInputs) {
            return Status::InvalidArgument;
        }
        const Gain gain = static_cast<Gain>((gains_ >> gainShift(setting->channel)) & kGainFieldMask);
        setting->gain = AnalogScaling::factor(gain);
        return Status::Ok;
    }
    case kSetMode: {
        const uint32_t* mode = argumentAs<uint32_t>(argument, length);
        if (mode == nullptr || *mode > static_cast<uint32_t>(ConversionMode::Polled)) {
            return Status::InvalidArgument;
        }
        mode_ = static_cast<ConversionMode>(*mode);
        applyControl();
        return Status::Ok;
    }
    case kGetMode: {
        uint32_t* mode = argumentAs<uint32_t>(argument, length);
        if (mode == nullptr) {
            return Status::InvalidArgument;
        }
        *mode = static_cast<uint32_t>(mode_);
        return Status::Ok;
    }
    case kGetStatistics: {
        BoardStatistics* out = argumentAs<BoardStatistics>(argument, length);
        if (out == nullptr) {
            return Status::InvalidArgument;
        }
        arch_x86::InterruptGuard guard;
        *out = statistics_;
        return Status::Ok;
    }
    case kGetInfo: {
        BoardInfo* out = argumentAs<BoardInfo>(argument, length);
        if (out == nullptr) {
            return Status::InvalidArgument;
        }
        *out = BoardInfo{base_, irq_, static_cast<uint8_t>(present_ ? 1 : 0), identity_.id, identity_.revision};
        return Status::Ok;
    }
    case kSetConversionEvent: {
        const uint32_t* events = argumentAs<uint32_t>(argument, length);
        if (events == nullptr || *events == 0) {
            return Status::InvalidArgument;
        }
        conversionEvent_ = *events;
        return Status::Ok;
    }
    case kSetInterruptBound: {
        const uint32_t* bound = argumentAs<uint32_t>(argument, length);
        if (bound == nullptr || *bound == 0) {
            return Status::InvalidArgument;
        }
        interruptBoundNs_ = *bound;
        return Status::Ok;
    }
    case kSetAutomaticFallback: {
        const uint32_t* enable = argumentAs<uint32_t>(argument, length);
        if (enable == nullptr || *enable > 1) {
            return Status::InvalidArgument;
        }
        automaticFallback_ = *enable != 0;
        return Status::Ok;
    }
    case kResetBoard:
        if (length != 0) {
            return Status::InvalidArgument;
        }
        initialiseBoard();
        applyControl();
        return Status::Ok;
    default:
        return Status::NotSupported;
    }
}

} // namespace iobus
