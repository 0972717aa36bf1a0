// Fuzz target: a master with a request outstanding fed arbitrary response
// bytes, framed responses, confirmations and jumps of time.
//
// The input chooses a request and retry count, then operations: raw bytes at
// some time, a frame built from the input with a right CRC (so the fuzzer
// gets past the CRC into response matching), a transmit confirmation, a poll,
// or a new submission. The checks: every transmission is the request's ADU;
// no more than 1 + retries transmissions per transaction; a transaction
// completes once, and then the master is idle; a success carries a response
// that checkResponse() accepts, an exception a two-byte exception response.
#include "../../can/fuzz/FuzzCheck.hpp"

#include <modbus/Crc16.hpp>
#include <modbus/Master.hpp>
#include <modbus/RtuTransport.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

modbus::Request chooseRequest(fuzz::InputReader& input)
{
    const uint8_t kind = input.byte();
    const uint8_t unit = static_cast<uint8_t>(kind >> 4);  // 0 (broadcast) .. 15
    const uint16_t address = static_cast<uint16_t>(input.bytes(2) % 0x8000);
    const uint16_t quantity = static_cast<uint16_t>(1 + input.byte() % 120);
    static const uint16_t values[125] = {1, 2, 3, 0xFFFF};
    static const uint8_t bits[250] = {0xA5, 0x5A};
    modbus::ModbusResult<modbus::Request> request = modbus::ModbusError::InvalidArgument;
    const uint8_t reading = unit == 0 ? 1 : 0;  // a read needs a slave address
    switch ((kind + reading * 4) % 10) {
    case 0: request = modbus::Request::readCoils(unit, address, quantity); break;
    case 1: request = modbus::Request::readDiscreteInputs(unit, address, quantity); break;
    case 2: request = modbus::Request::readHoldingRegisters(unit, address, quantity); break;
    case 3: request = modbus::Request::readInputRegisters(unit, address, quantity); break;
    case 4: request = modbus::Request::writeSingleCoil(unit, address, (quantity & 1) != 0); break;
    case 5: request = modbus::Request::writeSingleRegister(unit, address, quantity); break;
    case 6: request = modbus::Request::writeMultipleCoils(unit, address, quantity, bits); break;
    case 7: request = modbus::Request::writeMultipleRegisters(unit, address, quantity, values); break;
    case 8: request = modbus::Request::readWriteMultipleRegisters(unit, address, quantity, address, 3, values); break;
    case 9:
        request = modbus::Request::readDeviceIdentification(unit, static_cast<modbus::DeviceIdCode>(1 + quantity % 4),
                                                            static_cast<uint8_t>(quantity % 8));
        break;
    }
    if (!request.ok()) {
        // Reads and device identification refuse the broadcast address.
        return modbus::Request::readHoldingRegisters(1, 0, 1).value();
    }
    return request.value();
}

struct Harness {
    modbus::RtuTransport transport;
    modbus::Master master;
    modbus::Request request;
    std::vector<uint8_t> adu;
    bool active = false;
    unsigned transmissions = 0;
    uint8_t retries = 0;

    void step(const modbus::StationStep& step)
    {
        if (step.completed) {
            FUZZ_CHECK(active);
            FUZZ_CHECK(master.idle());
            active = false;
            if (step.error == modbus::ModbusError::Ok && !request.isBroadcast()) {
                modbus::ExceptionCode exception;
                FUZZ_CHECK(modbus::checkResponse(request, master.response().pdu(), master.response().length(),
                                                 exception)
                           == modbus::ModbusError::Ok);
            }
            if (step.error == modbus::ModbusError::ExceptionResponse) {
                FUZZ_CHECK(master.response().length() == 2);
                FUZZ_CHECK(master.response().pdu()[0] == (request.function() | 0x80));
                FUZZ_CHECK(static_cast<uint8_t>(step.exception) == master.response().pdu()[1]);
            } else {
                FUZZ_CHECK(step.exception == modbus::ExceptionCode::None);
            }
            FUZZ_CHECK(step.error != modbus::ModbusError::Timeout || transmissions == 1u + retries);
        }
        if (step.transmit != nullptr) {
            FUZZ_CHECK(active);
            ++transmissions;
            FUZZ_CHECK(transmissions <= 1u + retries);
            FUZZ_CHECK(std::vector<uint8_t>(step.transmit, step.transmit + step.transmitLength) == adu);
        }
        FUZZ_CHECK(active || master.idle());
    }
};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz::InputReader input(data, size);
    Harness h;
    modbus::MasterConfig config;
    config.retries = input.byte() % 4;
    config.responseTimeoutNs = 20000000;
    config.turnaroundDelayNs = 5000000;
    h.retries = config.retries;
    h.master = modbus::Master::create(h.transport, config).value();
    const modbus::RtuTiming timing;
    uint64_t now = 0;

    auto submit = [&]() {
        const modbus::Request request = chooseRequest(input);
        const bool wasIdle = h.master.idle();
        const modbus::StationStep step = h.master.submit(request, now);
        if (!wasIdle) {
            FUZZ_CHECK(step.rejected == modbus::ModbusError::Busy);
            return;
        }
        FUZZ_CHECK(step.rejected == modbus::ModbusError::Ok);
        h.request = request;
        h.adu.assign(1, request.unit);
        h.adu.insert(h.adu.end(), request.pdu, request.pdu + request.length);
        const uint16_t crc = modbus::Crc16::compute(h.adu.data(), h.adu.size());
        h.adu.push_back(static_cast<uint8_t>(crc & 0xFF));
        h.adu.push_back(static_cast<uint8_t>(crc >> 8));
        h.active = true;
        h.transmissions = 0;
        h.step(step);
    };
    submit();

    while (!input.empty()) {
        const uint8_t operation = input.byte();
        now += input.byte() * ((operation & 0x80) != 0 ? timing.t35Ns : timing.characterNs);
        switch (operation & 7) {
        case 0: {
            const uint8_t byte = input.byte();
            h.step(h.master.onBytes(&byte, 1, now));
            break;
        }
        case 1:
        case 2: {
            // A whole frame with a right CRC: the request's unit (mostly)
            // and a PDU from the input, starting with the request's function
            // or its exception.
            const size_t length = 1 + input.byte() % 40;
            std::vector<uint8_t> frame;
            frame.push_back((operation & 8) != 0 ? input.byte() : h.request.unit);
            const uint8_t first = input.byte();
            frame.push_back((first & 3) == 0 ? first : (first & 3) == 1 ? static_cast<uint8_t>(h.request.function() | 0x80)
                                                                         : h.request.function());
            for (size_t i = 1; i < length; ++i) {
                frame.push_back(input.byte());
            }
            const uint16_t crc = modbus::Crc16::compute(frame.data(), frame.size());
            frame.push_back(static_cast<uint8_t>(crc & 0xFF));
            frame.push_back(static_cast<uint8_t>(crc >> 8));
            for (uint8_t byte : frame) {
                h.step(h.master.onBytes(&byte, 1, now));
                now += timing.characterNs;
            }
            break;
        }
        case 3:
        case 4: {
            const bool transmitting = h.master.state() == modbus::Master::State::Transmitting;
            const modbus::StationStep step = h.master.onTransmitDone(now);
            FUZZ_CHECK(transmitting == (step.rejected == modbus::ModbusError::Ok));
            h.step(step);
            break;
        }
        case 5:
        case 6:
            h.step(h.master.poll(now));
            break;
        case 7:
            submit();
            break;
        }
    }
    return 0;
}
