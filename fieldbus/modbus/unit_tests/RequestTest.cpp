// Request: every builder byte for byte and every refusal; checkResponse()
// against good, exception and malformed responses; ResponseView.
#include <modbus/Request.hpp>
#include <modbus/Response.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using modbus::DeviceIdCode;
using modbus::ExceptionCode;
using modbus::ModbusError;
using modbus::Request;
using modbus::ResponseView;
using namespace modbus_test;

Bytes pduOf(const modbus::ModbusResult<Request>& request)
{
    EXPECT_TRUE(request.ok()) << modbus::modbusErrorName(request.error());
    return bytesOf(request.value().pdu, request.value().length);
}

TEST(RequestTest, ReadsByteForByte)
{
    EXPECT_EQ(pduOf(Request::readCoils(1, 0x0013, 0x0013)), (Bytes{0x01, 0x00, 0x13, 0x00, 0x13}));
    EXPECT_EQ(pduOf(Request::readDiscreteInputs(1, 0x00C4, 0x0016)), (Bytes{0x02, 0x00, 0xC4, 0x00, 0x16}));
    EXPECT_EQ(pduOf(Request::readHoldingRegisters(1, 0x006B, 3)), (Bytes{0x03, 0x00, 0x6B, 0x00, 0x03}));
    EXPECT_EQ(pduOf(Request::readInputRegisters(1, 0x0008, 1)), (Bytes{0x04, 0x00, 0x08, 0x00, 0x01}));
    EXPECT_EQ(Request::readInputRegisters(17, 8, 1).value().unit, 17);
}

TEST(RequestTest, WritesByteForByte)
{
    EXPECT_EQ(pduOf(Request::writeSingleCoil(1, 0x00AC, true)), (Bytes{0x05, 0x00, 0xAC, 0xFF, 0x00}));
    EXPECT_EQ(pduOf(Request::writeSingleCoil(1, 0x00AC, false)), (Bytes{0x05, 0x00, 0xAC, 0x00, 0x00}));
    EXPECT_EQ(pduOf(Request::writeSingleRegister(1, 0x0001, 0x0003)), (Bytes{0x06, 0x00, 0x01, 0x00, 0x03}));
    // Bits past the quantity in the caller's last byte are not sent.
    const uint8_t coils[2] = {0xCD, 0xFF};
    EXPECT_EQ(pduOf(Request::writeMultipleCoils(1, 0x0013, 10, coils)),
              (Bytes{0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x03}));
    const uint16_t registers[2] = {0x000A, 0x0102};
    EXPECT_EQ(pduOf(Request::writeMultipleRegisters(1, 0x0001, 2, registers)),
              (Bytes{0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0A, 0x01, 0x02}));
    const uint16_t written[3] = {0x00FF, 0x00FF, 0x00FF};
    EXPECT_EQ(pduOf(Request::readWriteMultipleRegisters(1, 0x0003, 6, 0x000E, 3, written)),
              (Bytes{0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x03, 0x06, 0x00, 0xFF, 0x00, 0xFF, 0x00, 0xFF}));
    EXPECT_EQ(pduOf(Request::readDeviceIdentification(1, DeviceIdCode::RegularStream, 0)),
              (Bytes{0x2B, 0x0E, 0x02, 0x00}));
}

TEST(RequestTest, BroadcastOnlyForWrites)
{
    const uint16_t values[1] = {1};
    const uint8_t bits[1] = {1};
    EXPECT_TRUE(Request::writeSingleCoil(0, 0, true).value().isBroadcast());
    EXPECT_TRUE(Request::writeSingleRegister(0, 0, 1).ok());
    EXPECT_TRUE(Request::writeMultipleCoils(0, 0, 1, bits).ok());
    EXPECT_TRUE(Request::writeMultipleRegisters(0, 0, 1, values).ok());
    EXPECT_EQ(Request::readCoils(0, 0, 1).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Request::readDiscreteInputs(0, 0, 1).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Request::readHoldingRegisters(0, 0, 1).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Request::readInputRegisters(0, 0, 1).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Request::readWriteMultipleRegisters(0, 0, 1, 0, 1, values).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Request::readDeviceIdentification(0, DeviceIdCode::BasicStream, 0).error(),
              ModbusError::InvalidSlaveAddress);
}

TEST(RequestTest, Refusals)
{
    const uint16_t values[125] = {};
    const uint8_t bits[250] = {};
    EXPECT_EQ(Request::readCoils(248, 0, 1).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_EQ(Request::writeSingleCoil(255, 0, true).error(), ModbusError::InvalidSlaveAddress);
    EXPECT_TRUE(Request::readCoils(247, 0, 2000).ok());
    EXPECT_EQ(Request::readCoils(1, 0, 2001).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::readDiscreteInputs(1, 0, 0).error(), ModbusError::InvalidQuantity);
    EXPECT_TRUE(Request::readHoldingRegisters(1, 0, 125).ok());
    EXPECT_EQ(Request::readHoldingRegisters(1, 0, 126).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::readInputRegisters(1, 0, 0).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::readInputRegisters(1, 0xFFFF, 2).error(), ModbusError::AddressOverflow);
    EXPECT_TRUE(Request::readInputRegisters(1, 0xFFFF, 1).ok());
    EXPECT_TRUE(Request::writeMultipleCoils(1, 0, 1968, bits).ok());
    EXPECT_EQ(Request::writeMultipleCoils(1, 0, 1969, bits).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::writeMultipleCoils(1, 0, 1, nullptr).error(), ModbusError::InvalidArgument);
    EXPECT_EQ(Request::writeMultipleCoils(1, 0xFFF0, 17, bits).error(), ModbusError::AddressOverflow);
    EXPECT_TRUE(Request::writeMultipleRegisters(1, 0, 123, values).ok());
    EXPECT_EQ(Request::writeMultipleRegisters(1, 0, 124, values).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::writeMultipleRegisters(1, 0, 1, nullptr).error(), ModbusError::InvalidArgument);
    EXPECT_TRUE(Request::readWriteMultipleRegisters(1, 0, 125, 0, 121, values).ok());
    EXPECT_EQ(Request::readWriteMultipleRegisters(1, 0, 126, 0, 1, values).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::readWriteMultipleRegisters(1, 0, 1, 0, 122, values).error(), ModbusError::InvalidQuantity);
    EXPECT_EQ(Request::readWriteMultipleRegisters(1, 0, 1, 0xFFFF, 2, values).error(), ModbusError::AddressOverflow);
    EXPECT_EQ(Request::readWriteMultipleRegisters(1, 0, 1, 0, 1, nullptr).error(), ModbusError::InvalidArgument);
    EXPECT_EQ(Request::readDeviceIdentification(1, static_cast<DeviceIdCode>(5), 0).error(),
              ModbusError::InvalidArgument);
    EXPECT_EQ(Request::readDeviceIdentification(1, static_cast<DeviceIdCode>(0), 0).error(),
              ModbusError::InvalidArgument);
}

// checkResponse() for one request and a response PDU.
ModbusError check(const Request& request, const Bytes& response, ExceptionCode* exception = nullptr)
{
    ExceptionCode code = ExceptionCode::ServerDeviceBusy;  // must be overwritten
    const ModbusError error = modbus::checkResponse(request, response.data(), response.size(), code);
    if (exception != nullptr) {
        *exception = code;
    } else {
        EXPECT_EQ(code, ExceptionCode::None);
    }
    return error;
}

TEST(CheckResponseTest, ReadsNeedTheByteCountOfTheQuantity)
{
    const Request coils = Request::readCoils(1, 0x13, 0x13).value();
    EXPECT_EQ(check(coils, {0x01, 0x03, 0xCD, 0x6B, 0x05}), ModbusError::Ok);
    EXPECT_EQ(check(coils, {0x01, 0x02, 0xCD, 0x6B}), ModbusError::InvalidResponse);
    EXPECT_EQ(check(coils, {0x01, 0x03, 0xCD, 0x6B}), ModbusError::InvalidResponse);
    EXPECT_EQ(check(coils, {0x01, 0x03, 0xCD, 0x6B, 0x05, 0x00}), ModbusError::InvalidResponse);
    const Request registers = Request::readHoldingRegisters(1, 0x6B, 3).value();
    EXPECT_EQ(check(registers, {0x03, 0x06, 0x02, 0x2B, 0x00, 0x00, 0x00, 0x64}), ModbusError::Ok);
    EXPECT_EQ(check(registers, {0x03, 0x04, 0x02, 0x2B, 0x00, 0x00}), ModbusError::InvalidResponse);
    EXPECT_EQ(check(registers, {0x03}), ModbusError::InvalidResponse);
    EXPECT_EQ(check(registers, {0x04, 0x06, 0x02, 0x2B, 0x00, 0x00, 0x00, 0x64}), ModbusError::UnexpectedFunction);
    EXPECT_EQ(check(registers, {}), ModbusError::InvalidResponse);
    const uint16_t values[1] = {5};
    const Request readWrite = Request::readWriteMultipleRegisters(1, 0, 2, 10, 1, values).value();
    EXPECT_EQ(check(readWrite, {0x17, 0x04, 0, 1, 0, 2}), ModbusError::Ok);
    EXPECT_EQ(check(readWrite, {0x17, 0x02, 0, 1}), ModbusError::InvalidResponse);
}

TEST(CheckResponseTest, WritesMustEcho)
{
    const Request coil = Request::writeSingleCoil(1, 0xAC, true).value();
    EXPECT_EQ(check(coil, {0x05, 0x00, 0xAC, 0xFF, 0x00}), ModbusError::Ok);
    EXPECT_EQ(check(coil, {0x05, 0x00, 0xAC, 0x00, 0x00}), ModbusError::EchoMismatch);
    EXPECT_EQ(check(coil, {0x05, 0x00, 0xAD, 0xFF, 0x00}), ModbusError::EchoMismatch);
    EXPECT_EQ(check(coil, {0x05, 0x00, 0xAC, 0xFF}), ModbusError::InvalidResponse);
    const uint16_t values[2] = {0x000A, 0x0102};
    const Request registers = Request::writeMultipleRegisters(1, 1, 2, values).value();
    EXPECT_EQ(check(registers, {0x10, 0x00, 0x01, 0x00, 0x02}), ModbusError::Ok);
    EXPECT_EQ(check(registers, {0x10, 0x00, 0x01, 0x00, 0x03}), ModbusError::EchoMismatch);
}

TEST(CheckResponseTest, ExceptionResponses)
{
    const Request request = Request::readHoldingRegisters(1, 0, 1).value();
    ExceptionCode code = ExceptionCode::None;
    EXPECT_EQ(check(request, {0x83, 0x02}, &code), ModbusError::ExceptionResponse);
    EXPECT_EQ(code, ExceptionCode::IllegalDataAddress);
    EXPECT_EQ(check(request, {0x83}, &code), ModbusError::InvalidException);
    EXPECT_EQ(code, ExceptionCode::None);
    EXPECT_EQ(check(request, {0x83, 0x02, 0x00}, &code), ModbusError::InvalidException);
    // The exception of another function is not an answer to this request.
    EXPECT_EQ(check(request, {0x84, 0x02}, &code), ModbusError::UnexpectedFunction);
}

TEST(CheckResponseTest, DeviceIdentificationLayout)
{
    const Request request = Request::readDeviceIdentification(1, DeviceIdCode::BasicStream, 0).value();
    const Bytes good = {0x2B, 0x0E, 0x01, 0x81, 0x00, 0x00, 0x02, 0x00, 0x01, 'A', 0x01, 0x02, 'B', 'C'};
    EXPECT_EQ(check(request, good), ModbusError::Ok);
    Bytes wrong = good;
    wrong[1] = 0x0D;
    EXPECT_EQ(check(request, wrong), ModbusError::InvalidResponse);
    wrong = good;
    wrong[2] = 0x02;
    EXPECT_EQ(check(request, wrong), ModbusError::InvalidResponse);
    wrong = good;
    wrong[4] = 0x01;
    EXPECT_EQ(check(request, wrong), ModbusError::InvalidResponse);
    wrong = good;
    wrong[6] = 3;  // one object more than there is
    EXPECT_EQ(check(request, wrong), ModbusError::InvalidResponse);
    wrong = good;
    wrong[11] = 3;  // an object running past the end
    EXPECT_EQ(check(request, wrong), ModbusError::InvalidResponse);
    wrong = good;
    wrong.push_back(0);  // a byte after the last object
    EXPECT_EQ(check(request, wrong), ModbusError::InvalidResponse);
    EXPECT_EQ(check(request, Bytes(good.begin(), good.begin() + 6)), ModbusError::InvalidResponse);

    const ResponseView view(good.data(), good.size());
    EXPECT_FALSE(view.moreFollows());
    EXPECT_EQ(view.conformityLevel(), 0x81);
    ASSERT_EQ(view.objectCount(), 2u);
    modbus::DeviceIdObject object;
    ASSERT_TRUE(view.object(1, object));
    EXPECT_EQ(object.id, 0x01);
    EXPECT_EQ(Bytes(object.value, object.value + object.length), (Bytes{'B', 'C'}));
    EXPECT_FALSE(view.object(2, object));
}

TEST(CheckResponseTest, HandMadeRequestOfAnotherFunctionCannotBeChecked)
{
    Request request;
    request.unit = 1;
    request.pdu[0] = 0x07;
    request.length = 1;
    EXPECT_EQ(check(request, {0x07, 0x00}), ModbusError::InvalidArgument);
}

TEST(ResponseViewTest, RegistersAndBits)
{
    const Bytes registers = {0x03, 0x04, 0x12, 0x34, 0xAB, 0xCD};
    const ResponseView view(registers.data(), registers.size());
    EXPECT_EQ(view.registerCount(), 2u);
    EXPECT_EQ(view.registerValue(0), 0x1234);
    EXPECT_EQ(view.registerValue(1), 0xABCD);
    EXPECT_EQ(view.registerValue(2), 0);
    const Bytes bits = {0x01, 0x02, 0x05, 0x80};
    const ResponseView bitView(bits.data(), bits.size());
    EXPECT_TRUE(bitView.bit(0));
    EXPECT_FALSE(bitView.bit(1));
    EXPECT_TRUE(bitView.bit(2));
    EXPECT_TRUE(bitView.bit(15));
    EXPECT_FALSE(bitView.bit(16));
    EXPECT_EQ(ResponseView().registerCount(), 0u);
}

} // namespace
