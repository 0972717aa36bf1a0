// Master: requests on the wire, response matching, time-outs and retries,
// the turnaround delay after a broadcast, with exact timing at 19200 baud.
#include <modbus/Master.hpp>
#include <modbus/RtuTransport.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using modbus::ExceptionCode;
using modbus::Master;
using modbus::MasterConfig;
using modbus::ModbusError;
using modbus::Request;
using modbus::StationStep;
using namespace modbus_test;

constexpr uint64_t kStart = 10000000;
constexpr uint64_t kTimeout = 100000000;     // 100 ms
constexpr uint64_t kTurnaround = 50000000;   // 50 ms

class MasterTest : public ::testing::Test {
protected:
    MasterTest() : transport_(timing19200())
    {
        MasterConfig config;
        config.responseTimeoutNs = kTimeout;
        config.turnaroundDelayNs = kTurnaround;
        config.retries = 2;
        master_ = Master::create(transport_, config).value();
    }

    // Submits @p request at @p now (the line long idle), checks the ADU sent
    // and confirms it; returns when the transmission ended.
    uint64_t start(const Request& request, const Bytes& adu, uint64_t now = kStart)
    {
        const StationStep step = master_.submit(request, now);
        EXPECT_EQ(step.rejected, ModbusError::Ok);
        EXPECT_EQ(bytesOf(step.transmit, step.transmitLength), adu);
        const uint64_t done = now + adu.size() * kChar19200;
        const StationStep confirmed = master_.onTransmitDone(done);
        EXPECT_EQ(confirmed.rejected, ModbusError::Ok);
        return done;
    }

    // The slave's response starting @p delay after @p after; returns the
    // step of the poll at the end of the frame.
    StationStep respond(const Bytes& frame, uint64_t after, uint64_t delay = 5000000)
    {
        StationStep step;
        const uint64_t end = feed(master_, frame, after + delay, step);
        EXPECT_FALSE(step.completed);
        end_ = end + kT35At19200;
        return master_.poll(end_);
    }

    modbus::RtuTransport transport_;
    Master master_;
    uint64_t end_ = 0;
    const Request read_ = Request::readHoldingRegisters(1, 0, 10).value();
    const Bytes readAdu_ = {0x01, 0x03, 0x00, 0x00, 0x00, 0x0A, 0xC5, 0xCD};
};

TEST_F(MasterTest, ReadHoldingRegisters)
{
    const uint64_t done = start(read_, readAdu_);
    EXPECT_EQ(master_.state(), Master::State::WaitingReply);
    // First the line's own silence after the request, then the time-out.
    EXPECT_EQ(master_.nextDeadlineNs(), done + kT35At19200);
    EXPECT_FALSE(master_.poll(done + kT35At19200).completed);
    EXPECT_EQ(master_.nextDeadlineNs(), done + kTimeout);
    Bytes pdu = {0x01, 0x03, 0x14};
    for (int i = 0; i < 10; ++i) {
        pdu.push_back(0);
        pdu.push_back(static_cast<uint8_t>(i * 3));
    }
    const StationStep step = respond(withCrc(pdu), done);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::Ok);
    EXPECT_EQ(step.exception, ExceptionCode::None);
    EXPECT_TRUE(master_.idle());
    ASSERT_EQ(master_.response().registerCount(), 10u);
    EXPECT_EQ(master_.response().registerValue(9), 27);
    EXPECT_EQ(master_.counters().responses, 1u);
    EXPECT_EQ(master_.counters().transmissions, 1u);
}

TEST_F(MasterTest, WaitsForTheLineToBeIdleBeforeSending)
{
    // A fresh line is in the Initial state until t3.5 has passed.
    modbus::RtuTransport transport(timing19200());
    Master master = Master::create(transport, MasterConfig{}).value();
    StationStep step = master.submit(read_, 0);
    EXPECT_EQ(step.rejected, ModbusError::Ok);
    EXPECT_EQ(step.transmit, nullptr);
    EXPECT_EQ(master.state(), Master::State::WaitingToSend);
    EXPECT_EQ(master.nextDeadlineNs(), kT35At19200);
    step = master.poll(kT35At19200 - 1);
    EXPECT_EQ(step.transmit, nullptr);
    step = master.poll(kT35At19200);
    EXPECT_EQ(bytesOf(step.transmit, step.transmitLength), readAdu_);
}

TEST_F(MasterTest, ExceptionResponseEndsTheTransactionWithoutRetry)
{
    const uint64_t done = start(read_, readAdu_);
    const StationStep step = respond(withCrc({0x01, 0x83, 0x02}), done);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::ExceptionResponse);
    EXPECT_EQ(step.exception, ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(master_.counters().exceptions, 1u);
    EXPECT_EQ(master_.counters().transmissions, 1u);
    EXPECT_EQ(master_.response().length(), 2u);
}

TEST_F(MasterTest, TimeoutIsRetriedThenReported)
{
    uint64_t done = start(read_, readAdu_);
    for (int attempt = 1; attempt <= 3; ++attempt) {
        StationStep step = master_.poll(done + kTimeout - 1);
        EXPECT_FALSE(step.completed);
        EXPECT_EQ(step.transmit, nullptr);
        step = master_.poll(done + kTimeout);
        if (attempt < 3) {
            // The same ADU again, at once: the line has been idle for long.
            EXPECT_FALSE(step.completed);
            ASSERT_EQ(bytesOf(step.transmit, step.transmitLength), readAdu_) << attempt;
            done = done + kTimeout + readAdu_.size() * kChar19200;
            EXPECT_EQ(master_.onTransmitDone(done).rejected, ModbusError::Ok);
        } else {
            EXPECT_TRUE(step.completed);
            EXPECT_EQ(step.error, ModbusError::Timeout);
            EXPECT_EQ(step.transmit, nullptr);
        }
    }
    EXPECT_TRUE(master_.idle());
    EXPECT_EQ(master_.counters().transmissions, 3u);
    EXPECT_EQ(master_.counters().timeouts, 3u);
    EXPECT_EQ(master_.counters().failures, 1u);
}

TEST_F(MasterTest, NoRetriesMeansOneAttempt)
{
    MasterConfig config;
    config.responseTimeoutNs = kTimeout;
    config.retries = 0;
    master_ = Master::create(transport_, config).value();
    const uint64_t done = start(read_, readAdu_);
    const StationStep step = master_.poll(done + kTimeout);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::Timeout);
}

TEST_F(MasterTest, ResponseArrivingAtTheDeadlineIsWaitedFor)
{
    const uint64_t done = start(read_, readAdu_);
    StationStep step;
    // The first byte ends just before the deadline; the rest comes after it.
    const Bytes response = withCrc({0x01, 0x03, 0x14, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0});
    const uint64_t end = feed(master_, response, done + kTimeout - 1, step);
    step = master_.poll(done + kTimeout);
    EXPECT_FALSE(step.completed);
    EXPECT_EQ(step.transmit, nullptr);
    step = master_.poll(end + kT35At19200);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::Ok);
}

TEST_F(MasterTest, FrameFromAnotherUnitKeepsTheTimeoutRunning)
{
    const uint64_t done = start(read_, readAdu_);
    StationStep step = respond(withCrc({0x02, 0x83, 0x02}), done);
    EXPECT_FALSE(step.completed);
    EXPECT_EQ(master_.counters().foreignFrames, 1u);
    EXPECT_EQ(master_.nextDeadlineNs(), done + kTimeout);
    step = master_.poll(done + kTimeout);
    EXPECT_NE(step.transmit, nullptr);  // retried
}

TEST_F(MasterTest, MalformedResponseIsRetried)
{
    const uint64_t done = start(read_, readAdu_);
    StationStep step = respond(withCrc({0x01, 0x03, 0x02, 0x00, 0x00}), done);
    EXPECT_FALSE(step.completed);
    EXPECT_EQ(bytesOf(step.transmit, step.transmitLength), readAdu_);
    EXPECT_EQ(master_.counters().invalidResponses, 1u);
    const uint64_t again = end_ + readAdu_.size() * kChar19200;
    EXPECT_EQ(master_.onTransmitDone(again).rejected, ModbusError::Ok);
    step = respond(withCrc({0x01, 0x04, 0x02, 0x00, 0x00}), again);  // wrong function
    EXPECT_NE(step.transmit, nullptr);
    const uint64_t third = end_ + readAdu_.size() * kChar19200;
    EXPECT_EQ(master_.onTransmitDone(third).rejected, ModbusError::Ok);
    step = respond(withCrc({0x01, 0x03, 0x01, 0x00}), third);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::InvalidResponse);
}

TEST_F(MasterTest, WriteEchoMismatchIsReported)
{
    MasterConfig config;
    config.retries = 0;
    master_ = Master::create(transport_, config).value();
    const Request write = Request::writeSingleRegister(1, 1, 3).value();
    const uint64_t done = start(write, withCrc({0x01, 0x06, 0x00, 0x01, 0x00, 0x03}));
    const StationStep step = respond(withCrc({0x01, 0x06, 0x00, 0x01, 0x00, 0x04}), done);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::EchoMismatch);
}

TEST_F(MasterTest, BroadcastWaitsTheTurnaroundDelay)
{
    const Request write = Request::writeSingleCoil(0, 0xAC, true).value();
    const uint64_t done = start(write, withCrc({0x00, 0x05, 0x00, 0xAC, 0xFF, 0x00}));
    EXPECT_EQ(master_.state(), Master::State::Turnaround);
    EXPECT_EQ(master_.nextDeadlineNs(), done + kT35At19200);
    EXPECT_FALSE(master_.poll(done + kT35At19200).completed);
    EXPECT_EQ(master_.nextDeadlineNs(), done + kTurnaround);
    StationStep step = master_.poll(done + kTurnaround - 1);
    EXPECT_FALSE(step.completed);
    EXPECT_EQ(master_.submit(read_, done + 1).rejected, ModbusError::Busy);
    step = master_.poll(done + kTurnaround);
    EXPECT_TRUE(step.completed);
    EXPECT_EQ(step.error, ModbusError::Ok);
    EXPECT_TRUE(master_.idle());
}

TEST_F(MasterTest, MisuseIsRejected)
{
    EXPECT_EQ(master_.onTransmitDone(kStart).rejected, ModbusError::NotExpected);
    EXPECT_EQ(master_.submit(read_, kStart).rejected, ModbusError::Ok);
    EXPECT_EQ(master_.submit(read_, kStart).rejected, ModbusError::Busy);
    Master fresh = Master::create(transport_, MasterConfig{}).value();
    Request handMade = read_;
    handMade.unit = 250;
    EXPECT_EQ(fresh.submit(handMade, kStart).rejected, ModbusError::InvalidSlaveAddress);
    handMade = read_;
    handMade.length = 0;
    EXPECT_EQ(fresh.submit(handMade, kStart).rejected, ModbusError::FrameTooLong);
    EXPECT_TRUE(fresh.idle());
    Master unmade;
    EXPECT_EQ(unmade.submit(read_, 0).rejected, ModbusError::NotExpected);
}

TEST_F(MasterTest, ResponsesWhenNoneIsDueAreIgnored)
{
    const StationStep step = respond(withCrc({0x01, 0x03, 0x02, 0x00, 0x00}), kStart);
    EXPECT_FALSE(step.completed);
    EXPECT_EQ(master_.counters().foreignFrames, 1u);
}

TEST(MasterConfigTest, Validation)
{
    MasterConfig config;
    EXPECT_EQ(config.validate(), ModbusError::Ok);
    config.responseTimeoutNs = 0;
    EXPECT_EQ(config.validate(), ModbusError::InvalidConfiguration);
    config = MasterConfig{};
    config.turnaroundDelayNs = MasterConfig::kMaxDelayNs + 1;
    EXPECT_EQ(config.validate(), ModbusError::InvalidConfiguration);
    config = MasterConfig{};
    config.retries = MasterConfig::kMaxRetries + 1;
    EXPECT_EQ(config.validate(), ModbusError::InvalidConfiguration);
    modbus::RtuTransport transport;
    EXPECT_EQ(Master::create(transport, config).error(), ModbusError::InvalidConfiguration);
}

} // namespace
