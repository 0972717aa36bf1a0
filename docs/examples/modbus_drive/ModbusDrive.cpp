// A controller between a plant's Modbus master and a Modbus drive.
//
// The controller polls a variable-speed drive on its second RS-485 port
// (COM3) and serves its own process values to the plant's master on its
// first (COM2), both declared below and started by the kernel at boot:
//
//   plant master --COM2--> [slave 1: the map] --DSM--> control --DSM--> [poll schedule] --COM3--> drive 17
//
// - The plant master writes a speed request (holding register 0) and a run
//   command (coil 0) into the "request" publisher, which the slave's line
//   writes.
// - The "control" task, every 50 ms, reads "request" and the drive's values
//   ("drive", which the polling line publishes), limits the speed request
//   to what the drive may run at, and publishes "command" (what the poll
//   schedule writes to the drive) and "process" (what the map serves back).
// - The schedule reads the drive's speed and motor temperature (input
//   registers 0-1) and its at-speed flag (discrete input 0) every 250 ms,
//   and writes the setpoint (holding register 0) and the run coil (coil 0)
//   every 250 ms; an answer has 1 s to come, and a request is sent twice
//   at most.
//
// A drive that stops answering is noticed by the data identifier of
// "drive", which the polling line advances only on a good answer: after
// kStaleCycles cycles without one, the control task clears the
// "drive answering" status bit the plant master reads, counts the loss,
// and goes on; the console's `modbus poll` names the time-outs. The drive is
// dcos-modbus-sim with host_tools/modbus/examples/drive.toml (slave 17).
#include "ModbusDrive.hpp"

#include <dcos/Application.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>

namespace drive {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;

ObjectId requestPublisher;
ObjectId drivePublisher;
ObjectId commandPublisher;
ObjectId processPublisher;

uint16_t registerAt(const dcos::DsmPage& page, unsigned byte)
{
    // Registers are high byte first in a page, as on the wire (docs/protocols/modbus.md).
    return static_cast<uint16_t>((page.bytes[byte] << 8) | page.bytes[byte + 1]);
}

void putRegister(dcos::DsmPage& page, unsigned byte, uint16_t value)
{
    page.bytes[byte] = static_cast<uint8_t>(value >> 8);
    page.bytes[byte + 1] = static_cast<uint8_t>(value);
}

// The latest page of a subscription: a new one when there is one, the last
// one otherwise. Returns whether a new one came, and counts a refusal.
bool readLatest(ObjectId subscription, uint32_t& lastSeen, dcos::DsmPage& page, Status& failure)
{
    dcos::DsmPage newer{};
    const Result<uint32_t> read = dcos::dsmAgent.Read(subscription, lastSeen, newer, dcos::kPoll);
    if (read.ok()) {
        page = newer;
        lastSeen = read.value();
        return true;
    }
    if (read.status() != Status::WouldBlock) {
        failure = read.status();
    }
    return false;
}

void control(uintptr_t)
{
    const Result<ObjectId> requests = dcos::dsmAgent.Open(requestPublisher);
    const Result<ObjectId> drives = dcos::dsmAgent.Open(drivePublisher);
    if (!requests.ok() || !drives.ok()) {
        state.lastFailure = static_cast<uint32_t>(!requests.ok() ? requests.status() : drives.status());
        state.failures = state.failures + 1;
        return;
    }
    dcos::DsmPage request{};
    dcos::DsmPage measured{};
    uint32_t requestSeen = dcos::kNoDsmData;
    uint32_t driveSeen = dcos::kNoDsmData;
    uint32_t staleCycles = kStaleCycles; // Not answering until the first answer.
    for (;;) {
        Status failure = Status::Ok;
        (void)readLatest(requests.value(), requestSeen, request, failure);
        if (readLatest(drives.value(), driveSeen, measured, failure)) {
            staleCycles = 0;
            state.drivePages = state.drivePages + 1;
        } else if (staleCycles < kStaleCycles) {
            ++staleCycles;
            if (staleCycles == kStaleCycles) {
                state.losses = state.losses + 1;
            }
        }
        const bool answering = staleCycles < kStaleCycles;
        const uint16_t requested = registerAt(request, kRequestSpeedByte);
        const bool run = (request.bytes[kRequestRunByte] & 1) != 0;
        const uint16_t setpoint = requested > kMaximumSpeedRpm ? kMaximumSpeedRpm : requested;

        dcos::DsmPage command{};
        putRegister(command, kCommandSetpointByte, setpoint);
        command.bytes[kCommandRunByte] = run ? 1 : 0;
        dcos::DsmPage process{};
        putRegister(process, kProcessSpeedByte, registerAt(measured, kDriveSpeedByte));
        putRegister(process, kProcessTemperatureByte, registerAt(measured, kDriveTemperatureByte));
        putRegister(process, kProcessSetpointByte, setpoint);
        const bool atSpeed = (measured.bytes[kDriveFlagsByte] & 1) != 0;
        process.bytes[kProcessFlagsByte] = static_cast<uint8_t>((atSpeed && answering ? 1 : 0) | (answering ? 2 : 0));
        const Result<uint32_t> commanded = dcos::dsmAgent.Write(commandPublisher, command);
        const Result<uint32_t> published = dcos::dsmAgent.Write(processPublisher, process);
        if (!commanded.ok() || !published.ok()) {
            failure = !commanded.ok() ? commanded.status() : published.status();
        }
        if (failure != Status::Ok) {
            state.failures = state.failures + 1;
            state.lastFailure = static_cast<uint32_t>(failure);
        }
        state.requested = requested;
        state.run = run ? 1 : 0;
        state.setpoint = setpoint;
        state.speed = registerAt(measured, kDriveSpeedByte);
        state.temperature = registerAt(measured, kDriveTemperatureByte);
        state.atSpeed = atSpeed ? 1 : 0;
        state.answering = answering ? 1 : 0;
        state.cycles = state.cycles + 1;
        (void)dcos::taskAgent.SleepFor(kPeriodNs);
    }
}

using dcos::app::ModbusTable;

constexpr dcos::app::TaskDeclaration tasks[] = {
    {.name = "control", .entry = control, .priority = 8},
};
constexpr dcos::app::PublisherDeclaration publishers[] = {
    {.name = "request", .id = &requestPublisher},                      // written by the slave's line (COM2)
    {.name = "drive", .id = &drivePublisher},                          // written by the polling line (COM3)
    {.name = "command", .writer = "control", .id = &commandPublisher}, // the control task's, sent to the drive
    {.name = "process", .writer = "control", .id = &processPublisher}, // the control task's, served to the plant
};

// What the plant's master sees (slave 1 on COM2).
constexpr dcos::app::ModbusMapEntry map[] = {
    {.name = "speed-request", .table = ModbusTable::HoldingRegisters, .address = 0, .count = 1, .object = "request",
     .offset = kRequestSpeedByte},
    {.name = "run", .table = ModbusTable::Coils, .address = 0, .count = 1, .object = "request",
     .offset = kRequestRunByte},
    {.name = "process", .table = ModbusTable::InputRegisters, .address = 0, .count = 3, .object = "process",
     .offset = kProcessSpeedByte},
    {.name = "status", .table = ModbusTable::DiscreteInputs, .address = 0, .count = 2, .object = "process",
     .offset = kProcessFlagsByte},
};

// What the controller asks of the drive (slave 17 on COM3).
constexpr dcos::app::ModbusPollEntry polls[] = {
    {.name = "drive-values", .unit = kDriveUnit, .table = ModbusTable::InputRegisters, .address = 0, .count = 2,
     .periodMs = 250, .object = "drive", .offset = kDriveSpeedByte},
    {.name = "at-speed", .unit = kDriveUnit, .table = ModbusTable::DiscreteInputs, .address = 0, .count = 1,
     .periodMs = 250, .object = "drive", .offset = kDriveFlagsByte},
    {.name = "setpoint", .unit = kDriveUnit, .table = ModbusTable::HoldingRegisters, .write = true, .address = 0,
     .count = 1, .periodMs = 250, .object = "command", .offset = kCommandSetpointByte},
    {.name = "run", .unit = kDriveUnit, .table = ModbusTable::Coils, .write = true, .address = 0, .count = 1,
     .periodMs = 250, .object = "command", .offset = kCommandRunByte},
};

} // namespace

DriveState state;

} // namespace drive

DCOS_APPLICATION(modbusDrive, {.name = "modbus_drive",
                               .tasks = drive::tasks,
                               .publishers = drive::publishers,
                               .modbusMap = drive::map,
                               .modbusSlave = {.address = drive::kControllerUnit, .baud = 19200},
                               .modbusPolls = drive::polls,
                               .modbusMaster = {.baud = 19200, .timeoutMs = 1000, .retries = 1},
                               .tickRateHz = 10000});
