#include <hostmodbus/RequestRanges.hpp>

namespace hostmodbus {

namespace {

uint32_t word(const uint8_t* bytes) { return static_cast<uint32_t>(bytes[0]) << 8 | bytes[1]; }

} // namespace

RequestScan scanRequest(const uint8_t* bytes, size_t size)
{
    RequestScan scan;
    if (size < 2) {
        return scan;
    }
    // The frame's length from the address to the CRC, once the bytes that
    // give it are in: fixed for most functions, with a byte count for the
    // writes of several items.
    size_t length = 0;
    switch (bytes[1]) {
    case 0x01: case 0x02: case 0x03: case 0x04: case 0x05: case 0x06:
        length = 8;
        break;
    case 0x07: case 0x0B: case 0x0C: case 0x11:
        length = 4;
        break;
    case 0x0F: case 0x10:
        if (size < 7) {
            return scan;
        }
        length = 9 + bytes[6];
        break;
    case 0x16:
        length = 10;
        break;
    case 0x17:
        if (size < 11) {
            return scan;
        }
        length = 13 + bytes[10];
        break;
    case 0x2B:
        // Only MEI type 0E is known: address, 2B, 0E, code, object, CRC.
        if (size < 3) {
            return scan;
        }
        if (bytes[2] != 0x0E) {
            scan.state = RequestScan::State::Unknown;
            return scan;
        }
        length = 7;
        break;
    default:
        scan.state = RequestScan::State::Unknown;
        return scan;
    }
    if (size >= length) {
        scan.state = RequestScan::State::Complete;
        scan.length = length;
    }
    return scan;
}

std::vector<TableRange> requestRanges(const uint8_t* pdu, size_t size)
{
    if (size < 5) {
        return {};
    }
    const uint32_t address = word(pdu + 1);
    const uint32_t count = word(pdu + 3);
    switch (pdu[0]) {
    case 0x01: return {{Table::Coil, address, count}};
    case 0x02: return {{Table::DiscreteInput, address, count}};
    case 0x03: return {{Table::HoldingRegister, address, count}};
    case 0x04: return {{Table::InputRegister, address, count}};
    // 05 and 06 carry a value where the others carry a count.
    case 0x05: return {{Table::Coil, address, 1}};
    case 0x06: return {{Table::HoldingRegister, address, 1}};
    case 0x0F: return {{Table::Coil, address, count}};
    case 0x10: return {{Table::HoldingRegister, address, count}};
    case 0x16: return {{Table::HoldingRegister, address, 1}};
    case 0x17:
        if (size < 9) {
            return {};
        }
        return {{Table::HoldingRegister, address, count}, {Table::HoldingRegister, word(pdu + 5), word(pdu + 7)}};
    default: return {};
    }
}

uint8_t requestException(const uint8_t* pdu, size_t size)
{
    constexpr uint8_t kIllegalFunction = 0x01;
    constexpr uint8_t kIllegalDataValue = 0x03;
    if (size < 1) {
        return kIllegalFunction;
    }
    const uint8_t function = pdu[0];
    const auto within = [](uint32_t value, uint32_t max) { return value >= 1 && value <= max; };
    switch (function) {
    case 0x01:
    case 0x02:
        return size == 5 && within(word(pdu + 3), 2000) ? 0 : kIllegalDataValue;
    case 0x03:
    case 0x04:
        return size == 5 && within(word(pdu + 3), 125) ? 0 : kIllegalDataValue;
    case 0x05:
        return size == 5 && (word(pdu + 3) == 0x0000 || word(pdu + 3) == 0xFF00) ? 0 : kIllegalDataValue;
    case 0x06:
        return size == 5 ? 0 : kIllegalDataValue;
    case 0x0F:
        // The byte count must be the quantity's, and the bytes must be there.
        return size >= 6 && within(word(pdu + 3), 1968) && pdu[5] == (word(pdu + 3) + 7) / 8 &&
                       size == 6u + pdu[5]
                   ? 0
                   : kIllegalDataValue;
    case 0x10:
        return size >= 6 && within(word(pdu + 3), 123) && pdu[5] == word(pdu + 3) * 2 && size == 6u + pdu[5]
                   ? 0
                   : kIllegalDataValue;
    case 0x16:
        return size == 7 ? 0 : kIllegalDataValue;
    case 0x17:
        return size >= 10 && within(word(pdu + 3), 125) && within(word(pdu + 7), 121) &&
                       pdu[9] == word(pdu + 7) * 2 && size == 10u + pdu[9]
                   ? 0
                   : kIllegalDataValue;
    // 2B is device identification, answered by the simulator from its own
    // table; its sub-fields are checked there.
    case 0x2B:
        return 0;
    default:
        return kIllegalFunction;
    }
}

} // namespace hostmodbus
