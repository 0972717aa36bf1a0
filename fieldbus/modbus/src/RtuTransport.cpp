#include <modbus/Crc16.hpp>
#include <modbus/RtuTransport.hpp>

namespace modbus {

ModbusResult<size_t> RtuTransport::encode(uint8_t unit, const uint8_t* pdu, size_t length, uint8_t* out,
                                          size_t capacity)
{
    if (unit > kMaxSlaveAddress) {
        return ModbusError::InvalidSlaveAddress;
    }
    if (pdu == nullptr || length == 0 || length > kMaxPduLength) {
        return ModbusError::FrameTooLong;
    }
    const size_t aduLength = kRtuAddressLength + length + kRtuCrcLength;
    if (out == nullptr || capacity < aduLength) {
        return ModbusError::BufferTooSmall;
    }
    out[0] = unit;
    for (size_t i = 0; i < length; ++i) {
        out[kRtuAddressLength + i] = pdu[i];
    }
    Crc16::append(out, kRtuAddressLength + length);
    return aduLength;
}

bool RtuTransport::takeFrame(ReceivedFrame& frame)
{
    if (!receiver_.frameReady()) {
        return false;
    }
    // The receiver delivers only frames of at least 4 bytes with a good CRC,
    // so the PDU has its function code.
    frame.unit = receiver_.frame()[0];
    frame.pdu = receiver_.frame() + kRtuAddressLength;
    frame.length = receiver_.frameLength() - kRtuAddressLength - kRtuCrcLength;
    receiver_.takeFrame();
    return true;
}

} // namespace modbus
