// The controller's Modbus RTU line on the board's RS-485 port (COM2), and
// the console command `modbus` that runs it (docs/protocols/modbus.md).
//
// One task, `modbus`, runs the line's station (mbline::LineRunner): the
// UART's interrupt stamps each received byte with the uptime and wakes the
// task, which feeds the bytes to the portable stack and sleeps until the
// stack's next deadline (t1.5/t3.5, a master's time-out) or the next
// interrupt. A line is either a slave or a master: RS-485 is one bus, and a
// node that polled as a master and answered as a slave on it would break
// the single-master rule of [SL] 2.1. The console changes the role and
// submits a master's requests through a one-slot mailbox the task takes;
// every wait of the console has a time-out.
//
// An application that declares a Modbus slave (modbusSlave) and its
// register map (modbusMap) has the line start at boot, serving the map:
// the application service below runs in the root task while the loader
// holds dispatching, hands the publishers the master writes to the line's
// task, installs the I/O board when the map names its points, and starts
// the slave before any task runs. `modbus slave` by hand still serves the
// console's data model instead.
#include <mbline/BoardLine.hpp>
#include <mbline/LineRunner.hpp>
#include <mbline/LineService.hpp>
#include <mbline/NodeMapBackend.hpp>
#include <mbline/PollLine.hpp>

#include <bsp/Board.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/SystemAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/ApplicationService.hpp>
#include <iobus/MfioBoard.hpp>
#include <runtime/Text.hpp>
#include <modbus/InMemoryDataModel.hpp>
#include <modbus/ModbusError.hpp>
#include <modbus/Request.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace mbline {

namespace {

using dcos::ObjectId;
using dcos::Status;
using dcos::taskAgent;
using dcos::timerAgent;
using modbus::ModbusError;
using shell::CommandResult;

// The RS-485 port the console and the application's slave use: the board's COM2 16550.
BoardLine com2(bsp::rs485Uart(), bsp::rs485Line, bsp::rs485PortAddress, "COM2");
LineRunner& runner = com2.runner();

// The data the console's slave serves when no application map is linked:
// 256 of each table. Discrete inputs and input registers hold a pattern a
// test can recognise (input register n is 0x1000 + n, discrete input n is
// on when n is a multiple of 3); coils and holding registers start at 0.
modbus::InMemoryDataModel<256, 256, 256, 256> consoleModel;
const modbus::DeviceIdentification identification{
    .vendorName = "DCOS",
    .productCode = "DCOS-486",
    .revision = "0.1",
    .productName = "DCOS controller",
    .modelName = "isa486",
};

// The application's register map, served at boot when the application
// declares its slave; the I/O board the map's points are read from.
NodeMapBackend nodeBackend;
ApplicationMapModel applicationModel({}, nodeBackend);
iobus::MfioBoard mapBoard("modbus.io");
// The application whose map the line serves, or null (the console's model
// or no slave). Set by the application service before the line's task
// runs; the task and the console only read it.
const dcos::app::Application* servedApplication = nullptr;
// The application the service started the slave for, which keeps the line's
// task, subscriptions and board until the service stops, even after the
// console took the line over by hand.
const dcos::app::Application* startedFor = nullptr;
modbus::DeviceIdentification applicationIdentification = identification;

// The task's events.
constexpr uint32_t kCommandEvent = 1u << 1; // the console's mailbox (BoardLine::kLineEvent is the UART's)
// The console task's event for a mailbox answer; bit 0 is its input, the
// can command uses bits 20 to 22.
constexpr uint32_t kAnswerEvent = 1u << 23;

constexpr uint64_t kMillisecond = 1'000'000;
constexpr uint64_t kCommandTimeoutNs = 2000 * kMillisecond;

enum class CommandKind : uint8_t { StartSlave, StartMaster, Stop, Submit };

struct Mailbox {
    CommandKind kind = CommandKind::Stop;
    uint8_t address = 0;
    bsp::UartSettings settings{};
    modbus::MasterConfig masterConfig{};
    modbus::Request request{};
    ObjectId requester{};
    // Written by the task before it answers.
    Status status = Status::Ok;
    ModbusError error = ModbusError::Ok;
    volatile bool pending = false;
};

Mailbox mailbox;
ObjectId lineTask;
Completion lastCompletion;
// The master's transmissions before the last accepted transaction, taken by
// the task as it submits, so that the transaction's end reports its own
// count rather than the line's total.
uint32_t transmissionsBefore = 0;
volatile bool completionReady = false;
ObjectId completionWaiter;

// The console slave's pattern in discrete inputs and input registers (see
// consoleModel), written when the first slave starts.
void fillPattern()
{
    for (size_t i = 0; i < 256; ++i) {
        consoleModel.inputRegister(i) = static_cast<uint16_t>(0x1000 + i);
        consoleModel.discreteInput(i) = i % 3 == 0;
    }
}

void stopPort() { com2.stop(); }

// Brings the port up with the mailbox's settings; the runner is started by the caller.
Status startPort(const bsp::UartSettings& settings) { return com2.start(settings); }

void serveMailbox()
{
    if (!mailbox.pending) {
        return;
    }
    const uint64_t now = timerAgent.Uptime();
    mailbox.status = Status::Ok;
    mailbox.error = ModbusError::Ok;
    switch (mailbox.kind) {
    case CommandKind::Stop:
        stopPort();
        servedApplication = nullptr;
        break;
    case CommandKind::StartSlave:
    case CommandKind::StartMaster: {
        const modbus::ModbusResult<modbus::RtuTiming> timing =
            modbus::RtuTiming::make(mailbox.settings.baud, static_cast<uint8_t>(mailbox.settings.characterBits()));
        if (!timing.ok()) {
            mailbox.error = timing.error();
            break;
        }
        static bool patternWritten = false;
        if (!patternWritten) {
            fillPattern();
            patternWritten = true;
        }
        mailbox.status = startPort(mailbox.settings);
        if (mailbox.status != Status::Ok) {
            stopPort();
            break;
        }
        // By hand, the line serves the console's data model, whatever the application declared.
        servedApplication = nullptr;
        mailbox.error = mailbox.kind == CommandKind::StartSlave
                            ? runner.startSlave(timing.value(), consoleModel, identification, mailbox.address, now)
                            : runner.startMaster(timing.value(), mailbox.masterConfig, now);
        if (mailbox.error != ModbusError::Ok) {
            stopPort();
        }
        break;
    }
    case CommandKind::Submit: {
        completionReady = false;
        completionWaiter = mailbox.requester;
        const uint32_t before = runner.master().counters().transmissions;
        mailbox.error = runner.submit(mailbox.request, now);
        if (mailbox.error == ModbusError::Ok) {
            transmissionsBefore = before;
        }
        break;
    }
    }
    mailbox.pending = false;
    (void)taskAgent.PostEvent(mailbox.requester, kAnswerEvent);
}

void lineTaskEntry(uintptr_t)
{
    for (;;) {
        nodeBackend.closeIfRequested();
        serveMailbox();
        const uint64_t timeout = com2.service(timerAgent.Uptime());
        Completion completion;
        if (runner.takeCompletion(completion)) {
            lastCompletion = completion;
            completionReady = true;
            (void)taskAgent.PostEvent(completionWaiter, kAnswerEvent);
        }
        (void)com2.wait(timeout, kCommandEvent);
    }
}

// Creates the line's task the first time the line is needed.
Status startLineTask()
{
    const Status started = com2.startTask("modbus", lineTaskEntry);
    lineTask = com2.task();
    return started;
}

// Discards a stale answer event, so that the next wait sees only its own.
void clearAnswerEvent() { (void)taskAgent.ReceiveEvent(kAnswerEvent, dcos::EventWait::Any, dcos::kPoll); }

// Hands the mailbox to the task and waits for its answer.
bool runCommand(shell::Shell& shell)
{
    if (const Status started = startLineTask(); started != Status::Ok) {
        shell.print("error: cannot start the modbus task: %s\r\n", dcos::statusName(started));
        return false;
    }
    clearAnswerEvent();
    mailbox.requester = taskAgent.IdOfSelf();
    mailbox.pending = true;
    (void)taskAgent.PostEvent(lineTask, kCommandEvent);
    const uint64_t deadline = timerAgent.Uptime() + kCommandTimeoutNs;
    while (mailbox.pending) {
        const uint64_t now = timerAgent.Uptime();
        if (now >= deadline) {
            shell.print("error: the modbus task did not answer within %lu ms\r\n",
                        static_cast<unsigned long>(kCommandTimeoutNs / kMillisecond));
            return false;
        }
        (void)taskAgent.ReceiveEvent(kAnswerEvent, dcos::EventWait::Any, deadline - now);
    }
    if (mailbox.status != Status::Ok) {
        if (mailbox.status == Status::NotFound) {
            shell.print("error: no 16550 answers at 0x%x (COM2): the board has no RS-485 port\r\n",
                        bsp::rs485PortAddress);
        } else {
            shell.print("error: the RS-485 port refused: %s\r\n", dcos::statusName(mailbox.status));
        }
        return false;
    }
    if (mailbox.error != ModbusError::Ok) {
        shell.print("error: %s\r\n", modbus::modbusErrorName(mailbox.error));
        return false;
    }
    return true;
}

bool parseNumber(shell::Shell& shell, const char* text, unsigned long limit, unsigned long& value, const char* what)
{
    if (!shell::Shell::parseUnsigned(text, value) || value > limit) {
        shell.print("error: %s '%s' is not a number from 0 to %lu\r\n", what, text, limit);
        return false;
    }
    return true;
}

// [baud] [parity n|e|o]: the line's settings, 19200 8E1 by default ([SL] 2.5.1).
bool parseLine(shell::Shell& shell, int argc, char** argv, int first, bsp::UartSettings& settings)
{
    unsigned long baud = 19200;
    if (argc > first && !parseNumber(shell, argv[first], dcos::app::kHighestModbusBaud, baud, "baud rate")) {
        return false;
    }
    dcos::app::ModbusParity parity = dcos::app::ModbusParity::Even;
    if (argc > first + 1) {
        const char* letter = argv[first + 1];
        if (letter[0] == 'n' && letter[1] == '\0') {
            parity = dcos::app::ModbusParity::None;
        } else if (letter[0] == 'o' && letter[1] == '\0') {
            parity = dcos::app::ModbusParity::Odd;
        } else if (!(letter[0] == 'e' && letter[1] == '\0')) {
            shell.print("error: parity '%s' is not n, e or o\r\n", letter);
            return false;
        }
    }
    settings = lineSettings(static_cast<uint32_t>(baud), parity);
    return true;
}

// The receiver's state ([SL] Figure 14): a test waits for "idle" before it
// puts a frame on the line, since a frame that starts before t3.5 of silence
// is ignored; the console's time is the controller's, so that wait holds in
// emulated time too.
const char* receiverStateName(modbus::RtuReceiver::State state)
{
    switch (state) {
    case modbus::RtuReceiver::State::Initial: return "initial";
    case modbus::RtuReceiver::State::Idle: return "idle";
    case modbus::RtuReceiver::State::Reception: return "reception";
    case modbus::RtuReceiver::State::ControlAndWaiting: return "control";
    }
    return "?";
}

const char* masterStateName(modbus::Master::State state)
{
    switch (state) {
    case modbus::Master::State::Idle: return "idle";
    case modbus::Master::State::WaitingToSend: return "waiting-to-send";
    case modbus::Master::State::Transmitting: return "transmitting";
    case modbus::Master::State::WaitingReply: return "waiting-reply";
    case modbus::Master::State::Turnaround: return "turnaround";
    }
    return "?";
}

CommandResult slave(shell::Shell& shell, int argc, char** argv)
{
    unsigned long address = 0;
    if (argc < 3 || !parseNumber(shell, argv[2], modbus::kMaxSlaveAddress, address, "slave address")
        || !parseLine(shell, argc, argv, 3, mailbox.settings)) {
        return CommandResult::UsageError;
    }
    mailbox.kind = CommandKind::StartSlave;
    mailbox.address = static_cast<uint8_t>(address);
    if (!runCommand(shell)) {
        return CommandResult::Failed;
    }
    shell.print("modbus: slave %lu on COM2 at %lu baud 8%c%u\r\n", address,
                static_cast<unsigned long>(mailbox.settings.baud), parityLetter(mailbox.settings.parity),
                mailbox.settings.stopBits);
    return CommandResult::Ok;
}

// master [baud] [parity] [time-out ms] [retries]
CommandResult master(shell::Shell& shell, int argc, char** argv)
{
    if (!parseLine(shell, argc, argv, 2, mailbox.settings)) {
        return CommandResult::UsageError;
    }
    mailbox.masterConfig = modbus::MasterConfig{};
    unsigned long value = 0;
    if (argc > 4) {
        if (!parseNumber(shell, argv[4], 60000, value, "time-out (ms)")) {
            return CommandResult::UsageError;
        }
        mailbox.masterConfig.responseTimeoutNs = value * kMillisecond;
    }
    if (argc > 5) {
        if (!parseNumber(shell, argv[5], modbus::MasterConfig::kMaxRetries, value, "retries")) {
            return CommandResult::UsageError;
        }
        mailbox.masterConfig.retries = static_cast<uint8_t>(value);
    }
    mailbox.kind = CommandKind::StartMaster;
    if (!runCommand(shell)) {
        return CommandResult::Failed;
    }
    shell.print("modbus: master on COM2 at %lu baud 8%c%u, time-out %lu ms, %u retries\r\n",
                static_cast<unsigned long>(mailbox.settings.baud), parityLetter(mailbox.settings.parity),
                mailbox.settings.stopBits,
                static_cast<unsigned long>(mailbox.masterConfig.responseTimeoutNs / kMillisecond),
                mailbox.masterConfig.retries);
    return CommandResult::Ok;
}

CommandResult off(shell::Shell& shell, int, char**)
{
    mailbox.kind = CommandKind::Stop;
    if (!lineTask.isNull() && !runCommand(shell)) {
        return CommandResult::Failed;
    }
    shell.print("modbus: off\r\n");
    return CommandResult::Ok;
}

CommandResult state(shell::Shell& shell, int, char**)
{
    const bsp::Uart16550& uart = bsp::rs485Uart();
    const Role role = runner.role();
    shell.print("modbus: %s", roleName(role));
    if (role == Role::Slave) {
        shell.print(" %u", runner.slave().address());
    }
    if (role != Role::Off) {
        shell.print(" on COM2 (0x%x, irq %u) at %lu baud 8%c%u, t1.5 %lu us, t3.5 %lu us, driver %s",
                    bsp::rs485PortAddress, bsp::rs485Line, static_cast<unsigned long>(uart.settings().baud),
                    parityLetter(uart.settings().parity), uart.settings().stopBits,
                    static_cast<unsigned long>(runner.timing().t15Ns / 1000),
                    static_cast<unsigned long>(runner.timing().t35Ns / 1000), uart.driverEnabled() ? "on" : "off");
    }
    shell.print("\r\n");
    if (role == Role::Slave) {
        if (servedApplication != nullptr) {
            shell.print("serving: the register map of application '%s', %u entries, backend failures %lu "
                        "(last: %s)\r\n",
                        servedApplication->name, static_cast<unsigned>(servedApplication->modbusMap.count),
                        static_cast<unsigned long>(nodeBackend.failures()),
                        dcos::statusName(nodeBackend.lastFailure()));
        } else {
            shell.print("serving: the console's data model\r\n");
        }
    }
    const LineCounters& line = runner.counters();
    const bsp::Uart16550::Statistics& errors = uart.statistics();
    shell.print("line: characters %lu frames-sent %lu refused %lu temt-polls %lu queue-overflows %lu "
                "uart-overruns %lu parity-errors %lu framing-errors %lu\r\n",
                static_cast<unsigned long>(line.charactersReceived), static_cast<unsigned long>(line.framesSent),
                static_cast<unsigned long>(line.transmitRefused), static_cast<unsigned long>(line.temtPolls),
                static_cast<unsigned long>(runner.queue().overflows()),
                static_cast<unsigned long>(errors.overrunErrors), static_cast<unsigned long>(errors.parityErrors),
                static_cast<unsigned long>(errors.framingErrors));
    const modbus::RtuReceiver::Counters& r = runner.transport().receiver().counters();
    shell.print("frames: seen %lu delivered %lu crc-errors %lu gap-errors %lu damaged %lu overruns %lu short %lu "
                "lost %lu ignored-characters %lu receiver %s\r\n",
                static_cast<unsigned long>(r.busMessages), static_cast<unsigned long>(r.framesDelivered),
                static_cast<unsigned long>(r.crcErrors), static_cast<unsigned long>(r.gapErrors),
                static_cast<unsigned long>(r.damagedFrames), static_cast<unsigned long>(r.overruns),
                static_cast<unsigned long>(r.shortFrames), static_cast<unsigned long>(r.framesLost),
                static_cast<unsigned long>(r.ignoredCharacters), receiverStateName(runner.transport().receiver().state()));
    const modbus::Slave::Counters& s = runner.slave().counters();
    shell.print("slave: messages %lu exceptions %lu no-responses %lu other-addresses %lu dropped %lu\r\n",
                static_cast<unsigned long>(s.messages), static_cast<unsigned long>(s.exceptions),
                static_cast<unsigned long>(s.noResponses), static_cast<unsigned long>(s.otherAddresses),
                static_cast<unsigned long>(s.droppedWhileSending));
    const modbus::Master::Counters& m = runner.master().counters();
    shell.print("master: transactions %lu transmissions %lu responses %lu exceptions %lu timeouts %lu "
                "invalid %lu failures %lu foreign %lu state %s\r\n",
                static_cast<unsigned long>(m.transactions), static_cast<unsigned long>(m.transmissions),
                static_cast<unsigned long>(m.responses), static_cast<unsigned long>(m.exceptions),
                static_cast<unsigned long>(m.timeouts), static_cast<unsigned long>(m.invalidResponses),
                static_cast<unsigned long>(m.failures), static_cast<unsigned long>(m.foreignFrames),
                masterStateName(runner.master().state()));
    return CommandResult::Ok;
}

bool sameText(const char* a, const char* b)
{
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return *a == *b;
}

// The four tables by name, as the commands below take them.
enum class Table : uint8_t { Coils, Inputs, Holding, InputRegisters };

bool parseTable(shell::Shell& shell, const char* text, Table& table)
{
    struct Name {
        const char* name;
        Table table;
    };
    constexpr Name kNames[] = {{"coils", Table::Coils},
                               {"inputs", Table::Inputs},
                               {"holding", Table::Holding},
                               {"input-registers", Table::InputRegisters}};
    for (const Name& name : kNames) {
        const char* a = name.name;
        const char* b = text;
        while (*a != '\0' && *a == *b) {
            ++a;
            ++b;
        }
        if (*a == '\0' && *b == '\0') {
            table = name.table;
            return true;
        }
    }
    shell.print("error: '%s' is not coils, inputs, holding or input-registers\r\n", text);
    return false;
}

// Whether read and write only submit their request ('modbus submit') and
// leave the wait for its end to 'modbus result'.
bool submitOnly = false;
// A transaction 'modbus submit' started whose end 'modbus result' has not
// yet shown: without one, result would wait for nothing or show an old end.
bool resultPending = false;

// Hands the mailbox's request to the line's task.
bool submitRequest(shell::Shell& shell)
{
    if (runner.role() != Role::Master) {
        shell.print("error: the line is not a master; start one with 'modbus master'\r\n");
        return false;
    }
    mailbox.kind = CommandKind::Submit;
    return runCommand(shell);
}

// Waits for the submitted transaction to end and prints how it ended.
CommandResult awaitCompletion(shell::Shell& shell)
{
    const modbus::MasterConfig& config = runner.master().config();
    const uint64_t longest = (config.responseTimeoutNs + 100 * kMillisecond) * (config.retries + 1u)
                             + config.turnaroundDelayNs + kCommandTimeoutNs;
    const uint64_t deadline = timerAgent.Uptime() + longest;
    while (!completionReady) {
        const uint64_t now = timerAgent.Uptime();
        if (now >= deadline) {
            shell.print("error: the transaction did not end within %lu ms\r\n",
                        static_cast<unsigned long>(longest / kMillisecond));
            return CommandResult::Failed;
        }
        (void)taskAgent.ReceiveEvent(kAnswerEvent, dcos::EventWait::Any, deadline - now);
    }
    const Completion& c = lastCompletion;
    if (c.error == ModbusError::ExceptionResponse) {
        shell.print("exception %02x %s\r\n", static_cast<unsigned>(c.exception), modbus::exceptionName(static_cast<uint8_t>(c.exception)));
        return CommandResult::Failed;
    }
    if (c.error != ModbusError::Ok) {
        shell.print("error: %s after %lu transmissions\r\n", modbus::modbusErrorName(c.error),
                    static_cast<unsigned long>(runner.master().counters().transmissions - transmissionsBefore));
        return CommandResult::Failed;
    }
    shell.print("ok %02x:", c.function);
    const modbus::ResponseView response(c.pdu, c.length);
    if (c.function == 0x03 || c.function == 0x04 || c.function == 0x17) {
        for (size_t i = 0; i < response.registerCount(); ++i) {
            shell.print(" %u", response.registerValue(i));
        }
    } else if (c.function == 0x01 || c.function == 0x02) {
        const unsigned count = mailbox.request.pdu[3] * 256u + mailbox.request.pdu[4];
        for (unsigned i = 0; i < count; ++i) {
            shell.print(" %u", response.bit(i) ? 1u : 0u);
        }
    } else {
        for (size_t i = 1; i < c.length; ++i) {
            shell.print(" %02x", c.pdu[i]);
        }
    }
    shell.print("\r\n");
    return CommandResult::Ok;
}

// Submits the request the console built (or says why it could not be
// built) and, unless only submitting, waits for the transaction to end.
CommandResult transactRequest(shell::Shell& shell, const modbus::ModbusResult<modbus::Request>& request)
{
    if (!request.ok()) {
        shell.print("error: %s\r\n", modbus::modbusErrorName(request.error()));
        return CommandResult::Failed;
    }
    mailbox.request = request.value();
    if (!submitRequest(shell)) {
        return CommandResult::Failed;
    }
    if (submitOnly) {
        resultPending = true;
        shell.print("submitted %02x to %u\r\n", mailbox.request.function(), mailbox.request.unit);
        return CommandResult::Ok;
    }
    return awaitCompletion(shell);
}

// read <unit> <table> <address> <count>
CommandResult read(shell::Shell& shell, int argc, char** argv)
{
    unsigned long unit = 0;
    unsigned long address = 0;
    unsigned long count = 0;
    Table table{};
    if (argc != 6 || !parseNumber(shell, argv[2], 255, unit, "unit") || !parseTable(shell, argv[3], table)
        || !parseNumber(shell, argv[4], 0xFFFF, address, "address")
        || !parseNumber(shell, argv[5], 0xFFFF, count, "count")) {
        return CommandResult::UsageError;
    }
    const uint8_t u = static_cast<uint8_t>(unit);
    const uint16_t a = static_cast<uint16_t>(address);
    const uint16_t n = static_cast<uint16_t>(count);
    modbus::ModbusResult<modbus::Request> request =
        table == Table::Coils      ? modbus::Request::readCoils(u, a, n)
        : table == Table::Inputs   ? modbus::Request::readDiscreteInputs(u, a, n)
        : table == Table::Holding  ? modbus::Request::readHoldingRegisters(u, a, n)
                                   : modbus::Request::readInputRegisters(u, a, n);
    return transactRequest(shell, request);
}

// write <unit> <coils|holding> <address> <value>...: one value is function
// 05 or 06, several are 0F or 10.
CommandResult write(shell::Shell& shell, int argc, char** argv)
{
    constexpr int kMostValues = 32;
    unsigned long unit = 0;
    unsigned long address = 0;
    Table table{};
    if (argc < 6 || argc > 5 + kMostValues || !parseNumber(shell, argv[2], 255, unit, "unit")
        || !parseTable(shell, argv[3], table) || !parseNumber(shell, argv[4], 0xFFFF, address, "address")) {
        return CommandResult::UsageError;
    }
    if (table != Table::Coils && table != Table::Holding) {
        shell.print("error: only coils and holding registers are written\r\n");
        return CommandResult::UsageError;
    }
    const int count = argc - 5;
    uint16_t values[kMostValues] = {};
    uint8_t bits[(kMostValues + 7) / 8] = {};
    for (int i = 0; i < count; ++i) {
        unsigned long value = 0;
        if (!parseNumber(shell, argv[5 + i], table == Table::Coils ? 1 : 0xFFFF, value, "value")) {
            return CommandResult::UsageError;
        }
        values[i] = static_cast<uint16_t>(value);
        modbus::setBit(bits, static_cast<size_t>(i), value != 0);
    }
    const uint8_t u = static_cast<uint8_t>(unit);
    const uint16_t a = static_cast<uint16_t>(address);
    const uint16_t n = static_cast<uint16_t>(count);
    modbus::ModbusResult<modbus::Request> request =
        table == Table::Coils ? (count == 1 ? modbus::Request::writeSingleCoil(u, a, values[0] != 0)
                                            : modbus::Request::writeMultipleCoils(u, a, n, bits))
                              : (count == 1 ? modbus::Request::writeSingleRegister(u, a, values[0])
                                            : modbus::Request::writeMultipleRegisters(u, a, n, values));
    return transactRequest(shell, request);
}

// data <table> <address> <count>: the console slave's own data, read here.
CommandResult data(shell::Shell& shell, int argc, char** argv)
{
    unsigned long address = 0;
    unsigned long count = 0;
    Table table{};
    if (argc != 5 || !parseTable(shell, argv[2], table) || !parseNumber(shell, argv[3], 255, address, "address")
        || !parseNumber(shell, argv[4], 64, count, "count") || count == 0 || address + count > 256) {
        return CommandResult::UsageError;
    }
    const uint16_t a = static_cast<uint16_t>(address);
    const uint16_t n = static_cast<uint16_t>(count);
    uint16_t values[64] = {};
    uint8_t bits[8] = {};
    const modbus::ExceptionCode result =
        table == Table::Coils     ? consoleModel.readCoils(a, n, bits)
        : table == Table::Inputs  ? consoleModel.readDiscreteInputs(a, n, bits)
        : table == Table::Holding ? consoleModel.readHoldingRegisters(a, n, values)
                                  : consoleModel.readInputRegisters(a, n, values);
    if (result != modbus::ExceptionCode::None) {
        shell.print("error: %s\r\n", modbus::exceptionName(static_cast<uint8_t>(result)));
        return CommandResult::Failed;
    }
    shell.print("data:");
    for (uint16_t i = 0; i < n; ++i) {
        shell.print(" %u", table == Table::Coils || table == Table::Inputs ? (modbus::getBit(bits, i) ? 1u : 0u)
                                                                            : static_cast<unsigned>(values[i]));
    }
    shell.print("\r\n");
    return CommandResult::Ok;
}

// submit read|write ...: the request of 'modbus read' or 'modbus write',
// submitted without waiting, so that the console stays free while the
// transaction runs (a test watches the line's state meanwhile).
CommandResult submit(shell::Shell& shell, int argc, char** argv)
{
    if (argc < 3) {
        return CommandResult::UsageError;
    }
    const bool isRead = sameText(argv[2], "read");
    if (!isRead && !sameText(argv[2], "write")) {
        shell.print("error: '%s' is not read or write\r\n", argv[2]);
        return CommandResult::UsageError;
    }
    // The subcommands take their arguments from argv[2] on, as 'modbus read ...' has them.
    submitOnly = true;
    const CommandResult result = isRead ? read(shell, argc - 1, argv + 1) : write(shell, argc - 1, argv + 1);
    submitOnly = false;
    return result;
}

// result: waits for the transaction 'modbus submit' started to end.
CommandResult result(shell::Shell& shell, int, char**)
{
    if (runner.role() != Role::Master) {
        shell.print("error: the line is not a master\r\n");
        return CommandResult::Failed;
    }
    if (!resultPending) {
        shell.print("error: no transaction was submitted; start one with 'modbus submit'\r\n");
        return CommandResult::Failed;
    }
    resultPending = false;
    return awaitCompletion(shell);
}

// poll: the application's polling schedule on the second RS-485 port.
CommandResult poll(shell::Shell& shell, int argc, char**)
{
    if (argc != 2) {
        return CommandResult::UsageError;
    }
    printPollStatus(shell);
    return CommandResult::Ok;
}

constexpr shell::Subcommand kSubcommands[] = {
    {"state", state}, {"slave", slave}, {"master", master}, {"off", off},
    {"read", read},   {"write", write}, {"data", data}, {"submit", submit}, {"result", result},
    {"poll", poll},
};

CommandResult modbusCommand(shell::Shell& shell, int argc, char** argv)
{
    if (argc == 1) {
        return state(shell, argc, argv);
    }
    return shell::runSubcommand(shell, argc, argv, kSubcommands);
}

// --- The application's slave, started at boot -------------------------------

using dcos::app::ConfigurationError;
using dcos::app::ConfigurationRule;
using dcos::app::ModbusMapEntry;
using dcos::app::ObjectKind;

bool namesBoardPoints(const dcos::app::DeclarationList<ModbusMapEntry>& map)
{
    for (const ModbusMapEntry& entry : map) {
        if (entry.source != dcos::app::ModbusSource::Publisher) {
            return true;
        }
    }
    return false;
}

// The publishers the master writes through the map: those bound to coils or
// holding registers (the rules allow only publishers without a writer task there).
bool mapWritesPublisher(const ModbusMapEntry& entry)
{
    return entry.source == dcos::app::ModbusSource::Publisher && dcos::app::rules::isWritable(entry.table);
}

// Installs and opens the line's own I/O board object (the board the
// console's `iobus` commands also reach, as "mfio0", which then finds its
// resources taken and says so).
dcos::Result<ObjectId> openMapBoard()
{
    iobus::IsaConflict conflict{};
    const dcos::Result<ObjectId> installed =
        mapBoard.installed() ? dcos::Result<ObjectId>(mapBoard.id())
                             : mapBoard.install("modbus.io", dcos::Visibility::Local, &conflict);
    if (!installed.ok()) {
        return installed.status();
    }
    const Status opened = dcos::systemAgent.Open(installed.value());
    if (opened != Status::Ok) {
        (void)mapBoard.uninstall();
        return opened;
    }
    return installed.value();
}

ConfigurationError startApplicationSlave(const dcos::app::Application& application)
{
    const dcos::app::ModbusSlaveDeclaration& declared = application.modbusSlave;
    if (declared.address == 0) {
        return {};
    }
    if (const Status started = startLineTask(); started != Status::Ok) {
        return refusedBy(application, ObjectKind::ModbusSlave, started);
    }
    if (const Status handed = handOverPublishers(application.modbusMap, mapWritesPublisher, lineTask);
        handed != Status::Ok) {
        return refusedBy(application, ObjectKind::ModbusSlave, handed);
    }
    ObjectId board{};
    if (namesBoardPoints(application.modbusMap)) {
        const dcos::Result<ObjectId> opened = openMapBoard();
        if (!opened.ok()) {
            return refusedBy(application, ObjectKind::ModbusSlave, opened.status());
        }
        board = opened.value();
    }
    const bsp::UartSettings settings = lineSettings(declared.baud, declared.parity);
    const modbus::ModbusResult<modbus::RtuTiming> timing =
        modbus::RtuTiming::make(settings.baud, static_cast<uint8_t>(settings.characterBits()));
    // The rules keep the baud rate in RtuTiming's range; a refusal here is the port's.
    Status status = timing.ok() ? startPort(settings) : Status::InvalidArgument;
    if (status == Status::Ok) {
        nodeBackend.useBoard(board);
        applicationModel.serve(application.modbusMap);
        applicationIdentification.userApplicationName = application.name;
        const ModbusError error = runner.startSlave(timing.value(), applicationModel, applicationIdentification,
                                                    static_cast<uint8_t>(declared.address), timerAgent.Uptime());
        status = error == ModbusError::Ok ? Status::Ok : modbus::toStatus(error);
    }
    if (status != Status::Ok) {
        stopPort();
        if (!board.isNull()) {
            (void)dcos::systemAgent.Close(board);
            (void)mapBoard.uninstall();
        }
        return refusedBy(application, ObjectKind::ModbusSlave, status);
    }
    servedApplication = &application;
    startedFor = &application;
    return {};
}

void stopApplicationSlave(const dcos::app::Application& application)
{
    if (startedFor != &application) {
        return;
    }
    if (servedApplication == &application) {
        stopPort(); // A line the console took over by hand stays as it is.
        servedApplication = nullptr;
    }
    startedFor = nullptr;
    nodeBackend.requestClose();
    if (mapBoard.installed()) {
        (void)dcos::systemAgent.Close(mapBoard.id());
        (void)mapBoard.uninstall();
    }
    (void)taskAgent.PostEvent(lineTask, kCommandEvent);
}

DCOS_APPLICATION_SERVICE(modbusApplicationService, "modbus", startApplicationSlave, stopApplicationSlave);

} // namespace


} // namespace mbline

DCOS_SHELL_COMMAND_DETAILED(modbusShellCommand, "modbus", "run the Modbus RTU line on the RS-485 port (COM2)",
                            "modbus [state] | slave <address> [baud] [n|e|o] | master [baud] [n|e|o] [time-out ms] "
                            "[retries] | off | read <unit> <table> <address> <count> | "
                            "write <unit> <coils|holding> <address> <value>... | submit read|write ... | result | "
                            "data <table> <address> <count> | poll",
                            "  tables: coils, inputs, holding, input-registers; the line is 19200 baud 8E1 unless\r\n"
                            "  told; state shows the line's, the receiver's, the slave's and the master's counters;\r\n"
                            "  data shows what the console slave serves (input register n is 0x1000 + n,\r\n"
                            "  discrete input n is on for multiples of 3); submit starts a read or write without\r\n"
                            "  waiting for it, result waits for its end; poll shows the application's polling schedule\r\n"
                            "  on the second RS-485 port (COM3), one line per entry",
                            mbline::modbusCommand);
