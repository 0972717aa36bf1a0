// Slave: addressing, broadcast, half duplex and its counters, through the
// RTU transport with real timing.
#include <modbus/InMemoryDataModel.hpp>
#include <modbus/RtuTransport.hpp>
#include <modbus/Slave.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using modbus::ModbusError;
using modbus::Slave;
using modbus::StationStep;
using namespace modbus_test;

constexpr uint64_t kStart = 10000000;

class SlaveTest : public ::testing::Test {
protected:
    SlaveTest() : transport_(timing19200())
    {
        modbus::DeviceIdentification identification;
        identification.vendorName = "DCOS";
        identification.productCode = "DC-486";
        identification.revision = "0.1";
        server_ = modbus::Server::create(model_, identification).value();
        slave_ = Slave::create(transport_, server_, 17).value();
    }

    // Sends @p frame at @p startNs and lets t3.5 pass; returns what the slave sent.
    Bytes exchange(const Bytes& frame, uint64_t startNs = kStart)
    {
        StationStep step;
        const uint64_t end = feed(slave_, frame, startNs, step);
        EXPECT_EQ(step.transmit, nullptr) << "answered before the end of the frame";
        step = slave_.poll(end + kT35At19200 - 1);
        EXPECT_EQ(step.transmit, nullptr) << "answered before t3.5";
        step = slave_.poll(end + kT35At19200);
        lastEnd_ = end + kT35At19200;
        if (step.transmit == nullptr) {
            return {};
        }
        EXPECT_TRUE(slave_.transmitting());
        const Bytes sent = bytesOf(step.transmit, step.transmitLength);
        EXPECT_EQ(slave_.onTransmitDone(lastEnd_ + sent.size() * kChar19200), ModbusError::Ok);
        lastEnd_ += sent.size() * kChar19200;
        return sent;
    }

    modbus::InMemoryDataModel<16, 16, 16, 16> model_;
    modbus::RtuTransport transport_;
    modbus::Server server_;
    Slave slave_;
    uint64_t lastEnd_ = 0;
};

TEST_F(SlaveTest, AnswersItsAddressWithAFramedResponse)
{
    model_.holdingRegister(0) = 0x1234;
    EXPECT_EQ(exchange(withCrc({17, 0x03, 0x00, 0x00, 0x00, 0x01})), withCrc({17, 0x03, 0x02, 0x12, 0x34}));
    EXPECT_EQ(slave_.counters().messages, 1u);
    EXPECT_EQ(slave_.counters().exceptions, 0u);
}

TEST_F(SlaveTest, AnswersExceptionsAndCountsThem)
{
    EXPECT_EQ(exchange(withCrc({17, 0x03, 0x00, 0x10, 0x00, 0x01})), withCrc({17, 0x83, 0x02}));
    EXPECT_EQ(exchange(withCrc({17, 0x07}), lastEnd_ + kT35At19200 + kChar19200), withCrc({17, 0x87, 0x01}));
    EXPECT_EQ(slave_.counters().exceptions, 2u);
}

TEST_F(SlaveTest, IgnoresOtherAddressesAndBadFrames)
{
    EXPECT_TRUE(exchange(withCrc({16, 0x03, 0x00, 0x00, 0x00, 0x01})).empty());
    EXPECT_TRUE(exchange(withCrc({248, 0x03, 0x00, 0x00, 0x00, 0x01}), kStart + 20000000).empty());
    Bytes corrupted = withCrc({17, 0x03, 0x00, 0x00, 0x00, 0x01});
    corrupted.back() ^= 0x40;
    EXPECT_TRUE(exchange(corrupted, kStart + 40000000).empty());
    EXPECT_EQ(slave_.counters().otherAddresses, 2u);
    EXPECT_EQ(slave_.counters().messages, 0u);
    EXPECT_EQ(transport_.receiver().counters().crcErrors, 1u);
}

TEST_F(SlaveTest, BroadcastWritesAreExecutedWithoutResponse)
{
    EXPECT_TRUE(exchange(withCrc({0, 0x06, 0x00, 0x02, 0xBE, 0xEF})).empty());
    EXPECT_EQ(model_.holdingRegister(2), 0xBEEF);
    EXPECT_TRUE(exchange(withCrc({0, 0x05, 0x00, 0x03, 0xFF, 0x00}), kStart + 20000000).empty());
    EXPECT_TRUE(model_.coil(3));
    EXPECT_TRUE(exchange(withCrc({0, 0x0F, 0x00, 0x04, 0x00, 0x02, 0x01, 0x03}), kStart + 40000000).empty());
    EXPECT_TRUE(model_.coil(4) && model_.coil(5));
    EXPECT_TRUE(exchange(withCrc({0, 0x10, 0x00, 0x05, 0x00, 0x01, 0x02, 0x00, 0x07}), kStart + 60000000).empty());
    EXPECT_EQ(model_.holdingRegister(5), 7);
    // A broadcast that would be an exception gets no response either.
    EXPECT_TRUE(exchange(withCrc({0, 0x06, 0x01, 0x00, 0x00, 0x01}), kStart + 80000000).empty());
    EXPECT_EQ(slave_.counters().noResponses, 5u);
    EXPECT_EQ(slave_.counters().exceptions, 0u);
}

TEST_F(SlaveTest, BroadcastReadsAreIgnored)
{
    EXPECT_TRUE(exchange(withCrc({0, 0x03, 0x00, 0x00, 0x00, 0x01})).empty());
    // Function 17 writes, but it also reads: broadcast, it is ignored whole.
    EXPECT_TRUE(exchange(withCrc({0, 0x17, 0, 0, 0, 1, 0, 1, 0, 1, 2, 0x12, 0x34}), kStart + 20000000).empty());
    EXPECT_EQ(model_.holdingRegister(1), 0);
    EXPECT_EQ(slave_.counters().noResponses, 2u);
}

TEST_F(SlaveTest, HalfDuplexDropsFramesWhileSending)
{
    StationStep step;
    const uint64_t end = feed(slave_, withCrc({17, 0x04, 0x00, 0x00, 0x00, 0x01}), kStart, step);
    step = slave_.poll(end + kT35At19200);
    ASSERT_NE(step.transmit, nullptr);
    // A second request completes while the response is still being sent.
    const uint64_t second = feed(slave_, withCrc({17, 0x04, 0x00, 0x01, 0x00, 0x01}), end + 2 * kT35At19200, step);
    step = slave_.poll(second + kT35At19200);
    EXPECT_EQ(step.transmit, nullptr);
    EXPECT_EQ(slave_.counters().droppedWhileSending, 1u);
    EXPECT_EQ(slave_.onTransmitDone(second + kT35At19200), ModbusError::Ok);
    EXPECT_EQ(slave_.onTransmitDone(second + kT35At19200), ModbusError::NotExpected);
}

TEST_F(SlaveTest, AfterItsResponseTheLineMustBeSilentForThreePointFive)
{
    ASSERT_FALSE(exchange(withCrc({17, 0x04, 0x00, 0x00, 0x00, 0x01})).empty());
    // A request starting right after the response ended falls in the
    // Initial state of the receiver and is not taken.
    EXPECT_TRUE(exchange(withCrc({17, 0x04, 0x00, 0x00, 0x00, 0x01}), lastEnd_ + kChar19200).empty());
    EXPECT_EQ(slave_.counters().messages, 1u);
}

TEST(SlaveCreateTest, AddressMustBeASlaveAddress)
{
    modbus::InMemoryDataModel<1, 1, 1, 1> model;
    modbus::DeviceIdentification identification;
    identification.vendorName = identification.productCode = identification.revision = "x";
    modbus::Server server = modbus::Server::create(model, identification).value();
    modbus::RtuTransport transport;
    EXPECT_EQ(Slave::create(transport, server, 0).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Slave::create(transport, server, 248).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_TRUE(Slave::create(transport, server, 1).ok());
    EXPECT_TRUE(Slave::create(transport, server, 247).ok());
    Slave unmade;
    EXPECT_EQ(unmade.poll(0).transmit, nullptr);
}

} // namespace
