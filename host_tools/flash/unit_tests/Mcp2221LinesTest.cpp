// The MCP2221A's GPIO reports (hostflash/Mcp2221.hpp) and the reset and
// strap sequence of dcos-flash --recover (hostflash/Mcp2221Lines.hpp),
// against a fake chip that answers as the data sheet (DS20005565B, 3.1.11
// to 3.1.14) says, and that can answer wrongly on purpose.
#include <hostflash/Mcp2221.hpp>
#include <hostflash/Mcp2221Lines.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <deque>
#include <optional>
#include <vector>

namespace {

using namespace hostflash;
using namespace hostflash::mcp2221;

// A fake MCP2221A: four GP settings (designation, direction, value) and
// every request kept; a fault replaces the next reply.
class FakeMcp2221 final : public HidDevice {
public:
    enum class Fault { None, Short, WrongCommand, Failed, Silent, WriteFails, NotGpio };

    FakeMcp2221()
    {
        for (auto& pin : pins) {
            pin = Pin{};
        }
    }

    struct Pin {
        uint8_t designation = kDesignationGpio;
        bool output = false;
        bool high = true;
    };

    bool write(const Report& report, std::string& why) override
    {
        requests.push_back(report);
        // The fault hits the reply to the request @p faultAfter requests after its injection.
        const Fault active = faultAfter == 0 ? fault : Fault::None;
        if (faultAfter > 0) {
            --faultAfter;
        } else if (fault != Fault::NotGpio) {
            fault = Fault::None; // NotGpio stays: the pin is no GPIO from then on.
        }
        if (active == Fault::WriteFails) {
            why = "the device went away";
            return false;
        }
        Report reply{};
        reply[0] = report[0];
        switch (static_cast<Command>(report[0])) {
        case Command::GetSramSettings:
            for (unsigned i = 0; i < kPinCount; ++i) {
                reply[kGetSramGpioFirst + i] = static_cast<uint8_t>(
                    pins[i].designation | (pins[i].output ? 0 : kGpSettingInput) | (pins[i].high ? kGpSettingOutputHigh : 0));
            }
            break;
        case Command::SetSramSettings:
            if (report[kSetSramAlterGpio] & kAlterGpioConfiguration) {
                for (unsigned i = 0; i < kPinCount; ++i) {
                    const uint8_t setting = report[kSetSramGpioFirst + i];
                    pins[i].designation = setting & kGpSettingDesignationMask;
                    pins[i].output = (setting & kGpSettingInput) == 0;
                    pins[i].high = (setting & kGpSettingOutputHigh) != 0;
                }
            }
            break;
        case Command::SetGpioOutputValues:
            for (unsigned i = 0; i < kPinCount; ++i) {
                const size_t at = kSetGpioFirst + kSetGpioStride * i;
                const bool gpio = pins[i].designation == kDesignationGpio && !(active == Fault::NotGpio && i == 1);
                if (!gpio) {
                    std::memset(&reply[at], kNotGpioValue, kSetGpioStride);
                    continue;
                }
                if (report[at + 2] == 1) {
                    pins[i].output = report[at + 3] == kDirectionOutput;
                }
                if (report[at] == 1) {
                    pins[i].high = report[at + 1] != 0;
                }
                std::memcpy(&reply[at], &report[at], kSetGpioStride);
            }
            levels.push_back({pins[0].high, pins[1].high});
            break;
        case Command::GetGpioValues:
            for (unsigned i = 0; i < kPinCount; ++i) {
                const size_t at = kGetGpioFirst + kGetGpioStride * i;
                if (pins[i].designation != kDesignationGpio) {
                    reply[at] = kNotGpioValue;
                    reply[at + 1] = kNotGpioDirection;
                } else {
                    reply[at] = pins[i].high ? 1 : 0;
                    reply[at + 1] = pins[i].output ? kDirectionOutput : kDirectionInput;
                }
            }
            break;
        default:
            reply[1] = 0xFF;
            break;
        }
        size_t length = kReportSize;
        switch (active) {
        case Fault::Short: length = 8; break;
        case Fault::WrongCommand: reply[0] = 0x11; break;
        case Fault::Failed: reply[1] = 0x01; break;
        case Fault::Silent: length = 0; break;
        default: break;
        }
        replies.push_back(std::vector<uint8_t>(reply.begin(), reply.begin() + static_cast<long>(length)));
        return true;
    }

    int read(uint8_t* buffer, size_t capacity, std::chrono::milliseconds, std::string&) override
    {
        if (replies.empty()) {
            return 0;
        }
        const std::vector<uint8_t> reply = replies.front();
        replies.pop_front();
        const size_t length = std::min(capacity, reply.size());
        if (length != 0) {
            std::memcpy(buffer, reply.data(), length);
        }
        return static_cast<int>(length);
    }

    // Injects @p kind into the reply to the request after @p after more.
    void inject(Fault kind, int after = 0)
    {
        fault = kind;
        faultAfter = after;
    }

    Pin pins[kPinCount];
    std::vector<Report> requests;
    std::deque<std::vector<uint8_t>> replies;
    std::vector<std::pair<bool, bool>> levels; // GP0 and GP1 after each SET GPIO OUTPUT VALUES.
    Fault fault = Fault::None;
    int faultAfter = 0;
};

TEST(Mcp2221Reports, SetPinAltersOnlyThatPinsValueAndDirection)
{
    const Report report = setPin(1, false, true);
    Report expected{};
    expected[0] = 0x50;
    expected[6] = 1;    // GP1: alter output
    expected[7] = 0;    // low
    expected[8] = 1;    // alter direction
    expected[9] = 0x00; // output
    EXPECT_EQ(report, expected);
    EXPECT_EQ(setPin(3, true, false)[14], 1);
    EXPECT_EQ(setPin(3, true, false)[15], 1);
    EXPECT_EQ(setPin(3, true, false)[16], 0);
}

TEST(Mcp2221Reports, DesignationsMakeTheLinesReleasedGpioOutputsAndKeepTheOtherPins)
{
    const Report report = setGpioDesignations({0x08, 0x01, 0x02, 0x0B}, 0x03);
    EXPECT_EQ(report[0], 0x60);
    EXPECT_EQ(report[7], 0x80);
    EXPECT_EQ(report[8], 0x10);
    EXPECT_EQ(report[9], 0x10);
    EXPECT_EQ(report[10], 0x02);
    EXPECT_EQ(report[11], 0x0B);
    for (size_t i = 2; i < 7; ++i) {
        EXPECT_EQ(report[i], 0) << "byte " << i << " would alter a chip setting";
    }
}

TEST(Mcp2221Reports, RepliesAreRefusedShortToAnotherCommandOrFailed)
{
    uint8_t reply[kReportSize] = {0x51, 0x00};
    EXPECT_TRUE(checkReply(Command::GetGpioValues, reply, sizeof reply).ok());
    const ReplyCheck shortReply = checkReply(Command::GetGpioValues, reply, 63);
    EXPECT_EQ(shortReply.error, ReplyError::Short);
    EXPECT_EQ(shortReply.detail, "the MCP2221A answered GET GPIO VALUES (0x51) with 63 bytes, not 64");
    EXPECT_EQ(checkReply(Command::SetGpioOutputValues, reply, sizeof reply).error, ReplyError::WrongCommand);
    reply[1] = 0x41;
    const ReplyCheck failed = checkReply(Command::GetGpioValues, reply, sizeof reply);
    EXPECT_EQ(failed.error, ReplyError::Failed);
    EXPECT_EQ(failed.detail, "the MCP2221A did not complete GET GPIO VALUES (0x51): status 0x41");
    EXPECT_EQ(checkReply(Command::GetGpioValues, nullptr, 0).error, ReplyError::Short);
}

TEST(Mcp2221Reports, GpioValuesAreReadPerPinAndNonsenseIsRefused)
{
    uint8_t reply[kReportSize] = {0x51, 0x00, 1, 0, 0, 0, 0xEE, 0xEF, 0, 1};
    GpioValues values;
    ASSERT_TRUE(readGpioValues(reply, sizeof reply, values).ok());
    EXPECT_TRUE(values.pins[0].gpio && values.pins[0].output && values.pins[0].high);
    EXPECT_TRUE(values.pins[1].gpio && values.pins[1].output && !values.pins[1].high);
    EXPECT_FALSE(values.pins[2].gpio);
    EXPECT_TRUE(values.pins[3].gpio && !values.pins[3].output);
    reply[7] = 0;  // GP2: "not a GPIO" value with a GPIO's direction
    EXPECT_EQ(readGpioValues(reply, sizeof reply, values).error, ReplyError::Inconsistent);
    reply[6] = 7;  // GP2: a level of 7
    EXPECT_EQ(readGpioValues(reply, sizeof reply, values).error, ReplyError::Inconsistent);
}

TEST(Mcp2221Reports, ASetPinReplyForAPinThatIsNoGpioIsRefused)
{
    uint8_t reply[kReportSize] = {0x50, 0x00};
    EXPECT_TRUE(readSetPinReply(reply, sizeof reply, 2).ok());
    reply[10] = kNotGpioValue;
    reply[11] = kNotGpioValue;
    EXPECT_EQ(readSetPinReply(reply, sizeof reply, 2).error, ReplyError::NotGpio);
    EXPECT_EQ(readSetPinReply(reply, sizeof reply, 4).error, ReplyError::Inconsistent);
}

TEST(Mcp2221Lines, ConfigureMakesBothLinesReleasedOutputsFromAlternateFunctions)
{
    FakeMcp2221 chip;
    chip.pins[0].designation = 1; // SSPND, say: not a GPIO until configured
    chip.pins[2].designation = 2;
    Mcp2221Lines lines(chip, LineWiring{0, 1});
    const LineResult result = lines.configure();
    ASSERT_TRUE(result.ok()) << result.message;
    ASSERT_EQ(chip.requests.size(), 3u);
    EXPECT_EQ(chip.requests[0][0], 0x61);
    EXPECT_EQ(chip.requests[1][0], 0x60);
    EXPECT_EQ(chip.requests[2][0], 0x51);
    EXPECT_EQ(chip.pins[0].designation, kDesignationGpio);
    EXPECT_TRUE(chip.pins[0].output && chip.pins[0].high && chip.pins[1].output && chip.pins[1].high);
    EXPECT_EQ(chip.pins[2].designation, 2) << "a pin that is no line keeps its function";
}

TEST(Mcp2221Lines, RecoverySequencePullsTheStrapThenPulsesReset)
{
    FakeMcp2221 chip;
    Mcp2221Lines lines(chip, LineWiring{0, 1});
    ASSERT_TRUE(lines.configure().ok());
    ASSERT_TRUE(lines.setStrap(true).ok());
    ASSERT_TRUE(lines.pulseReset(std::chrono::milliseconds(1)).ok());
    ASSERT_TRUE(lines.setStrap(false).ok());
    const std::vector<std::pair<bool, bool>> expected = {
        {true, false},  // strap low
        {false, false}, // reset low
        {true, false},  // reset released: the board starts with the strap low
        {true, true},   // strap released
    };
    EXPECT_EQ(chip.levels, expected);
}

TEST(Mcp2221Lines, OtherWiringsAreHonouredAndBadOnesRefused)
{
    FakeMcp2221 chip;
    Mcp2221Lines lines(chip, LineWiring{3, 2});
    ASSERT_TRUE(lines.configure().ok());
    ASSERT_TRUE(lines.setReset(true).ok());
    EXPECT_FALSE(chip.pins[3].high);
    EXPECT_TRUE(chip.pins[2].high);
    FakeMcp2221 other;
    EXPECT_EQ(Mcp2221Lines(other, LineWiring{1, 1}).configure().error, LineError::BadArgument);
    EXPECT_EQ(Mcp2221Lines(other, LineWiring{0, 4}).configure().error, LineError::BadArgument);
    EXPECT_TRUE(other.requests.empty()) << "nothing is sent for a wiring that cannot be";
}

struct FaultCase {
    FakeMcp2221::Fault fault;
    int after;
    LineError error;
    const char* message;
};

class Mcp2221LinesFault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(Mcp2221LinesFault, AFaultyReplyEndsTheWorkWithAClearMessage)
{
    const FaultCase& c = GetParam();
    FakeMcp2221 chip;
    Mcp2221Lines lines(chip, LineWiring{0, 1});
    chip.inject(c.fault, c.after);
    LineResult result = lines.configure();
    if (result.ok()) {
        result = lines.setStrap(true);
    }
    EXPECT_EQ(result.error, c.error);
    EXPECT_NE(result.message.find(c.message), std::string::npos) << result.message;
}

INSTANTIATE_TEST_SUITE_P(
    Faults, Mcp2221LinesFault,
    ::testing::Values(
        FaultCase{FakeMcp2221::Fault::Short, 0, LineError::BadReply,
                  "answered GET SRAM SETTINGS (0x61) with 8 bytes, not 64"},
        FaultCase{FakeMcp2221::Fault::WrongCommand, 1, LineError::BadReply,
                  "answered SET SRAM SETTINGS (0x60) with a reply to command 0x11"},
        FaultCase{FakeMcp2221::Fault::Failed, 3, LineError::BadReply,
                  "did not complete SET GPIO OUTPUT VALUES (0x50): status 0x01"},
        FaultCase{FakeMcp2221::Fault::Silent, 2, LineError::Timeout, "did not answer GET GPIO VALUES (0x51)"},
        FaultCase{FakeMcp2221::Fault::WriteFails, 0, LineError::Io, "does not take GET SRAM SETTINGS (0x61)"},
        FaultCase{FakeMcp2221::Fault::NotGpio, 3, LineError::BadReply, "GP1 of the MCP2221A is not designated"}));

} // namespace
