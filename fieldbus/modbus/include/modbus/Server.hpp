// The server side of the Modbus application protocol ([AP] 6, 7): a request
// PDU in, the response PDU out, against the application's DataModel.
//
// It knows nothing of lines or addresses (Slave does): it checks a request
// in the order of the state diagrams of [AP] 6 and answers with the first
// exception they reach:
//   01 IllegalFunction      a function code it does not serve (or MEI type other than 0x0E)
//   03 IllegalDataValue     a quantity out of its limits, a byte count or PDU length
//                           that does not match it, a coil value other than 0000/FF00,
//                           a Read Device ID code other than 01..04
//   02 IllegalDataAddress   start address + quantity past 0xFFFF, an address range the
//                           model does not have, an individual device id object it lacks
//   04 ServerDeviceFailure  the model could not read or write
// Function 17 writes before it reads ([AP] 6.17). Read Device Identification
// (2B / 0E, [AP] 6.21) serves the basic objects 0x00..0x02 and the regular
// objects 0x03..0x06 the application gives, by stream (codes 01, 02, 03) and
// individual (04) access; a stream that does not fit one response is split
// with "more follows" and the id of the next object.
#pragma once

#include <modbus/DataModel.hpp>
#include <modbus/ModbusResult.hpp>
#include <modbus/Protocol.hpp>

#include <stddef.h>
#include <stdint.h>

namespace modbus {

/// The objects Read Device Identification returns, as NUL-terminated ASCII
/// strings that live as long as the server. The basic three are mandatory
/// ([AP] 6.21); a regular object left null is absent.
struct DeviceIdentification {
    const char* vendorName = nullptr;           ///< 0x00 VendorName
    const char* productCode = nullptr;          ///< 0x01 ProductCode
    const char* revision = nullptr;             ///< 0x02 MajorMinorRevision
    const char* vendorUrl = nullptr;            ///< 0x03 VendorUrl
    const char* productName = nullptr;          ///< 0x04 ProductName
    const char* modelName = nullptr;            ///< 0x05 ModelName
    const char* userApplicationName = nullptr;  ///< 0x06 UserApplicationName
};

/// The response a request produced.
struct ServerReply {
    size_t length = 0;  ///< Bytes of the response PDU; 0 only for an empty request.
    ExceptionCode exception = ExceptionCode::None;  ///< The exception answered, or None.
};

class Server {
public:
    /// A placeholder with no model; only a target for assignment.
    Server() = default;

    /// A server of @p model identifying itself with @p identification, or
    /// InvalidArgument when a basic object is missing or an object is longer
    /// than kMaxDeviceIdObjectLength.
    static ModbusResult<Server> create(DataModel& model, const DeviceIdentification& identification);

    /// Handles the @p length bytes of the request PDU at @p request and writes
    /// the response PDU (at most kMaxPduLength bytes) to @p response.
    ServerReply handle(const uint8_t* request, size_t length, uint8_t* response);

    /// Whether a request with function code @p function changes data only, so
    /// that it is executed when broadcast ([AP] 4.1, [SL] 2.1: broadcasts are
    /// write functions); every other broadcast request is ignored.
    static bool isBroadcastWrite(uint8_t function);

private:
    ServerReply readBits(const uint8_t* request, size_t length, uint8_t* response, bool coils);
    ServerReply readRegisters(const uint8_t* request, size_t length, uint8_t* response, bool holding);
    ServerReply writeSingleCoil(const uint8_t* request, size_t length, uint8_t* response);
    ServerReply writeSingleRegister(const uint8_t* request, size_t length, uint8_t* response);
    ServerReply writeMultipleCoils(const uint8_t* request, size_t length, uint8_t* response);
    ServerReply writeMultipleRegisters(const uint8_t* request, size_t length, uint8_t* response);
    ServerReply readWriteMultipleRegisters(const uint8_t* request, size_t length, uint8_t* response);
    ServerReply readDeviceIdentification(const uint8_t* request, size_t length, uint8_t* response);
    const char* object(uint8_t id) const;

    DataModel* model_ = nullptr;
    DeviceIdentification identification_;
    // Register values between the wire and the model: function 17 needs the
    // written ones and the read ones, each at most 125.
    uint16_t registers_[kMaxReadRegisters] = {};
};

} // namespace modbus
