// A master and a slave talking through an in-memory RS-485 line at 19200
// baud in simulated time: every function code end to end, exceptions,
// broadcast, and a polling schedule running for simulated seconds.
#include <modbus/InMemoryDataModel.hpp>
#include <modbus/Master.hpp>
#include <modbus/PollSchedule.hpp>
#include <modbus/RtuTransport.hpp>
#include <modbus/Slave.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <string>

namespace {

using modbus::DeviceIdCode;
using modbus::ExceptionCode;
using modbus::Master;
using modbus::ModbusError;
using modbus::Request;
using modbus::StationStep;
using namespace modbus_test;

constexpr uint64_t kNever = ~0ull;

// The line: bytes a station sends reach the other one character time apart,
// and the sender hears "transmit done" when its last byte has left.
template <typename MasterSide>
class Line {
public:
    Line(MasterSide& master, modbus::Slave& slave) : master_(master), slave_(slave) {}

    // Runs the simulation until @p untilNs; returns the completed master steps.
    std::vector<StationStep> run(uint64_t untilNs)
    {
        std::vector<StationStep> completed;
        for (;;) {
            uint64_t next = std::min(master_.nextDeadlineNs(), slave_.nextDeadlineNs());
            for (const auto& byte : toMaster_) next = std::min(next, byte.atNs);
            for (const auto& byte : toSlave_) next = std::min(next, byte.atNs);
            next = std::min({next, masterDoneNs_, slaveDoneNs_});
            if (next > untilNs) {
                now_ = untilNs;
                return completed;
            }
            now_ = std::max(now_, next);
            while (!toSlave_.empty() && toSlave_.front().atNs <= now_) {
                handleSlave(slave_.onBytes(&toSlave_.front().byte, 1, toSlave_.front().atNs));
                toSlave_.pop_front();
            }
            while (!toMaster_.empty() && toMaster_.front().atNs <= now_) {
                handleMaster(master_.onBytes(&toMaster_.front().byte, 1, toMaster_.front().atNs), completed);
                toMaster_.pop_front();
            }
            if (masterDoneNs_ <= now_) {
                masterDoneNs_ = kNever;
                handleMaster(master_.onTransmitDone(now_), completed);
            }
            if (slaveDoneNs_ <= now_) {
                slaveDoneNs_ = kNever;
                EXPECT_EQ(slave_.onTransmitDone(now_), ModbusError::Ok);
            }
            handleSlave(slave_.poll(now_));
            handleMaster(master_.poll(now_), completed);
        }
    }

    // Hands a step from outside the loop (a submit) to the line.
    template <typename Step>
    void transmitFromMaster(const Step& step)
    {
        std::vector<StationStep> ignored;
        handleMaster(step, ignored);
    }

    uint64_t now() const { return now_; }
    size_t bytesToSlave() const { return sentToSlave_; }

private:
    struct Timed {
        uint64_t atNs;
        uint8_t byte;
    };

    template <typename Step>
    void handleMaster(const Step& step, std::vector<StationStep>& completed)
    {
        EXPECT_EQ(step.rejected, ModbusError::Ok);
        if (step.completed) {
            completed.push_back(step);
        }
        if (step.transmit != nullptr) {
            EXPECT_EQ(masterDoneNs_, kNever) << "the master sent while sending";
            masterDoneNs_ = send(step, toSlave_);
            sentToSlave_ += step.transmitLength;
        }
    }

    void handleSlave(const StationStep& step)
    {
        if (step.transmit != nullptr) {
            EXPECT_EQ(slaveDoneNs_, kNever) << "the slave sent while sending";
            slaveDoneNs_ = send(step, toMaster_);
        }
    }

    uint64_t send(const StationStep& step, std::deque<Timed>& queue)
    {
        uint64_t at = now_;
        for (size_t i = 0; i < step.transmitLength; ++i) {
            at += kChar19200;
            queue.push_back({at, step.transmit[i]});
        }
        return at;
    }

    MasterSide& master_;
    modbus::Slave& slave_;
    std::deque<Timed> toSlave_;
    std::deque<Timed> toMaster_;
    uint64_t masterDoneNs_ = kNever;
    uint64_t slaveDoneNs_ = kNever;
    uint64_t now_ = 0;
    size_t sentToSlave_ = 0;
};

class LoopbackTest : public ::testing::Test {
protected:
    LoopbackTest() : masterTransport_(timing19200()), slaveTransport_(timing19200())
    {
        modbus::DeviceIdentification identification;
        identification.vendorName = "DCOS";
        identification.productCode = "DC-486";
        identification.revision = "0.1";
        identification.productName = "loopback slave";
        server_ = modbus::Server::create(model_, identification).value();
        slave_ = modbus::Slave::create(slaveTransport_, server_, 5).value();
        modbus::MasterConfig config;
        config.responseTimeoutNs = 50000000;
        config.turnaroundDelayNs = 20000000;
        config.retries = 1;
        master_ = Master::create(masterTransport_, config).value();
    }

    // Runs one transaction to its end and returns how it ended.
    StationStep transact(const modbus::ModbusResult<Request>& request)
    {
        EXPECT_TRUE(request.ok());
        line_.transmitFromMaster(master_.submit(request.value(), line_.now()));
        const std::vector<StationStep> completed = line_.run(line_.now() + 1000000000);
        EXPECT_EQ(completed.size(), 1u);
        return completed.empty() ? StationStep{} : completed.front();
    }

    modbus::InMemoryDataModel<64, 64, 64, 64> model_;
    modbus::RtuTransport masterTransport_;
    modbus::RtuTransport slaveTransport_;
    modbus::Server server_;
    modbus::Slave slave_;
    Master master_;
    Line<Master> line_{master_, slave_};
};

TEST_F(LoopbackTest, EveryFunctionCodeEndToEnd)
{
    model_.discreteInput(3) = true;
    model_.inputRegister(7) = 0x7777;

    const uint16_t values[3] = {0x1111, 0x2222, 0x3333};
    EXPECT_EQ(transact(Request::writeMultipleRegisters(5, 10, 3, values)).error, ModbusError::Ok);
    EXPECT_EQ(model_.holdingRegister(12), 0x3333);

    EXPECT_EQ(transact(Request::readHoldingRegisters(5, 10, 3)).error, ModbusError::Ok);
    EXPECT_EQ(master_.response().registerValue(1), 0x2222);

    EXPECT_EQ(transact(Request::writeSingleRegister(5, 11, 0xABCD)).error, ModbusError::Ok);
    EXPECT_EQ(model_.holdingRegister(11), 0xABCD);

    EXPECT_EQ(transact(Request::readInputRegisters(5, 7, 1)).error, ModbusError::Ok);
    EXPECT_EQ(master_.response().registerValue(0), 0x7777);

    const uint8_t coils[2] = {0x05, 0x01};
    EXPECT_EQ(transact(Request::writeMultipleCoils(5, 20, 9, coils)).error, ModbusError::Ok);
    EXPECT_EQ(transact(Request::writeSingleCoil(5, 21, true)).error, ModbusError::Ok);
    EXPECT_EQ(transact(Request::readCoils(5, 20, 9)).error, ModbusError::Ok);
    EXPECT_TRUE(master_.response().bit(0) && master_.response().bit(1) && master_.response().bit(2));
    EXPECT_FALSE(master_.response().bit(3));
    EXPECT_TRUE(master_.response().bit(8));

    EXPECT_EQ(transact(Request::readDiscreteInputs(5, 0, 4)).error, ModbusError::Ok);
    EXPECT_TRUE(master_.response().bit(3));
    EXPECT_FALSE(master_.response().bit(2));

    const uint16_t written[1] = {0x4242};
    EXPECT_EQ(transact(Request::readWriteMultipleRegisters(5, 12, 2, 13, 1, written)).error, ModbusError::Ok);
    EXPECT_EQ(master_.response().registerValue(0), 0x3333);
    EXPECT_EQ(master_.response().registerValue(1), 0x4242);

    EXPECT_EQ(transact(Request::readDeviceIdentification(5, DeviceIdCode::RegularStream, 0)).error, ModbusError::Ok);
    ASSERT_EQ(master_.response().objectCount(), 4u);
    modbus::DeviceIdObject object;
    ASSERT_TRUE(master_.response().object(3, object));
    EXPECT_EQ(object.id, 0x04);
    EXPECT_EQ(std::string(reinterpret_cast<const char*>(object.value), object.length), "loopback slave");

    EXPECT_EQ(slave_.counters().messages, 10u);
    EXPECT_EQ(master_.counters().transmissions, 10u);
    EXPECT_EQ(slaveTransport_.receiver().counters().crcErrors, 0u);
    EXPECT_EQ(masterTransport_.receiver().counters().gapErrors, 0u);
}

TEST_F(LoopbackTest, ExceptionsTravelBack)
{
    StationStep step = transact(Request::readHoldingRegisters(5, 60, 10));
    EXPECT_EQ(step.error, ModbusError::ExceptionResponse);
    EXPECT_EQ(step.exception, ExceptionCode::IllegalDataAddress);
    model_.failNext();
    step = transact(Request::writeSingleCoil(5, 0, true));
    EXPECT_EQ(step.exception, ExceptionCode::ServerDeviceFailure);
    step = transact(Request::readDeviceIdentification(5, DeviceIdCode::Individual, 0x05));
    EXPECT_EQ(step.exception, ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(slave_.counters().exceptions, 3u);
}

TEST_F(LoopbackTest, BroadcastIsExecutedAndTheMasterWaitsItsTurnaround)
{
    const StationStep step = transact(Request::writeSingleRegister(0, 1, 99));
    EXPECT_EQ(step.error, ModbusError::Ok);
    EXPECT_EQ(model_.holdingRegister(1), 99);
    EXPECT_EQ(slave_.counters().noResponses, 1u);
    EXPECT_EQ(master_.counters().responses, 0u);
}

TEST_F(LoopbackTest, AbsentSlaveTimesOutAfterItsRetry)
{
    const StationStep step = transact(Request::readHoldingRegisters(9, 0, 1));
    EXPECT_EQ(step.error, ModbusError::Timeout);
    EXPECT_EQ(master_.counters().transmissions, 2u);
    EXPECT_EQ(slave_.counters().otherAddresses, 2u);
}

TEST_F(LoopbackTest, PollingScheduleOverSimulatedTime)
{
    model_.inputRegister(0) = 321;
    modbus::PollSchedule<3> schedule(master_);
    Line<modbus::PollSchedule<3>> line(schedule, slave_);
    ASSERT_EQ(schedule.add(Request::readInputRegisters(5, 0, 1).value(), 100000000).value(), 0u);     // 100 ms
    ASSERT_EQ(schedule.add(Request::readCoils(5, 0, 16).value(), 250000000).value(), 1u);             // 250 ms
    ASSERT_EQ(schedule.add(Request::readHoldingRegisters(9, 0, 1).value(), 500000000).value(), 2u);   // absent

    line.run(999999999);
    const modbus::PollStatistics& fast = schedule.statistics(0);
    const modbus::PollStatistics& slow = schedule.statistics(1);
    const modbus::PollStatistics& absent = schedule.statistics(2);
    // The absent slave costs two time-outs of 50 ms per try, so the fast
    // entry falls behind while it runs and skips cycles instead of bursting.
    EXPECT_EQ(absent.transactions, 2u);
    EXPECT_EQ(absent.timeouts, 2u);
    EXPECT_EQ(absent.lastError, ModbusError::Timeout);
    EXPECT_EQ(slow.transactions, 4u);
    EXPECT_EQ(slow.successes, 4u);
    EXPECT_GE(fast.transactions, 8u);
    EXPECT_LE(fast.transactions, 10u);
    EXPECT_EQ(fast.successes, fast.transactions);
    EXPECT_EQ(fast.transactions + fast.overruns, 10u);
    EXPECT_EQ(schedule.response(0).registerValue(0), 321);
    EXPECT_EQ(slow.lastError, ModbusError::Ok);
    EXPECT_GT(fast.lastSuccessNs, 900000000u);

    // The values follow the data model between cycles.
    model_.inputRegister(0) = 654;
    line.run(1200000000);
    EXPECT_EQ(schedule.response(0).registerValue(0), 654);
}

TEST(PollScheduleTest, TableLimitsAndPeriods)
{
    modbus::RtuTransport transport;
    Master master = Master::create(transport, modbus::MasterConfig{}).value();
    modbus::PollSchedule<1> schedule(master);
    const Request request = Request::readCoils(1, 0, 1).value();
    EXPECT_EQ(schedule.add(request, 0).error(), ModbusError::InvalidArgument);
    EXPECT_EQ(schedule.add(Request{}, 1000).error(), ModbusError::InvalidArgument);
    EXPECT_TRUE(schedule.add(request, 1000, 5000).ok());
    EXPECT_EQ(schedule.add(request, 1000).error(), ModbusError::BufferTooSmall);
    EXPECT_EQ(schedule.size(), 1u);
    EXPECT_EQ(schedule.response(0).length(), 0u);
    // The entry is due at 5000, before the line's own Initial silence ends.
    EXPECT_EQ(schedule.nextDeadlineNs(), 5000u);
    EXPECT_EQ(schedule.poll(4999).transmit, nullptr);
    EXPECT_EQ(schedule.statistics(0).transactions, 0u);
}

} // namespace
