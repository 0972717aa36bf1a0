// An application whose polling schedule the controller's master runs on the
// second RS-485 port (COM3) from boot on (tests_renode/test_modbus_polling.py).
//
// Slave 17 is the test's pymodbus slave, with the tables of
// tests_renode/modbus/pymodbus_slave.py. The schedule reads each of its
// four tables into the "read" publisher, writes holding registers 50-51 and
// coils 60-63 from the application's "out" publisher and reads them back
// into "echo", and reads slave 99, which no one is, and an input register
// slave 17 does not have (exception 02) into "ghost", which therefore stays
// all zero. The
// "app" task writes "out" every 50 ms and counts its cycles, so a test sees
// the application go on while a slave does not answer; the `pages` command
// prints the pages it reads and its cycle count.
#include <dcos/Application.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

constexpr uint64_t kPeriodNs = 50'000'000;
// What "out" holds: holding registers 0x1234 and 0x5678, coils 1, 1, 0, 1.
constexpr dcos::DsmPage kOut{{0x12, 0x34, 0x56, 0x78, 0x0B}};

ObjectId readPublisher;
ObjectId echoPublisher;
ObjectId ghostPublisher;
ObjectId outPublisher;

// The pages the task read last and its counts, for the console.
dcos::DsmPage pages[3];
volatile uint32_t cycles = 0;
volatile uint32_t failures = 0;

void app(uintptr_t)
{
    const ObjectId publishers[3] = {readPublisher, echoPublisher, ghostPublisher};
    ObjectId subscriptions[3];
    for (int i = 0; i < 3; ++i) {
        const Result<ObjectId> opened = dcos::dsmAgent.Open(publishers[i]);
        if (!opened.ok()) {
            failures = failures + 1;
            return;
        }
        subscriptions[i] = opened.value();
    }
    uint32_t seen[3] = {dcos::kNoDsmData, dcos::kNoDsmData, dcos::kNoDsmData};
    for (;;) {
        if (!dcos::dsmAgent.Write(outPublisher, kOut).ok()) {
            failures = failures + 1;
        }
        for (int i = 0; i < 3; ++i) {
            dcos::DsmPage page{};
            const Result<uint32_t> read = dcos::dsmAgent.Read(subscriptions[i], seen[i], page, dcos::kPoll);
            if (read.ok()) {
                seen[i] = read.value();
                pages[i] = page;
            } else if (read.status() != Status::WouldBlock) {
                failures = failures + 1;
            }
        }
        cycles = cycles + 1;
        (void)dcos::taskAgent.SleepFor(kPeriodNs);
    }
}

shell::CommandResult pagesCommand(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const char* names[3] = {"read", "echo", "ghost"};
    for (int i = 0; i < 3; ++i) {
        shell.print("%s:", names[i]);
        for (uint8_t byte : pages[i].bytes) {
            shell.print(" %02x", byte);
        }
        shell.print("\r\n");
    }
    shell.print("app: cycles %lu failures %lu\r\n", static_cast<unsigned long>(cycles),
                static_cast<unsigned long>(failures));
    return shell::CommandResult::Ok;
}

using dcos::app::ModbusTable;

constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "app", .entry = app, .priority = 8}};
constexpr dcos::app::PublisherDeclaration publishers[] = {
    {.name = "read", .id = &readPublisher},   // the polling line's
    {.name = "echo", .id = &echoPublisher},   // the polling line's
    {.name = "ghost", .id = &ghostPublisher}, // the polling line's, never written: slave 99 is absent
    {.name = "out", .writer = "app", .id = &outPublisher},
};
constexpr dcos::app::ModbusPollEntry polls[] = {
    {.name = "coils", .unit = 17, .table = ModbusTable::Coils, .address = 0, .count = 16, .periodMs = 200,
     .object = "read", .offset = 0},
    {.name = "inputs", .unit = 17, .table = ModbusTable::DiscreteInputs, .address = 0, .count = 16, .periodMs = 200,
     .object = "read", .offset = 2},
    {.name = "holding", .unit = 17, .table = ModbusTable::HoldingRegisters, .address = 10, .count = 2,
     .periodMs = 200, .object = "read", .offset = 4},
    {.name = "input-regs", .unit = 17, .table = ModbusTable::InputRegisters, .address = 3, .count = 2,
     .periodMs = 200, .object = "read", .offset = 8},
    {.name = "w-holding", .unit = 17, .table = ModbusTable::HoldingRegisters, .write = true, .address = 50,
     .count = 2, .periodMs = 200, .object = "out", .offset = 0},
    {.name = "w-coils", .unit = 17, .table = ModbusTable::Coils, .write = true, .address = 60, .count = 4,
     .periodMs = 200, .object = "out", .offset = 4},
    {.name = "r-holding", .unit = 17, .table = ModbusTable::HoldingRegisters, .address = 50, .count = 2,
     .periodMs = 200, .object = "echo", .offset = 0},
    {.name = "r-coils", .unit = 17, .table = ModbusTable::Coils, .address = 60, .count = 4, .periodMs = 200,
     .object = "echo", .offset = 4},
    {.name = "ghost", .unit = 99, .table = ModbusTable::HoldingRegisters, .address = 0, .count = 1,
     .periodMs = 1000, .object = "ghost"},
    {.name = "beyond", .unit = 17, .table = ModbusTable::InputRegisters, .address = 150, .count = 1,
     .periodMs = 1000, .object = "ghost", .offset = 2},
};

} // namespace

DCOS_SHELL_COMMAND(pagesShellCommand, "pages", "the pages the polling application read last", "pages",
                   pagesCommand);

DCOS_APPLICATION(polling, {.name = "polling",
                           .tasks = tasks,
                           .publishers = publishers,
                           .modbusPolls = polls,
                           .modbusMaster = {.baud = 19200, .timeoutMs = 1000, .retries = 2},
                           .tickRateHz = 10000});
