// Fuzz target: what an MCP2221A (or something that claims to be one)
// answers dcos-flash --recover (host_tools/flash/src/Mcp2221.cpp): the
// input is one input report, read as the reply to each command the tool
// sends, and then, split into replies of the lengths its first bytes say,
// as the whole conversation of Mcp2221Lines::configure and a strap change
// against a scripted device.
//
// The checks: a reply is accepted only at 64 bytes or more with the
// command echoed and the status completed; a refusal always says why; a
// GET GPIO VALUES reply that is accepted gives levels and directions only
// for pins that are GPIOs; a conversation that is refused at any step has
// a message, and one that succeeds leaves both lines GPIO outputs as the
// chip's own reply said.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostflash/Mcp2221.hpp>
#include <hostflash/Mcp2221Lines.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

using namespace hostflash;
using namespace hostflash::mcp2221;

namespace {

// A device whose replies are the fuzzer's bytes, in turn.
class ScriptedDevice final : public HidDevice {
public:
    explicit ScriptedDevice(std::vector<std::vector<uint8_t>> replies) : replies_(std::move(replies)) {}

    bool write(const Report&, std::string&) override { return true; }

    int read(uint8_t* buffer, size_t capacity, std::chrono::milliseconds, std::string&) override
    {
        if (next_ >= replies_.size()) {
            return 0;
        }
        const std::vector<uint8_t>& reply = replies_[next_++];
        const size_t length = std::min(capacity, reply.size());
        if (length != 0) {
            std::memcpy(buffer, reply.data(), length);
        }
        return static_cast<int>(length);
    }

private:
    std::vector<std::vector<uint8_t>> replies_;
    size_t next_ = 0;
};

void checkOneReply(const uint8_t* data, size_t size)
{
    for (const Command command : {Command::StatusSetParameters, Command::SetGpioOutputValues, Command::GetGpioValues,
                                  Command::SetSramSettings, Command::GetSramSettings}) {
        const ReplyCheck check = checkReply(command, data, size);
        FUZZ_CHECK(check.ok() == (size >= kReportSize && data[0] == static_cast<uint8_t>(command) && data[1] == 0));
        FUZZ_CHECK(check.ok() || !check.detail.empty());
    }
    GpioValues values;
    const ReplyCheck gpio = readGpioValues(data, size, values);
    FUZZ_CHECK(gpio.ok() || !gpio.detail.empty());
    if (gpio.ok()) {
        for (unsigned pin = 0; pin < kPinCount; ++pin) {
            const uint8_t value = data[kGetGpioFirst + kGetGpioStride * pin];
            FUZZ_CHECK(values.pins[pin].gpio == (value != kNotGpioValue));
            FUZZ_CHECK(!values.pins[pin].gpio || values.pins[pin].high == (value == 1));
        }
    }
    std::array<uint8_t, kPinCount> settings{};
    const ReplyCheck sram = readSramGpioSettings(data, size, settings);
    FUZZ_CHECK(!sram.ok() || std::equal(settings.begin(), settings.end(), data + kGetSramGpioFirst));
    for (unsigned pin = 0; pin < kPinCount + 1; ++pin) {
        const ReplyCheck set = readSetPinReply(data, size, pin);
        FUZZ_CHECK(set.ok() || !set.detail.empty());
        FUZZ_CHECK(!set.ok() || pin < kPinCount);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    checkOneReply(data, size);

    // The conversation: each reply's length is its first byte (0 to 255,
    // so short, whole and long replies all occur), then that many bytes.
    std::vector<std::vector<uint8_t>> replies;
    for (size_t at = 0; at < size && replies.size() < 8;) {
        const size_t length = data[at++];
        const size_t take = std::min(length, size - at);
        replies.emplace_back(data + at, data + at + take);
        at += take;
    }
    ScriptedDevice device(replies);
    Mcp2221Lines lines(device, LineWiring{0, 1});
    LineResult result = lines.configure();
    FUZZ_CHECK(result.ok() || !result.message.empty());
    if (result.ok()) {
        // The third reply, GET GPIO VALUES, said both lines are released outputs.
        FUZZ_CHECK(replies.size() >= 3 && replies[2].size() >= kReportSize);
        FUZZ_CHECK(replies[2][2] == 1 && replies[2][3] == kDirectionOutput);
        FUZZ_CHECK(replies[2][4] == 1 && replies[2][5] == kDirectionOutput);
        result = lines.setStrap(true);
        FUZZ_CHECK(result.ok() || !result.message.empty());
    }
    return 0;
}
