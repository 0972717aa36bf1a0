// dcos-modbus: read and write a Modbus RTU slave's coils, discrete inputs,
// holding and input registers from a Linux host, on libmodbus
// (docs/guide/modbus-host.md). One request per run, its answer on stdout
// as "address value" lines (or one JSON object), so that scripts and other
// tools can use it as they use can-utils.
//
//     dcos-modbus -d /dev/ttyUSB0 -b 19200 --parity E -a 17 read-holding 100 4
//     dcos-modbus -d /dev/ttyUSB0 -a 17 write-registers 100=1,2,-3
//     dcos-modbus -d /dev/ttyUSB0 -a 17 --json identify
//
// Exit status: 0 done; 1 the slave answered with an exception (named);
// 2 bad arguments; 3 the port is not available (no such device, no
// permission, no RS-485 mode); 4 no answer within the time-out and
// retries; 5 the answer was not valid (CRC, length, other slave) or the
// port failed.
#include <hostmodbus/Arguments.hpp>
#include <hostmodbus/DeviceIdentification.hpp>

#include <dcos/Version.hpp>

#include <modbus.h>
#include <modbus-rtu.h>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace hostmodbus;
using Clock = std::chrono::steady_clock;

constexpr int kExitOk = 0;
constexpr int kExitException = 1;
constexpr int kExitUsage = 2;
constexpr int kExitNotAvailable = 3;
constexpr int kExitNoAnswer = 4;
constexpr int kExitBadAnswer = 5;

// A device identification stream longer than this many responses is a
// slave that keeps saying "more follows": stop rather than loop for ever.
constexpr int kMaxIdentificationResponses = 16;
// The longest silence within one response frame before it counts as cut
// off, as libmodbus's default byte time-out.
constexpr int kByteTimeoutMs = 500;

struct Settings {
    std::string device;
    long baud = 19200;
    std::string parity = "E";
    int stopBits = 1;
    std::string slave;
    long timeoutMs = 1000;
    int retries = 2;
    std::string rts = "none";
    bool rs485 = false;
    bool json = false;
};

// What went wrong with one request, as the exit status and the message.
struct Failure {
    int status = kExitOk;
    std::string message;
    int exceptionCode = 0;
};

void report(const Failure& failure, bool json, const std::string& command)
{
    fmt::print(stderr, "dcos-modbus: {}\n", failure.message);
    if (json) {
        nlohmann::json j{{"command", command}, {"error", failure.message}, {"exit_status", failure.status}};
        if (failure.exceptionCode != 0) {
            j["exception"] = failure.exceptionCode;
            j["exception_name"] = modbus_strerror(MODBUS_ENOBASE + failure.exceptionCode);
        }
        fmt::print("{}\n", j.dump());
    }
}

using ModbusContext = std::unique_ptr<modbus_t, void (*)(modbus_t*)>;

void closeContext(modbus_t* context)
{
    modbus_close(context);
    modbus_free(context);
}

// Opens the port with the checked settings; a port that cannot be opened
// or set up is "not available", the same status dcos-can gives.
ModbusContext openPort(const Settings& s, char parity, uint8_t slave, Failure& failure)
{
    ModbusContext context(modbus_new_rtu(s.device.c_str(), static_cast<int>(s.baud), parity, 8, s.stopBits),
                          closeContext);
    if (!context) {
        failure = {kExitUsage, fmt::format("libmodbus refused the settings: {}", modbus_strerror(errno))};
        return context;
    }
    modbus_set_slave(context.get(), slave);
    modbus_set_response_timeout(context.get(), static_cast<uint32_t>(s.timeoutMs / 1000),
                                static_cast<uint32_t>(s.timeoutMs % 1000 * 1000));
    if (modbus_connect(context.get()) == -1) {
        failure = {kExitNotAvailable, fmt::format("cannot open {}: {}", s.device, modbus_strerror(errno))};
        return ModbusContext(nullptr, closeContext);
    }
    if (s.rs485 && modbus_rtu_set_serial_mode(context.get(), MODBUS_RTU_RS485) == -1) {
        failure = {kExitNotAvailable,
                   fmt::format("{} has no RS-485 mode in its kernel driver ({}); for an adapter that needs its "
                               "driver enabled by RTS, use --rts up or --rts down instead",
                               s.device, modbus_strerror(errno))};
        return ModbusContext(nullptr, closeContext);
    }
    if (s.rts != "none") {
        const int mode = s.rts == "up" ? MODBUS_RTU_RTS_UP : MODBUS_RTU_RTS_DOWN;
        if (modbus_rtu_set_rts(context.get(), mode) == -1) {
            failure = {kExitNotAvailable,
                       fmt::format("{} cannot drive RTS: {}", s.device, modbus_strerror(errno))};
            return ModbusContext(nullptr, closeContext);
        }
    }
    return context;
}

bool isException(int error) { return error > MODBUS_ENOBASE && error <= EMBXGTAR; }

// Whether another attempt may succeed: silence and damaged answers may be
// noise on the line; an exception is the slave's considered answer.
bool worthRetrying(int error) { return error == ETIMEDOUT || error == EMBBADCRC || error == EMBBADDATA || error == EMBMDATA || error == EMBBADSLAVE; }

Failure failureOf(int error, const std::string& what, uint8_t slave, const Settings& s, int attempts)
{
    if (isException(error)) {
        const int code = error - MODBUS_ENOBASE;
        return {kExitException,
                fmt::format("slave {} refused {}: exception {:02X} ({})", slave, what, code, modbus_strerror(error)),
                code};
    }
    if (error == ETIMEDOUT) {
        return {kExitNoAnswer, fmt::format("no answer from slave {} to {} within {} ms ({} attempt{})", slave, what,
                                           s.timeoutMs, attempts, attempts == 1 ? "" : "s")};
    }
    return {kExitBadAnswer, fmt::format("{} to slave {} failed: {}", what, slave, modbus_strerror(error))};
}

// Runs @p request (a libmodbus call returning -1 on failure with errno
// set) up to 1 + retries times.
Failure transact(modbus_t* context, const Settings& s, uint8_t slave, const std::string& what,
                 const std::function<int()>& request)
{
    int error = 0;
    int attempts = 0;
    for (int attempt = 0; attempt <= s.retries; ++attempt) {
        ++attempts;
        if (request() != -1) {
            return {};
        }
        error = errno;
        if (!worthRetrying(error)) {
            break;
        }
        // A late or damaged answer must not be taken for the next one's.
        modbus_flush(context);
    }
    return failureOf(error, what, slave, s, attempts);
}

// Reads one device identification response frame from the port: waits up
// to the response time-out for its first byte, then reads until its own
// lengths say it is whole. Returns -1 with errno set, as libmodbus does.
int readIdentificationFrame(modbus_t* context, long timeoutMs, std::vector<uint8_t>& frame)
{
    frame.clear();
    const int fd = modbus_get_socket(context);
    const auto deadline = Clock::now() + std::chrono::milliseconds(timeoutMs);
    while (true) {
        int wait = kByteTimeoutMs;
        if (frame.empty()) {
            wait = static_cast<int>(
                std::max<long>(0, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count()));
        }
        pollfd p{fd, POLLIN, 0};
        const int ready = poll(&p, 1, wait);
        if (ready == -1 && errno == EINTR) {
            continue;
        }
        if (ready == -1) {
            return -1;
        }
        if (ready == 0) {
            // Silence before the first byte is no answer; in the middle of a
            // frame, a cut-off answer.
            errno = frame.empty() ? ETIMEDOUT : EMBBADDATA;
            return -1;
        }
        uint8_t buffer[260];
        const ssize_t got = read(fd, buffer, sizeof buffer);
        if (got <= 0) {
            errno = got == 0 ? ECONNRESET : errno;
            return -1;
        }
        frame.insert(frame.end(), buffer, buffer + got);
        const FrameScan scan = scanDeviceIdResponse(frame.data(), frame.size());
        if (scan.state == FrameScan::State::Invalid) {
            errno = EMBBADDATA;
            return -1;
        }
        if (scan.state == FrameScan::State::Complete) {
            // Anything after the frame is not part of this answer.
            frame.resize(scan.length);
            return static_cast<int>(frame.size());
        }
    }
}

int identify(modbus_t* context, const Settings& s, uint8_t slave, const std::string& codeName, uint8_t objectId)
{
    const ReadDeviceIdCode code = codeName == "basic"      ? ReadDeviceIdCode::Basic
                                  : codeName == "regular"  ? ReadDeviceIdCode::Regular
                                  : codeName == "extended" ? ReadDeviceIdCode::Extended
                                                           : ReadDeviceIdCode::Individual;
    const std::string what = "device identification (2B/0E)";
    std::vector<DeviceIdObject> objects;
    DeviceIdentificationReply last;
    uint8_t next = objectId;
    for (int response = 0; response < kMaxIdentificationResponses; ++response) {
        std::vector<uint8_t> request{slave};
        const std::vector<uint8_t> pdu = deviceIdRequestPdu(code, next);
        request.insert(request.end(), pdu.begin(), pdu.end());
        std::string decodeError;
        const Failure failure = transact(context, s, slave, what, [&]() {
            if (modbus_send_raw_request(context, request.data(), static_cast<int>(request.size())) == -1) {
                return -1;
            }
            std::vector<uint8_t> frame;
            if (readIdentificationFrame(context, s.timeoutMs, frame) == -1) {
                return -1;
            }
            const Result<DeviceIdentificationReply> reply = decodeDeviceIdResponse(frame.data(), frame.size(), slave);
            if (!reply.ok()) {
                decodeError = reply.error();
                errno = EMBBADDATA;
                return -1;
            }
            if (reply.value().exceptionCode != 0) {
                errno = MODBUS_ENOBASE + reply.value().exceptionCode;
                return -1;
            }
            last = reply.value();
            return 0;
        });
        if (failure.status != kExitOk) {
            Failure shown = failure;
            if (!decodeError.empty() && failure.status == kExitBadAnswer) {
                shown.message = fmt::format("{} to slave {} failed: {}", what, slave, decodeError);
            }
            report(shown, s.json, "identify");
            return shown.status;
        }
        objects.insert(objects.end(), last.objects.begin(), last.objects.end());
        if (!last.moreFollows || code == ReadDeviceIdCode::Individual) {
            break;
        }
        next = last.nextObjectId;
    }
    if (s.json) {
        nlohmann::json list = nlohmann::json::array();
        for (const DeviceIdObject& o : objects) {
            list.push_back({{"id", o.id}, {"name", deviceIdObjectName(o.id)}, {"value", o.value}});
        }
        fmt::print("{}\n", nlohmann::json{{"device", s.device},
                                          {"slave", slave},
                                          {"command", "identify"},
                                          {"function", 0x2B},
                                          {"conformity", last.conformity},
                                          {"objects", list}}
                               .dump());
    } else {
        for (const DeviceIdObject& o : objects) {
            fmt::print("{}: {}\n", deviceIdObjectName(o.id), o.value);
        }
    }
    return kExitOk;
}

void printValues(const Settings& s, uint8_t slave, const std::string& command, int function, uint16_t address,
                 const std::vector<uint16_t>& values)
{
    if (s.json) {
        fmt::print("{}\n", nlohmann::json{{"device", s.device},
                                          {"slave", slave},
                                          {"command", command},
                                          {"function", function},
                                          {"address", address},
                                          {"values", values}}
                               .dump());
        return;
    }
    for (size_t i = 0; i < values.size(); ++i) {
        fmt::print("{} {}\n", address + i, values[i]);
    }
}

void printWritten(const Settings& s, uint8_t slave, const std::string& command, int function, uint16_t address,
                  size_t count)
{
    if (s.json) {
        fmt::print("{}\n", nlohmann::json{{"device", s.device},
                                          {"slave", slave},
                                          {"command", command},
                                          {"function", function},
                                          {"address", address},
                                          {"count", count}}
                               .dump());
    }
}

// A read of bits or registers: @p function is the libmodbus call.
template <typename Item, typename Call>
int readItems(modbus_t* context, const Settings& s, uint8_t slave, const std::string& command, int function,
              const Range& range, Call call)
{
    std::vector<Item> items(range.count);
    const Failure failure =
        transact(context, s, slave, fmt::format("{} ({:02X}) of {} from {}", command, function, range.count, range.address),
                 [&]() { return call(context, range.address, range.count, items.data()); });
    if (failure.status != kExitOk) {
        report(failure, s.json, command);
        return failure.status;
    }
    printValues(s, slave, command, function, range.address, std::vector<uint16_t>(items.begin(), items.end()));
    return kExitOk;
}

// Parses with a hostmodbus parser, printing its message on failure.
template <typename T>
bool parsed(const Result<T>& result, T& out)
{
    if (!result.ok()) {
        fmt::print(stderr, "dcos-modbus: {}\n", result.error());
        return false;
    }
    out = result.value();
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-modbus: read and write a Modbus RTU slave's coils, inputs and registers (libmodbus)",
                 "dcos-modbus"};
    app.set_version_flag("--version", std::string("dcos-modbus ") + dcos::versionString);
    app.require_subcommand(1);
    app.footer("addresses are the protocol's, from 0 (holding register 40001 is address 0); numbers may be written "
               "in hexadecimal with 0x\n"
               "exit status: 0 done, 1 the slave answered with an exception, 2 bad arguments, 3 port not available, "
               "4 no answer, 5 invalid answer or port failure");
    Settings s;
    app.add_option("-d,--device", s.device, "the serial port, e.g. /dev/ttyUSB0")->required();
    app.add_option("-b,--baud", s.baud, "the baud rate")->capture_default_str();
    app.add_option("--parity", s.parity, "N, E or O ([SL] 2.5.1: even by default)")->capture_default_str();
    app.add_option("--stop", s.stopBits, "stop bits, 1 or 2")->check(CLI::IsMember({1, 2}))->capture_default_str();
    app.add_option("-a,--slave", s.slave, "the slave address, 1 to 247")->required();
    app.add_option("-t,--timeout-ms", s.timeoutMs, "how long to wait for each answer")
        ->check(CLI::Range(10L, 60'000L))
        ->capture_default_str();
    app.add_option("-r,--retries", s.retries, "how often to repeat a request that got no or a damaged answer")
        ->check(CLI::Range(0, 10))
        ->capture_default_str();
    app.add_option("--rts", s.rts,
                   "drive RTS around each request for an RS-485 adapter's driver enable: up (RTS on while "
                   "sending) or down")
        ->check(CLI::IsMember({"none", "up", "down"}))
        ->capture_default_str();
    app.add_flag("--rs485", s.rs485, "put the port in the kernel's RS-485 mode (TIOCSRS485), for UARTs that have it");
    app.add_flag("--json", s.json, "one JSON object on stdout, for the answer or the error");

    std::string address;
    std::string count = "1";
    std::string value;
    std::string list;
    std::string readRange;
    struct ReadCommand {
        const char* name;
        const char* help;
        int function;
        unsigned max;
        CLI::App* command = nullptr;
    };
    ReadCommand reads[] = {
        {"read-coils", "read coils (01)", 0x01, kMaxReadBits},
        {"read-discrete-inputs", "read discrete inputs (02)", 0x02, kMaxReadBits},
        {"read-holding-registers", "read holding registers (03)", 0x03, kMaxReadRegisters},
        {"read-input-registers", "read input registers (04)", 0x04, kMaxReadRegisters},
    };
    for (ReadCommand& r : reads) {
        r.command = app.add_subcommand(r.name, r.help);
        r.command->add_option("address", address, "the first address")->required();
        r.command->add_option("count", count, fmt::format("how many, 1 to {} (default 1)", r.max));
    }
    CLI::App* writeCoil = app.add_subcommand("write-coil", "write one coil (05)");
    writeCoil->add_option("address", address, "the coil's address")->required();
    writeCoil->add_option("value", value, "1, 0, on, off, true or false")->required();
    CLI::App* writeRegister = app.add_subcommand("write-register", "write one holding register (06)");
    writeRegister->add_option("address", address, "the register's address")->required();
    writeRegister->add_option("value", value, "0 to 65535, 0x0000 to 0xFFFF or -32768 to -1")->required();
    CLI::App* writeCoils = app.add_subcommand("write-coils", "write several coils (0F)");
    writeCoils->add_option("list", list, "address=bit,bit,..., e.g. 16=1,0,1")->required();
    CLI::App* writeRegisters = app.add_subcommand("write-registers", "write several holding registers (10)");
    writeRegisters->add_option("list", list, "address=value,value,..., e.g. 100=1,0x20,-3")->required();
    CLI::App* writeRead =
        app.add_subcommand("write-read", "write holding registers, then read holding registers, in one request (17)");
    writeRead->add_option("write", list, "address=value,... to write first (up to 121)")->required();
    writeRead->add_option("read", readRange, "address:count to read then (up to 125)")->required();
    std::string idCode = "regular";
    std::string idObject = "0";
    CLI::App* identifyCommand = app.add_subcommand("identify", "read the device identification (2B/0E)");
    identifyCommand->add_option("--code", idCode, "basic, regular, extended, or individual (one object)")
        ->check(CLI::IsMember({"basic", "regular", "extended", "individual"}))
        ->capture_default_str();
    identifyCommand->add_option("--object", idObject, "the object to start at, or the one object with individual")
        ->capture_default_str();

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }

    // Every argument is checked before the port is opened, so a typo never
    // sends half a job.
    uint8_t slave = 0;
    char parity = 'N';
    int baud = 0;
    if (!parsed(parseSlaveAddress(s.slave), slave) || !parsed(parseParity(s.parity), parity) ||
        !parsed(checkBaudRate(s.baud), baud)) {
        return kExitUsage;
    }
    Range range;
    uint16_t start = 0;
    bool bit = false;
    uint16_t word = 0;
    RegisterList registers;
    BitList bits;
    Range readPart;
    uint32_t object = 0;
    const ReadCommand* read = nullptr;
    for (const ReadCommand& r : reads) {
        if (*r.command) {
            read = &r;
            uint16_t first = 0;
            uint32_t n = 0;
            const Result<uint32_t> countValue = parseUnsigned(count, 0xFFFF, "count");
            if (!parsed(parseAddress(address), first) || !parsed(countValue, n) ||
                !parsed(checkRange(first, n, r.max), range)) {
                return kExitUsage;
            }
        }
    }
    if ((*writeCoil && (!parsed(parseAddress(address), start) || !parsed(parseBit(value), bit))) ||
        (*writeRegister && (!parsed(parseAddress(address), start) || !parsed(parseRegisterValue(value), word))) ||
        (*writeCoils && !parsed(parseBitList(list, kMaxWriteBits), bits)) ||
        (*writeRegisters && !parsed(parseRegisterList(list, kMaxWriteRegisters), registers)) ||
        (*writeRead && (!parsed(parseRegisterList(list, kMaxReadWriteWriteRegisters), registers) ||
                        !parsed(parseRange(readRange, kMaxReadRegisters), readPart))) ||
        (*identifyCommand && !parsed(parseUnsigned(idObject, 0xFF, "object id"), object))) {
        return kExitUsage;
    }

    Failure failure;
    const ModbusContext context = openPort(s, parity, slave, failure);
    if (!context) {
        report(failure, s.json, app.get_subcommands().front()->get_name());
        return failure.status;
    }
    modbus_t* c = context.get();
    if (read != nullptr) {
        switch (read->function) {
        case 0x01: return readItems<uint8_t>(c, s, slave, read->name, 0x01, range, modbus_read_bits);
        case 0x02: return readItems<uint8_t>(c, s, slave, read->name, 0x02, range, modbus_read_input_bits);
        case 0x03: return readItems<uint16_t>(c, s, slave, read->name, 0x03, range, modbus_read_registers);
        default: return readItems<uint16_t>(c, s, slave, read->name, 0x04, range, modbus_read_input_registers);
        }
    }
    if (*identifyCommand) {
        return identify(c, s, slave, idCode, static_cast<uint8_t>(object));
    }
    // The writes: the command, its function code, where and how many, and the call.
    std::string command;
    int function = 0;
    uint16_t where = 0;
    size_t written = 0;
    std::function<int()> call;
    std::vector<uint8_t> bitBytes(bits.values.begin(), bits.values.end());
    std::vector<uint16_t> readBack(readPart.count);
    if (*writeCoil) {
        command = "write-coil", function = 0x05, where = start, written = 1;
        call = [&]() { return modbus_write_bit(c, start, bit ? 1 : 0); };
    } else if (*writeRegister) {
        command = "write-register", function = 0x06, where = start, written = 1;
        call = [&]() { return modbus_write_register(c, start, word); };
    } else if (*writeCoils) {
        command = "write-coils", function = 0x0F, where = bits.address, written = bitBytes.size();
        call = [&]() { return modbus_write_bits(c, bits.address, static_cast<int>(bitBytes.size()), bitBytes.data()); };
    } else if (*writeRegisters) {
        command = "write-registers", function = 0x10, where = registers.address, written = registers.values.size();
        call = [&]() {
            return modbus_write_registers(c, registers.address, static_cast<int>(registers.values.size()),
                                          registers.values.data());
        };
    } else {
        command = "write-read", function = 0x17, where = readPart.address, written = registers.values.size();
        call = [&]() {
            return modbus_write_and_read_registers(c, registers.address, static_cast<int>(registers.values.size()),
                                                   registers.values.data(), readPart.address, readPart.count,
                                                   readBack.data());
        };
    }
    failure = transact(c, s, slave, fmt::format("{} ({:02X}) at {}", command, function, where), call);
    if (failure.status != kExitOk) {
        report(failure, s.json, command);
        return failure.status;
    }
    if (function == 0x17) {
        printValues(s, slave, command, function, readPart.address, readBack);
    } else {
        printWritten(s, slave, command, function, where, written);
    }
    return kExitOk;
}
