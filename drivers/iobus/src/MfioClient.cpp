#include <iobus/MfioClient.hpp>

#include <iobus/MfioRegisters.hpp>

#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>

namespace iobus {

using dcos::Result;
using dcos::Status;
using dcos::systemAgent;

namespace {

// Reads, waits and reads again: one Read to start the conversion, and after
// each wait one more, for an event that arrived late from an earlier call.
constexpr unsigned kMaximumAttempts = 4;
// What the default time-out adds to the driver's bound: a tick and a margin.
constexpr uint64_t kTimeoutMarginNs = 3000000;

} // namespace

Result<uint16_t> readAnalogInput(dcos::ObjectId board, unsigned input, uint64_t timeoutNs, uint32_t event)
{
    if (input >= mfio::kAnalogInputs) {
        return Status::InvalidArgument;
    }
    if (timeoutNs == 0) {
        timeoutNs = MfioBoard::kDefaultInterruptBoundNs + kTimeoutMarginNs;
    }
    uint16_t word = 0;
    for (unsigned attempt = 0; attempt < kMaximumAttempts; ++attempt) {
        const Result<size_t> read = systemAgent.Read(board, channel::kAnalogInput0 + input, &word, sizeof word);
        if (!read.ok()) {
            return read.status();
        }
        if (read.value() == sizeof word) {
            return word;
        }
        const Result<uint32_t> received = dcos::taskAgent.ReceiveEvent(event, dcos::EventWait::Any, timeoutNs);
        if (!received.ok() && received.status() != Status::Timeout) {
            return received.status();
        }
    }
    return Status::Timeout;
}

Result<AnalogValue> readAnalogInputMicrovolts(dcos::ObjectId board, unsigned input)
{
    GainSetting setting{input, 0};
    const Status gain = systemAgent.Control(board, MfioBoard::kGetGain, &setting, sizeof setting);
    if (gain != Status::Ok) {
        return gain;
    }
    const Result<uint16_t> word = readAnalogInput(board, input);
    if (!word.ok()) {
        return word.status();
    }
    return AnalogScaling::adcToMicrovolts(word.value(), AnalogScaling::fromFactor(setting.gain).value());
}

Status setGain(dcos::ObjectId board, unsigned input, uint32_t factor)
{
    GainSetting setting{input, factor};
    return systemAgent.Control(board, MfioBoard::kSetGain, &setting, sizeof setting);
}

Result<uint16_t> readWord(dcos::ObjectId board, uint32_t channel)
{
    uint16_t word = 0;
    const Result<size_t> read = systemAgent.Read(board, channel, &word, sizeof word);
    if (!read.ok()) {
        return read.status();
    }
    if (read.value() != sizeof word) {
        return Status::WouldBlock;
    }
    return word;
}

Status writeWord(dcos::ObjectId board, uint32_t channel, uint16_t value)
{
    const Result<size_t> written = systemAgent.Write(board, channel, &value, sizeof value);
    if (!written.ok()) {
        return written.status();
    }
    return written.value() == sizeof value ? Status::Ok : Status::Busy;
}

} // namespace iobus
