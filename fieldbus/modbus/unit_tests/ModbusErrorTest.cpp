// ModbusError: every value has its own name and a kernel status.
#include <modbus/ModbusError.hpp>
#include <modbus/Protocol.hpp>

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace {

using modbus::ModbusError;

TEST(ModbusErrorTest, EveryErrorHasItsOwnName)
{
    std::set<std::string> names;
    for (int value = 0; value <= static_cast<int>(ModbusError::InvalidException); ++value) {
        const std::string name = modbus::modbusErrorName(static_cast<ModbusError>(value));
        EXPECT_NE(name, "unknown modbus error") << value;
        names.insert(name);
    }
    EXPECT_EQ(names.size(), static_cast<size_t>(ModbusError::InvalidException) + 1);
    EXPECT_STREQ(modbus::modbusErrorName(static_cast<ModbusError>(200)), "unknown modbus error");
}

TEST(ModbusErrorTest, StatusMapping)
{
    EXPECT_EQ(modbus::toStatus(ModbusError::Ok), dcos::Status::Ok);
    EXPECT_EQ(modbus::toStatus(ModbusError::Timeout), dcos::Status::Timeout);
    EXPECT_EQ(modbus::toStatus(ModbusError::Busy), dcos::Status::Busy);
    EXPECT_EQ(modbus::toStatus(ModbusError::BufferTooSmall), dcos::Status::NoMemory);
    EXPECT_EQ(modbus::toStatus(ModbusError::EchoMismatch), dcos::Status::InvalidArgument);
}

TEST(ModbusErrorTest, ExceptionNames)
{
    EXPECT_STREQ(modbus::exceptionName(0x01), "illegal function");
    EXPECT_STREQ(modbus::exceptionName(0x02), "illegal data address");
    EXPECT_STREQ(modbus::exceptionName(0x03), "illegal data value");
    EXPECT_STREQ(modbus::exceptionName(0x04), "server device failure");
    EXPECT_STREQ(modbus::exceptionName(0x07), "unknown exception");
}

} // namespace
