// The declarations an application's configuration is made of (seed 8.2).
//
// Applications include dcos/Application.hpp, which adds the compile-time
// checks and DCOS_APPLICATION; the rules (ConfigurationRules.hpp) and the
// loader need only these types.
#pragma once

#include <dcos/MessagePortAgent.hpp>
#include <dcos/ObjectId.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/Visibility.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::app {

/// A task the loader creates (TaskAgent::Create).
struct TaskDeclaration {
    const char* name = nullptr;    ///< Required, 1 to 15 characters, unique among tasks.
    TaskEntry entry = nullptr;     ///< Required.
    uint8_t priority = 16;         ///< 0 (highest) to 31 (lowest).
    size_t stackSize = 4096;       ///< At least kMinimumStackSize bytes.
    uintptr_t argument = 0;        ///< Passed to entry.
    bool timeSlicing = false;
    bool floatingPoint = false;    ///< Save and restore the FPU for this task.
    bool superUser = false;        ///< May use privileged services (AddObjects, devices).
    Visibility visibility = Visibility::Local;
    ObjectId* id = nullptr;        ///< Optional: receives the task's id before any task runs.

    /// The attributes TaskAgent::Create takes for this declaration; every
    /// root task (the loader of either kernel configuration) creates from them.
    TaskAttributes attributes() const
    {
        TaskAttributes made;
        made.name = name;
        made.priority = priority;
        made.stackSize = stackSize;
        made.timeSlicing = timeSlicing;
        made.floatingPoint = floatingPoint;
        made.superUser = superUser;
        made.visibility = visibility;
        return made;
    }
};

/// A semaphore the loader creates (SemaphoreAgent::Create).
struct SemaphoreDeclaration {
    const char* name = nullptr;
    SemaphoreKind kind = SemaphoreKind::Binary;
    uint32_t initialCount = 1;     ///< 0 or 1 for a binary semaphore; at most maximumCount.
    uint32_t maximumCount = 0xFFFFFFFF;
    bool priorityInheritance = false; ///< Binary semaphores only.
    WaitOrder order = WaitOrder::Priority;
    Visibility visibility = Visibility::Local;
    const char* owner = nullptr;   ///< A declared task, or null for the system.
    ObjectId* id = nullptr;
};

/// A message port the loader creates and hands to its receiver.
struct MessagePortDeclaration {
    const char* name = nullptr;
    const char* receiver = nullptr; ///< Required: the declared task that receives from it.
    PortOrder order = PortOrder::Priority;
    Visibility visibility = Visibility::Local;
    ObjectId* id = nullptr;
};

/// A distributed shared memory publisher the loader creates and hands to its writer.
struct PublisherDeclaration {
    const char* name = nullptr;
    const char* writer = nullptr;  ///< A declared task, or null for the system (interrupt handlers).
    Visibility visibility = Visibility::Local;
    ObjectId* id = nullptr;
};

/// A buffer pool over an area the application provides (BufferPoolAgent::Create).
struct BufferPoolDeclaration {
    const char* name = nullptr;
    void* area = nullptr;          ///< Required: static storage, e.g. sized with BufferPoolAgent::AreaBytes.
    size_t areaBytes = 0;
    size_t bufferSize = 0;         ///< At least BufferPoolAgent::kMinimumBufferSize.
    Visibility visibility = Visibility::Local;
    const char* owner = nullptr;   ///< A declared task, or null for the system.
    ObjectId* id = nullptr;
};

/// A segmented heap over an area the application provides (HeapAgent::Create).
struct HeapDeclaration {
    const char* name = nullptr;
    void* area = nullptr;          ///< Required: static storage.
    size_t areaBytes = 0;
    Visibility visibility = Visibility::Local;
    const char* owner = nullptr;   ///< A declared task, or null for the system.
    ObjectId* id = nullptr;
};

/// The four tables a Modbus slave serves ([AP] 4.3). Coils and holding
/// registers are written by the master; discrete inputs and input registers
/// only read.
enum class ModbusTable : uint8_t {
    Coils,
    DiscreteInputs,
    HoldingRegisters,
    InputRegisters,
};

/// What a Modbus register map entry serves.
enum class ModbusSource : uint8_t {
    /// Bytes of a declared DSM publisher's page, from `offset` on: registers
    /// two bytes each, high byte first as on the wire; bits packed from bit 0
    /// of byte `offset`. A publisher with no writer is written by the
    /// Modbus line (the application subscribes to it and reads what the
    /// master wrote); a publisher with a writer task is the application's,
    /// which Modbus only reads.
    Publisher,
    /// Analog input channels of the I/O board in raw counts, from channel
    /// `offset` on, one register each. Read-only.
    AnalogInput,
    /// Digital outputs of the I/O board, from output `offset` on, one bit
    /// each. Written by the master through coils.
    DigitalOutput,
};

/// The I/O board's points a map can reach (drivers/iobus: MfioRegisters.hpp's
/// kAnalogInputs and kDigitalBits, checked equal in MfioBoard.hpp).
constexpr uint32_t kModbusAnalogInputPoints = 8;
constexpr uint32_t kModbusDigitalOutputPoints = 16;

/// One range of a Modbus slave's addresses bound to a DCOS object; the
/// application's `modbusMap` lists them. The compiler and the loader check
/// them; the controller's RS-485 line serves them from boot on when the
/// application also declares its `modbusSlave` (drivers/modbus).
struct ModbusMapEntry {
    const char* name = nullptr;    ///< Required, 1 to 15 characters, unique in the map; errors name it.
    ModbusTable table = ModbusTable::HoldingRegisters;
    uint32_t address = 0;          ///< The first address, 0 to 65535.
    uint32_t count = 1;            ///< Registers or bits; address + count - 1 at most 65535.
    ModbusSource source = ModbusSource::Publisher;
    const char* object = nullptr;  ///< Publisher: the declared publisher's name; unused for the I/O board.
    uint32_t offset = 0;           ///< Publisher: the first byte in its page; I/O board: the first channel.
};

/// The parity of a Modbus serial line ([SL] 2.5.1: even by default; no
/// parity takes a second stop bit, so that a character stays 11 bits).
enum class ModbusParity : uint8_t {
    Even,
    Odd,
    None,
};

/// The lowest and highest baud rates of a declared Modbus line: what the
/// 16550's divisor reaches from 1.8432 MHz with an error the line tolerates,
/// the same range the `modbus` console command takes.
constexpr uint32_t kLowestModbusBaud = 300;
constexpr uint32_t kHighestModbusBaud = 115200;

/// The controller's Modbus slave on its RS-485 port, which serves the
/// application's `modbusMap` from boot on. An application that declares no
/// address (0) has no slave at boot; the console's `modbus slave` still
/// starts one by hand.
struct ModbusSlaveDeclaration {
    uint32_t address = 0;          ///< The slave's address, 1 to 247 ([SL] 2.2); 0: none.
    uint32_t baud = 19200;         ///< kLowestModbusBaud to kHighestModbusBaud.
    ModbusParity parity = ModbusParity::Even;
};

/// One request the controller's Modbus master sends a slave periodically,
/// on the board's second RS-485 port; the application's `modbusPolls`
/// lists them (run by fieldbus/modbus's PollSchedule, drivers/modbus).
///
/// A read (function 01, 02, 03 or 04 by `table`) publishes what the slave
/// answered on the publisher `object`, from byte `offset` on, laid out as a
/// map entry's bytes (registers two bytes each, high byte first; bits
/// packed from bit 0); the publisher has no writer task, the master's line
/// is its writer, and the application subscribes to it. A write (0F for
/// coils, 10 for holding registers) sends the slave those bytes of the
/// publisher `object`, as they are when the request is due; any declared
/// publisher will do (the application's, typically).
struct ModbusPollEntry {
    const char* name = nullptr;    ///< Required, 1 to 15 characters, unique in the schedule; errors name it.
    uint32_t unit = 1;             ///< The slave's address, 1 to 247.
    ModbusTable table = ModbusTable::HoldingRegisters;
    bool write = false;            ///< Write the slave's coils or holding registers rather than read.
    uint32_t address = 0;          ///< The slave's first address, 0 to 65535.
    uint32_t count = 1;            ///< Registers or bits; they fit in the page from `offset`.
    uint32_t periodMs = 100;       ///< How often, 1 ms to one hour; due times do not drift.
    const char* object = nullptr;  ///< A declared publisher's name.
    uint32_t offset = 0;           ///< The first byte in its page.
};

/// The controller's Modbus master on its second RS-485 port, which runs the
/// application's `modbusPolls` from boot on.
struct ModbusMasterDeclaration {
    uint32_t baud = 19200;         ///< kLowestModbusBaud to kHighestModbusBaud.
    ModbusParity parity = ModbusParity::Even;
    uint32_t timeoutMs = 1000;     ///< A response's time-out, 1 to 60000 ms.
    uint32_t retries = 2;          ///< Transmissions after the first, 0 to 15.
};

/// The declared task an object is handed to: its owner, a port's receiver,
/// a publisher's writer. Null: the object stays the system's. (The loader
/// never hands a task over.)
constexpr const char* ownerOf(const TaskDeclaration&) { return nullptr; }
constexpr const char* ownerOf(const SemaphoreDeclaration& declaration) { return declaration.owner; }
constexpr const char* ownerOf(const MessagePortDeclaration& declaration) { return declaration.receiver; }
constexpr const char* ownerOf(const PublisherDeclaration& declaration) { return declaration.writer; }
constexpr const char* ownerOf(const BufferPoolDeclaration& declaration) { return declaration.owner; }
constexpr const char* ownerOf(const HeapDeclaration& declaration) { return declaration.owner; }

/// A read-only view of a constexpr array of declarations.
template <class Declaration>
struct DeclarationList {
    const Declaration* items = nullptr;
    size_t count = 0;

    constexpr DeclarationList() = default;
    template <size_t N>
    constexpr DeclarationList(const Declaration (&array)[N]) : items(array), count(N)
    {
    }
    constexpr DeclarationList(const Declaration* first, size_t length) : items(first), count(length) {}

    constexpr const Declaration& operator[](size_t index) const { return items[index]; }
    constexpr const Declaration* begin() const { return items; }
    constexpr const Declaration* end() const { return items + count; }
};

/// The whole application. Lists left out are empty.
struct Application {
    const char* name = nullptr;    ///< Required, 1 to 31 characters; shown at boot and by 'app'.
    DeclarationList<TaskDeclaration> tasks;
    DeclarationList<SemaphoreDeclaration> semaphores;
    DeclarationList<MessagePortDeclaration> messagePorts;
    DeclarationList<PublisherDeclaration> publishers;
    DeclarationList<BufferPoolDeclaration> bufferPools;
    DeclarationList<HeapDeclaration> heaps;
    /// The Modbus register map the controller's slave serves.
    DeclarationList<ModbusMapEntry> modbusMap;
    /// The slave that serves modbusMap from boot on (address 0: none).
    ModbusSlaveDeclaration modbusSlave{};
    /// The requests the controller's master polls its slaves with (empty: no master).
    DeclarationList<ModbusPollEntry> modbusPolls;
    /// The master's line, when modbusPolls is not empty.
    ModbusMasterDeclaration modbusMaster{};
    /// The system tick the application needs, in Hz (timer resolution is one
    /// tick); 0 keeps the board's default. A tick_hz= on the kernel command
    /// line still wins.
    uint32_t tickRateHz = 0;
};

} // namespace dcos::app
