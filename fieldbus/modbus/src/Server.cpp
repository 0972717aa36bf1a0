#include <modbus/Server.hpp>
#include <modbus/Wire.hpp>

namespace modbus {

namespace {

constexpr size_t kTextLimit = kMaxDeviceIdObjectLength + 1;

// Length of a NUL-terminated string, up to kTextLimit: the freestanding
// firmware has no strlen, and a string above the limit is refused anyway.
size_t textLength(const char* text)
{
    size_t length = 0;
    while (length < kTextLimit && text[length] != '\0') {
        ++length;
    }
    return length;
}

ServerReply exception(uint8_t function, ExceptionCode code, uint8_t* response)
{
    response[0] = static_cast<uint8_t>(function | kExceptionFlag);
    response[1] = static_cast<uint8_t>(code);
    return {2, code};
}

// [AP] 6: "Starting Address + Quantity" must stay within the 16-bit address
// space; beyond it is exception 02 whatever the model holds.
bool rangeFits(uint16_t address, uint16_t quantity)
{
    return static_cast<uint32_t>(address) + quantity <= 0x10000;
}

} // namespace

ModbusResult<Server> Server::create(DataModel& model, const DeviceIdentification& identification)
{
    if (identification.vendorName == nullptr || identification.productCode == nullptr
        || identification.revision == nullptr) {
        return ModbusError::InvalidArgument;
    }
    Server server;
    server.model_ = &model;
    server.identification_ = identification;
    for (uint8_t id = kVendorNameObject; id <= kLastRegularObject; ++id) {
        const char* text = server.object(id);
        if (text != nullptr && textLength(text) > kMaxDeviceIdObjectLength) {
            return ModbusError::InvalidArgument;
        }
    }
    return server;
}

bool Server::isBroadcastWrite(uint8_t function)
{
    switch (static_cast<FunctionCode>(function)) {
    case FunctionCode::WriteSingleCoil:
    case FunctionCode::WriteSingleRegister:
    case FunctionCode::WriteMultipleCoils:
    case FunctionCode::WriteMultipleRegisters:
        return true;
    default:
        return false;
    }
}

ServerReply Server::handle(const uint8_t* request, size_t length, uint8_t* response)
{
    if (request == nullptr || length == 0 || response == nullptr) {
        return {};
    }
    if (model_ == nullptr) {
        return exception(request[0], ExceptionCode::ServerDeviceFailure, response);
    }
    switch (static_cast<FunctionCode>(request[0])) {
    case FunctionCode::ReadCoils: return readBits(request, length, response, true);
    case FunctionCode::ReadDiscreteInputs: return readBits(request, length, response, false);
    case FunctionCode::ReadHoldingRegisters: return readRegisters(request, length, response, true);
    case FunctionCode::ReadInputRegisters: return readRegisters(request, length, response, false);
    case FunctionCode::WriteSingleCoil: return writeSingleCoil(request, length, response);
    case FunctionCode::WriteSingleRegister: return writeSingleRegister(request, length, response);
    case FunctionCode::WriteMultipleCoils: return writeMultipleCoils(request, length, response);
    case FunctionCode::WriteMultipleRegisters: return writeMultipleRegisters(request, length, response);
    case FunctionCode::ReadWriteMultipleRegisters: return readWriteMultipleRegisters(request, length, response);
    case FunctionCode::EncapsulatedInterface: return readDeviceIdentification(request, length, response);
    }
    return exception(request[0], ExceptionCode::IllegalFunction, response);
}

// [AP] 6.1, 6.2: address, quantity 1..2000; bits packed, padded with zeros.
ServerReply Server::readBits(const uint8_t* request, size_t length, uint8_t* response, bool coils)
{
    const uint8_t function = request[0];
    if (length != 5) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t address = readU16(request + 1);
    const uint16_t quantity = readU16(request + 3);
    if (quantity < 1 || quantity > kMaxReadBits) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    if (!rangeFits(address, quantity)) {
        return exception(function, ExceptionCode::IllegalDataAddress, response);
    }
    const size_t byteCount = bitBytes(quantity);
    for (size_t i = 0; i < byteCount; ++i) {
        response[2 + i] = 0;
    }
    const ExceptionCode code = coils ? model_->readCoils(address, quantity, response + 2)
                                     : model_->readDiscreteInputs(address, quantity, response + 2);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    response[0] = function;
    response[1] = static_cast<uint8_t>(byteCount);
    return {2 + byteCount, ExceptionCode::None};
}

// [AP] 6.3, 6.4: address, quantity 1..125; two bytes per register.
ServerReply Server::readRegisters(const uint8_t* request, size_t length, uint8_t* response, bool holding)
{
    const uint8_t function = request[0];
    if (length != 5) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t address = readU16(request + 1);
    const uint16_t quantity = readU16(request + 3);
    if (quantity < 1 || quantity > kMaxReadRegisters) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    if (!rangeFits(address, quantity)) {
        return exception(function, ExceptionCode::IllegalDataAddress, response);
    }
    const ExceptionCode code = holding ? model_->readHoldingRegisters(address, quantity, registers_)
                                       : model_->readInputRegisters(address, quantity, registers_);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    response[0] = function;
    response[1] = static_cast<uint8_t>(2 * quantity);
    for (size_t i = 0; i < quantity; ++i) {
        writeU16(response + 2 + 2 * i, registers_[i]);
    }
    return {2 + 2 * static_cast<size_t>(quantity), ExceptionCode::None};
}

// [AP] 6.5: the value is FF00 (on) or 0000 (off); the response echoes the request.
ServerReply Server::writeSingleCoil(const uint8_t* request, size_t length, uint8_t* response)
{
    const uint8_t function = request[0];
    if (length != 5) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t address = readU16(request + 1);
    const uint16_t value = readU16(request + 3);
    if (value != kCoilOn && value != kCoilOff) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint8_t bit = value == kCoilOn ? 1 : 0;
    const ExceptionCode code = model_->writeCoils(address, 1, &bit);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    for (size_t i = 0; i < 5; ++i) {
        response[i] = request[i];
    }
    return {5, ExceptionCode::None};
}

// [AP] 6.6: any 16-bit value; the response echoes the request.
ServerReply Server::writeSingleRegister(const uint8_t* request, size_t length, uint8_t* response)
{
    const uint8_t function = request[0];
    if (length != 5) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t address = readU16(request + 1);
    registers_[0] = readU16(request + 3);
    const ExceptionCode code = model_->writeHoldingRegisters(address, 1, registers_);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    for (size_t i = 0; i < 5; ++i) {
        response[i] = request[i];
    }
    return {5, ExceptionCode::None};
}

// [AP] 6.11: quantity 1..1968, byte count N = ceil(quantity / 8), then N bytes.
ServerReply Server::writeMultipleCoils(const uint8_t* request, size_t length, uint8_t* response)
{
    const uint8_t function = request[0];
    if (length < 6) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t address = readU16(request + 1);
    const uint16_t quantity = readU16(request + 3);
    const uint8_t byteCount = request[5];
    if (quantity < 1 || quantity > kMaxWriteCoils || byteCount != bitBytes(quantity) || length != 6u + byteCount) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    if (!rangeFits(address, quantity)) {
        return exception(function, ExceptionCode::IllegalDataAddress, response);
    }
    const ExceptionCode code = model_->writeCoils(address, quantity, request + 6);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    for (size_t i = 0; i < 5; ++i) {
        response[i] = request[i];
    }
    return {5, ExceptionCode::None};
}

// [AP] 6.12: quantity 1..123, byte count 2 x quantity, then the values.
ServerReply Server::writeMultipleRegisters(const uint8_t* request, size_t length, uint8_t* response)
{
    const uint8_t function = request[0];
    if (length < 6) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t address = readU16(request + 1);
    const uint16_t quantity = readU16(request + 3);
    const uint8_t byteCount = request[5];
    if (quantity < 1 || quantity > kMaxWriteRegisters || byteCount != 2 * quantity || length != 6u + byteCount) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    if (!rangeFits(address, quantity)) {
        return exception(function, ExceptionCode::IllegalDataAddress, response);
    }
    for (size_t i = 0; i < quantity; ++i) {
        registers_[i] = readU16(request + 6 + 2 * i);
    }
    const ExceptionCode code = model_->writeHoldingRegisters(address, quantity, registers_);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    for (size_t i = 0; i < 5; ++i) {
        response[i] = request[i];
    }
    return {5, ExceptionCode::None};
}

// [AP] 6.17: read address and quantity (1..125), write address and quantity
// (1..121), byte count 2 x write quantity, the values; written first, then read.
ServerReply Server::readWriteMultipleRegisters(const uint8_t* request, size_t length, uint8_t* response)
{
    const uint8_t function = request[0];
    if (length < 10) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint16_t readAddress = readU16(request + 1);
    const uint16_t readQuantity = readU16(request + 3);
    const uint16_t writeAddress = readU16(request + 5);
    const uint16_t writeQuantity = readU16(request + 7);
    const uint8_t byteCount = request[9];
    if (readQuantity < 1 || readQuantity > kMaxReadWriteReadRegisters || writeQuantity < 1
        || writeQuantity > kMaxReadWriteWriteRegisters || byteCount != 2 * writeQuantity
        || length != 10u + byteCount) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    if (!rangeFits(readAddress, readQuantity) || !rangeFits(writeAddress, writeQuantity)) {
        return exception(function, ExceptionCode::IllegalDataAddress, response);
    }
    // The model alone knows whether the read range exists. It is asked
    // first, so that a request refused for its read range writes nothing:
    // a master that gets an exception must be able to assume no effect.
    ExceptionCode code = model_->readHoldingRegisters(readAddress, readQuantity, registers_);
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    for (size_t i = 0; i < writeQuantity; ++i) {
        registers_[i] = readU16(request + 10 + 2 * i);
    }
    code = model_->writeHoldingRegisters(writeAddress, writeQuantity, registers_);
    if (code == ExceptionCode::None) {
        code = model_->readHoldingRegisters(readAddress, readQuantity, registers_);
    }
    if (code != ExceptionCode::None) {
        return exception(function, code, response);
    }
    response[0] = function;
    response[1] = static_cast<uint8_t>(2 * readQuantity);
    for (size_t i = 0; i < readQuantity; ++i) {
        writeU16(response + 2 + 2 * i, registers_[i]);
    }
    return {2 + 2 * static_cast<size_t>(readQuantity), ExceptionCode::None};
}

const char* Server::object(uint8_t id) const
{
    switch (id) {
    case kVendorNameObject: return identification_.vendorName;
    case kProductCodeObject: return identification_.productCode;
    case kRevisionObject: return identification_.revision;
    case kVendorUrlObject: return identification_.vendorUrl;
    case kProductNameObject: return identification_.productName;
    case kModelNameObject: return identification_.modelName;
    case kUserApplicationNameObject: return identification_.userApplicationName;
    default: return nullptr;
    }
}

// [AP] 6.21: MEI type 0x0E, Read Device ID code, object id.
ServerReply Server::readDeviceIdentification(const uint8_t* request, size_t length, uint8_t* response)
{
    const uint8_t function = request[0];
    if (length < 2 || request[1] != kMeiReadDeviceIdentification) {
        // Only MEI type 0x0E is served; CANopen general reference (0x0D) and
        // any other type are functions this server does not have.
        return exception(function, ExceptionCode::IllegalFunction, response);
    }
    if (length != 4) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    const uint8_t code = request[2];
    uint8_t objectId = request[3];
    if (code < static_cast<uint8_t>(DeviceIdCode::BasicStream) || code > static_cast<uint8_t>(DeviceIdCode::Individual)) {
        return exception(function, ExceptionCode::IllegalDataValue, response);
    }
    bool regular = false;
    for (uint8_t id = kVendorUrlObject; id <= kLastRegularObject; ++id) {
        regular = regular || object(id) != nullptr;
    }

    response[0] = function;
    response[1] = kMeiReadDeviceIdentification;
    response[2] = code;
    // Individual access comes with either level: 0x81 (basic) or 0x82 (regular).
    response[3] = regular ? kConformityRegularIndividual : static_cast<uint8_t>(kConformityRegularIndividual - 1);
    response[4] = 0;  // more follows
    response[5] = 0;  // next object id
    response[6] = 0;  // number of objects
    size_t position = kDeviceIdHeaderLength;

    if (code == static_cast<uint8_t>(DeviceIdCode::Individual)) {
        const char* text = object(objectId);
        if (text == nullptr) {
            return exception(function, ExceptionCode::IllegalDataAddress, response);
        }
        const size_t textSize = textLength(text);
        response[position++] = objectId;
        response[position++] = static_cast<uint8_t>(textSize);
        for (size_t i = 0; i < textSize; ++i) {
            response[position++] = static_cast<uint8_t>(text[i]);
        }
        response[6] = 1;
        return {position, ExceptionCode::None};
    }

    // Stream access: the basic category ends at 0x02; the regular one at
    // 0x06, and so does the extended one, since this server has no extended
    // objects. An object id outside the category or absent restarts the
    // stream at object 0, as [AP] 6.21 prescribes.
    const uint8_t last = code == static_cast<uint8_t>(DeviceIdCode::BasicStream) ? kRevisionObject : kLastRegularObject;
    if (objectId > last || object(objectId) == nullptr) {
        objectId = kVendorNameObject;
    }
    for (uint8_t id = objectId; id <= last; ++id) {
        const char* text = object(id);
        if (text == nullptr) {
            continue;
        }
        const size_t textSize = textLength(text);
        if (position + 2 + textSize > kMaxPduLength) {
            response[4] = kMoreFollows;
            response[5] = id;
            break;
        }
        response[position++] = id;
        response[position++] = static_cast<uint8_t>(textSize);
        for (size_t i = 0; i < textSize; ++i) {
            response[position++] = static_cast<uint8_t>(text[i]);
        }
        ++response[6];
    }
    return {position, ExceptionCode::None};
}

} // namespace modbus
