// The command-line values of the Modbus host tools: what is accepted, what
// it means, and that every refusal says what was expected.
#include <hostmodbus/Arguments.hpp>

#include <gtest/gtest.h>

namespace {

using namespace hostmodbus;

TEST(ModbusArguments, AddressesInDecimalAndHexadecimal)
{
    EXPECT_EQ(parseAddress("0").value(), 0);
    EXPECT_EQ(parseAddress("65535").value(), 65535);
    EXPECT_EQ(parseAddress("0x10").value(), 16);
    EXPECT_EQ(parseAddress("0XfFfF").value(), 65535);
    for (const char* bad : {"", "65536", "-1", "0x", "0x10000", "1e3", "12a", " 1", "99999999999999999999"}) {
        const Result<uint16_t> r = parseAddress(bad);
        EXPECT_FALSE(r.ok()) << bad;
        EXPECT_NE(r.error().find("data address"), std::string::npos) << r.error();
    }
}

TEST(ModbusArguments, RegisterValuesTakeTwosComplementForNegatives)
{
    EXPECT_EQ(parseRegisterValue("0").value(), 0);
    EXPECT_EQ(parseRegisterValue("65535").value(), 65535);
    EXPECT_EQ(parseRegisterValue("-1").value(), 0xFFFF);
    EXPECT_EQ(parseRegisterValue("-32768").value(), 0x8000);
    EXPECT_EQ(parseRegisterValue("0xBEEF").value(), 0xBEEF);
    for (const char* bad : {"-0", "-32769", "65536", "--1", "-", "", "0x1FFFF"}) {
        const Result<uint16_t> r = parseRegisterValue(bad);
        EXPECT_FALSE(r.ok()) << bad;
        EXPECT_NE(r.error().find("-32768 to -1"), std::string::npos) << r.error();
    }
}

TEST(ModbusArguments, BitsAndSlaveAddresses)
{
    EXPECT_TRUE(parseBit("ON").value());
    EXPECT_TRUE(parseBit("1").value());
    EXPECT_FALSE(parseBit("false").value());
    EXPECT_FALSE(parseBit("2").ok());
    EXPECT_EQ(parseSlaveAddress("247").value(), 247);
    EXPECT_EQ(parseSlaveAddress("0x11").value(), 17);
    EXPECT_FALSE(parseSlaveAddress("0").ok());   // broadcast is not offered
    EXPECT_FALSE(parseSlaveAddress("248").ok()); // reserved ([SL] 2.2)
}

TEST(ModbusArguments, RegisterListsAndTheirLimits)
{
    const Result<RegisterList> list = parseRegisterList("100=1,0x20,-3", kMaxWriteRegisters);
    ASSERT_TRUE(list.ok()) << list.error();
    EXPECT_EQ(list.value().address, 100);
    EXPECT_EQ(list.value().values, (std::vector<uint16_t>{1, 0x20, 0xFFFD}));
    EXPECT_FALSE(parseRegisterList("100", kMaxWriteRegisters).ok());
    EXPECT_FALSE(parseRegisterList("100=", kMaxWriteRegisters).ok());
    EXPECT_FALSE(parseRegisterList("100=1,,2", kMaxWriteRegisters).ok());
    EXPECT_FALSE(parseRegisterList("=1", kMaxWriteRegisters).ok());
    EXPECT_FALSE(parseRegisterList("65535=1,2", kMaxWriteRegisters).ok()); // runs past 65535
    EXPECT_TRUE(parseRegisterList("65535=1", kMaxWriteRegisters).ok());
    std::string many = "0=";
    for (unsigned i = 0; i < kMaxWriteRegisters; ++i) {
        many += i == 0 ? "1" : ",1";
    }
    EXPECT_TRUE(parseRegisterList(many, kMaxWriteRegisters).ok());
    const Result<RegisterList> tooMany = parseRegisterList(many + ",1", kMaxWriteRegisters);
    EXPECT_FALSE(tooMany.ok());
    EXPECT_EQ(tooMany.error(), "more than 123 registers in one write");
}

TEST(ModbusArguments, BitListsAndRanges)
{
    const Result<BitList> bits = parseBitList("16=1,0,on", kMaxWriteBits);
    ASSERT_TRUE(bits.ok()) << bits.error();
    EXPECT_EQ(bits.value().address, 16);
    EXPECT_EQ(bits.value().values, (std::vector<bool>{true, false, true}));
    EXPECT_FALSE(parseBitList("16=1,x", kMaxWriteBits).ok());
    const Result<Range> range = parseRange("100:4", kMaxReadRegisters);
    ASSERT_TRUE(range.ok());
    EXPECT_EQ(range.value().address, 100);
    EXPECT_EQ(range.value().count, 4);
    EXPECT_FALSE(parseRange("100:0", kMaxReadRegisters).ok());
    EXPECT_FALSE(parseRange("100:126", kMaxReadRegisters).ok());
    EXPECT_FALSE(parseRange("100", kMaxReadRegisters).ok());
    EXPECT_EQ(checkRange(0, 126, 125).error(), "a count of 126 is out of range: 1 to 125");
}

TEST(ModbusArguments, SerialSettings)
{
    EXPECT_EQ(parseParity("e").value(), 'E');
    EXPECT_EQ(parseParity("None").value(), 'N');
    EXPECT_EQ(parseParity("odd").value(), 'O');
    EXPECT_FALSE(parseParity("mark").ok());
    EXPECT_EQ(checkBaudRate(19200).value(), 19200);
    EXPECT_FALSE(checkBaudRate(19201).ok());
    EXPECT_FALSE(checkBaudRate(0).ok());
}

TEST(ModbusArguments, UnprintableInputIsEscapedInMessages)
{
    const Result<uint16_t> r = parseAddress(std::string("1\x1b[2J", 5));
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("\\x1b"), std::string::npos) << r.error();
    EXPECT_EQ(r.error().find('\x1b'), std::string::npos);
}

} // namespace
