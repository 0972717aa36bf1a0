// Server: every function code's request and response byte for byte (the
// examples of [AP] 6 where it has them), and every exception where [AP] 6's
// state diagrams put it.
#include <modbus/InMemoryDataModel.hpp>
#include <modbus/Server.hpp>

#include "ModbusTestSupport.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using modbus::DeviceIdentification;
using modbus::ExceptionCode;
using modbus::ModbusError;
using modbus::Server;
using namespace modbus_test;

using Model = modbus::InMemoryDataModel<256, 256, 256, 256>;

DeviceIdentification basicIdentification()
{
    DeviceIdentification identification;
    identification.vendorName = "DCOS";
    identification.productCode = "DC-486";
    identification.revision = "0.1";
    return identification;
}

class ServerTest : public ::testing::Test {
protected:
    ServerTest()
    {
        auto server = Server::create(model_, basicIdentification());
        EXPECT_TRUE(server.ok());
        server_ = server.value();
    }

    Bytes handle(const Bytes& request)
    {
        uint8_t response[modbus::kMaxPduLength + 16];
        const modbus::ServerReply reply = server_.handle(request.data(), request.size(), response);
        EXPECT_LE(reply.length, modbus::kMaxPduLength);
        lastException_ = reply.exception;
        return bytesOf(response, reply.length);
    }

    // The exception response to @p request: the function with 0x80 and the code.
    void expectException(const Bytes& request, uint8_t code)
    {
        EXPECT_EQ(handle(request), (Bytes{static_cast<uint8_t>(request[0] | 0x80), code}));
        EXPECT_EQ(static_cast<uint8_t>(lastException_), code);
    }

    Model model_;
    Server server_;
    ExceptionCode lastException_ = ExceptionCode::None;
};

TEST_F(ServerTest, ReadCoilsSpecificationExample)
{
    // [AP] 6.1: coils 20..38 (addresses 19..37) read as CD 6B 05.
    const Bytes packed = {0xCD, 0x6B, 0x05};
    for (size_t i = 0; i < 19; ++i) {
        model_.coil(19 + i) = modbus::getBit(packed.data(), i);
    }
    model_.coil(38) = true;  // beyond the quantity: must not show in the padding
    EXPECT_EQ(handle({0x01, 0x00, 0x13, 0x00, 0x13}), (Bytes{0x01, 0x03, 0xCD, 0x6B, 0x05}));
    EXPECT_EQ(lastException_, ExceptionCode::None);
}

TEST_F(ServerTest, ReadDiscreteInputsSpecificationExample)
{
    // [AP] 6.2: inputs 197..218 (addresses 196..217) read as AC DB 35.
    const Bytes packed = {0xAC, 0xDB, 0x35};
    for (size_t i = 0; i < 22; ++i) {
        model_.discreteInput(196 + i) = modbus::getBit(packed.data(), i);
    }
    EXPECT_EQ(handle({0x02, 0x00, 0xC4, 0x00, 0x16}), (Bytes{0x02, 0x03, 0xAC, 0xDB, 0x35}));
}

TEST_F(ServerTest, ReadHoldingRegistersSpecificationExample)
{
    // [AP] 6.3: registers 108..110 hold 555, 0, 100.
    model_.holdingRegister(107) = 0x022B;
    model_.holdingRegister(108) = 0x0000;
    model_.holdingRegister(109) = 0x0064;
    EXPECT_EQ(handle({0x03, 0x00, 0x6B, 0x00, 0x03}), (Bytes{0x03, 0x06, 0x02, 0x2B, 0x00, 0x00, 0x00, 0x64}));
}

TEST_F(ServerTest, ReadInputRegistersSpecificationExample)
{
    // [AP] 6.4: register 9 holds 10.
    model_.inputRegister(8) = 0x000A;
    EXPECT_EQ(handle({0x04, 0x00, 0x08, 0x00, 0x01}), (Bytes{0x04, 0x02, 0x00, 0x0A}));
}

TEST_F(ServerTest, WriteSingleCoilEchoes)
{
    // [AP] 6.5: coil 173 on.
    EXPECT_EQ(handle({0x05, 0x00, 0xAC, 0xFF, 0x00}), (Bytes{0x05, 0x00, 0xAC, 0xFF, 0x00}));
    EXPECT_TRUE(model_.coil(0xAC));
    EXPECT_EQ(handle({0x05, 0x00, 0xAC, 0x00, 0x00}), (Bytes{0x05, 0x00, 0xAC, 0x00, 0x00}));
    EXPECT_FALSE(model_.coil(0xAC));
}

TEST_F(ServerTest, WriteSingleRegisterEchoes)
{
    // [AP] 6.6: register 2 set to 3.
    EXPECT_EQ(handle({0x06, 0x00, 0x01, 0x00, 0x03}), (Bytes{0x06, 0x00, 0x01, 0x00, 0x03}));
    EXPECT_EQ(model_.holdingRegister(1), 3);
}

TEST_F(ServerTest, WriteMultipleCoilsSpecificationExample)
{
    // [AP] 6.11: ten coils from 20: CD 01 = 1011 0011 10.
    EXPECT_EQ(handle({0x0F, 0x00, 0x13, 0x00, 0x0A, 0x02, 0xCD, 0x01}), (Bytes{0x0F, 0x00, 0x13, 0x00, 0x0A}));
    const bool expected[10] = {true, false, true, true, false, false, true, true, true, false};
    for (size_t i = 0; i < 10; ++i) {
        EXPECT_EQ(model_.coil(19 + i), expected[i]) << i;
    }
    EXPECT_FALSE(model_.coil(29));
}

TEST_F(ServerTest, WriteMultipleRegistersSpecificationExample)
{
    // [AP] 6.12: registers 2 and 3 set to 000A and 0102.
    EXPECT_EQ(handle({0x10, 0x00, 0x01, 0x00, 0x02, 0x04, 0x00, 0x0A, 0x01, 0x02}),
              (Bytes{0x10, 0x00, 0x01, 0x00, 0x02}));
    EXPECT_EQ(model_.holdingRegister(1), 0x000A);
    EXPECT_EQ(model_.holdingRegister(2), 0x0102);
}

TEST_F(ServerTest, ReadWriteMultipleRegistersSpecificationExample)
{
    // [AP] 6.17: read six from 4, write three (00FF each) from 15.
    const uint16_t values[6] = {0x00FE, 0x0ACD, 0x0001, 0x0003, 0x000D, 0x00FF};
    for (size_t i = 0; i < 6; ++i) {
        model_.holdingRegister(3 + i) = values[i];
    }
    EXPECT_EQ(handle({0x17, 0x00, 0x03, 0x00, 0x06, 0x00, 0x0E, 0x00, 0x03, 0x06, 0x00, 0xFF, 0x00, 0xFF, 0x00, 0xFF}),
              (Bytes{0x17, 0x0C, 0x00, 0xFE, 0x0A, 0xCD, 0x00, 0x01, 0x00, 0x03, 0x00, 0x0D, 0x00, 0xFF}));
    EXPECT_EQ(model_.holdingRegister(14), 0x00FF);
    EXPECT_EQ(model_.holdingRegister(16), 0x00FF);
}

TEST_F(ServerTest, ReadWriteWritesBeforeItReads)
{
    // Overlapping ranges: the read must see the values just written.
    EXPECT_EQ(handle({0x17, 0x00, 0x00, 0x00, 0x02, 0x00, 0x01, 0x00, 0x01, 0x02, 0x12, 0x34}),
              (Bytes{0x17, 0x04, 0x00, 0x00, 0x12, 0x34}));
}

TEST_F(ServerTest, QuantityLimitsAtTheirEdges)
{
    using Model4k = modbus::InMemoryDataModel<4000, 4000, 300, 300>;
    Model4k big;
    Server server = Server::create(big, basicIdentification()).value();
    uint8_t response[300];
    auto code = [&](const Bytes& request) {
        const auto reply = server.handle(request.data(), request.size(), response);
        return static_cast<int>(reply.exception);
    };
    // 01/02: 1..2000.
    EXPECT_EQ(code({0x01, 0, 0, 0x07, 0xD0}), 0);
    EXPECT_EQ(code({0x01, 0, 0, 0x07, 0xD1}), 3);
    EXPECT_EQ(code({0x02, 0, 0, 0x07, 0xD0}), 0);
    EXPECT_EQ(code({0x02, 0, 0, 0, 0}), 3);
    // 03/04: 1..125.
    EXPECT_EQ(code({0x03, 0, 0, 0, 0x7D}), 0);
    EXPECT_EQ(code({0x03, 0, 0, 0, 0x7E}), 3);
    EXPECT_EQ(code({0x04, 0, 0, 0, 0x7D}), 0);
    EXPECT_EQ(code({0x04, 0, 0, 0, 0}), 3);
    // 0F: 1..1968 (0x7B0) with byte count 246.
    Bytes coils = {0x0F, 0, 0, 0x07, 0xB0, 246};
    coils.resize(6 + 246, 0xFF);
    EXPECT_EQ(code(coils), 0);
    coils[4] = 0xB1;
    coils[5] = 247;
    coils.push_back(0x01);
    EXPECT_EQ(code(coils), 3);
    // 10: 1..123 (0x7B) with byte count 246.
    Bytes registers = {0x10, 0, 0, 0, 0x7B, 246};
    registers.resize(6 + 246, 0x11);
    EXPECT_EQ(code(registers), 0);
    registers[4] = 0x7C;
    registers[5] = 248;
    registers.push_back(0);
    registers.push_back(0);
    EXPECT_EQ(code(registers), 3);
    // 17: read 1..125, write 1..121.
    Bytes readWrite = {0x17, 0, 0, 0, 0x7D, 0, 0, 0, 0x79, 242};
    readWrite.resize(10 + 242, 0x22);
    EXPECT_EQ(code(readWrite), 0);
    readWrite[4] = 0x7E;
    EXPECT_EQ(code(readWrite), 3);
    readWrite[4] = 0x7D;
    readWrite[8] = 0x7A;
    readWrite[9] = 244;
    readWrite.push_back(0);
    readWrite.push_back(0);
    EXPECT_EQ(code(readWrite), 3);
    readWrite[8] = 0;
    EXPECT_EQ(code(readWrite), 3);
}

TEST_F(ServerTest, IllegalFunction)
{
    expectException({0x07}, 0x01);                    // Read Exception Status: not served
    expectException({0x08, 0x00, 0x00, 0x12, 0x34}, 0x01);
    expectException({0x2B, 0x0D, 0x00}, 0x01);        // CANopen general reference MEI type
    expectException({0x2B}, 0x01);
    expectException({0x81, 0x00}, 0x01);
}

TEST_F(ServerTest, IllegalDataValueForQuantityLengthByteCountAndCoilValue)
{
    expectException({0x01, 0x00, 0x00, 0x00}, 0x03);              // PDU too short
    expectException({0x03, 0x00, 0x00, 0x00, 0x01, 0x00}, 0x03);  // PDU too long
    expectException({0x03, 0x00, 0x00, 0x00, 0x00}, 0x03);        // quantity 0
    expectException({0x05, 0x00, 0x00, 0x12, 0x34}, 0x03);        // coil value
    expectException({0x05, 0x00, 0x00, 0x00, 0xFF}, 0x03);
    expectException({0x06, 0x00, 0x00, 0x00}, 0x03);
    expectException({0x0F, 0x00, 0x00, 0x00, 0x0A, 0x01, 0xFF}, 0x03);        // byte count 1 for 10 coils
    expectException({0x0F, 0x00, 0x00, 0x00, 0x0A, 0x02, 0xFF}, 0x03);        // one data byte missing
    expectException({0x0F, 0x00, 0x00, 0x00, 0x08, 0x01, 0xFF, 0x00}, 0x03);  // one data byte too many
    expectException({0x10, 0x00, 0x00, 0x00, 0x02, 0x03, 0, 0, 0}, 0x03);     // byte count odd
    expectException({0x10, 0x00, 0x00, 0x00, 0x00, 0x00}, 0x03);              // quantity 0
    expectException({0x10, 0x00}, 0x03);
    expectException({0x17, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x02, 0x00}, 0x03);
    expectException({0x2B, 0x0E, 0x05, 0x00}, 0x03);  // Read Device ID code 05
    expectException({0x2B, 0x0E, 0x00, 0x00}, 0x03);  // and 00
    expectException({0x2B, 0x0E, 0x01}, 0x03);        // object id missing
}

TEST_F(ServerTest, IllegalDataValueComesBeforeIllegalDataAddress)
{
    // Quantity 0 at an address the model lacks: [AP] 6.1 checks the quantity first.
    expectException({0x01, 0xFF, 0xFF, 0x00, 0x00}, 0x03);
}

TEST_F(ServerTest, IllegalDataAddressForRangesAndOverflow)
{
    expectException({0x01, 0x00, 0xFF, 0x00, 0x02}, 0x02);  // 255..256, table is 256
    expectException({0x02, 0x01, 0x00, 0x00, 0x01}, 0x02);
    expectException({0x03, 0x00, 0xFE, 0x00, 0x03}, 0x02);
    expectException({0x04, 0x01, 0x00, 0x00, 0x01}, 0x02);
    expectException({0x05, 0x01, 0x00, 0xFF, 0x00}, 0x02);
    expectException({0x06, 0x01, 0x00, 0x00, 0x01}, 0x02);
    expectException({0x0F, 0x00, 0xFF, 0x00, 0x02, 0x01, 0x03}, 0x02);
    expectException({0x10, 0x00, 0xFF, 0x00, 0x02, 0x04, 0, 1, 0, 2}, 0x02);
    expectException({0x17, 0x00, 0xFF, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x02, 0x00, 0x01}, 0x02);
    expectException({0x17, 0x00, 0x00, 0x00, 0x01, 0x00, 0xFF, 0x00, 0x02, 0x04, 0, 1, 0, 2}, 0x02);
    // Past 0xFFFF: refused before the model is asked.
    expectException({0x03, 0xFF, 0xFF, 0x00, 0x02}, 0x02);
    expectException({0x01, 0xFF, 0x00, 0x01, 0x01}, 0x02);
    expectException({0x2B, 0x0E, 0x04, 0x03}, 0x02);  // individual access to an absent object
    expectException({0x2B, 0x0E, 0x04, 0x80}, 0x02);
}

TEST_F(ServerTest, NothingIsWrittenWhenARequestIsRefused)
{
    expectException({0x10, 0x00, 0xFF, 0x00, 0x02, 0x04, 0, 1, 0, 2}, 0x02);
    EXPECT_EQ(model_.holdingRegister(0xFF), 0);
    expectException({0x17, 0x01, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x02, 0x12, 0x34}, 0x02);
    EXPECT_EQ(model_.holdingRegister(0), 0);
}

TEST_F(ServerTest, ServerDeviceFailureFromTheModel)
{
    model_.failNext();
    expectException({0x03, 0x00, 0x00, 0x00, 0x01}, 0x04);
    model_.failNext();
    expectException({0x05, 0x00, 0x00, 0xFF, 0x00}, 0x04);
    model_.failNext();
    expectException({0x17, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x02, 0x00, 0x01}, 0x04);
    // And the next request is served again.
    EXPECT_EQ(handle({0x04, 0x00, 0x00, 0x00, 0x01}), (Bytes{0x04, 0x02, 0x00, 0x00}));
}

TEST_F(ServerTest, EmptyRequestGetsNoResponse)
{
    EXPECT_TRUE(handle({}).empty());
}

TEST_F(ServerTest, ServerWithoutModelAnswersDeviceFailure)
{
    Server unmade;
    uint8_t response[8];
    const uint8_t request[5] = {0x03, 0, 0, 0, 1};
    const auto reply = unmade.handle(request, 5, response);
    EXPECT_EQ(reply.exception, ExceptionCode::ServerDeviceFailure);
    EXPECT_EQ(reply.length, 2u);
}

TEST(ServerCreateTest, BasicObjectsAreMandatoryAndObjectsBounded)
{
    Model model;
    DeviceIdentification identification = basicIdentification();
    identification.revision = nullptr;
    EXPECT_EQ(Server::create(model, identification).error(), ModbusError::InvalidArgument);
    identification = basicIdentification();
    const std::string longest(modbus::kMaxDeviceIdObjectLength, 'x');
    const std::string tooLong(modbus::kMaxDeviceIdObjectLength + 1, 'x');
    identification.modelName = longest.c_str();
    EXPECT_TRUE(Server::create(model, identification).ok());
    identification.modelName = tooLong.c_str();
    EXPECT_EQ(Server::create(model, identification).error(), ModbusError::InvalidArgument);
}

TEST_F(ServerTest, ReadDeviceIdentificationBasicStream)
{
    // Objects 00 "DCOS", 01 "DC-486", 02 "0.1"; conformity 0x81 without
    // regular objects.
    EXPECT_EQ(handle({0x2B, 0x0E, 0x01, 0x00}),
              (Bytes{0x2B, 0x0E, 0x01, 0x81, 0x00, 0x00, 0x03, 0x00, 0x04, 'D', 'C', 'O', 'S', 0x01, 0x06, 'D', 'C',
                     '-', '4', '8', '6', 0x02, 0x03, '0', '.', '1'}));
}

TEST_F(ServerTest, ReadDeviceIdentificationStreamFromAnObjectAndRestart)
{
    EXPECT_EQ(handle({0x2B, 0x0E, 0x01, 0x02}),
              (Bytes{0x2B, 0x0E, 0x01, 0x81, 0x00, 0x00, 0x01, 0x02, 0x03, '0', '.', '1'}));
    // An object outside the category restarts the stream at object 0.
    const Bytes fromStart = handle({0x2B, 0x0E, 0x01, 0x00});
    EXPECT_EQ(handle({0x2B, 0x0E, 0x01, 0x05}), fromStart);
    EXPECT_EQ(handle({0x2B, 0x0E, 0x01, 0x80}), fromStart);
}

TEST_F(ServerTest, ReadDeviceIdentificationIndividual)
{
    EXPECT_EQ(handle({0x2B, 0x0E, 0x04, 0x01}),
              (Bytes{0x2B, 0x0E, 0x04, 0x81, 0x00, 0x00, 0x01, 0x01, 0x06, 'D', 'C', '-', '4', '8', '6'}));
}

TEST(ServerDeviceIdTest, RegularObjectsAreSplitWithMoreFollows)
{
    Model model;
    DeviceIdentification identification = basicIdentification();
    const std::string url(100, 'u');
    const std::string product(100, 'p');
    identification.vendorUrl = url.c_str();
    identification.productName = product.c_str();
    identification.userApplicationName = "tank";  // 05 ModelName absent
    Server server = Server::create(model, identification).value();
    uint8_t response[modbus::kMaxPduLength];

    // Header 7 + basic objects 6 + 8 + 5 + the URL 102 = 128; the product
    // name would make 230, the application name then 236: everything fits.
    const uint8_t all[4] = {0x2B, 0x0E, 0x02, 0x00};
    auto reply = server.handle(all, 4, response);
    ASSERT_EQ(reply.length, 7u + 6 + 8 + 5 + 102 + 102 + 6);
    EXPECT_EQ(response[3], 0x82);
    EXPECT_EQ(response[4], 0x00);
    EXPECT_EQ(response[6], 6);

    // With a longer product name the application name no longer fits.
    const std::string longer(120, 'p');
    identification.productName = longer.c_str();
    server = Server::create(model, identification).value();
    reply = server.handle(all, 4, response);
    ASSERT_EQ(reply.length, 7u + 6 + 8 + 5 + 102 + 122);
    EXPECT_EQ(response[4], 0xFF);  // more follows
    EXPECT_EQ(response[5], 0x06);  // from the user application name
    EXPECT_EQ(response[6], 5);
    // The master asks again from there.
    const uint8_t rest[4] = {0x2B, 0x0E, 0x02, 0x06};
    reply = server.handle(rest, 4, response);
    EXPECT_EQ(bytesOf(response, reply.length),
              (Bytes{0x2B, 0x0E, 0x02, 0x82, 0x00, 0x00, 0x01, 0x06, 0x04, 't', 'a', 'n', 'k'}));
    // The basic stream leaves regular objects out; the extended one is the regular one.
    const uint8_t basic[4] = {0x2B, 0x0E, 0x01, 0x00};
    reply = server.handle(basic, 4, response);
    EXPECT_EQ(response[6], 3);
    EXPECT_EQ(reply.length, 7u + 6 + 8 + 5);
    const uint8_t extended[4] = {0x2B, 0x0E, 0x03, 0x06};
    reply = server.handle(extended, 4, response);
    EXPECT_EQ(response[6], 1);
    EXPECT_EQ(response[7], 0x06);
    // An absent regular object restarts the stream; individually it is 02.
    const uint8_t absent[4] = {0x2B, 0x0E, 0x02, 0x05};
    reply = server.handle(absent, 4, response);
    EXPECT_EQ(response[7], 0x00);
    const uint8_t individual[4] = {0x2B, 0x0E, 0x04, 0x05};
    reply = server.handle(individual, 4, response);
    EXPECT_EQ(reply.exception, ExceptionCode::IllegalDataAddress);
}

TEST(ServerBroadcastTest, OnlyWritesAreBroadcastWrites)
{
    for (int function = 0; function < 256; ++function) {
        const bool write = function == 0x05 || function == 0x06 || function == 0x0F || function == 0x10;
        EXPECT_EQ(Server::isBroadcastWrite(static_cast<uint8_t>(function)), write) << function;
    }
}

} // namespace
