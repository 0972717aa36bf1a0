// The board driver through the system agent, with the recording port mock
// standing in for the board and FakeAgents for the interrupt and task
// services: probe, gain, conversions by interrupt and by polling, the
// interrupt acknowledge, the fallback, DAC and DO writes, and conflicts.
#include <iobus/MfioBoard.hpp>
#include <iobus/MfioClient.hpp>

#include <dcos/SystemAgent.hpp>

#include "../../../firmware/dcos/unit_tests/FakeKernelContext.hpp"
#include "FakeAgents.hpp"
#include "MfioTestSupport.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Result;
using dcos::Status;
using dcos::systemAgent;
using iobus::MfioBoard;
using namespace iobus::mfio;
using namespace iobus_test;
using Log = std::vector<port_io_mock::Access>;

const ObjectId kSuperUser(dcos::fake::kDefaultNode, ObjectType::Task, 10);
const ObjectId kUserTask(dcos::fake::kDefaultNode, ObjectType::Task, 20);

class StringSink final : public runtime::CharacterSink {
public:
    void put(char character) override { text += character; }
    std::string text;
};

class MfioBoardTest : public ::testing::Test {
protected:
    void SetUp() override
    {
        port_io_mock::reset();
        iobus_fake::reset();
        dcos::fake::reset();
        dcos::fake::playSuperUser(kSuperUser);
        // Idle board: not busy, nothing waiting.
        port_io_mock::setDefaultRead(port(kStatusRegister), 0);
    }

    void TearDown() override
    {
        dcos::fake::playSuperUser(kSuperUser);
        while (systemAgent.Close(board.id()) == Status::Ok) {
        }
        if (board.installed()) {
            EXPECT_EQ(board.uninstall(), Status::Ok);
        }
        EXPECT_EQ(iobus::isaResources().release("mfio-test"), 0u) << "uninstall releases the resources";
        EXPECT_TRUE(iobus_fake::installedIsrs().empty()) << "uninstall removes the routine";
    }

    ObjectId install()
    {
        const Result<ObjectId> id = board.install("mfio-test", dcos::Visibility::Local, nullptr);
        EXPECT_TRUE(id.ok()) << dcos::statusName(id.status());
        return id.value();
    }

    ObjectId installAndOpen()
    {
        const ObjectId id = install();
        answerProbe();
        EXPECT_EQ(systemAgent.Open(id), Status::Ok);
        port_io_mock::takeLog();
        return id;
    }

    Status setMode(ObjectId id, iobus::ConversionMode mode)
    {
        uint32_t value = static_cast<uint32_t>(mode);
        return systemAgent.Control(id, MfioBoard::kSetMode, &value, sizeof value);
    }

    iobus::BoardStatistics statistics(ObjectId id)
    {
        iobus::BoardStatistics s{};
        EXPECT_EQ(systemAgent.Control(id, MfioBoard::kGetStatistics, &s, sizeof s), Status::Ok);
        return s;
    }

    // The board finishing a conversion of @p input with @p code: what the
    // interrupt service routine reads.
    void completeConversion(unsigned input, uint16_t code, bool overrange = false)
    {
        port_io_mock::queueRead(port(kStatusRegister), kStatusDone | kStatusIrqPending);
        port_io_mock::queueRead(port(kAdcDataRegister), static_cast<uint16_t>((overrange ? kAdcDataOverrange : 0) |
                                                                              (input << kAdcDataChannelShift) | code));
    }

    MfioBoard board{"mfio-test", kBase, 5};
};

TEST_F(MfioBoardTest, InstallReservesResourcesAndTheInterruptLine)
{
    const ObjectId id = install();
    EXPECT_FALSE(id.isNull());
    ASSERT_EQ(iobus_fake::installedIsrs().size(), 1u);
    EXPECT_EQ(iobus_fake::installedIsrs()[0].line, 5u);
    iobus::IsaConflict conflict;
    EXPECT_EQ(iobus::isaResources().reserve("other", 0x330, 0x10, iobus::kNoIrq, &conflict), Status::AlreadyExists);
    EXPECT_STREQ(conflict.heldBy, "mfio-test");
    EXPECT_TRUE(port_io_mock::takeLog().empty()) << "installing does not touch the board";
    EXPECT_EQ(board.configure(0x310, 5), Status::Busy) << "an installed board cannot move";
}

TEST_F(MfioBoardTest, ProbeOfAPresentBoard)
{
    const ObjectId id = install();
    answerProbe();
    EXPECT_EQ(systemAgent.Probe(id), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x00, 0x4D46), in16(0x02, 0x0100)}));
}

TEST_F(MfioBoardTest, AnAbsentBoardFailsCleanly)
{
    const ObjectId id = install();
    port_io_mock::setDefaultRead(port(kIdRegister), kEmptyBus);
    EXPECT_EQ(systemAgent.Probe(id), Status::NotFound);
    EXPECT_EQ(systemAgent.Open(id), Status::NotFound);
    const Log log = port_io_mock::takeLog();
    for (const auto& access : log) {
        EXPECT_FALSE(access.write) << "nothing is written to an empty slot: " << port_io_mock::describe(log);
    }
    uint16_t word = 0;
    EXPECT_EQ(systemAgent.Read(id, 0, &word, sizeof word).status(), Status::NotOpen);
}

TEST_F(MfioBoardTest, FirstOpenResetsTheBoardAndEnablesTheInterrupt)
{
    const ObjectId id = install();
    answerProbe();
    ASSERT_EQ(systemAgent.Open(id), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x00, 0x4D46), in16(0x02, 0x0100), out16(0x04, 0x8000),
                                            out16(0x0C, 0x0000), out16(0x04, 0x0001)}));
    ASSERT_EQ(systemAgent.Close(id), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{out16(0x04, 0x0000)})) << "interrupts off at the last close";
    answerProbe();
    ASSERT_EQ(systemAgent.Open(id), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x00, 0x4D46), in16(0x02, 0x0100), out16(0x04, 0x0001)}))
        << "a reopen does not reset the outputs";
}

TEST_F(MfioBoardTest, GainsAreWrittenAsOneRegister)
{
    const ObjectId id = installAndOpen();
    EXPECT_EQ(iobus::setGain(id, 2, 100), Status::Ok);
    EXPECT_EQ(iobus::setGain(id, 7, 1000), Status::Ok);
    EXPECT_EQ(iobus::setGain(id, 0, 10), Status::Ok);
    EXPECT_EQ(iobus::setGain(id, 2, 1), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(),
              (Log{out16(0x0C, 0x0020), out16(0x0C, 0xC020), out16(0x0C, 0xC021), out16(0x0C, 0xC001)}));
    iobus::GainSetting setting{7, 0};
    EXPECT_EQ(systemAgent.Control(id, MfioBoard::kGetGain, &setting, sizeof setting), Status::Ok);
    EXPECT_EQ(setting.gain, 1000u);
    EXPECT_EQ(iobus::setGain(id, 1, 50), Status::InvalidArgument);
    EXPECT_EQ(iobus::setGain(id, 8, 10), Status::InvalidArgument);
    EXPECT_EQ(systemAgent.Control(id, MfioBoard::kSetGain, &setting, 4), Status::InvalidArgument);
    EXPECT_EQ(systemAgent.Control(id, 99, nullptr, 0), Status::NotSupported);
    EXPECT_TRUE(port_io_mock::takeLog().empty()) << "refused settings write nothing";
}

TEST_F(MfioBoardTest, InterruptDrivenConversion)
{
    const ObjectId id = installAndOpen();
    dcos::fake::playUserTask(kUserTask);
    uint16_t word = 0;
    Result<size_t> read = systemAgent.Read(id, 3, &word, sizeof word);
    ASSERT_TRUE(read.ok());
    EXPECT_EQ(read.value(), 0u) << "the conversion is started, the result not there yet";
    EXPECT_EQ(port_io_mock::takeLog(), (Log{out16(0x08, 3)}));
    EXPECT_EQ(systemAgent.Read(id, 3, &word, sizeof word).value(), 0u) << "still converting";
    EXPECT_EQ(systemAgent.Read(id, 4, &word, sizeof word).status(), Status::Busy) << "one conversion at a time";
    port_io_mock::takeLog();

    iobus_fake::uptimeNs() += 25000;
    completeConversion(3, 0x0C00);
    ASSERT_TRUE(iobus_fake::raise(5));
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x06, 0x000A), in16(0x0A, 0x3C00), out16(0x0E, 0x0001)}))
        << "status, data, then the acknowledge";
    ASSERT_EQ(iobus_fake::postedEvents().size(), 1u);
    EXPECT_EQ(iobus_fake::postedEvents()[0].task, kUserTask);
    EXPECT_EQ(iobus_fake::postedEvents()[0].events, MfioBoard::kDefaultConversionEvent);

    read = systemAgent.Read(id, 3, &word, sizeof word);
    ASSERT_TRUE(read.ok());
    EXPECT_EQ(read.value(), 2u);
    EXPECT_EQ(word, 0x3C00);
    EXPECT_TRUE(port_io_mock::takeLog().empty()) << "the latched result needs no register access";
    const auto s = statistics(id);
    EXPECT_EQ(s.conversions, 1u);
    EXPECT_EQ(s.interrupts, 1u);
    EXPECT_EQ(s.lastInterruptNs - s.lastStartNs, 25000u);
}

TEST_F(MfioBoardTest, StatisticsCountFromTheInstall)
{
    // The same board object uninstalled and installed again (as the console
    // and the on-target tests do) starts counting afresh: a test that
    // expects four overranges must see four however often it runs.
    for (int installation = 0; installation < 2; ++installation) {
        const ObjectId id = installAndOpen();
        const auto before = statistics(id);
        EXPECT_EQ(before.conversions, 0u) << "installation " << installation;
        EXPECT_EQ(before.overranges, 0u) << "installation " << installation;
        EXPECT_EQ(before.interrupts, 0u) << "installation " << installation;
        iobus_fake::onReceiveEvent([this](uint32_t events, uint64_t) -> Result<uint32_t> {
            completeConversion(6, 0x0123, true);
            iobus_fake::raise(5);
            return events;
        });
        ASSERT_TRUE(iobus::readAnalogInput(id, 6).ok());
        EXPECT_EQ(statistics(id).overranges, 1u) << "installation " << installation;
        while (systemAgent.Close(id) == Status::Ok) {
        }
        ASSERT_EQ(board.uninstall(), Status::Ok);
    }
}

TEST_F(MfioBoardTest, AnInterruptWithNothingWaitingIsCountedAsSpurious)
{
    const ObjectId id = installAndOpen();
    ASSERT_TRUE(iobus_fake::raise(5));
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x06, 0x0000)})) << "no acknowledge without a result";
    EXPECT_EQ(statistics(id).spuriousInterrupts, 1u);
}

TEST_F(MfioBoardTest, TheClientWaitsForTheInterrupt)
{
    const ObjectId id = installAndOpen();
    iobus_fake::onReceiveEvent([this](uint32_t events, uint64_t) -> Result<uint32_t> {
        completeConversion(6, 0x0123, true);
        iobus_fake::raise(5);
        return events;
    });
    const Result<uint16_t> word = iobus::readAnalogInput(id, 6);
    ASSERT_TRUE(word.ok()) << dcos::statusName(word.status());
    EXPECT_EQ(word.value(), 0x8000 | 0x6000 | 0x0123);
    EXPECT_EQ(statistics(id).overranges, 1u);
}

TEST_F(MfioBoardTest, PolledConversion)
{
    const ObjectId id = installAndOpen();
    ASSERT_EQ(setMode(id, iobus::ConversionMode::Polled), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{out16(0x04, 0x0000)})) << "polled mode turns the interrupt off";
    port_io_mock::queueRead(port(kStatusRegister), kStatusBusy); // A conversion still running...
    port_io_mock::queueRead(port(kStatusRegister), 0);           // ...ends before the start.
    port_io_mock::queueRead(port(kStatusRegister), kStatusBusy);
    port_io_mock::queueRead(port(kStatusRegister), kStatusDone);
    port_io_mock::queueRead(port(kAdcDataRegister), 0x1FFF);
    uint16_t word = 0;
    const Result<size_t> read = systemAgent.Read(id, 1, &word, sizeof word);
    ASSERT_TRUE(read.ok());
    EXPECT_EQ(read.value(), 2u);
    EXPECT_EQ(word, 0x1FFF);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x06, kStatusBusy), in16(0x06, 0), out16(0x08, 1),
                                            in16(0x06, kStatusBusy), in16(0x06, kStatusDone), in16(0x0A, 0x1FFF),
                                            out16(0x0E, 0x0001)}));
    uint32_t mode = 99;
    EXPECT_EQ(systemAgent.Control(id, MfioBoard::kGetMode, &mode, sizeof mode), Status::Ok);
    EXPECT_EQ(mode, 1u);
}

TEST_F(MfioBoardTest, APolledConversionThatNeverEndsTimesOut)
{
    const ObjectId id = installAndOpen();
    ASSERT_EQ(setMode(id, iobus::ConversionMode::Polled), Status::Ok);
    port_io_mock::takeLog();
    port_io_mock::setDefaultRead(port(kStatusRegister), kStatusBusy);
    iobus_fake::setUptimeStep(1000);
    uint16_t word = 0;
    EXPECT_EQ(systemAgent.Read(id, 0, &word, sizeof word).status(), Status::Timeout);
    const Log log = port_io_mock::takeLog();
    EXPECT_LE(log.size(), MfioBoard::kPollLimit + 1u) << "the poll is bounded";
    for (const auto& access : log) {
        EXPECT_FALSE(access.write) << "a board that stays busy is not started";
    }
    EXPECT_EQ(statistics(id).timeouts, 1u);
}

TEST_F(MfioBoardTest, AMissingInterruptFallsBackToPollingWithADiagnostic)
{
    StringSink diagnostics;
    board.setDiagnosticSink(&diagnostics);
    const ObjectId id = installAndOpen();
    port_io_mock::queueRead(port(kStatusRegister), kStatusDone); // Done, but no interrupt came.
    port_io_mock::queueRead(port(kAdcDataRegister), 0x2ABC);
    const Result<uint16_t> word = iobus::readAnalogInput(id, 2); // The fake wait times out.
    ASSERT_TRUE(word.ok()) << dcos::statusName(word.status());
    EXPECT_EQ(word.value(), 0x2ABC);
    const Log log = port_io_mock::takeLog();
    EXPECT_EQ(log, (Log{out16(0x08, 2), out16(0x04, 0x0000), in16(0x06, kStatusDone), in16(0x0A, 0x2ABC),
                        out16(0x0E, 0x0001)}))
        << port_io_mock::describe(log);
    const auto s = statistics(id);
    EXPECT_EQ(s.missedInterrupts, 1u);
    EXPECT_EQ(s.fallbacks, 1u);
    EXPECT_EQ(diagnostics.text,
              "iobus: mfio-test: no interrupt on IRQ 5 within 2000 us; conversions are polled from now on\r\n");
    uint32_t mode = 0;
    EXPECT_EQ(systemAgent.Control(id, MfioBoard::kGetMode, &mode, sizeof mode), Status::Ok);
    EXPECT_EQ(mode, static_cast<uint32_t>(iobus::ConversionMode::Polled));
    board.setDiagnosticSink(nullptr);
}

TEST_F(MfioBoardTest, WithoutAutomaticFallbackTheModeStays)
{
    const ObjectId id = installAndOpen();
    uint32_t off = 0;
    ASSERT_EQ(systemAgent.Control(id, MfioBoard::kSetAutomaticFallback, &off, sizeof off), Status::Ok);
    port_io_mock::queueRead(port(kStatusRegister), kStatusDone);
    port_io_mock::queueRead(port(kAdcDataRegister), 0x0800);
    ASSERT_TRUE(iobus::readAnalogInput(id, 0).ok());
    const auto s = statistics(id);
    EXPECT_EQ(s.missedInterrupts, 1u);
    EXPECT_EQ(s.fallbacks, 0u);
    uint32_t mode = 1;
    EXPECT_EQ(systemAgent.Control(id, MfioBoard::kGetMode, &mode, sizeof mode), Status::Ok);
    EXPECT_EQ(mode, 0u);
}

TEST_F(MfioBoardTest, DacAndDigitalOutputWrites)
{
    const ObjectId id = installAndOpen();
    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(iobus::writeWord(id, iobus::channel::kAnalogOutput0 + 0, 0x000), Status::Ok);
    EXPECT_EQ(iobus::writeWord(id, iobus::channel::kAnalogOutput0 + 5, 0xFFF), Status::Ok);
    EXPECT_EQ(iobus::writeWord(id, iobus::channel::kDigitalOutputs, 0x8001), Status::Ok);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{out16(0x20, 0x000), out16(0x2A, 0xFFF), out16(0x12, 0x8001)}));
    EXPECT_EQ(iobus::writeWord(id, iobus::channel::kAnalogOutput0 + 1, 0x1000), Status::InvalidArgument);
    EXPECT_EQ(iobus::writeWord(id, 3, 1), Status::NotSupported) << "an analog input cannot be written";
    EXPECT_EQ(iobus::writeWord(id, iobus::channel::kDigitalInputs, 1), Status::NotSupported);
    EXPECT_EQ(iobus::writeWord(id, iobus::channel::kCount, 1), Status::InvalidArgument);
    uint32_t wide = 0;
    EXPECT_EQ(systemAgent.Write(id, iobus::channel::kDigitalOutputs, &wide, sizeof wide).status(),
              Status::InvalidArgument);
    EXPECT_TRUE(port_io_mock::takeLog().empty());
}

TEST_F(MfioBoardTest, DigitalInputsAndReadBacks)
{
    const ObjectId id = installAndOpen();
    port_io_mock::queueRead(port(kDigitalInputRegister), 0x5AA5);
    port_io_mock::queueRead(port(kDigitalOutputRegister), 0x0F0F);
    port_io_mock::queueRead(port(dacRegister(7)), 0x0321);
    EXPECT_EQ(iobus::readWord(id, iobus::channel::kDigitalInputs).value(), 0x5AA5);
    EXPECT_EQ(iobus::readWord(id, iobus::channel::kDigitalOutputs).value(), 0x0F0F);
    EXPECT_EQ(iobus::readWord(id, iobus::channel::kAnalogOutput0 + 7).value(), 0x0321);
    EXPECT_EQ(port_io_mock::takeLog(), (Log{in16(0x10, 0x5AA5), in16(0x12, 0x0F0F), in16(0x2E, 0x0321)}));
    uint8_t narrow = 0;
    EXPECT_EQ(systemAgent.Read(id, iobus::channel::kDigitalInputs, &narrow, 1).status(), Status::InvalidArgument);
    EXPECT_EQ(iobus::readWord(id, 18).status(), Status::InvalidArgument);
}

TEST_F(MfioBoardTest, ResourceConflictsNameBothClaimantsAndLeaveNothingBehind)
{
    MfioBoard second("mfio-second", 0x320, 7);
    iobus::IsaConflict conflict;
    install();
    EXPECT_EQ(second.install("second", dcos::Visibility::Local, &conflict).status(), Status::AlreadyExists);
    char text[128];
    iobus::IsaResourceManager::describe(conflict, text, sizeof text);
    EXPECT_STREQ(text, "ports 0x320-0x35f wanted by mfio-second are held by mfio-test (0x300-0x33f)");
    ASSERT_EQ(second.configure(0x3F8, 7), Status::Ok);
    EXPECT_EQ(second.install("second", dcos::Visibility::Local, &conflict).status(), Status::AlreadyExists);
    iobus::IsaResourceManager::describe(conflict, text, sizeof text);
    EXPECT_STREQ(text, "ports 0x3f8-0x437 wanted by mfio-second are held by com1 (0x3f8-0x3ff)");
    ASSERT_EQ(second.configure(0x280, 5), Status::Ok);
    EXPECT_EQ(second.install("second", dcos::Visibility::Local, &conflict).status(), Status::AlreadyExists);
    iobus::IsaResourceManager::describe(conflict, text, sizeof text);
    EXPECT_STREQ(text, "IRQ 5 wanted by mfio-second is held by mfio-test");
    EXPECT_FALSE(second.installed());
    EXPECT_EQ(iobus_fake::installedIsrs().size(), 1u);
    EXPECT_EQ(iobus::isaResources().release("mfio-second"), 0u);
}

TEST_F(MfioBoardTest, AFailedInstallReleasesTheResources)
{
    iobus_fake::failNextInstall(Status::Busy);
    EXPECT_EQ(board.install("mfio-test", dcos::Visibility::Local, nullptr).status(), Status::Busy);
    EXPECT_EQ(iobus::isaResources().release("mfio-test"), 0u);
    dcos::fake::playUserTask(kUserTask);
    EXPECT_EQ(board.install("mfio-test", dcos::Visibility::Local, nullptr).status(), Status::NotPermitted)
        << "Create refuses a user task";
    EXPECT_EQ(iobus::isaResources().release("mfio-test"), 0u);
    EXPECT_TRUE(iobus_fake::installedIsrs().empty());
    dcos::fake::playSuperUser(kSuperUser);
}

TEST_F(MfioBoardTest, UninstallRefusesAnOpenDevice)
{
    const ObjectId id = installAndOpen();
    EXPECT_EQ(board.uninstall(), Status::Busy);
    ASSERT_EQ(systemAgent.Close(id), Status::Ok);
    EXPECT_EQ(board.uninstall(), Status::Ok);
    EXPECT_FALSE(board.installed());
}

} // namespace
