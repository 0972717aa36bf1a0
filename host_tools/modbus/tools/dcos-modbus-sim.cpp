// dcos-modbus-sim: a simulated Modbus RTU slave on a serial port, for tests
// and demos: a drive whose speed ramps towards its setpoint, a sensor whose
// reading follows a sine, as a TOML file declares them
// (docs/guide/modbus-host.md). It answers any master: functions 01-06, 0F,
// 10 and 17 through libmodbus's modbus_reply(), device identification
// (2B/0E) from the file's [device] table. Requests are framed here, not by
// libmodbus's modbus_receive(), which cannot frame a 2B request.
//
//     dcos-modbus-sim -d /dev/ttyUSB1 -b 19200 --parity E drive.toml
//     dcos-modbus-sim --check drive.toml
//
// Exit status: 0 stopped (--seconds passed, SIGINT or SIGTERM); 2 bad
// arguments; 3 the port is not available; 5 the port failed; 6 the
// configuration file is not valid (the message names file and line).
#include <hostmodbus/Arguments.hpp>
#include <hostmodbus/DeviceIdentification.hpp>
#include <hostmodbus/RequestRanges.hpp>
#include <hostmodbus/Simulator.hpp>
#include <hostmodbus/SimulatorConfig.hpp>

#include <dcos/Version.hpp>

#include <modbus.h>
#include <modbus/Crc16.hpp>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

namespace {

using namespace hostmodbus;
using Clock = std::chrono::steady_clock;

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;
constexpr int kExitNotAvailable = 3;
constexpr int kExitPortFailed = 5;
constexpr int kExitBadConfig = 6;

// How long one wait for a request lasts: the behaviours advance at least
// this often, and a stop request is noticed within it.
constexpr int kTickMilliseconds = 50;
// The silence that ends a frame whose length its function does not give,
// or that abandons a frame cut off. [SL] 2.5.1.1 says 3.5 characters, but a
// host sees a USB adapter's or a pseudo-terminal's bytes in bursts the
// kernel and the scheduler time, so the host waits at least this long.
constexpr auto kMinFrameGap = std::chrono::milliseconds(20);
// The longest RTU frame ([SL] 2.5.1): address, 253 bytes of PDU, CRC.
constexpr size_t kMaxAduSize = 256;

Clock::duration frameGap(int baud)
{
    // 3.5 characters of 11 bits.
    const auto characters = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(38.5 / baud));
    return std::max<Clock::duration>(characters, kMinFrameGap);
}

volatile std::sig_atomic_t stopRequested = 0;

void requestStop(int) { stopRequested = 1; }

struct Counts {
    unsigned long requests = 0;
    unsigned long exceptions = 0;
    unsigned long badFrames = 0;
};

nlohmann::json values(const Simulator& simulator)
{
    nlohmann::json j = nlohmann::json::object();
    for (size_t i = 0; i < simulator.config().points.size(); ++i) {
        j[simulator.config().points[i].name] = simulator.value(i);
    }
    return j;
}

// The exception code for a request the simulator refuses: an unserved
// function, a quantity out of range, an address not in the map; zero when
// it is served.
int refusal(const Simulator& simulator, const uint8_t* pdu, size_t size)
{
    if (const uint8_t exception = requestException(pdu, size)) {
        return exception;
    }
    for (const TableRange& range : requestRanges(pdu, size)) {
        if (!simulator.declared(range.table, range.address, range.count)) {
            return MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS;
        }
    }
    return 0;
}

// Answers one request; returns the exception code sent, or zero.
int answer(modbus_t* context, Simulator& simulator, const uint8_t* request, int length, Counts& counts)
{
    const int header = modbus_get_header_length(context);
    // libmodbus's request length includes the CRC; the PDU is what lies
    // between the address and it.
    const uint8_t* pdu = request + header;
    const size_t pduSize = static_cast<size_t>(length - header - 2);
    const uint8_t function = pdu[0];
    const uint8_t slave = request[0];
    if (function == kFunctionEncapsulated) {
        // libmodbus does not serve 2B; the frame is built here and written
        // to the port as libmodbus would, unless the request was a
        // broadcast, which is never answered ([SL] 2.1).
        if (slave == 0) {
            return 0;
        }
        const std::vector<uint8_t> frame =
            deviceIdResponseFrame(slave, pdu, pduSize, simulator.config().identification);
        if (write(modbus_get_socket(context), frame.data(), frame.size()) != static_cast<ssize_t>(frame.size())) {
            ++counts.badFrames;
        }
        return (frame[1] & 0x80) != 0 ? frame[2] : 0;
    }
    if (const int exception = refusal(simulator, pdu, pduSize)) {
        // A broadcast is never answered, not even with an exception ([SL] 2.1).
        if (slave != 0) {
            modbus_reply_exception(context, request, static_cast<unsigned>(exception));
        }
        return exception;
    }
    // What is left is a request libmodbus serves from the mapping as it is.
    if (modbus_reply(context, request, length, simulator.mapping()) == -1) {
        ++counts.badFrames;
    }
    return 0;
}

void logRequest(const std::vector<uint8_t>& frame, int exception, bool json, bool verbose)
{
    if (json) {
        nlohmann::json j{{"event", "request"}, {"slave", frame[0]}, {"function", frame[1]}};
        j["exception"] = exception != 0 ? nlohmann::json(exception) : nlohmann::json(nullptr);
        fmt::print("{}\n", j.dump());
        std::fflush(stdout);
    } else if (verbose) {
        fmt::print("request {:02X} to slave {}{}\n", frame[1], frame[0],
                   exception != 0 ? fmt::format(": exception {:02X}", exception) : std::string());
        std::fflush(stdout);
    }
}

} // namespace

int main(int argc, char** argv)
{
    CLI::App app{"dcos-modbus-sim: a simulated Modbus RTU slave (a drive, a sensor) declared in a TOML file",
                 "dcos-modbus-sim"};
    app.set_version_flag("--version", std::string("dcos-modbus-sim ") + dcos::versionString);
    app.footer("exit status: 0 stopped (--seconds, SIGINT, SIGTERM), 2 bad arguments, 3 port not available, "
               "5 port failed, 6 configuration file not valid\n"
               "the file's format: docs/guide/modbus-host.md");
    std::string configPath;
    std::string device;
    long baud = 19200;
    std::string parityText = "E";
    int stopBits = 1;
    std::string slaveText;
    double seconds = 0;
    uint32_t seed = 1;
    double turnaroundMs = 0;
    bool json = false;
    bool verbose = false;
    bool checkOnly = false;
    app.add_option("config", configPath, "the TOML file that declares the slave")->required();
    app.add_option("-d,--device", device, "the serial port to answer on, e.g. /dev/ttyUSB1");
    app.add_option("-b,--baud", baud, "the baud rate")->capture_default_str();
    app.add_option("--parity", parityText, "N, E or O")->capture_default_str();
    app.add_option("--stop", stopBits, "stop bits, 1 or 2")->check(CLI::IsMember({1, 2}))->capture_default_str();
    app.add_option("-a,--slave", slaveText, "the slave address, 1 to 247 (default: the file's [device] slave)");
    app.add_option("-s,--seconds", seconds, "stop after this long (default: until SIGINT or SIGTERM)")
        ->check(CLI::Range(0.0, 31'536'000.0));
    app.add_option("--seed", seed, "the noise generator's seed, for repeatable runs")->capture_default_str();
    app.add_flag("--json", json, "status as JSON lines: ready, each request, stopped with the values");
    app.add_flag("-v,--verbose", verbose, "a line for each request answered");
    app.add_option("--turnaround", turnaroundMs,
                   "milliseconds between a request's end and the answer, as a slow device takes; also how a test "
                   "makes a slave answer after the master's time-out")
        ->check(CLI::Range(0.0, 60000.0))
        ->capture_default_str();
    app.add_flag("--check", checkOnly, "check the file and exit");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int code = app.exit(error);
        return code == 0 ? kExitOk : kExitUsage;
    }

    const Result<SimulatorConfig> loaded = loadSimulatorConfig(configPath);
    if (!loaded.ok()) {
        fmt::print(stderr, "dcos-modbus-sim: {}\n", loaded.error());
        if (json) {
            fmt::print("{}\n", nlohmann::json{{"event", "error"}, {"error", loaded.error()},
                                              {"exit_status", kExitBadConfig}}.dump());
        }
        return kExitBadConfig;
    }
    SimulatorConfig config = loaded.value();
    if (checkOnly) {
        if (json) {
            fmt::print("{}\n", nlohmann::json{{"event", "checked"}, {"config", configPath},
                                              {"points", config.points.size()}}.dump());
        } else {
            fmt::print("{}: {} entries, slave {}\n", configPath, config.points.size(), config.slave);
        }
        return kExitOk;
    }
    char parity = 'N';
    if (device.empty()) {
        fmt::print(stderr, "dcos-modbus-sim: say which port to answer on with -d (or give --check)\n");
        return kExitUsage;
    }
    const Result<char> parityValue = parseParity(parityText);
    const Result<int> baudValue = checkBaudRate(baud);
    for (const std::string& error : {parityValue.error(), baudValue.error()}) {
        if (!error.empty()) {
            fmt::print(stderr, "dcos-modbus-sim: {}\n", error);
            return kExitUsage;
        }
    }
    parity = parityValue.value();
    if (!slaveText.empty()) {
        const Result<uint8_t> slave = parseSlaveAddress(slaveText);
        if (!slave.ok()) {
            fmt::print(stderr, "dcos-modbus-sim: {}\n", slave.error());
            return kExitUsage;
        }
        config.slave = slave.value();
    }

    Result<std::unique_ptr<Simulator>> created = Simulator::create(config, seed);
    if (!created.ok()) {
        fmt::print(stderr, "dcos-modbus-sim: {}\n", created.error());
        return kExitPortFailed;
    }
    Simulator& simulator = *created.value();

    std::unique_ptr<modbus_t, void (*)(modbus_t*)> context(
        modbus_new_rtu(device.c_str(), baudValue.value(), parity, 8, stopBits), [](modbus_t* c) {
            modbus_close(c);
            modbus_free(c);
        });
    if (!context) {
        fmt::print(stderr, "dcos-modbus-sim: libmodbus refused the settings: {}\n", modbus_strerror(errno));
        return kExitUsage;
    }
    modbus_set_slave(context.get(), config.slave);
    if (modbus_connect(context.get()) == -1) {
        fmt::print(stderr, "dcos-modbus-sim: cannot open {}: {}\n", device, modbus_strerror(errno));
        return kExitNotAvailable;
    }

    std::signal(SIGINT, requestStop);
    std::signal(SIGTERM, requestStop);
    const std::string serial = fmt::format("{} 8{}{}", baudValue.value(), parity, stopBits);
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"event", "ready"}, {"device", device}, {"serial", serial},
                                          {"slave", config.slave}, {"points", config.points.size()}}.dump());
    } else {
        fmt::print("dcos-modbus-sim: slave {} on {} at {}, {} entries from {}\n", config.slave, device, serial,
                   config.points.size(), configPath);
    }
    std::fflush(stdout);

    Counts counts;
    const auto start = Clock::now();
    auto last = start;
    auto lastByte = start;
    const auto gap = frameGap(baudValue.value());
    const int fd = modbus_get_socket(context.get());
    std::vector<uint8_t> pending;
    int status = kExitOk;
    while (!stopRequested && status == kExitOk) {
        const auto now = Clock::now();
        if (seconds > 0 && std::chrono::duration<double>(now - start).count() >= seconds) {
            break;
        }
        simulator.advance(std::chrono::duration<double>(now - last).count());
        last = now;
        // Waits a tick for bytes, or less while a frame is open, so that
        // the silence that ends it is seen on time.
        auto wait = std::chrono::milliseconds(kTickMilliseconds);
        if (!pending.empty()) {
            wait = std::clamp(std::chrono::duration_cast<std::chrono::milliseconds>(lastByte + gap - now),
                              std::chrono::milliseconds(1), wait);
        }
        pollfd p{fd, POLLIN, 0};
        const int ready = poll(&p, 1, static_cast<int>(wait.count()));
        if (ready == -1 && errno != EINTR) {
            fmt::print(stderr, "dcos-modbus-sim: waiting on {} failed: {}\n", device, std::strerror(errno));
            status = kExitPortFailed;
            break;
        }
        if (ready == 1) {
            uint8_t buffer[512];
            const ssize_t got = read(fd, buffer, sizeof buffer);
            if (got <= 0 && !(got == -1 && (errno == EINTR || errno == EAGAIN))) {
                fmt::print(stderr, "dcos-modbus-sim: {} went away: {}\n", device,
                           got == 0 ? "end of file" : std::strerror(errno));
                status = kExitPortFailed;
                break;
            }
            if (got > 0) {
                pending.insert(pending.end(), buffer, buffer + got);
                lastByte = Clock::now();
            }
        }
        // Every whole frame in what has arrived is answered in turn.
        while (!pending.empty()) {
            const RequestScan scan = scanRequest(pending.data(), pending.size());
            const bool silent = Clock::now() - lastByte >= gap;
            size_t length = 0;
            if (scan.state == RequestScan::State::Complete) {
                length = scan.length;
            } else if (silent && scan.state == RequestScan::State::Unknown) {
                length = pending.size();
            } else if (silent || pending.size() > kMaxAduSize) {
                // A frame cut off by silence is noise, never a request; so is
                // a run of bytes longer than any frame, which would otherwise
                // grow without bound on a line that never falls silent.
                ++counts.badFrames;
                pending.clear();
                break;
            } else {
                break;
            }
            const std::vector<uint8_t> frame(pending.begin(), pending.begin() + static_cast<long>(length));
            pending.erase(pending.begin(), pending.begin() + static_cast<long>(length));
            if (frame.size() < 4 || !modbus::Crc16::check(frame.data(), frame.size())) {
                // After a damaged frame nothing that follows can be trusted
                // to start a frame: start again at the next silence.
                ++counts.badFrames;
                pending.clear();
                break;
            }
            if (frame[0] != config.slave && frame[0] != 0) {
                continue; // A request for another slave.
            }
            // The request is answered with the values as of now.
            const auto arrived = Clock::now();
            simulator.advance(std::chrono::duration<double>(arrived - last).count());
            last = arrived;
            ++counts.requests;
            if (turnaroundMs > 0) {
                std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(turnaroundMs));
            }
            const int exception = answer(context.get(), simulator, frame.data(), static_cast<int>(frame.size()), counts);
            counts.exceptions += exception != 0 ? 1 : 0;
            logRequest(frame, exception, json, verbose);
        }
    }
    const double ran = std::chrono::duration<double>(Clock::now() - start).count();
    if (json) {
        fmt::print("{}\n", nlohmann::json{{"event", "stopped"},
                                          {"seconds", ran},
                                          {"requests", counts.requests},
                                          {"exceptions", counts.exceptions},
                                          {"bad_frames", counts.badFrames},
                                          {"values", values(simulator)},
                                          {"exit_status", status}}
                               .dump());
    } else {
        fmt::print("dcos-modbus-sim: stopped after {:.1f} s: {} requests, {} exceptions, {} bad frames\n", ran,
                   counts.requests, counts.exceptions, counts.badFrames);
    }
    return status;
}
