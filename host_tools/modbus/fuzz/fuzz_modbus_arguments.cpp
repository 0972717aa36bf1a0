// Fuzz target: the command-line values of dcos-modbus and dcos-modbus-sim
// (host_tools/modbus/src/Arguments.cpp), which come from users and scripts.
//
// The first byte picks the parser, the rest is its text. The checks: every
// refusal has a message, and the message carries no control character (the
// text is echoed escaped, so a pasted escape sequence cannot reach the
// terminal); every accepted value is in its range, and lists stay within
// their count and below address 65536; a number written back in decimal
// parses to itself.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostmodbus/Arguments.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace {

using namespace hostmodbus;

template <typename T>
void checkMessage(const Result<T>& r)
{
    if (r.ok()) {
        FUZZ_CHECK(r.error().empty());
        return;
    }
    FUZZ_CHECK(!r.error().empty());
    for (char c : r.error()) {
        FUZZ_CHECK(static_cast<unsigned char>(c) >= 0x20 || c == '\t');
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    if (size == 0) {
        return 0;
    }
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    const unsigned max = 1 + data[0] % 2000;
    switch (data[0] % 9) {
    case 0: {
        const Result<uint16_t> r = parseAddress(text);
        checkMessage(r);
        if (r.ok()) {
            const Result<uint16_t> again = parseAddress(std::to_string(r.value()));
            FUZZ_CHECK(again.ok() && again.value() == r.value());
        }
        break;
    }
    case 1: {
        const Result<uint16_t> r = parseRegisterValue(text);
        checkMessage(r);
        if (r.ok()) {
            const Result<uint16_t> again = parseRegisterValue(std::to_string(r.value()));
            FUZZ_CHECK(again.ok() && again.value() == r.value());
        }
        break;
    }
    case 2: checkMessage(parseBit(text)); break;
    case 3: {
        const Result<uint8_t> r = parseSlaveAddress(text);
        checkMessage(r);
        FUZZ_CHECK(!r.ok() || (r.value() >= 1 && r.value() <= 247));
        break;
    }
    case 4: {
        const Result<RegisterList> r = parseRegisterList(text, max);
        checkMessage(r);
        if (r.ok()) {
            FUZZ_CHECK(!r.value().values.empty() && r.value().values.size() <= max);
            FUZZ_CHECK(r.value().address + r.value().values.size() <= 0x10000);
        }
        break;
    }
    case 5: {
        const Result<BitList> r = parseBitList(text, max);
        checkMessage(r);
        if (r.ok()) {
            FUZZ_CHECK(!r.value().values.empty() && r.value().values.size() <= max);
            FUZZ_CHECK(r.value().address + r.value().values.size() <= 0x10000);
        }
        break;
    }
    case 6: {
        const Result<Range> r = parseRange(text, max);
        checkMessage(r);
        if (r.ok()) {
            FUZZ_CHECK(r.value().count >= 1 && r.value().count <= max);
            FUZZ_CHECK(r.value().address + static_cast<uint32_t>(r.value().count) <= 0x10000);
        }
        break;
    }
    case 7: {
        const Result<char> r = parseParity(text);
        checkMessage(r);
        FUZZ_CHECK(!r.ok() || r.value() == 'N' || r.value() == 'E' || r.value() == 'O');
        break;
    }
    default: {
        const Result<uint32_t> r = parseUnsigned(text, max, "number");
        checkMessage(r);
        FUZZ_CHECK(!r.ok() || r.value() <= max);
        break;
    }
    }
    return 0;
}
