// An application whose Modbus register map the controller's slave serves
// from boot on (tests_renode/test_modbus_application.py).
//
// The master writes the "command" publisher (holding registers 0-3 and coils
// 0-7), which has no writer task, so the Modbus line is its single writer;
// the "control" task subscribes to it and every 10 ms publishes "process"
// from what it read: input register 0 is command register 0 plus 1000,
// input register 1 is command register 1 times two, input registers 2-3 the
// task's cycle count, and discrete inputs 0-7 echo coils 0-7. So a test
// sees a write land where the application reads it (the `mbmap` command
// prints what the task read) and reads back what the application
// publishes. Input registers 10-13 are the command page read only, input
// registers 100-101 the I/O board's analog inputs 0-1, and coils 100-103
// its digital outputs 0-3.
#include <bsp/Board.hpp>
#include <dcos/Application.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <runtime/Format.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr uint64_t kPeriodNs = 10'000'000;

dcos::ObjectId commandPublisher;
dcos::ObjectId processPublisher;

// What the control task read last, for the console command. Written by the
// task alone and read whole-word by the console, so no field is torn.
struct Seen {
    volatile uint32_t command0 = 0;
    volatile uint32_t command1 = 0;
    volatile uint32_t enable = 0;
    volatile uint32_t updates = 0; // Pages of "command" the task received.
    volatile uint32_t cycles = 0;
    volatile uint32_t errors = 0;  // Refusals of Open, Read or Write.
    volatile uint32_t lastError = 0;
};
Seen seen;

uint16_t registerAt(const dcos::DsmPage& page, unsigned index)
{
    // Registers are high byte first in the page, as on the wire (docs/protocols/modbus.md).
    return static_cast<uint16_t>((page.bytes[2 * index] << 8) | page.bytes[2 * index + 1]);
}

void putRegister(dcos::DsmPage& page, unsigned index, uint16_t value)
{
    page.bytes[2 * index] = static_cast<uint8_t>(value >> 8);
    page.bytes[2 * index + 1] = static_cast<uint8_t>(value);
}

void failed(Status status)
{
    seen.errors = seen.errors + 1;
    seen.lastError = static_cast<uint32_t>(status);
}

void control(uintptr_t)
{
    const Result<ObjectId> subscription = dcos::dsmAgent.Open(commandPublisher);
    if (!subscription.ok()) {
        failed(subscription.status());
        return;
    }
    dcos::DsmPage command{};
    uint32_t lastDataId = dcos::kNoDsmData;
    for (uint32_t cycle = 1;; ++cycle) {
        // A new command page when the master wrote one, else the last one.
        dcos::DsmPage newer{};
        const Result<uint32_t> read = dcos::dsmAgent.Read(subscription.value(), lastDataId, newer, dcos::kPoll);
        if (read.ok()) {
            command = newer;
            lastDataId = read.value();
            seen.updates = seen.updates + 1;
        } else if (read.status() != Status::WouldBlock) {
            failed(read.status());
        }
        seen.command0 = registerAt(command, 0);
        seen.command1 = registerAt(command, 1);
        seen.enable = command.bytes[8];
        dcos::DsmPage process{};
        putRegister(process, 0, static_cast<uint16_t>(registerAt(command, 0) + 1000));
        putRegister(process, 1, static_cast<uint16_t>(registerAt(command, 1) * 2));
        putRegister(process, 2, static_cast<uint16_t>(cycle >> 16));
        putRegister(process, 3, static_cast<uint16_t>(cycle));
        process.bytes[8] = command.bytes[8];
        if (const Result<uint32_t> written = dcos::dsmAgent.Write(processPublisher, process); !written.ok()) {
            failed(written.status());
        }
        seen.cycles = cycle;
        (void)dcos::taskAgent.SleepFor(kPeriodNs);
    }
}

shell::CommandResult mbmapCommand(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    shell.print("mbmap: command %lu %lu enable 0x%02lx updates %lu cycles %lu errors %lu (last status %lu)\r\n",
                static_cast<unsigned long>(seen.command0), static_cast<unsigned long>(seen.command1),
                static_cast<unsigned long>(seen.enable), static_cast<unsigned long>(seen.updates),
                static_cast<unsigned long>(seen.cycles), static_cast<unsigned long>(seen.errors),
                static_cast<unsigned long>(seen.lastError));
    return shell::CommandResult::Ok;
}

using dcos::app::ModbusSource;
using dcos::app::ModbusTable;

constexpr dcos::app::TaskDeclaration tasks[] = {
    {.name = "control", .entry = control, .priority = 8},
};
constexpr dcos::app::PublisherDeclaration publishers[] = {
    {.name = "command", .id = &commandPublisher},                       // no writer: the Modbus master writes it
    {.name = "process", .writer = "control", .id = &processPublisher},  // the application's; Modbus reads it
};
constexpr dcos::app::ModbusMapEntry map[] = {
    {.name = "command", .table = ModbusTable::HoldingRegisters, .address = 0, .count = 4, .object = "command"},
    {.name = "enable", .table = ModbusTable::Coils, .address = 0, .count = 8, .object = "command", .offset = 8},
    {.name = "process", .table = ModbusTable::InputRegisters, .address = 0, .count = 4, .object = "process"},
    {.name = "status", .table = ModbusTable::DiscreteInputs, .address = 0, .count = 8, .object = "process",
     .offset = 8},
    {.name = "echo", .table = ModbusTable::InputRegisters, .address = 10, .count = 4, .object = "command"},
    {.name = "ai", .table = ModbusTable::InputRegisters, .address = 100, .count = 2,
     .source = ModbusSource::AnalogInput},
    {.name = "do", .table = ModbusTable::Coils, .address = 100, .count = 4, .source = ModbusSource::DigitalOutput},
};

} // namespace

DCOS_SHELL_COMMAND(mbmapShellCommand, "mbmap", "what the mapped application's control task read last", "mbmap",
                   mbmapCommand);

DCOS_APPLICATION(mbmap, {.name = "mbmap",
                         .tasks = tasks,
                         .publishers = publishers,
                         .modbusMap = map,
                         .modbusSlave = {.address = 17, .baud = 19200},
                         .tickRateHz = 10000});
