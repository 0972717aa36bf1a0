// Fuzz target: the frames the Modbus host tools read from a serial line
// (host_tools/modbus/src/DeviceIdentification.cpp, RequestRanges.cpp): a
// device identification answer as dcos-modbus frames and decodes it, a
// request as dcos-modbus-sim frames and screens it, and the simulator's
// own answer to that request.
//
// The checks: a complete scan never claims more bytes than arrived or than
// an ADU holds; a decoded answer's objects fit the frame; a request's
// ranges are only given for a request that passes its screening or is
// merely out of the map; and the simulator's device identification answer
// to any request is a frame its own reader accepts whole, with the CRC
// right and every object it reports one the simulator has.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostmodbus/DeviceIdentification.hpp>
#include <hostmodbus/RequestRanges.hpp>

#include <modbus/Crc16.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

using namespace hostmodbus;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const FrameScan scan = scanDeviceIdResponse(data, size);
    if (scan.state == FrameScan::State::Complete) {
        FUZZ_CHECK(scan.length <= size && scan.length <= 256 && scan.length >= 5);
        const Result<DeviceIdentificationReply> reply = decodeDeviceIdResponse(data, scan.length, size > 0 ? data[0] : 0);
        if (reply.ok()) {
            size_t bytes = 0;
            for (const DeviceIdObject& o : reply.value().objects) {
                bytes += 2 + o.value.size();
            }
            FUZZ_CHECK(bytes + 10 <= scan.length || reply.value().exceptionCode != 0);
        }
    }

    const RequestScan request = scanRequest(data, size);
    if (request.state == RequestScan::State::Complete) {
        FUZZ_CHECK(request.length <= size && request.length >= 4);
        const uint8_t* pdu = data + 1;
        const size_t pduSize = request.length - 3;
        const uint8_t exception = requestException(pdu, pduSize);
        FUZZ_CHECK(exception == 0 || exception == 1 || exception == 3);
        for (const TableRange& range : requestRanges(pdu, pduSize)) {
            FUZZ_CHECK(range.address <= 0xFFFF && range.count <= 0xFFFF);
            if (exception == 0) {
                FUZZ_CHECK(range.count >= 1 && range.count <= 2000);
            }
        }
        // The simulator's answer to whatever came, with objects from the input too.
        std::vector<DeviceIdObject> objects{{0, "DCOS"}, {1, "FUZZ"}, {2, "1"}};
        for (size_t i = request.length; i + 1 < size && objects.size() < 20; i += 2) {
            const uint8_t id = static_cast<uint8_t>(objects.back().id + 1 + data[i] % 8);
            if (id <= objects.back().id) {
                break;
            }
            objects.push_back({id, std::string(data[i + 1] % 65, 'x')});
        }
        const uint8_t slave = data[0] == 0 ? 1 : data[0];
        const std::vector<uint8_t> frame = deviceIdResponseFrame(slave, pdu, pduSize, objects);
        FUZZ_CHECK(frame.size() <= 256);
        FUZZ_CHECK(modbus::Crc16::check(frame.data(), frame.size()));
        const FrameScan own = scanDeviceIdResponse(frame.data(), frame.size());
        FUZZ_CHECK(own.state == FrameScan::State::Complete && own.length == frame.size());
        const Result<DeviceIdentificationReply> reply = decodeDeviceIdResponse(frame.data(), frame.size(), slave);
        FUZZ_CHECK(reply.ok());
        for (const DeviceIdObject& o : reply.value().objects) {
            bool known = false;
            for (const DeviceIdObject& have : objects) {
                known |= have.id == o.id && have.value == o.value;
            }
            FUZZ_CHECK(known);
        }
        // A stream that says more follows must have delivered something, or
        // a master following it would ask for the same object for ever.
        FUZZ_CHECK(!reply.value().moreFollows || !reply.value().objects.empty());
    }
    return 0;
}
