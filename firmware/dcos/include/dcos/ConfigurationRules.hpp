// The rules an application's configuration (dcos/Application.hpp) must keep.
//
// findConfigurationError is one constexpr function for two callers: the
// compiler, which runs it on every DCOS_APPLICATION and turns a broken rule
// into a compile-time error naming the object (internal/ConfigurationCheck.hpp),
// and the application loader, which runs it again at boot on the linked
// configuration before it creates anything. Rules are checked in declaration
// order: the application, then tasks, semaphores, ports, publishers, pools
// and heaps, then the totals, then the Modbus register map and slave; the
// first broken rule is reported.
#pragma once

#include <dcos/ApplicationDeclarations.hpp>
#include <dcos/BufferPoolAgent.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>
#include <runtime/Text.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::app {

/// Which kind of object a configuration error is about.
enum class ObjectKind : uint8_t {
    Application,
    Task,
    Semaphore,
    MessagePort,
    Publisher,
    BufferPool,
    Heap,
    ModbusMapEntry,
    ModbusSlave,
    ModbusPollEntry,
    ModbusMaster,
};

/// The rule a configuration breaks.
enum class ConfigurationRule : uint8_t {
    None,
    NameMissing,          ///< value: the declaration's index in its list.
    NameTooLong,          ///< value: its length; limit: the longest allowed.
    DuplicateName,        ///< Two declarations of one kind share the name.
    ReservedName,         ///< The kernel's own task already has the name.
    EntryMissing,
    PriorityOutOfRange,   ///< value: the priority; limit: kLowestPriority.
    StackTooSmall,        ///< value: the size; limit: kMinimumStackSize.
    StacksExceedArena,    ///< value: bytes all stacks need; limit: the arena.
    TooManyObjects,       ///< value: declared plus the kernel's own; limit: the table.
    OwnerNotDeclared,     ///< The owner, receiver or writer names no declared task.
    ReceiverMissing,
    InitialCountTooLarge, ///< value: initialCount; limit: 1 or maximumCount.
    InheritanceNeedsBinary,
    TickRateOutOfRange,   ///< value: the rate; limit: kHighestTickRateHz.
    AreaMissing,
    AreaTooSmall,         ///< value: areaBytes; limit: the least that holds one buffer or segment.
    BufferTooSmall,       ///< value: bufferSize; limit: kMinimumBufferSize.
    MapRangeEmpty,        ///< A Modbus map entry of count 0.
    MapAddressPastEnd,    ///< value: its last address (address + count - 1); limit: 65535.
    MapSourceWrongTable,  ///< Analog inputs in a bit table, digital outputs in a register table.
    MapObjectNotDeclared, ///< The entry's publisher is not a declared publisher.
    MapTooLarge,          ///< value: page bytes or I/O points it needs (offset + size); limit: what there is.
    MapWritesReadOnly,    ///< A coil or holding register entry bound to something Modbus may not write.
    MapOverlap,           ///< value: the first address it shares with an earlier entry of its table; limit: the last.
    SlaveAddressOutOfRange, ///< value: the Modbus slave's address (or a poll entry's unit); limit: 247.
    BaudOutOfRange,       ///< value: a Modbus line's baud rate; limit: kHighestModbusBaud.
    SlaveWithoutMap,      ///< A Modbus slave declared with an empty register map.
    PollPeriodOutOfRange, ///< value: the period in ms; limit: kLongestModbusPollMs.
    PollWritesReadOnlyTable, ///< A poll entry writing discrete inputs or input registers.
    PollPublisherHasWriter, ///< A read's publisher has a writer task, or the slave's map writes it too.
    TimeoutOutOfRange,    ///< value: the master's time-out in ms; limit: kLongestModbusTimeoutMs.
    RetriesOutOfRange,    ///< value: the master's retries; limit: 15.
    // Rules only the running node can check (application loader).
    NameInUse,            ///< An object of the node already has the name.
    CreateFailed,         ///< The agent refused; the loader prints its status.
};

/// The first broken rule, and about which object.
struct ConfigurationError {
    ConfigurationRule rule = ConfigurationRule::None;
    ObjectKind kind = ObjectKind::Application;
    const char* object = nullptr; ///< The object's name (null when it has none).
    size_t value = 0;
    size_t limit = 0;

    constexpr bool ok() const { return rule == ConfigurationRule::None; }
};

/// The tick rates every DCOS board can run at, in Hz.
constexpr uint32_t kLowestTickRateHz = 19;
constexpr uint32_t kHighestTickRateHz = 10000;

/// Longest application name.
constexpr size_t kMaximumApplicationName = 31;
/// Longest object name (every agent's name field holds 15 characters).
constexpr size_t kMaximumObjectName = 15;

/// Most entries in an application's Modbus register map.
constexpr size_t kMaximumModbusMapEntries = 32;
/// The last Modbus address of every table ([AP] 4.4: addresses 0 to 65535).
constexpr uint32_t kLastModbusAddress = 0xFFFF;
/// The highest address of a Modbus slave ([SL] 2.2: 248 to 255 are reserved).
constexpr uint32_t kMaxModbusSlaveAddress = 247;
/// Most entries in an application's Modbus polling schedule.
constexpr size_t kMaximumModbusPollEntries = 16;
/// The longest poll period and master time-out, in milliseconds.
constexpr uint32_t kLongestModbusPollMs = 3600000;
constexpr uint32_t kLongestModbusTimeoutMs = 60000;
/// Most retries of the master ([SL] leaves it to the implementation; modbus::MasterConfig's limit).
constexpr uint32_t kMostModbusRetries = 15;

/// Tasks the kernel itself runs on every node (idle, the root task and the console shell).
constexpr const char* kKernelTaskNames[] = {internal::kIdleTaskName, internal::kRootTaskName,
                                            internal::kShellTaskName};
constexpr size_t kKernelTaskCount = sizeof kKernelTaskNames / sizeof kKernelTaskNames[0];
/// Stack arena bytes a task of @p stackSize takes: whole pages and a guard page.
constexpr size_t stackArenaBytes(size_t stackSize) { return internal::StackArena::blockSize(stackSize); }

/// Stack bytes the kernel's own tasks take from the stack arena.
constexpr size_t kKernelStackBytes = stackArenaBytes(internal::kIdleStackSize) +
                                     stackArenaBytes(internal::kRootStackSize) +
                                     stackArenaBytes(internal::kShellStackSize);

/// Stable English names, for messages.
constexpr const char* objectKindName(ObjectKind kind)
{
    switch (kind) {
    case ObjectKind::Application: return "application";
    case ObjectKind::Task: return "task";
    case ObjectKind::Semaphore: return "semaphore";
    case ObjectKind::MessagePort: return "message port";
    case ObjectKind::Publisher: return "publisher";
    case ObjectKind::BufferPool: return "buffer pool";
    case ObjectKind::Heap: return "heap";
    case ObjectKind::ModbusMapEntry: return "Modbus map entry";
    case ObjectKind::ModbusSlave: return "Modbus slave";
    case ObjectKind::ModbusPollEntry: return "Modbus poll entry";
    case ObjectKind::ModbusMaster: return "Modbus master";
    }
    return "object";
}

/// What the rule says, as a phrase that follows the object's name.
constexpr const char* ruleText(ConfigurationRule rule)
{
    switch (rule) {
    case ConfigurationRule::None: return "is valid";
    case ConfigurationRule::NameMissing: return "has no name";
    case ConfigurationRule::NameTooLong: return "has a name that is too long";
    case ConfigurationRule::DuplicateName: return "is declared twice (names are unique per kind)";
    case ConfigurationRule::ReservedName: return "has the name of a kernel task";
    case ConfigurationRule::EntryMissing: return "has no entry function";
    case ConfigurationRule::PriorityOutOfRange: return "has a priority out of range (0 highest to 31 lowest)";
    case ConfigurationRule::StackTooSmall: return "has a stack smaller than kMinimumStackSize";
    case ConfigurationRule::StacksExceedArena: return "does not fit: all stacks together exceed the stack arena";
    case ConfigurationRule::TooManyObjects: return "is one too many: the table of its kind is full";
    case ConfigurationRule::OwnerNotDeclared: return "names an owner that is not a declared task";
    case ConfigurationRule::ReceiverMissing: return "has no receiver task";
    case ConfigurationRule::InitialCountTooLarge: return "has an initial count above its maximum";
    case ConfigurationRule::InheritanceNeedsBinary: return "asks for priority inheritance, which only binary semaphores have";
    case ConfigurationRule::TickRateOutOfRange: return "asks for a tick rate out of range (19 to 10000 Hz, or 0 for the default)";
    case ConfigurationRule::AreaMissing: return "has no memory area";
    case ConfigurationRule::AreaTooSmall: return "has an area too small for one buffer or segment";
    case ConfigurationRule::BufferTooSmall: return "has buffers smaller than kMinimumBufferSize";
    case ConfigurationRule::MapRangeEmpty: return "has a count of 0";
    case ConfigurationRule::MapAddressPastEnd: return "runs past the last Modbus address";
    case ConfigurationRule::MapSourceWrongTable:
        return "puts its source in the wrong table (analog inputs are registers, digital outputs bits)";
    case ConfigurationRule::MapObjectNotDeclared: return "names an object that is not a declared publisher";
    case ConfigurationRule::MapTooLarge: return "does not fit its source (a DSM page, or the I/O board's points)";
    case ConfigurationRule::MapWritesReadOnly:
        return "is writable (coils, holding registers) but bound to something read-only";
    case ConfigurationRule::MapOverlap: return "overlaps an earlier entry of its table";
    case ConfigurationRule::SlaveAddressOutOfRange: return "has a slave address out of range (1 to 247)";
    case ConfigurationRule::BaudOutOfRange: return "has a baud rate out of range (300 to 115200)";
    case ConfigurationRule::SlaveWithoutMap: return "is declared without a register map to serve";
    case ConfigurationRule::PollPeriodOutOfRange: return "has a period out of range (1 ms to one hour)";
    case ConfigurationRule::PollWritesReadOnlyTable:
        return "writes a read-only table (only coils and holding registers are written)";
    case ConfigurationRule::PollPublisherHasWriter:
        return "publishes on a publisher another writer has (a writer task, or the slave's map)";
    case ConfigurationRule::TimeoutOutOfRange: return "has a response time-out out of range (1 to 60000 ms)";
    case ConfigurationRule::RetriesOutOfRange: return "has too many retries (at most 15)";
    case ConfigurationRule::NameInUse: return "has a name another object of the node already uses";
    case ConfigurationRule::CreateFailed: return "was refused by its agent";
    }
    return "breaks a configuration rule";
}

namespace rules {

using runtime::textEquals;
using runtime::textLength;

constexpr ConfigurationError broken(ConfigurationRule rule, ObjectKind kind, const char* object, size_t value = 0,
                                    size_t limit = 0)
{
    return ConfigurationError{rule, kind, object, value, limit};
}

/// The name rules every declaration keeps: present, short enough, unique in its list.
template <class Declaration>
constexpr ConfigurationError checkNames(const DeclarationList<Declaration>& list, ObjectKind kind)
{
    for (size_t i = 0; i < list.count; ++i) {
        const char* name = list[i].name;
        if (name == nullptr || name[0] == '\0') {
            return broken(ConfigurationRule::NameMissing, kind, nullptr, i);
        }
        if (textLength(name) > kMaximumObjectName) {
            return broken(ConfigurationRule::NameTooLong, kind, name, textLength(name), kMaximumObjectName);
        }
        for (size_t j = 0; j < i; ++j) {
            if (textEquals(list[j].name, name)) {
                return broken(ConfigurationRule::DuplicateName, kind, name);
            }
        }
    }
    return {};
}

constexpr bool isDeclaredTask(const Application& application, const char* name)
{
    for (const TaskDeclaration& task : application.tasks) {
        if (textEquals(task.name, name)) {
            return true;
        }
    }
    return false;
}

/// An optional owner (null: the system) must be a declared task.
constexpr bool ownerIsValid(const Application& application, const char* owner)
{
    return owner == nullptr || isDeclaredTask(application, owner);
}

constexpr ConfigurationError checkTasks(const Application& application)
{
    if (ConfigurationError names = checkNames(application.tasks, ObjectKind::Task); !names.ok()) {
        return names;
    }
    for (const TaskDeclaration& task : application.tasks) {
        for (const char* reserved : kKernelTaskNames) {
            if (textEquals(task.name, reserved)) {
                return broken(ConfigurationRule::ReservedName, ObjectKind::Task, task.name);
            }
        }
        if (task.entry == nullptr) {
            return broken(ConfigurationRule::EntryMissing, ObjectKind::Task, task.name);
        }
        if (task.priority > kLowestPriority) {
            return broken(ConfigurationRule::PriorityOutOfRange, ObjectKind::Task, task.name, task.priority,
                          kLowestPriority);
        }
        if (task.stackSize < kMinimumStackSize) {
            return broken(ConfigurationRule::StackTooSmall, ObjectKind::Task, task.name, task.stackSize,
                          kMinimumStackSize);
        }
    }
    return {};
}

constexpr ConfigurationError checkSemaphores(const Application& application)
{
    if (ConfigurationError names = checkNames(application.semaphores, ObjectKind::Semaphore); !names.ok()) {
        return names;
    }
    for (const SemaphoreDeclaration& semaphore : application.semaphores) {
        const bool binary = semaphore.kind == SemaphoreKind::Binary;
        const size_t most = binary ? 1 : semaphore.maximumCount;
        if (semaphore.initialCount > most) {
            return broken(ConfigurationRule::InitialCountTooLarge, ObjectKind::Semaphore, semaphore.name,
                          semaphore.initialCount, most);
        }
        if (semaphore.priorityInheritance && !binary) {
            return broken(ConfigurationRule::InheritanceNeedsBinary, ObjectKind::Semaphore, semaphore.name);
        }
        if (!ownerIsValid(application, semaphore.owner)) {
            return broken(ConfigurationRule::OwnerNotDeclared, ObjectKind::Semaphore, semaphore.name);
        }
    }
    return {};
}

constexpr ConfigurationError checkPortsAndPublishers(const Application& application)
{
    if (ConfigurationError names = checkNames(application.messagePorts, ObjectKind::MessagePort); !names.ok()) {
        return names;
    }
    for (const MessagePortDeclaration& port : application.messagePorts) {
        if (port.receiver == nullptr) {
            return broken(ConfigurationRule::ReceiverMissing, ObjectKind::MessagePort, port.name);
        }
        if (!isDeclaredTask(application, port.receiver)) {
            return broken(ConfigurationRule::OwnerNotDeclared, ObjectKind::MessagePort, port.name);
        }
    }
    if (ConfigurationError names = checkNames(application.publishers, ObjectKind::Publisher); !names.ok()) {
        return names;
    }
    for (const PublisherDeclaration& publisher : application.publishers) {
        if (!ownerIsValid(application, publisher.writer)) {
            return broken(ConfigurationRule::OwnerNotDeclared, ObjectKind::Publisher, publisher.name);
        }
    }
    return {};
}

constexpr ConfigurationError checkMemoryAreas(const Application& application)
{
    if (ConfigurationError names = checkNames(application.bufferPools, ObjectKind::BufferPool); !names.ok()) {
        return names;
    }
    for (const BufferPoolDeclaration& pool : application.bufferPools) {
        if (pool.area == nullptr) {
            return broken(ConfigurationRule::AreaMissing, ObjectKind::BufferPool, pool.name);
        }
        if (pool.bufferSize < BufferPoolAgent::kMinimumBufferSize) {
            return broken(ConfigurationRule::BufferTooSmall, ObjectKind::BufferPool, pool.name, pool.bufferSize,
                          BufferPoolAgent::kMinimumBufferSize);
        }
        const size_t least = BufferPoolAgent::AreaBytes(pool.bufferSize, 1);
        if (pool.areaBytes < least) {
            return broken(ConfigurationRule::AreaTooSmall, ObjectKind::BufferPool, pool.name, pool.areaBytes, least);
        }
        if (!ownerIsValid(application, pool.owner)) {
            return broken(ConfigurationRule::OwnerNotDeclared, ObjectKind::BufferPool, pool.name);
        }
    }
    if (ConfigurationError names = checkNames(application.heaps, ObjectKind::Heap); !names.ok()) {
        return names;
    }
    for (const HeapDeclaration& heap : application.heaps) {
        if (heap.area == nullptr) {
            return broken(ConfigurationRule::AreaMissing, ObjectKind::Heap, heap.name);
        }
        const size_t least = HeapAgent::SegmentBytes(HeapAgent::kMinimumSegment);
        if (heap.areaBytes < least) {
            return broken(ConfigurationRule::AreaTooSmall, ObjectKind::Heap, heap.name, heap.areaBytes, least);
        }
        if (!ownerIsValid(application, heap.owner)) {
            return broken(ConfigurationRule::OwnerNotDeclared, ObjectKind::Heap, heap.name);
        }
    }
    return {};
}

/// A list longer than its table (less what the kernel uses) names its first object that does not fit.
template <class Declaration>
constexpr ConfigurationError checkCount(const DeclarationList<Declaration>& list, ObjectKind kind, size_t capacity,
                                        size_t kernelUses = 0)
{
    if (list.count + kernelUses > capacity) {
        const size_t firstOver = capacity > kernelUses ? capacity - kernelUses : 0;
        return broken(ConfigurationRule::TooManyObjects, kind, list[firstOver].name, list.count + kernelUses,
                      capacity);
    }
    return {};
}

constexpr ConfigurationError checkTotals(const Application& application)
{
    using namespace dcos::internal;
    ConfigurationError error = checkCount(application.tasks, ObjectKind::Task, kTaskCapacity, kKernelTaskCount);
    if (error.ok()) error = checkCount(application.semaphores, ObjectKind::Semaphore, kSemaphoreCapacity);
    if (error.ok()) error = checkCount(application.messagePorts, ObjectKind::MessagePort, kPortCapacity);
    if (error.ok()) error = checkCount(application.publishers, ObjectKind::Publisher, kPublisherCapacity);
    if (error.ok()) error = checkCount(application.bufferPools, ObjectKind::BufferPool, kPoolCapacity);
    if (error.ok()) error = checkCount(application.heaps, ObjectKind::Heap, kHeapCapacity);
    if (!error.ok()) {
        return error;
    }
    // Compared before it is added, so that a huge stack size (SIZE_MAX, say)
    // cannot wrap the total around to a small number that seems to fit.
    size_t stackBytes = kKernelStackBytes;
    for (const TaskDeclaration& task : application.tasks) {
        const size_t block = stackArenaBytes(task.stackSize);
        if (block > kStackArenaBytes - stackBytes) {
            const size_t needed = block > SIZE_MAX - stackBytes ? SIZE_MAX : stackBytes + block;
            return broken(ConfigurationRule::StacksExceedArena, ObjectKind::Task, task.name, needed,
                          kStackArenaBytes);
        }
        stackBytes += block;
    }
    return {};
}

constexpr bool isWritable(ModbusTable table)
{
    return table == ModbusTable::Coils || table == ModbusTable::HoldingRegisters;
}

constexpr bool isBitTable(ModbusTable table)
{
    return table == ModbusTable::Coils || table == ModbusTable::DiscreteInputs;
}

constexpr const PublisherDeclaration* findPublisher(const Application& application, const char* name)
{
    if (name == nullptr) {
        return nullptr;
    }
    for (const PublisherDeclaration& publisher : application.publishers) {
        if (textEquals(publisher.name, name)) {
            return &publisher;
        }
    }
    return nullptr;
}

/// Page bytes @p count items of @p table take: two per register, eight bits a byte.
constexpr uint64_t pageBytesOf(ModbusTable table, uint32_t count)
{
    return isBitTable(table) ? (uint64_t{count} + 7) / 8 : uint64_t{count} * 2;
}

/// Page bytes a publisher entry takes.
constexpr uint64_t pageBytesOf(const ModbusMapEntry& entry) { return pageBytesOf(entry.table, entry.count); }

/// The rules every Modbus item bound to a range of addresses keeps: a count
/// of at least 1 and a last address at most 65535.
template <class Entry>
constexpr ConfigurationError checkAddressRange(const Entry& entry, ObjectKind kind)
{
    if (entry.count == 0) {
        return broken(ConfigurationRule::MapRangeEmpty, kind, entry.name);
    }
    const uint64_t last = uint64_t{entry.address} + entry.count - 1;
    if (last > kLastModbusAddress) {
        return broken(ConfigurationRule::MapAddressPastEnd, kind, entry.name,
                      last > SIZE_MAX ? SIZE_MAX : static_cast<size_t>(last), kLastModbusAddress);
    }
    return {};
}

/// A Modbus line's baud rate.
constexpr ConfigurationError checkBaud(uint32_t baud, ObjectKind kind, const char* name)
{
    if (baud < kLowestModbusBaud || baud > kHighestModbusBaud) {
        return broken(ConfigurationRule::BaudOutOfRange, kind, name, baud, kHighestModbusBaud);
    }
    return {};
}

/// The rules one entry keeps on its own; the sizes are summed in 64 bits,
/// so that no offset or count near 2^32 can wrap around into a fit.
constexpr ConfigurationError checkMapEntry(const Application& application, const ModbusMapEntry& entry)
{
    constexpr ObjectKind kind = ObjectKind::ModbusMapEntry;
    if (ConfigurationError range = checkAddressRange(entry, kind); !range.ok()) {
        return range;
    }
    uint64_t needed = 0;
    uint64_t available = 0;
    bool readOnly = false;
    switch (entry.source) {
    case ModbusSource::Publisher: {
        const PublisherDeclaration* publisher = findPublisher(application, entry.object);
        if (publisher == nullptr) {
            return broken(ConfigurationRule::MapObjectNotDeclared, kind, entry.name);
        }
        needed = uint64_t{entry.offset} + pageBytesOf(entry);
        available = kDsmPageSize;
        // A publisher has one writer: the task declared as its writer, or,
        // when none is, the Modbus line. The master may only write the latter.
        readOnly = publisher->writer != nullptr;
        break;
    }
    case ModbusSource::AnalogInput:
        if (isBitTable(entry.table)) {
            return broken(ConfigurationRule::MapSourceWrongTable, kind, entry.name);
        }
        needed = uint64_t{entry.offset} + entry.count;
        available = kModbusAnalogInputPoints;
        readOnly = true;
        break;
    case ModbusSource::DigitalOutput:
        if (!isBitTable(entry.table)) {
            return broken(ConfigurationRule::MapSourceWrongTable, kind, entry.name);
        }
        needed = uint64_t{entry.offset} + entry.count;
        available = kModbusDigitalOutputPoints;
        break;
    }
    if (needed > available) {
        return broken(ConfigurationRule::MapTooLarge, kind, entry.name,
                      needed > SIZE_MAX ? SIZE_MAX : static_cast<size_t>(needed), static_cast<size_t>(available));
    }
    if (readOnly && isWritable(entry.table)) {
        return broken(ConfigurationRule::MapWritesReadOnly, kind, entry.name);
    }
    return {};
}

constexpr ConfigurationError checkModbusMap(const Application& application)
{
    const DeclarationList<ModbusMapEntry>& map = application.modbusMap;
    if (ConfigurationError names = checkNames(map, ObjectKind::ModbusMapEntry); !names.ok()) {
        return names;
    }
    if (ConfigurationError count = checkCount(map, ObjectKind::ModbusMapEntry, kMaximumModbusMapEntries);
        !count.ok()) {
        return count;
    }
    for (size_t i = 0; i < map.count; ++i) {
        const ModbusMapEntry& entry = map[i];
        if (ConfigurationError error = checkMapEntry(application, entry); !error.ok()) {
            return error;
        }
        // Every entry before this one has passed, so no sum below wraps.
        const uint32_t last = entry.address + entry.count - 1;
        for (size_t j = 0; j < i; ++j) {
            const ModbusMapEntry& earlier = map[j];
            const uint32_t earlierLast = earlier.address + earlier.count - 1;
            if (earlier.table == entry.table && entry.address <= earlierLast && earlier.address <= last) {
                const uint32_t first = entry.address > earlier.address ? entry.address : earlier.address;
                const uint32_t shared = last < earlierLast ? last : earlierLast;
                return broken(ConfigurationRule::MapOverlap, ObjectKind::ModbusMapEntry, entry.name, first, shared);
            }
        }
    }
    return {};
}

/// Whether the slave's map writes @p publisher (a coil or holding register entry names it).
constexpr bool mapWrites(const Application& application, const char* publisher)
{
    for (const ModbusMapEntry& entry : application.modbusMap) {
        if (entry.source == ModbusSource::Publisher && isWritable(entry.table) && textEquals(entry.object, publisher)) {
            return true;
        }
    }
    return false;
}

/// One poll entry's rules.
constexpr ConfigurationError checkPollEntry(const Application& application, const ModbusPollEntry& entry)
{
    constexpr ObjectKind kind = ObjectKind::ModbusPollEntry;
    if (entry.unit == 0 || entry.unit > kMaxModbusSlaveAddress) {
        return broken(ConfigurationRule::SlaveAddressOutOfRange, kind, entry.name, entry.unit, kMaxModbusSlaveAddress);
    }
    if (ConfigurationError range = checkAddressRange(entry, kind); !range.ok()) {
        return range;
    }
    if (entry.periodMs == 0 || entry.periodMs > kLongestModbusPollMs) {
        return broken(ConfigurationRule::PollPeriodOutOfRange, kind, entry.name, entry.periodMs, kLongestModbusPollMs);
    }
    if (entry.write && !isWritable(entry.table)) {
        return broken(ConfigurationRule::PollWritesReadOnlyTable, kind, entry.name);
    }
    const PublisherDeclaration* publisher = findPublisher(application, entry.object);
    if (publisher == nullptr) {
        return broken(ConfigurationRule::MapObjectNotDeclared, kind, entry.name);
    }
    const uint64_t needed = uint64_t{entry.offset} + pageBytesOf(entry.table, entry.count);
    if (needed > kDsmPageSize) {
        return broken(ConfigurationRule::MapTooLarge, kind, entry.name,
                      needed > SIZE_MAX ? SIZE_MAX : static_cast<size_t>(needed), kDsmPageSize);
    }
    // A publisher has one writer (seed 7.10): what a read publishes, the master's line writes alone.
    if (!entry.write && (publisher->writer != nullptr || mapWrites(application, entry.object))) {
        return broken(ConfigurationRule::PollPublisherHasWriter, kind, entry.name);
    }
    return {};
}

/// The polling schedule and its master's line.
constexpr ConfigurationError checkModbusPolls(const Application& application)
{
    const DeclarationList<ModbusPollEntry>& polls = application.modbusPolls;
    if (polls.count == 0) {
        return {};
    }
    if (ConfigurationError names = checkNames(polls, ObjectKind::ModbusPollEntry); !names.ok()) {
        return names;
    }
    if (ConfigurationError count = checkCount(polls, ObjectKind::ModbusPollEntry, kMaximumModbusPollEntries);
        !count.ok()) {
        return count;
    }
    for (const ModbusPollEntry& entry : polls) {
        if (ConfigurationError error = checkPollEntry(application, entry); !error.ok()) {
            return error;
        }
    }
    const ModbusMasterDeclaration& master = application.modbusMaster;
    constexpr ObjectKind kind = ObjectKind::ModbusMaster;
    if (ConfigurationError baud = checkBaud(master.baud, kind, application.name); !baud.ok()) {
        return baud;
    }
    if (master.timeoutMs == 0 || master.timeoutMs > kLongestModbusTimeoutMs) {
        return broken(ConfigurationRule::TimeoutOutOfRange, kind, application.name, master.timeoutMs,
                      kLongestModbusTimeoutMs);
    }
    if (master.retries > kMostModbusRetries) {
        return broken(ConfigurationRule::RetriesOutOfRange, kind, application.name, master.retries,
                      kMostModbusRetries);
    }
    return {};
}

/// The declared slave's line settings. The error names the application,
/// since an application declares at most one slave.
constexpr ConfigurationError checkModbusSlave(const Application& application)
{
    const ModbusSlaveDeclaration& slave = application.modbusSlave;
    constexpr ObjectKind kind = ObjectKind::ModbusSlave;
    if (slave.address == 0) {
        return {};
    }
    if (slave.address > kMaxModbusSlaveAddress) {
        return broken(ConfigurationRule::SlaveAddressOutOfRange, kind, application.name, slave.address,
                      kMaxModbusSlaveAddress);
    }
    if (ConfigurationError baud = checkBaud(slave.baud, kind, application.name); !baud.ok()) {
        return baud;
    }
    if (application.modbusMap.count == 0) {
        return broken(ConfigurationRule::SlaveWithoutMap, kind, application.name);
    }
    return {};
}

} // namespace rules

/// The first rule @p application breaks, or an error with rule None.
constexpr ConfigurationError findConfigurationError(const Application& application)
{
    if (application.name == nullptr || application.name[0] == '\0') {
        return rules::broken(ConfigurationRule::NameMissing, ObjectKind::Application, nullptr);
    }
    const size_t nameLength = rules::textLength(application.name);
    if (nameLength > kMaximumApplicationName) {
        return rules::broken(ConfigurationRule::NameTooLong, ObjectKind::Application, application.name, nameLength,
                             kMaximumApplicationName);
    }
    if (application.tickRateHz != 0
        && (application.tickRateHz < kLowestTickRateHz || application.tickRateHz > kHighestTickRateHz)) {
        return rules::broken(ConfigurationRule::TickRateOutOfRange, ObjectKind::Application, application.name,
                             application.tickRateHz, kHighestTickRateHz);
    }
    // One group after the other, stopping at the first broken rule.
    ConfigurationError error = rules::checkTasks(application);
    if (error.ok()) error = rules::checkSemaphores(application);
    if (error.ok()) error = rules::checkPortsAndPublishers(application);
    if (error.ok()) error = rules::checkMemoryAreas(application);
    if (error.ok()) error = rules::checkTotals(application);
    if (error.ok()) error = rules::checkModbusMap(application);
    if (error.ok()) error = rules::checkModbusSlave(application);
    if (error.ok()) error = rules::checkModbusPolls(application);
    return error;
}

} // namespace dcos::app
