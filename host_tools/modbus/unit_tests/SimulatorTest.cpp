// dcos-modbus-sim's configuration checks (each refusal names its line) and
// its behaviours in time: the drive's ramp, enable and "at speed", the
// sensor's sine and noise, the map's gaps, the request framing.
#include <hostmodbus/RequestRanges.hpp>
#include <hostmodbus/Simulator.hpp>
#include <hostmodbus/SimulatorConfig.hpp>

#include <modbus/Crc16.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace {

using namespace hostmodbus;

const char* const kDevice = "[device]\nvendor_name = \"DCOS\"\nproduct_code = \"T\"\nrevision = \"1\"\n";

SimulatorConfig parsed(const std::string& entries)
{
    const Result<SimulatorConfig> r = parseSimulatorConfig(std::string(kDevice) + entries, "test.toml");
    EXPECT_TRUE(r.ok()) << r.error();
    return r.ok() ? r.value() : SimulatorConfig{};
}

std::string refusal(const std::string& text)
{
    const Result<SimulatorConfig> r = parseSimulatorConfig(text, "test.toml");
    EXPECT_FALSE(r.ok()) << text;
    return r.error();
}

const char* const kDrive = R"(
[[coil]]
name = "run"
address = 0
[[holding_register]]
name = "setpoint"
address = 0
[[input_register]]
name = "speed"
address = 0
ramp = { follows = "setpoint", per_second = 100, enable = "run" }
[[discrete_input]]
name = "at_speed"
address = 0
compare = { a = "speed", b = "setpoint", tolerance = 2 }
)";

TEST(ModbusSimulatorConfig, ReadsTheDriveExample)
{
    const SimulatorConfig config = parsed(kDrive);
    ASSERT_EQ(config.points.size(), 4u);
    EXPECT_EQ(config.slave, 1);
    ASSERT_EQ(config.identification.size(), 3u);
    EXPECT_EQ(config.identification[1].value, "T");
    const Point& speed = config.points[static_cast<size_t>(config.find("speed"))];
    EXPECT_EQ(speed.table, Table::InputRegister);
    EXPECT_EQ(speed.behaviour.kind, Behaviour::Kind::Ramp);
    EXPECT_EQ(speed.behaviour.source, config.find("setpoint"));
    EXPECT_EQ(speed.behaviour.enable, config.find("run"));
    EXPECT_EQ(speed.line, 12);
}

TEST(ModbusSimulatorConfig, RefusalsNameTheLine)
{
    const std::string d = kDevice; // lines 1-4
    EXPECT_EQ(refusal(d + "[[coil]]\naddress = 0\nvalue = 3\n"),
              "test.toml:7: [[coil]]: 'value' must be true or false");
    EXPECT_EQ(refusal(d + "[[holding_register]]\naddress = 0\nvalue = 65536\n"),
              "test.toml:7: [[holding_register]]: 'value' must be an integer from -32768 to 65535");
    EXPECT_EQ(refusal(d + "[[coil]]\nname = \"9lives\"\naddress = 0\n"),
              "test.toml:6: [[coil]]: '9lives' is not a name: letters, digits and _, not starting with a digit");
    EXPECT_EQ(refusal(d + "[[coil]]\nname = \"a\"\naddress = 0\n[[coil]]\nname = \"a\"\naddress = 1\n"),
              "test.toml:9: [[coil]]: the name 'a' is taken by the entry on line 5");
    EXPECT_EQ(refusal(d + "[[coil]]\naddress = 65535\ncount = 2\n"),
              "test.toml:5: [[coil]]: 2 items from address 65535 run past 65535");
    EXPECT_EQ(refusal(d + "[[input_register]]\nname = \"s\"\naddress = 0\nsine = { amplitude = 1 }\n"),
              "test.toml:8: input register 's' sine: 'period_s' is required");
    EXPECT_EQ(refusal(d + "[[input_register]]\nname = \"s\"\naddress = 0\nsine = { period_s = 0 }\n"),
              "test.toml:8: input register 's' sine: 'period_s' must be a number from 0.001 to 1000000000");
    EXPECT_EQ(refusal(d + "[[input_register]]\nname = \"s\"\naddress = 0\nconstant = { value = 1 }\n"
                          "sine = { period_s = 1 }\n"),
              "test.toml:8: input register 's': 'sine' and 'constant' together: a point has one behaviour");
    EXPECT_EQ(refusal(d + "[[input_register]]\nname = \"s\"\naddress = 0\nramp = { follows = \"s\", per_second = 1 }\n"),
              "test.toml:8: input register 's' ramp: a register cannot ramp towards itself");
    EXPECT_EQ(refusal(d + "[[coil]]\nname = \"c\"\naddress = 0\n[[input_register]]\naddress = 0\n"
                          "ramp = { follows = \"c\", per_second = 1 }\n"),
              "test.toml:10: input register 'input_register_0' ramp: 'follows' names 'c', a coil, where a register "
              "is needed");
    EXPECT_EQ(refusal(d + "[[holding_register]]\naddress = 0\ncount = 2\nconstant = { value = 1 }\n"),
              "test.toml:8: holding register 'holding_register_0': a block of 2 cannot have a behaviour; give it "
              "count = 1");
    EXPECT_EQ(refusal("coil = 3\n" + d), "test.toml:1: 'coil' must be an array of tables: write [[coil]] before each "
                                         "entry");
    EXPECT_EQ(refusal(d), "test.toml:1: no entries: declare at least one [[coil]], [[discrete_input]], "
                          "[[holding_register]] or [[input_register]]");
    EXPECT_EQ(refusal("[[coil]]\naddress = 0\n"),
              "test.toml:1: a [device] table with vendor_name, product_code and revision is required");
    EXPECT_EQ(refusal("[device]\nvendor_name = 1\n"),
              "test.toml:2: [device]: 'vendor_name' must be a string of at most 64 bytes");
    EXPECT_EQ(refusal(std::string(kDevice) + "[[coil]]\naddress = \n"),
              "test.toml:6:11: not TOML: Error while parsing key-value pair: expected value, saw '\\n'");
}

// toml++ reaches __builtin_unreachable() on some non-ASCII characters where
// it looks for white space (U+011A in a key, found by the fuzzer), so such a
// file is refused before toml++ sees it, with the line of the first byte.
TEST(ModbusSimulatorConfig, OnlyAsciiIsAccepted)
{
    EXPECT_EQ(refusal(std::string(kDevice) + "[[coil]]\nr\xc4\x9avision = 1\n"),
              "test.toml:6: only ASCII characters are accepted (the TOML library fails on some others)");
    EXPECT_EQ(refusal("# Gr\xc3\xbc\xc3\x9f\n"), "test.toml:1: only ASCII characters are accepted (the TOML library "
                                                  "fails on some others)");
}

TEST(ModbusSimulatorConfig, BehavioursMayNameLaterEntries)
{
    const SimulatorConfig config = parsed("[[input_register]]\nname = \"speed\"\naddress = 0\n"
                                          "ramp = { follows = \"setpoint\", per_second = 10 }\n"
                                          "[[holding_register]]\nname = \"setpoint\"\naddress = 0\n");
    const Point& speed = config.points[static_cast<size_t>(config.find("speed"))];
    EXPECT_EQ(speed.behaviour.source, config.find("setpoint"));
    EXPECT_GE(speed.behaviour.source, 0);
}

TEST(ModbusSimulator, TheDriveRampsWhileRunningAndReportsAtSpeed)
{
    const SimulatorConfig config = parsed(kDrive);
    Result<std::unique_ptr<Simulator>> created = Simulator::create(config, 1);
    ASSERT_TRUE(created.ok()) << created.error();
    Simulator& s = *created.value();
    modbus_mapping_t* m = s.mapping();
    m->tab_registers[0] = 250; // the master writes the setpoint
    s.advance(1.0);
    EXPECT_EQ(m->tab_input_registers[0], 0) << "off: no ramp";
    m->tab_bits[0] = 1; // run
    s.advance(1.0);
    EXPECT_EQ(m->tab_input_registers[0], 100);
    EXPECT_EQ(m->tab_input_bits[0], 0);
    for (int i = 0; i < 100; ++i) {
        s.advance(0.005); // slow steps still add up: 0.5 per step
    }
    EXPECT_EQ(m->tab_input_registers[0], 150);
    s.advance(0.98);
    EXPECT_EQ(m->tab_input_registers[0], 248);
    EXPECT_EQ(m->tab_input_bits[0], 1) << "within the tolerance of 2";
    s.advance(10);
    EXPECT_EQ(m->tab_input_registers[0], 250) << "no overshoot";
    m->tab_bits[0] = 0;
    s.advance(1.0);
    EXPECT_EQ(m->tab_input_registers[0], 150) << "off: ramps down";
    EXPECT_EQ(m->tab_input_bits[0], 0);
}

TEST(ModbusSimulator, SineConstantNoiseAndClamping)
{
    const SimulatorConfig config =
        parsed("[[input_register]]\naddress = 0\nsine = { offset = 1000, amplitude = 100, period_s = 4 }\n"
               "[[input_register]]\naddress = 1\nconstant = { value = 500, noise = 5 }\n"
               "[[input_register]]\naddress = 2\nsine = { offset = 0, amplitude = 100, period_s = 4 }\n"
               "[[holding_register]]\naddress = 0\nvalue = -2\n");
    Result<std::unique_ptr<Simulator>> created = Simulator::create(config, 7);
    ASSERT_TRUE(created.ok());
    Simulator& s = *created.value();
    modbus_mapping_t* m = s.mapping();
    EXPECT_EQ(m->tab_registers[0], 0xFFFE);
    EXPECT_EQ(m->tab_input_registers[0], 1000);
    s.advance(1.0);
    EXPECT_EQ(m->tab_input_registers[0], 1100);
    EXPECT_EQ(m->tab_input_registers[2], 100);
    s.advance(2.0);
    EXPECT_EQ(m->tab_input_registers[0], 900);
    EXPECT_EQ(m->tab_input_registers[2], 0) << "held at 0, not wrapped";
    std::set<uint16_t> seen;
    for (int i = 0; i < 200; ++i) {
        s.advance(0.01);
        seen.insert(m->tab_input_registers[1]);
        EXPECT_GE(m->tab_input_registers[1], 495);
        EXPECT_LE(m->tab_input_registers[1], 505);
    }
    EXPECT_GT(seen.size(), 5u);
}

TEST(ModbusSimulator, GapsInTheMapAreNotDeclared)
{
    const SimulatorConfig config = parsed("[[holding_register]]\naddress = 10\ncount = 5\n"
                                          "[[holding_register]]\naddress = 15\n"
                                          "[[holding_register]]\naddress = 20\n");
    Result<std::unique_ptr<Simulator>> created = Simulator::create(config, 1);
    ASSERT_TRUE(created.ok());
    const Simulator& s = *created.value();
    EXPECT_TRUE(s.declared(Table::HoldingRegister, 10, 6));
    EXPECT_FALSE(s.declared(Table::HoldingRegister, 10, 7));
    EXPECT_FALSE(s.declared(Table::HoldingRegister, 9, 1));
    EXPECT_TRUE(s.declared(Table::HoldingRegister, 20, 1));
    EXPECT_FALSE(s.declared(Table::InputRegister, 10, 1));
}

std::vector<uint8_t> framed(std::vector<uint8_t> frame)
{
    frame.resize(frame.size() + 2);
    modbus::Crc16::append(frame.data(), frame.size() - 2);
    return frame;
}

TEST(ModbusRequestFraming, LengthsFromTheFunction)
{
    const std::vector<uint8_t> read = framed({17, 0x03, 0x00, 0x00, 0x00, 0x02});
    const std::vector<uint8_t> write = framed({17, 0x10, 0x00, 0x00, 0x00, 0x02, 0x04, 0, 1, 0, 2});
    const std::vector<uint8_t> both = framed({17, 0x17, 0, 0, 0, 1, 0, 5, 0, 1, 2, 0, 9});
    const std::vector<uint8_t> identify = framed({17, 0x2B, 0x0E, 0x01, 0x00});
    for (const std::vector<uint8_t>& frame : {read, write, both, identify}) {
        for (size_t n = 0; n < frame.size(); ++n) {
            EXPECT_EQ(scanRequest(frame.data(), n).state, RequestScan::State::NeedMore) << n;
        }
        const RequestScan scan = scanRequest(frame.data(), frame.size() + 0);
        EXPECT_EQ(scan.state, RequestScan::State::Complete);
        EXPECT_EQ(scan.length, frame.size());
    }
    const uint8_t unknown[] = {17, 0x41, 0, 0};
    EXPECT_EQ(scanRequest(unknown, sizeof unknown).state, RequestScan::State::Unknown);
}

TEST(ModbusRequestFraming, ExceptionsBeforeAddresses)
{
    const uint8_t unknown[] = {0x41, 0, 0, 0, 1};
    EXPECT_EQ(requestException(unknown, sizeof unknown), 0x01);
    const uint8_t tooMany[] = {0x03, 0, 0, 0, 126};
    EXPECT_EQ(requestException(tooMany, sizeof tooMany), 0x03);
    const uint8_t coilValue[] = {0x05, 0, 0, 0x12, 0x34};
    EXPECT_EQ(requestException(coilValue, sizeof coilValue), 0x03);
    const uint8_t countMismatch[] = {0x10, 0, 0, 0, 2, 2, 0, 1};
    EXPECT_EQ(requestException(countMismatch, sizeof countMismatch), 0x03);
    const uint8_t fine[] = {0x0F, 0, 0, 0, 9, 2, 0xFF, 0x01};
    EXPECT_EQ(requestException(fine, sizeof fine), 0x00);
    const std::vector<TableRange> ranges = requestRanges(fine, sizeof fine);
    ASSERT_EQ(ranges.size(), 1u);
    EXPECT_EQ(ranges[0].table, Table::Coil);
    EXPECT_EQ(ranges[0].count, 9u);
    const uint8_t both[] = {0x17, 0, 1, 0, 2, 0, 9, 0, 1, 2, 0, 0};
    const std::vector<TableRange> two = requestRanges(both, sizeof both);
    ASSERT_EQ(two.size(), 2u);
    EXPECT_EQ(two[1].address, 9u);
}

} // namespace
