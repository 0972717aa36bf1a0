// Host tests for the data model of an application's Modbus register map:
// the addresses of each table reach the bytes of the right page or the
// right I/O board points, through a fake backend that records every call.
#include <mbline/ApplicationMapModel.hpp>

#include <dcos/ConfigurationRules.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <string>

using dcos::app::ModbusMapEntry;
using dcos::app::ModbusSource;
using dcos::app::ModbusTable;
using modbus::ExceptionCode;

namespace {

void control(uintptr_t) {}

constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "control", .entry = control}};
constexpr dcos::app::PublisherDeclaration publishers[] = {{.name = "setpoint"}, {.name = "measured", .writer = "control"}};
// Holding 0-3 and coils 0-15 on the setpoint page (bytes 0-7 and 8-9);
// input registers 10-17 the measured page; 20-23 analog inputs 2-5; coils
// 100-107 digital outputs 4-11. Input registers 18 and 19 are a hole.
constexpr ModbusMapEntry map[] = {
    {.name = "setpoint", .table = ModbusTable::HoldingRegisters, .address = 0, .count = 4, .object = "setpoint"},
    {.name = "enable", .table = ModbusTable::Coils, .address = 0, .count = 16, .object = "setpoint", .offset = 8},
    {.name = "measured", .table = ModbusTable::InputRegisters, .address = 10, .count = 8, .object = "measured"},
    {.name = "ai", .table = ModbusTable::InputRegisters, .address = 20, .count = 4,
     .source = ModbusSource::AnalogInput, .offset = 2},
    {.name = "do", .table = ModbusTable::Coils, .address = 100, .count = 8, .source = ModbusSource::DigitalOutput,
     .offset = 4},
};
constexpr dcos::app::Application application{
    .name = "mapped", .tasks = tasks, .publishers = publishers, .modbusMap = map};
static_assert(dcos::app::findConfigurationError(application).ok());

class FakeBackend final : public mbline::MapBackend {
public:
    ExceptionCode readPage(const char* publisher, dcos::DsmPage& page) override
    {
        page = pages[publisher];
        return failing ? ExceptionCode::ServerDeviceFailure : ExceptionCode::None;
    }
    ExceptionCode writePage(const char* publisher, const dcos::DsmPage& page) override
    {
        pages[publisher] = page;
        ++pageWrites;
        return ExceptionCode::None;
    }
    ExceptionCode readAnalogInput(uint32_t channel, uint16_t& counts) override
    {
        counts = static_cast<uint16_t>(0x100 * channel + 7);
        return ExceptionCode::None;
    }
    ExceptionCode readDigitalOutputs(uint16_t& value) override
    {
        value = outputs;
        return ExceptionCode::None;
    }
    ExceptionCode writeDigitalOutputs(uint16_t mask, uint16_t value) override
    {
        outputs = static_cast<uint16_t>((outputs & ~mask) | (value & mask));
        ++outputWrites;
        return ExceptionCode::None;
    }

    std::map<std::string, dcos::DsmPage> pages;
    uint16_t outputs = 0;
    int pageWrites = 0;
    int outputWrites = 0;
    bool failing = false;
};

struct ApplicationMapModelTest : ::testing::Test {
    FakeBackend backend;
    mbline::ApplicationMapModel model{application.modbusMap, backend};
};

} // namespace

TEST_F(ApplicationMapModelTest, AHoldingRegisterWriteLandsInThePageHighByteFirst)
{
    backend.pages["setpoint"].bytes[15] = 0x5A; // Not named by the write: kept.
    const uint16_t values[] = {0x1234, 0xABCD};
    EXPECT_EQ(model.writeHoldingRegisters(1, 2, values), ExceptionCode::None);
    const dcos::DsmPage& page = backend.pages["setpoint"];
    const uint8_t expected[16] = {0, 0, 0x12, 0x34, 0xAB, 0xCD, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x5A};
    EXPECT_EQ(std::memcmp(page.bytes, expected, 16), 0);
    EXPECT_EQ(backend.pageWrites, 1);
    uint16_t read[4] = {};
    EXPECT_EQ(model.readHoldingRegisters(0, 4, read), ExceptionCode::None);
    EXPECT_EQ(read[0], 0);
    EXPECT_EQ(read[1], 0x1234);
    EXPECT_EQ(read[2], 0xABCD);
    EXPECT_EQ(read[3], 0);
}

TEST_F(ApplicationMapModelTest, CoilsArePackedBitsFromTheirOffset)
{
    uint8_t bits[2] = {0x05, 0x01}; // Coils 3, 5 and 11 of 3..11.
    EXPECT_EQ(model.writeCoils(3, 9, bits), ExceptionCode::None);
    const dcos::DsmPage& page = backend.pages["setpoint"];
    // Coil n is bit n of bytes 8 and 9: 3, 5 and 11 on.
    EXPECT_EQ(page.bytes[8], 0x28);
    EXPECT_EQ(page.bytes[9], 0x08);
    uint8_t read[2] = {};
    EXPECT_EQ(model.readCoils(0, 16, read), ExceptionCode::None);
    EXPECT_EQ(read[0], 0x28);
    EXPECT_EQ(read[1], 0x08);
}

TEST_F(ApplicationMapModelTest, InputRegistersServeThePublishedPageAndTheAnalogInputs)
{
    dcos::DsmPage& page = backend.pages["measured"];
    page.bytes[0] = 0x01;
    page.bytes[1] = 0x02;
    page.bytes[14] = 0xFE;
    page.bytes[15] = 0xDC;
    uint16_t values[8] = {};
    EXPECT_EQ(model.readInputRegisters(10, 8, values), ExceptionCode::None);
    EXPECT_EQ(values[0], 0x0102);
    EXPECT_EQ(values[7], 0xFEDC);
    // Analog inputs 3 and 4 at addresses 21 and 22.
    uint16_t counts[2] = {};
    EXPECT_EQ(model.readInputRegisters(21, 2, counts), ExceptionCode::None);
    EXPECT_EQ(counts[0], 0x307);
    EXPECT_EQ(counts[1], 0x407);
}

TEST_F(ApplicationMapModelTest, CoilsDriveTheirDigitalOutputsOnly)
{
    backend.outputs = 0x8001; // Outputs 0 and 15 are not in the map and stay.
    const uint8_t bits[1] = {0xA5};
    EXPECT_EQ(model.writeCoils(100, 8, bits), ExceptionCode::None);
    EXPECT_EQ(backend.outputs, 0x8A51);
    uint8_t read[1] = {};
    EXPECT_EQ(model.readCoils(102, 4, read), ExceptionCode::None);
    EXPECT_EQ(read[0], 0x09); // Outputs 6 to 9: 1, 0, 0, 1.
}

TEST_F(ApplicationMapModelTest, ARangeMayCrossEntriesButNotAHole)
{
    uint16_t values[12] = {};
    // 10-17 the page, 18 and 19 nothing: refused before any read.
    EXPECT_EQ(model.readInputRegisters(16, 6, values), ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(model.readInputRegisters(18, 1, values), ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(model.readInputRegisters(23, 2, values), ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(model.readDiscreteInputs(0, 1, reinterpret_cast<uint8_t*>(values)), ExceptionCode::IllegalDataAddress);
    // Holding 4 is past the setpoint entry: the write changes nothing.
    const uint16_t writes[2] = {1, 2};
    EXPECT_EQ(model.writeHoldingRegisters(3, 2, writes), ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(backend.pageWrites, 0);
    const uint8_t bits[3] = {0xFF, 0xFF, 0xFF};
    EXPECT_EQ(model.writeCoils(99, 2, bits), ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(model.writeCoils(0, 17, bits), ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(backend.pageWrites, 0);
    EXPECT_EQ(backend.outputWrites, 0);
}

TEST_F(ApplicationMapModelTest, ABackendFailureIsTheSlavesException)
{
    backend.failing = true;
    uint16_t values[1] = {};
    EXPECT_EQ(model.readHoldingRegisters(0, 1, values), ExceptionCode::ServerDeviceFailure);
    EXPECT_EQ(model.writeHoldingRegisters(0, 1, values), ExceptionCode::ServerDeviceFailure);
    EXPECT_EQ(backend.pageWrites, 0);
}
