// The controller's Modbus master on the board's second RS-485 port (COM3),
// running the application's polling schedule.
//
// The RS-485 port on COM2 is a slave or a master at one time (one master
// per line, [SL] 2.1); an application that both answers a plant master and
// polls its own field devices needs a second line, as the issue asks: "a
// controller answers any Modbus master on its RS-485 port, polls slaves on
// another". This line is the second: the application declares its
// requests (`modbusPolls`) and the line's settings (`modbusMaster`), and
// the application service below starts it at boot, before any of the
// application's tasks runs.
//
// One task, `modbus-poll`, runs fieldbus/modbus's PollSchedule through a
// LineRunner on COM3. Before each round it refreshes the requests of the
// write entries from their publishers' latest pages; after each round it
// publishes what every read entry that succeeded received on its publisher,
// keeping the page's other bytes. A read that fails (time-out after every
// retry, an exception, a malformed answer) leaves the page as it was, so
// the application goes on with the last good values; the entry's counters
// and last error are what the console's `modbus poll` shows.
#include <mbline/BoardLine.hpp>
#include <mbline/LineService.hpp>
#include <mbline/NodeMapBackend.hpp>
#include <mbline/PollLine.hpp>

#include <bsp/Board.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/ApplicationService.hpp>
#include <modbus/ModbusError.hpp>
#include <modbus/Request.hpp>
#include <shell/Shell.hpp>

namespace mbline {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::timerAgent;
using dcos::app::ConfigurationError;
using dcos::app::ModbusPollEntry;
using dcos::app::ModbusTable;
using dcos::app::ObjectKind;
using modbus::ModbusError;

constexpr uint64_t kMillisecond = 1'000'000;
// Posted by the service's stop, so that the task closes its subscriptions.
constexpr uint32_t kStopEvent = 1u << 1;

BoardLine com3(bsp::secondRs485Uart(), bsp::secondRs485Line, bsp::secondRs485PortAddress, "COM3");
LineRunner& runner = com3.runner();
NodeMapBackend pages;
ObjectId pollTask;
// The application whose schedule runs, or null; set by the service before
// the task first runs, read by the task and the console.
const dcos::app::Application* polled = nullptr;

static_assert(dcos::app::kMaximumModbusPollEntries <= LineRunner::kPollCapacity,
              "the line's schedule holds every entry an application may declare");

// The request an entry sends now: a read of its range, or a write of the
// bytes of its publisher's page from its offset.
modbus::ModbusResult<modbus::Request> requestOf(const ModbusPollEntry& entry, const dcos::DsmPage& page)
{
    const uint8_t unit = static_cast<uint8_t>(entry.unit);
    const uint16_t address = static_cast<uint16_t>(entry.address);
    const uint16_t count = static_cast<uint16_t>(entry.count);
    const uint8_t* bytes = page.bytes + entry.offset;
    if (entry.write) {
        if (entry.table == ModbusTable::Coils) {
            return modbus::Request::writeMultipleCoils(unit, address, count, bytes);
        }
        // Registers are high byte first in the page, as on the wire.
        uint16_t values[dcos::kDsmPageSize / 2] = {};
        for (uint16_t i = 0; i < count; ++i) {
            values[i] = static_cast<uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]);
        }
        return modbus::Request::writeMultipleRegisters(unit, address, count, values);
    }
    switch (entry.table) {
    case ModbusTable::Coils: return modbus::Request::readCoils(unit, address, count);
    case ModbusTable::DiscreteInputs: return modbus::Request::readDiscreteInputs(unit, address, count);
    case ModbusTable::HoldingRegisters: return modbus::Request::readHoldingRegisters(unit, address, count);
    case ModbusTable::InputRegisters: break;
    }
    return modbus::Request::readInputRegisters(unit, address, count);
}

// Each write entry sends its publisher's latest page from its next submission on.
void refreshWrites(const dcos::app::Application& application)
{
    const dcos::app::DeclarationList<ModbusPollEntry>& polls = application.modbusPolls;
    for (size_t i = 0; i < polls.count; ++i) {
        dcos::DsmPage page{};
        if (!polls[i].write || pages.readPage(polls[i].object, page) != modbus::ExceptionCode::None) {
            // A page that cannot be read keeps the request as it was; the
            // backend counts the refusal, which `modbus poll` shows.
            continue;
        }
        const modbus::ModbusResult<modbus::Request> request = requestOf(polls[i], page);
        if (request.ok()) {
            (void)runner.schedule().replace(i, request.value());
        }
    }
}

// Publishes what the read entries in @p ended received, each on its publisher.
void publishResults(const dcos::app::Application& application, uint32_t ended)
{
    const dcos::app::DeclarationList<ModbusPollEntry>& polls = application.modbusPolls;
    for (size_t i = 0; i < polls.count; ++i) {
        const ModbusPollEntry& entry = polls[i];
        if ((ended & (1u << i)) == 0 || entry.write || runner.schedule().statistics(i).lastError != ModbusError::Ok) {
            continue;
        }
        dcos::DsmPage page{};
        if (pages.readPage(entry.object, page) != modbus::ExceptionCode::None) {
            continue;
        }
        const modbus::ResponseView response = runner.schedule().response(i);
        uint8_t* bytes = page.bytes + entry.offset;
        for (uint32_t k = 0; k < entry.count; ++k) {
            if (dcos::app::rules::isBitTable(entry.table)) {
                modbus::setBit(bytes, k, response.bit(k));
            } else {
                const uint16_t value = response.registerValue(k);
                bytes[2 * k] = static_cast<uint8_t>(value >> 8);
                bytes[2 * k + 1] = static_cast<uint8_t>(value);
            }
        }
        (void)pages.writePage(entry.object, page);
    }
}

void pollTaskEntry(uintptr_t)
{
    for (;;) {
        pages.closeIfRequested();
        const dcos::app::Application* application = polled;
        if (application != nullptr) {
            refreshWrites(*application);
        }
        const uint64_t timeout = com3.service(timerAgent.Uptime());
        const uint32_t ended = runner.takePolled();
        if (application != nullptr && ended != 0) {
            publishResults(*application, ended);
        }
        (void)com3.wait(timeout, kStopEvent);
    }
}

Status startPollTask()
{
    const Status started = com3.startTask("modbus-poll", pollTaskEntry);
    pollTask = com3.task();
    return started;
}

bool pollPublishes(const ModbusPollEntry& entry) { return !entry.write; }

// Fills the line's schedule: every entry due at once, in declaration order,
// then each at its own period. A write's first request carries a zero page;
// the task refreshes it from the publisher before it is first sent.
ModbusError fillSchedule(const dcos::app::Application& application, uint64_t nowNs)
{
    for (const ModbusPollEntry& entry : application.modbusPolls) {
        const modbus::ModbusResult<modbus::Request> request = requestOf(entry, dcos::DsmPage{});
        if (!request.ok()) {
            return request.error();
        }
        const modbus::ModbusResult<size_t> added =
            runner.schedule().add(request.value(), uint64_t{entry.periodMs} * kMillisecond, nowNs);
        if (!added.ok()) {
            return added.error();
        }
    }
    return ModbusError::Ok;
}

ConfigurationError startPolling(const dcos::app::Application& application)
{
    if (application.modbusPolls.count == 0) {
        return {};
    }
    constexpr ObjectKind kind = ObjectKind::ModbusMaster;
    if (const Status started = startPollTask(); started != Status::Ok) {
        return refusedBy(application, kind, started);
    }
    if (const Status handed = handOverPublishers(application.modbusPolls, pollPublishes, pollTask);
        handed != Status::Ok) {
        return refusedBy(application, kind, handed);
    }
    const dcos::app::ModbusMasterDeclaration& declared = application.modbusMaster;
    const bsp::UartSettings settings = lineSettings(declared.baud, declared.parity);
    const modbus::ModbusResult<modbus::RtuTiming> timing =
        modbus::RtuTiming::make(settings.baud, static_cast<uint8_t>(settings.characterBits()));
    // The rules keep the baud rate in RtuTiming's range; a refusal here is the port's.
    Status status = timing.ok() ? com3.start(settings) : Status::InvalidArgument;
    if (status == Status::Ok) {
        modbus::MasterConfig config;
        config.responseTimeoutNs = uint64_t{declared.timeoutMs} * kMillisecond;
        config.retries = static_cast<uint8_t>(declared.retries);
        const uint64_t now = timerAgent.Uptime();
        ModbusError error = runner.startPolling(timing.value(), config, now);
        if (error == ModbusError::Ok) {
            error = fillSchedule(application, now);
        }
        status = error == ModbusError::Ok ? Status::Ok : modbus::toStatus(error);
    }
    if (status != Status::Ok) {
        com3.stop();
        return refusedBy(application, kind, status);
    }
    pages.useBoard(ObjectId{});
    polled = &application;
    return {};
}

void stopPolling(const dcos::app::Application& application)
{
    if (polled != &application) {
        return;
    }
    com3.stop();
    polled = nullptr;
    pages.requestClose();
    (void)dcos::taskAgent.PostEvent(pollTask, kStopEvent);
}

const char* tableLetters(const ModbusPollEntry& entry)
{
    switch (entry.table) {
    case ModbusTable::Coils: return entry.write ? "0f" : "01";
    case ModbusTable::DiscreteInputs: return "02";
    case ModbusTable::HoldingRegisters: return entry.write ? "10" : "03";
    case ModbusTable::InputRegisters: return "04";
    }
    return "??";
}

} // namespace

void printPollStatus(shell::Shell& shell)
{
    const dcos::app::Application* application = polled;
    if (application == nullptr) {
        shell.print("poll: no schedule runs (no application with modbusPolls was started; see 'app')\r\n");
        return;
    }
    const bsp::UartSettings& settings = com3.uart().settings();
    const modbus::MasterConfig& config = runner.master().config();
    shell.print("poll: %u entries of application '%s' on %s (0x%x, irq %u) at %lu baud 8%c%u, time-out %lu ms, "
                "%u retries\r\n",
                static_cast<unsigned>(application->modbusPolls.count), application->name, com3.portName(),
                com3.portAddress(), com3.interruptLine(), static_cast<unsigned long>(settings.baud),
                parityLetter(settings.parity), settings.stopBits,
                static_cast<unsigned long>(config.responseTimeoutNs / kMillisecond), config.retries);
    const modbus::Master::Counters& m = runner.master().counters();
    const modbus::RtuReceiver::Counters& r = runner.transport().receiver().counters();
    shell.print("line: transmissions %lu responses %lu timeouts %lu crc-errors %lu foreign %lu page-failures %lu "
                "(last: %s)\r\n",
                static_cast<unsigned long>(m.transmissions), static_cast<unsigned long>(m.responses),
                static_cast<unsigned long>(m.timeouts), static_cast<unsigned long>(r.crcErrors),
                static_cast<unsigned long>(m.foreignFrames), static_cast<unsigned long>(pages.failures()),
                dcos::statusName(pages.lastFailure()));
    shell.print("  %-15s %4s %2s %5s %5s %7s %6s %6s %4s %4s %4s %4s  %s\r\n", "entry", "unit", "fn", "addr", "count",
                "period", "done", "ok", "exc", "t/o", "err", "over", "last");
    const dcos::app::DeclarationList<ModbusPollEntry>& polls = application->modbusPolls;
    for (size_t i = 0; i < polls.count; ++i) {
        const ModbusPollEntry& entry = polls[i];
        const modbus::PollStatistics& s = runner.schedule().statistics(i);
        shell.print("  %-15s %4lu %2s %5lu %5lu %5lums %6lu %6lu %4lu %4lu %4lu %4lu  ", entry.name,
                    static_cast<unsigned long>(entry.unit), tableLetters(entry),
                    static_cast<unsigned long>(entry.address), static_cast<unsigned long>(entry.count),
                    static_cast<unsigned long>(entry.periodMs), static_cast<unsigned long>(s.transactions),
                    static_cast<unsigned long>(s.successes), static_cast<unsigned long>(s.exceptions),
                    static_cast<unsigned long>(s.timeouts), static_cast<unsigned long>(s.errors),
                    static_cast<unsigned long>(s.overruns));
        if (s.successes + s.exceptions + s.timeouts + s.errors == 0) {
            shell.print("-\r\n"); // No transaction has ended yet.
        } else if (s.lastError == ModbusError::ExceptionResponse) {
            shell.print("exception %02x %s\r\n", static_cast<unsigned>(s.lastException),
                        modbus::exceptionName(static_cast<uint8_t>(s.lastException)));
        } else if (s.lastError != ModbusError::Ok) {
            shell.print("error: %s\r\n", modbus::modbusErrorName(s.lastError));
        } else {
            shell.print("ok\r\n");
        }
    }
}

DCOS_APPLICATION_SERVICE(modbusPollService, "modbus-poll", startPolling, stopPolling);

} // namespace mbline
