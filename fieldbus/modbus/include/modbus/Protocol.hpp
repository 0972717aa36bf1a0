// The numbers of the Modbus protocol, each named after the place in the
// specifications that defines it:
//   [AP]  Modbus Application Protocol Specification V1.1b3
//   [SL]  MODBUS over Serial Line, Specification and Implementation Guide V1.02
// The stack spells every limit through these names so that a reader can check
// each one against its section, and so that the tests and the code cannot
// drift apart on a value.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace modbus {

/// Public function codes served and requested by this stack ([AP] 5.1, 6).
enum class FunctionCode : uint8_t {
    ReadCoils = 0x01,                   ///< [AP] 6.1
    ReadDiscreteInputs = 0x02,          ///< [AP] 6.2
    ReadHoldingRegisters = 0x03,        ///< [AP] 6.3
    ReadInputRegisters = 0x04,          ///< [AP] 6.4
    WriteSingleCoil = 0x05,             ///< [AP] 6.5
    WriteSingleRegister = 0x06,         ///< [AP] 6.6
    WriteMultipleCoils = 0x0F,          ///< [AP] 6.11
    WriteMultipleRegisters = 0x10,      ///< [AP] 6.12
    ReadWriteMultipleRegisters = 0x17,  ///< [AP] 6.17
    EncapsulatedInterface = 0x2B,       ///< [AP] 6.19: MEI transport, here only type 0x0E (6.21)
};

/// Exception codes a server answers with ([AP] 7). Zero means "no exception"
/// and never goes on the wire.
enum class ExceptionCode : uint8_t {
    None = 0x00,
    IllegalFunction = 0x01,       ///< The function code is not served.
    IllegalDataAddress = 0x02,    ///< An address, or address plus quantity, is not served.
    IllegalDataValue = 0x03,      ///< A value in the request is invalid: a quantity, a byte count, a coil value.
    ServerDeviceFailure = 0x04,   ///< The server failed while performing the action.
    Acknowledge = 0x05,           ///< Accepted, but a long action follows (programming commands).
    ServerDeviceBusy = 0x06,      ///< Busy with a long action; retry later.
    MemoryParityError = 0x08,     ///< File record parity error (functions 0x14, 0x15).
    GatewayPathUnavailable = 0x0A,
    GatewayTargetFailed = 0x0B,
};

/// The bit a server sets in the function code of an exception response ([AP] 7).
inline constexpr uint8_t kExceptionFlag = 0x80;

/// Frame size limits ([AP] 4.1; [SL] 2.5.1): a serial-line ADU is at most 256
/// bytes, of which one is the address and two the CRC, leaving 253 for the PDU.
inline constexpr size_t kMaxRtuAduLength = 256;
inline constexpr size_t kRtuAddressLength = 1;
inline constexpr size_t kRtuCrcLength = 2;
inline constexpr size_t kMaxPduLength = kMaxRtuAduLength - kRtuAddressLength - kRtuCrcLength;
static_assert(kMaxPduLength == 253, "[AP] 4.1: the PDU of a serial-line ADU is at most 253 bytes");
/// The shortest RTU frame: an address, a function code and the CRC.
inline constexpr size_t kMinRtuAduLength = kRtuAddressLength + 1 + kRtuCrcLength;

/// Serial-line addresses ([SL] 2.2): 0 is broadcast, 1..247 are slaves,
/// 248..255 are reserved.
inline constexpr uint8_t kBroadcastAddress = 0;
inline constexpr uint8_t kMinSlaveAddress = 1;
inline constexpr uint8_t kMaxSlaveAddress = 247;

/// Quantity limits of the request fields ([AP] 6.1 to 6.17).
inline constexpr uint16_t kMaxReadBits = 2000;               ///< 0x7D0, functions 01 and 02 ([AP] 6.1, 6.2)
inline constexpr uint16_t kMaxReadRegisters = 125;           ///< 0x7D, functions 03 and 04 ([AP] 6.3, 6.4)
inline constexpr uint16_t kMaxWriteCoils = 1968;             ///< 0x7B0, function 0F ([AP] 6.11)
inline constexpr uint16_t kMaxWriteRegisters = 123;          ///< 0x7B, function 10 ([AP] 6.12)
inline constexpr uint16_t kMaxReadWriteReadRegisters = 125;  ///< 0x7D, function 17, read part ([AP] 6.17)
inline constexpr uint16_t kMaxReadWriteWriteRegisters = 121; ///< 0x79, function 17, write part ([AP] 6.17)
static_assert(2 + (kMaxReadBits + 7) / 8 <= kMaxPduLength, "a full read of bits fits a PDU");
static_assert(2 + 2 * kMaxReadRegisters <= kMaxPduLength, "a full read of registers fits a PDU");
static_assert(6 + (kMaxWriteCoils + 7) / 8 <= kMaxPduLength, "a full write of coils fits a PDU");
static_assert(6 + 2 * kMaxWriteRegisters <= kMaxPduLength, "a full write of registers fits a PDU");
static_assert(10 + 2 * kMaxReadWriteWriteRegisters <= kMaxPduLength, "a full function 17 request fits a PDU");

/// The two values function 05 accepts for a coil ([AP] 6.5).
inline constexpr uint16_t kCoilOn = 0xFF00;
inline constexpr uint16_t kCoilOff = 0x0000;

/// Read Device Identification ([AP] 6.21): the MEI type under function 2B,
/// the access codes, the object ids and the conformity level this server has.
inline constexpr uint8_t kMeiReadDeviceIdentification = 0x0E;
enum class DeviceIdCode : uint8_t {
    BasicStream = 0x01,     ///< The basic objects 0x00..0x02, stream access.
    RegularStream = 0x02,   ///< Basic and regular objects 0x00..0x06, stream access.
    ExtendedStream = 0x03,  ///< All objects, stream access; this server has no extended ones.
    Individual = 0x04,      ///< One object, individual access.
};
inline constexpr uint8_t kVendorNameObject = 0x00;
inline constexpr uint8_t kProductCodeObject = 0x01;
inline constexpr uint8_t kRevisionObject = 0x02;
inline constexpr uint8_t kVendorUrlObject = 0x03;
inline constexpr uint8_t kProductNameObject = 0x04;
inline constexpr uint8_t kModelNameObject = 0x05;
inline constexpr uint8_t kUserApplicationNameObject = 0x06;
inline constexpr uint8_t kLastRegularObject = kUserApplicationNameObject;
/// "Regular identification, stream access and individual access" ([AP] 6.21).
inline constexpr uint8_t kConformityRegularIndividual = 0x82;
inline constexpr uint8_t kMoreFollows = 0xFF;
/// The fixed part of a Read Device Identification response: function, MEI
/// type, code, conformity, more follows, next object id, number of objects.
inline constexpr size_t kDeviceIdHeaderLength = 7;
/// The longest object value: one object (id and length bytes included) must
/// fit in a response by itself, or individual access could not return it.
inline constexpr size_t kMaxDeviceIdObjectLength = kMaxPduLength - kDeviceIdHeaderLength - 2;

} // namespace modbus
