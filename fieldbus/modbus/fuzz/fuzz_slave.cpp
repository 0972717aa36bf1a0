// Fuzz target: arbitrary request PDUs into the server against the in-memory
// data model, then whole RTU frames into a slave.
//
// The input is a sequence of requests, each a length byte and that many
// bytes. The checks: every response is 2..253 bytes; an exception response
// is the function with 0x80 and one of the codes 01..04; a normal response
// passes the master's own checkResponse() for the same request, so server
// and client agree on every layout; writes that succeeded are in the model;
// a refused request changes nothing in the model (it is compared whole); the
// slave answers a unicast frame exactly with the server's response, framed,
// and a broadcast never.
#include "../../can/fuzz/FuzzCheck.hpp"

#include <modbus/Crc16.hpp>
#include <modbus/InMemoryDataModel.hpp>
#include <modbus/Request.hpp>
#include <modbus/RtuTransport.hpp>
#include <modbus/Slave.hpp>
#include <modbus/Wire.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

namespace {

using Model = modbus::InMemoryDataModel<300, 300, 300, 300>;

modbus::DeviceIdentification identification()
{
    modbus::DeviceIdentification id;
    id.vendorName = "DCOS";
    id.productCode = "DC-486";
    id.revision = "0.1";
    id.vendorUrl = "https://example.invalid/dcos/modbus/a-rather-long-url-so-that-streams-get-split-now-and-then";
    id.productName = "Distributed Controller Operating System, Modbus RTU slave, fuzzing edition, long name";
    id.userApplicationName = "fuzz";
    return id;
}

struct Snapshot {
    std::vector<uint8_t> coils;
    std::vector<uint16_t> registers;

    static Snapshot of(Model& model)
    {
        Snapshot s;
        for (size_t i = 0; i < 300; ++i) {
            s.coils.push_back(model.coil(i));
            s.registers.push_back(model.holdingRegister(i));
        }
        return s;
    }
    bool operator==(const Snapshot& other) const { return coils == other.coils && registers == other.registers; }
};

void checkServer(modbus::Server& server, Model& model, const uint8_t* pdu, size_t length)
{
    const Snapshot before = Snapshot::of(model);
    // The response buffer is exactly kMaxPduLength, so AddressSanitizer sees
    // a write one byte too far.
    std::unique_ptr<uint8_t[]> response(new uint8_t[modbus::kMaxPduLength]);
    const modbus::ServerReply reply = server.handle(pdu, length, response.get());
    FUZZ_CHECK(reply.length >= 2 && reply.length <= modbus::kMaxPduLength);

    modbus::Request request;
    request.unit = 1;
    std::memcpy(request.pdu, pdu, length);
    request.length = static_cast<uint8_t>(length);
    modbus::ExceptionCode exception = modbus::ExceptionCode::None;
    const modbus::ModbusError check = modbus::checkResponse(request, response.get(), reply.length, exception);

    if (reply.exception != modbus::ExceptionCode::None) {
        const uint8_t code = static_cast<uint8_t>(reply.exception);
        FUZZ_CHECK(reply.length == 2 && response[0] == (pdu[0] | 0x80) && response[1] == code);
        FUZZ_CHECK(code >= 1 && code <= 4);
        FUZZ_CHECK(Snapshot::of(model) == before);
        FUZZ_CHECK(check == modbus::ModbusError::ExceptionResponse || pdu[0] >= 0x80
                   || check == modbus::ModbusError::InvalidArgument);
        return;
    }
    FUZZ_CHECK(response[0] == pdu[0]);
    FUZZ_CHECK(check == modbus::ModbusError::Ok);
    // Written values are in the model.
    switch (pdu[0]) {
    case 0x06:
        FUZZ_CHECK(model.holdingRegister(modbus::readU16(pdu + 1)) == modbus::readU16(pdu + 3));
        break;
    case 0x10: {
        const uint16_t address = modbus::readU16(pdu + 1);
        for (size_t i = 0; i < modbus::readU16(pdu + 3); ++i) {
            FUZZ_CHECK(model.holdingRegister(address + i) == modbus::readU16(pdu + 6 + 2 * i));
        }
        break;
    }
    case 0x05:
        FUZZ_CHECK(model.coil(modbus::readU16(pdu + 1)) == (pdu[3] == 0xFF));
        break;
    case 0x0F: {
        const uint16_t address = modbus::readU16(pdu + 1);
        for (size_t i = 0; i < modbus::readU16(pdu + 3); ++i) {
            FUZZ_CHECK(model.coil(address + i) == modbus::getBit(pdu + 6, i));
        }
        break;
    }
    default:
        // Reads change nothing.
        if (pdu[0] != 0x17) {
            FUZZ_CHECK(Snapshot::of(model) == before);
        }
        break;
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz::InputReader input(data, size);
    Model model;
    for (size_t i = 0; i < 300; ++i) {
        model.inputRegister(i) = static_cast<uint16_t>(i * 7);
        model.discreteInput(i) = (i % 3) == 0;
    }
    modbus::Server server = modbus::Server::create(model, identification()).value();
    modbus::RtuTransport transport;
    modbus::Slave slave = modbus::Slave::create(transport, server, 7).value();
    const modbus::RtuTiming timing;
    uint64_t now = 10 * timing.t35Ns;

    while (!input.empty()) {
        const uint8_t header = input.byte();
        const size_t length = 1 + input.byte() % modbus::kMaxPduLength;
        std::unique_ptr<uint8_t[]> pdu(new uint8_t[length]);
        for (size_t i = 0; i < length; ++i) {
            pdu[i] = input.byte();
        }
        if ((header & 0x08) != 0) {
            model.failNext();
        }
        if ((header & 1) == 0) {
            checkServer(server, model, pdu.get(), length);
            continue;
        }
        // Through the slave: to its address, to another, or broadcast.
        const uint8_t unit = (header & 6) == 0 ? 0 : (header & 6) == 2 ? 8 : 7;
        std::vector<uint8_t> frame(1, unit);
        frame.insert(frame.end(), pdu.get(), pdu.get() + length);
        const uint16_t crc = modbus::Crc16::compute(frame.data(), frame.size());
        frame.push_back(static_cast<uint8_t>(crc & 0xFF));
        frame.push_back(static_cast<uint8_t>(crc >> 8));
        modbus::StationStep step = slave.onBytes(frame.data(), frame.size(), now);
        FUZZ_CHECK(step.transmit == nullptr);
        now += timing.t35Ns;
        step = slave.poll(now);
        if (unit != 7) {
            FUZZ_CHECK(step.transmit == nullptr);
            continue;
        }
        FUZZ_CHECK(step.transmit != nullptr);
        FUZZ_CHECK(step.transmitLength >= 5 && step.transmitLength <= modbus::kMaxRtuAduLength);
        FUZZ_CHECK(step.transmit[0] == 7);
        FUZZ_CHECK(modbus::Crc16::check(step.transmit, step.transmitLength));
        FUZZ_CHECK(slave.onTransmitDone(now) == modbus::ModbusError::Ok);
        now += 2 * timing.t35Ns;
    }
    return 0;
}
