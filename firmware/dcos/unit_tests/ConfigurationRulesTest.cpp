// Host tests for an application's configuration rules and their messages.
//
// The same constexpr rules run in the compiler (DCOS_APPLICATION) and in the
// loader at boot; here each rule is broken once at run time and the first
// error, the object it names and the printed message are checked.
#include <dcos/Application.hpp>
#include <dcos/ConfigurationRules.hpp>
#include <dcos/internal/ConfigurationReport.hpp>

#include <gtest/gtest.h>

#include <string>
#include <vector>

using dcos::app::Application;
using dcos::app::BufferPoolDeclaration;
using dcos::app::ConfigurationError;
using dcos::app::ConfigurationRule;
using dcos::app::findConfigurationError;
using dcos::app::HeapDeclaration;
using dcos::app::MessagePortDeclaration;
using dcos::app::ModbusMapEntry;
using dcos::app::ModbusSource;
using dcos::app::ModbusTable;
using dcos::app::ObjectKind;
using dcos::app::PublisherDeclaration;
using dcos::app::SemaphoreDeclaration;
using dcos::app::TaskDeclaration;

namespace {

void entry(uintptr_t) {}

alignas(8) uint8_t poolArea[dcos::BufferPoolAgent::AreaBytes(16, 4)];
alignas(8) uint8_t heapArea[256];

// A valid configuration of every kind, checked by the compiler too.
constexpr TaskDeclaration validTasks[] = {
    {.name = "sampler", .entry = entry, .priority = 4},
    {.name = "logger", .entry = entry, .priority = 20, .stackSize = 8192},
};
constexpr SemaphoreDeclaration validSemaphores[] = {{.name = "bus", .priorityInheritance = true, .owner = "logger"}};
constexpr MessagePortDeclaration validPorts[] = {{.name = "samples", .receiver = "logger"}};
constexpr PublisherDeclaration validPublishers[] = {{.name = "level", .writer = "sampler"}, {.name = "alarm"}};
constexpr Application valid{.name = "plant-logger",
                            .tasks = validTasks,
                            .semaphores = validSemaphores,
                            .messagePorts = validPorts,
                            .publishers = validPublishers};
static_assert(findConfigurationError(valid).ok());
static_assert(dcos::internal::ConfigurationCheck<valid>::passed);

std::string message(const char* application, const ConfigurationError& error)
{
    char text[256];
    runtime::BufferSink sink(text, sizeof text);
    dcos::internal::formatConfigurationError(sink, application, error);
    return text;
}

// A configuration built at run time, which the compiler never checked.
struct Configuration {
    // One valid task to start from. (Filled in the constructor: GCC 12 warns
    // wrongly about a vector initialised from designated initialisers.)
    Configuration()
    {
        TaskDeclaration sampler;
        sampler.name = "sampler";
        sampler.entry = entry;
        sampler.priority = 4;
        tasks.push_back(sampler);
    }

    std::vector<TaskDeclaration> tasks;
    std::vector<SemaphoreDeclaration> semaphores;
    std::vector<MessagePortDeclaration> ports;
    std::vector<PublisherDeclaration> publishers;
    std::vector<BufferPoolDeclaration> pools;
    std::vector<HeapDeclaration> heaps;
    std::vector<ModbusMapEntry> map;
    dcos::app::ModbusSlaveDeclaration slave{};
    std::vector<dcos::app::ModbusPollEntry> polls;
    dcos::app::ModbusMasterDeclaration master{};
    const char* name = "demo";
    uint32_t tickRateHz = 0;

    ConfigurationError check() const
    {
        Application application{.name = name,
                                .tasks = {tasks.data(), tasks.size()},
                                .semaphores = {semaphores.data(), semaphores.size()},
                                .messagePorts = {ports.data(), ports.size()},
                                .publishers = {publishers.data(), publishers.size()},
                                .bufferPools = {pools.data(), pools.size()},
                                .heaps = {heaps.data(), heaps.size()},
                                .modbusMap = {map.data(), map.size()},
                                .modbusSlave = slave,
                                .modbusPolls = {polls.data(), polls.size()},
                                .modbusMaster = master,
                                .tickRateHz = tickRateHz};
        return findConfigurationError(application);
    }
};

void expectBroken(const ConfigurationError& error, ConfigurationRule rule, ObjectKind kind, const char* object)
{
    EXPECT_EQ(error.rule, rule);
    EXPECT_EQ(error.kind, kind);
    if (object == nullptr) {
        EXPECT_EQ(error.object, nullptr);
    } else {
        ASSERT_NE(error.object, nullptr);
        EXPECT_STREQ(error.object, object);
    }
}

} // namespace

TEST(ConfigurationRulesTest, AValidConfigurationPasses)
{
    EXPECT_TRUE(findConfigurationError(valid).ok());
    EXPECT_TRUE(Configuration{}.check().ok());
}

TEST(ConfigurationRulesTest, PriorityOutOfRangeNamesTheTaskAndTheValue)
{
    Configuration configuration;
    configuration.tasks.push_back({.name = "blinker", .entry = entry, .priority = 40});
    const ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::PriorityOutOfRange, ObjectKind::Task, "blinker");
    EXPECT_EQ(error.value, 40u);
    EXPECT_EQ(error.limit, 31u);
    EXPECT_EQ(message("demo", error), "application 'demo' not started: task 'blinker' has a priority out of range "
                                      "(0 highest to 31 lowest) (40, limit 31)");
}

TEST(ConfigurationRulesTest, StackTooSmallNamesTheTask)
{
    Configuration configuration;
    configuration.tasks.push_back({.name = "tiny", .entry = entry, .stackSize = 1024});
    const ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::StackTooSmall, ObjectKind::Task, "tiny");
    EXPECT_EQ(error.value, 1024u);
    EXPECT_EQ(error.limit, dcos::kMinimumStackSize);
}

TEST(ConfigurationRulesTest, DuplicateNamesAreFoundPerKind)
{
    Configuration configuration;
    configuration.tasks.push_back({.name = "sampler", .entry = entry});
    expectBroken(configuration.check(), ConfigurationRule::DuplicateName, ObjectKind::Task, "sampler");

    // The same name on objects of different kinds is allowed: each agent has its own names.
    Configuration mixed;
    mixed.ports.push_back({.name = "sampler", .receiver = "sampler"});
    mixed.publishers.push_back({.name = "sampler"});
    EXPECT_TRUE(mixed.check().ok());

    mixed.publishers.push_back({.name = "sampler"});
    expectBroken(mixed.check(), ConfigurationRule::DuplicateName, ObjectKind::Publisher, "sampler");
}

TEST(ConfigurationRulesTest, KernelTaskNamesAreReserved)
{
    for (const char* reserved : {"idle", "console", "shell"}) {
        Configuration configuration;
        configuration.tasks.push_back({.name = reserved, .entry = entry});
        expectBroken(configuration.check(), ConfigurationRule::ReservedName, ObjectKind::Task, reserved);
    }
}

TEST(ConfigurationRulesTest, TooManyTasksNamesTheFirstThatDoesNotFit)
{
    Configuration configuration;
    std::vector<std::string> names;
    const size_t fit = dcos::internal::kTaskCapacity - dcos::app::kKernelTaskCount;
    names.reserve(fit + 2);
    for (size_t i = 1; i <= fit; ++i) {
        names.push_back("t" + std::to_string(i));
    }
    configuration.tasks.clear();
    for (const std::string& name : names) {
        configuration.tasks.push_back({.name = name.c_str(), .entry = entry, .stackSize = 2048});
    }
    EXPECT_TRUE(configuration.check().ok()) << message("demo", configuration.check());
    names.push_back("one-too-many");
    configuration.tasks.push_back({.name = names.back().c_str(), .entry = entry, .stackSize = 2048});
    const ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::TooManyObjects, ObjectKind::Task, "one-too-many");
    EXPECT_EQ(error.value, dcos::internal::kTaskCapacity + 1);
    EXPECT_EQ(error.limit, dcos::internal::kTaskCapacity);
}

TEST(ConfigurationRulesTest, StacksThatExceedTheArenaNameTheTaskThatOverflows)
{
    Configuration configuration;
    const size_t room = dcos::internal::kStackArenaBytes - dcos::app::kKernelStackBytes;
    configuration.tasks.clear();
    // Every stack takes whole pages and a guard page: "big" takes room less
    // two pages, "fits" one page and its guard, which fills the arena.
    configuration.tasks.push_back({.name = "big", .entry = entry, .stackSize = room - 3 * 4096});
    configuration.tasks.push_back({.name = "fits", .entry = entry, .stackSize = 4096});
    EXPECT_TRUE(configuration.check().ok());
    configuration.tasks.push_back({.name = "overflow", .entry = entry, .stackSize = 2048});
    expectBroken(configuration.check(), ConfigurationRule::StacksExceedArena, ObjectKind::Task, "overflow");
}

TEST(ConfigurationRulesTest, AHugeStackDoesNotWrapTheTotalAround)
{
    // SIZE_MAX and sizes just below it used to add up past SIZE_MAX to a
    // total that seemed to fit; the node then refused them at boot.
    for (const size_t huge : {SIZE_MAX, SIZE_MAX - 4095, SIZE_MAX / 2 + 1, dcos::internal::kStackArenaBytes}) {
        Configuration configuration;
        configuration.tasks.clear();
        configuration.tasks.push_back({.name = "huge", .entry = entry, .stackSize = huge});
        const ConfigurationError error = configuration.check();
        expectBroken(error, ConfigurationRule::StacksExceedArena, ObjectKind::Task, "huge");
        EXPECT_GT(error.value, dcos::internal::kStackArenaBytes) << huge;
        // Two stacks that each fit alone but wrap when added.
        configuration.tasks.clear();
        configuration.tasks.push_back({.name = "small", .entry = entry, .stackSize = 4096});
        configuration.tasks.push_back({.name = "huge", .entry = entry, .stackSize = huge});
        expectBroken(configuration.check(), ConfigurationRule::StacksExceedArena, ObjectKind::Task, "huge");
    }
}

TEST(ConfigurationRulesTest, NamesMustBePresentAndShort)
{
    Configuration unnamed;
    unnamed.tasks.push_back({.entry = entry});
    const ConfigurationError missing = unnamed.check();
    expectBroken(missing, ConfigurationRule::NameMissing, ObjectKind::Task, nullptr);
    EXPECT_EQ(missing.value, 1u);
    EXPECT_EQ(message("demo", missing), "application 'demo' not started: task number 2 in its list has no name");

    Configuration longName;
    longName.semaphores.push_back({.name = "sixteen-letters!"});
    const ConfigurationError tooLong = longName.check();
    expectBroken(tooLong, ConfigurationRule::NameTooLong, ObjectKind::Semaphore, "sixteen-letters!");
    EXPECT_EQ(tooLong.value, 16u);

    Configuration noApplicationName;
    noApplicationName.name = "";
    expectBroken(noApplicationName.check(), ConfigurationRule::NameMissing, ObjectKind::Application, nullptr);
}

TEST(ConfigurationRulesTest, OwnersReceiversAndWritersMustBeDeclaredTasks)
{
    Configuration port;
    port.ports.push_back({.name = "commands"});
    expectBroken(port.check(), ConfigurationRule::ReceiverMissing, ObjectKind::MessagePort, "commands");
    port.ports.back().receiver = "nobody";
    expectBroken(port.check(), ConfigurationRule::OwnerNotDeclared, ObjectKind::MessagePort, "commands");

    Configuration publisher;
    publisher.publishers.push_back({.name = "level", .writer = "nobody"});
    expectBroken(publisher.check(), ConfigurationRule::OwnerNotDeclared, ObjectKind::Publisher, "level");

    Configuration semaphore;
    semaphore.semaphores.push_back({.name = "bus", .owner = "shell"});
    expectBroken(semaphore.check(), ConfigurationRule::OwnerNotDeclared, ObjectKind::Semaphore, "bus");
}

TEST(ConfigurationRulesTest, SemaphoreCountsAndInheritance)
{
    Configuration binary;
    binary.semaphores.push_back({.name = "bus", .initialCount = 2});
    const ConfigurationError error = binary.check();
    expectBroken(error, ConfigurationRule::InitialCountTooLarge, ObjectKind::Semaphore, "bus");
    EXPECT_EQ(error.limit, 1u);

    Configuration counting;
    counting.semaphores.push_back(
        {.name = "slots", .kind = dcos::SemaphoreKind::Counting, .initialCount = 5, .maximumCount = 4});
    expectBroken(counting.check(), ConfigurationRule::InitialCountTooLarge, ObjectKind::Semaphore, "slots");

    Configuration inheritance;
    inheritance.semaphores.push_back(
        {.name = "slots", .kind = dcos::SemaphoreKind::Counting, .priorityInheritance = true});
    expectBroken(inheritance.check(), ConfigurationRule::InheritanceNeedsBinary, ObjectKind::Semaphore, "slots");
}

TEST(ConfigurationRulesTest, PoolAndHeapAreas)
{
    Configuration pool;
    pool.pools.push_back({.name = "frames", .areaBytes = sizeof poolArea, .bufferSize = 16});
    expectBroken(pool.check(), ConfigurationRule::AreaMissing, ObjectKind::BufferPool, "frames");
    pool.pools.back().area = poolArea;
    EXPECT_TRUE(pool.check().ok());
    pool.pools.back().bufferSize = 2;
    expectBroken(pool.check(), ConfigurationRule::BufferTooSmall, ObjectKind::BufferPool, "frames");
    pool.pools.back().bufferSize = 16;
    pool.pools.back().areaBytes = 8;
    expectBroken(pool.check(), ConfigurationRule::AreaTooSmall, ObjectKind::BufferPool, "frames");

    Configuration heap;
    heap.heaps.push_back({.name = "work", .area = heapArea, .areaBytes = 8});
    expectBroken(heap.check(), ConfigurationRule::AreaTooSmall, ObjectKind::Heap, "work");
    heap.heaps.back().areaBytes = sizeof heapArea;
    heap.heaps.back().owner = "ghost";
    expectBroken(heap.check(), ConfigurationRule::OwnerNotDeclared, ObjectKind::Heap, "work");
}

TEST(ConfigurationRulesTest, TaskNeedsAnEntryAndTheTickMustBeOneTheBoardsRun)
{
    Configuration noEntry;
    noEntry.tasks.push_back({.name = "lost"});
    expectBroken(noEntry.check(), ConfigurationRule::EntryMissing, ObjectKind::Task, "lost");

    Configuration tick;
    tick.tickRateHz = 8000;
    EXPECT_TRUE(tick.check().ok());
    tick.tickRateHz = 20000;
    const ConfigurationError error = tick.check();
    expectBroken(error, ConfigurationRule::TickRateOutOfRange, ObjectKind::Application, "demo");
    EXPECT_EQ(message("demo", error), "application 'demo' not started: the application asks for a tick rate out of "
                                      "range (19 to 10000 Hz, or 0 for the default) (20000, limit 10000)");
}

TEST(ConfigurationRulesTest, TheFirstBrokenRuleInDeclarationOrderIsReported)
{
    Configuration configuration;
    configuration.tasks.push_back({.name = "late", .entry = entry, .priority = 99});
    configuration.publishers.push_back({.name = "level", .writer = "nobody"});
    expectBroken(configuration.check(), ConfigurationRule::PriorityOutOfRange, ObjectKind::Task, "late");
}

TEST(ConfigurationRulesTest, LoaderErrorsAreWorded)
{
    const ConfigurationError inUse{ConfigurationRule::NameInUse, ObjectKind::MessagePort, "commands", 0, 0};
    EXPECT_EQ(message("demo", inUse), "application 'demo' not started: message port 'commands' has a name another "
                                      "object of the node already uses");
    const ConfigurationError refused{ConfigurationRule::CreateFailed, ObjectKind::Heap, "work",
                                     static_cast<size_t>(dcos::Status::AlreadyExists), 0};
    EXPECT_EQ(message("demo", refused),
              "application 'demo' not started: heap 'work' was refused by its agent (already exists)");
}

// A map that keeps every rule, checked by the compiler too: a setpoint the
// master writes (a publisher with no writer), a measurement the application
// publishes, the I/O board's analog inputs and digital outputs, and one
// address used in two different tables.
constexpr TaskDeclaration mapTasks[] = {{.name = "control", .entry = entry}};
constexpr PublisherDeclaration mapPublishers[] = {{.name = "setpoint"}, {.name = "measured", .writer = "control"}};
constexpr ModbusMapEntry validMap[] = {
    {.name = "setpoint", .table = ModbusTable::HoldingRegisters, .address = 0, .count = 8, .object = "setpoint"},
    {.name = "enable", .table = ModbusTable::Coils, .address = 0, .count = 16, .object = "setpoint", .offset = 14},
    {.name = "measured", .table = ModbusTable::InputRegisters, .address = 0, .count = 8, .object = "measured"},
    {.name = "ai", .table = ModbusTable::InputRegisters, .address = 100, .count = 8,
     .source = ModbusSource::AnalogInput},
    {.name = "do", .table = ModbusTable::Coils, .address = 100, .count = 16, .source = ModbusSource::DigitalOutput},
    {.name = "top", .table = ModbusTable::DiscreteInputs, .address = 65535, .count = 1, .object = "measured",
     .offset = 15},
};
constexpr Application mapped{.name = "mapped", .tasks = mapTasks, .publishers = mapPublishers, .modbusMap = validMap};
static_assert(findConfigurationError(mapped).ok());
static_assert(dcos::internal::ConfigurationCheck<mapped>::passed);

namespace {

// The valid map above as a run-time configuration, to break one rule at a time.
Configuration mappedConfiguration()
{
    Configuration configuration;
    configuration.tasks.assign(std::begin(mapTasks), std::end(mapTasks));
    configuration.publishers.assign(std::begin(mapPublishers), std::end(mapPublishers));
    configuration.map.assign(std::begin(validMap), std::end(validMap));
    return configuration;
}

} // namespace

TEST(ConfigurationRulesTest, AValidModbusMapPasses)
{
    EXPECT_TRUE(findConfigurationError(mapped).ok());
    EXPECT_TRUE(mappedConfiguration().check().ok());
}

TEST(ConfigurationRulesTest, OverlappingMapEntriesNameTheLaterAndTheSharedAddresses)
{
    Configuration configuration = mappedConfiguration();
    // Holding registers 0 to 7 are "setpoint"; 5 to 9 share 5 to 7.
    configuration.map.push_back({.name = "speed", .table = ModbusTable::HoldingRegisters, .address = 5, .count = 5,
                                 .object = "setpoint", .offset = 6});
    const ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::MapOverlap, ObjectKind::ModbusMapEntry, "speed");
    EXPECT_EQ(error.value, 5u);
    EXPECT_EQ(error.limit, 7u);
    EXPECT_EQ(message("demo", error), "application 'demo' not started: Modbus map entry 'speed' overlaps an earlier "
                                      "entry of its table (5, limit 7)");
    // Touching is not overlapping, and another table's addresses are its own.
    configuration.map.back().address = 8;
    EXPECT_TRUE(configuration.check().ok());
    configuration.map.back().address = 7;
    EXPECT_EQ(configuration.check().rule, ConfigurationRule::MapOverlap);
    // Discrete inputs 7 to 11 are free (the valid map has only 65535 there).
    configuration.map.back().table = ModbusTable::DiscreteInputs;
    EXPECT_TRUE(configuration.check().ok());
}

TEST(ConfigurationRulesTest, AMapEntryEndsAtTheLastModbusAddress)
{
    Configuration configuration = mappedConfiguration();
    configuration.map.push_back({.name = "tail", .table = ModbusTable::Coils, .address = 65530, .count = 6,
                                 .source = ModbusSource::DigitalOutput});
    EXPECT_TRUE(configuration.check().ok());
    configuration.map.back().count = 7;
    const ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::MapAddressPastEnd, ObjectKind::ModbusMapEntry, "tail");
    EXPECT_EQ(error.value, 65536u);
    EXPECT_EQ(error.limit, 65535u);
    // A count near 2^32 does not wrap around into a fit.
    configuration.map.back().count = 0xFFFFFFFF;
    EXPECT_EQ(configuration.check().rule, ConfigurationRule::MapAddressPastEnd);
    configuration.map.back().count = 0;
    expectBroken(configuration.check(), ConfigurationRule::MapRangeEmpty, ObjectKind::ModbusMapEntry, "tail");
}

TEST(ConfigurationRulesTest, AMapEntryNamesADeclaredPublisher)
{
    Configuration configuration = mappedConfiguration();
    configuration.map.push_back({.name = "ghost", .table = ModbusTable::InputRegisters, .address = 200,
                                 .object = "pressure"});
    expectBroken(configuration.check(), ConfigurationRule::MapObjectNotDeclared, ObjectKind::ModbusMapEntry, "ghost");
    configuration.map.back().object = nullptr;
    expectBroken(configuration.check(), ConfigurationRule::MapObjectNotDeclared, ObjectKind::ModbusMapEntry, "ghost");
}

TEST(ConfigurationRulesTest, AMapEntryFitsItsPageOrTheBoardsPoints)
{
    Configuration page = mappedConfiguration();
    // Eight registers are the whole sixteen-byte page; from byte 2 on they need 18.
    page.map[0].offset = 2;
    ConfigurationError error = page.check();
    expectBroken(error, ConfigurationRule::MapTooLarge, ObjectKind::ModbusMapEntry, "setpoint");
    EXPECT_EQ(error.value, 18u);
    EXPECT_EQ(error.limit, 16u);
    // Sixteen coils are two bytes: from byte 14 they fit, from 15 they do not.
    Configuration bits = mappedConfiguration();
    bits.map[1].offset = 15;
    error = bits.check();
    expectBroken(error, ConfigurationRule::MapTooLarge, ObjectKind::ModbusMapEntry, "enable");
    EXPECT_EQ(error.value, 17u);
    // An offset near 2^32 does not wrap around into a fit.
    bits.map[1].offset = 0xFFFFFFFF;
    EXPECT_EQ(bits.check().rule, ConfigurationRule::MapTooLarge);

    Configuration board = mappedConfiguration();
    board.map[3].offset = 1; // AI1 to AI8: the board has AI0 to AI7.
    error = board.check();
    expectBroken(error, ConfigurationRule::MapTooLarge, ObjectKind::ModbusMapEntry, "ai");
    EXPECT_EQ(error.value, 9u);
    EXPECT_EQ(error.limit, 8u);
    board = mappedConfiguration();
    board.map[4].count = 17;
    error = board.check();
    expectBroken(error, ConfigurationRule::MapTooLarge, ObjectKind::ModbusMapEntry, "do");
    EXPECT_EQ(error.limit, 16u);
}

TEST(ConfigurationRulesTest, TheMasterWritesOnlyWhatModbusOwns)
{
    // The application's own publication cannot be a holding register or a coil.
    Configuration published = mappedConfiguration();
    published.map[2].table = ModbusTable::HoldingRegisters;
    published.map[2].address = 50;
    const ConfigurationError error = published.check();
    expectBroken(error, ConfigurationRule::MapWritesReadOnly, ObjectKind::ModbusMapEntry, "measured");
    EXPECT_EQ(message("demo", error), "application 'demo' not started: Modbus map entry 'measured' is writable "
                                      "(coils, holding registers) but bound to something read-only");
    // Nor can an analog input.
    Configuration analog = mappedConfiguration();
    analog.map[3].table = ModbusTable::HoldingRegisters;
    expectBroken(analog.check(), ConfigurationRule::MapWritesReadOnly, ObjectKind::ModbusMapEntry, "ai");
    // The master's setpoint is also readable as input registers.
    Configuration readBack = mappedConfiguration();
    readBack.map.push_back({.name = "echo", .table = ModbusTable::InputRegisters, .address = 20, .count = 8,
                            .object = "setpoint"});
    EXPECT_TRUE(readBack.check().ok());
}

TEST(ConfigurationRulesTest, BoardPointsGoInTheirTables)
{
    Configuration analog = mappedConfiguration();
    analog.map[3].table = ModbusTable::DiscreteInputs;
    expectBroken(analog.check(), ConfigurationRule::MapSourceWrongTable, ObjectKind::ModbusMapEntry, "ai");
    Configuration digital = mappedConfiguration();
    digital.map[4].table = ModbusTable::HoldingRegisters;
    expectBroken(digital.check(), ConfigurationRule::MapSourceWrongTable, ObjectKind::ModbusMapEntry, "do");
}

TEST(ConfigurationRulesTest, MapEntriesHaveUniqueNamesAndAreCounted)
{
    Configuration twice = mappedConfiguration();
    twice.map.push_back(twice.map[0]);
    twice.map.back().address = 300;
    expectBroken(twice.check(), ConfigurationRule::DuplicateName, ObjectKind::ModbusMapEntry, "setpoint");

    Configuration crowd = mappedConfiguration();
    std::vector<std::string> names;
    for (size_t i = crowd.map.size(); i <= dcos::app::kMaximumModbusMapEntries; ++i) {
        names.push_back("di" + std::to_string(i));
    }
    for (size_t i = 0; i < names.size(); ++i) {
        crowd.map.push_back({.name = names[i].c_str(), .table = ModbusTable::DiscreteInputs,
                             .address = static_cast<uint32_t>(1000 + i), .object = "measured"});
    }
    const ConfigurationError error = crowd.check();
    EXPECT_EQ(error.rule, ConfigurationRule::TooManyObjects);
    EXPECT_EQ(error.value, dcos::app::kMaximumModbusMapEntries + 1);
    EXPECT_EQ(error.limit, dcos::app::kMaximumModbusMapEntries);
}

TEST(ConfigurationRulesTest, TheSlaveHasAnAddressABaudRateAndAMapToServe)
{
    Configuration configuration = mappedConfiguration();
    // Address 0 declares no slave, whatever the other settings say.
    configuration.slave.baud = 7;
    EXPECT_TRUE(configuration.check().ok());
    configuration.slave = {.address = 247, .baud = 300, .parity = dcos::app::ModbusParity::None};
    EXPECT_TRUE(configuration.check().ok());
    configuration.slave.address = 248;
    ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::SlaveAddressOutOfRange, ObjectKind::ModbusSlave, "demo");
    EXPECT_EQ(error.value, 248u);
    EXPECT_EQ(error.limit, 247u);
    EXPECT_EQ(message("demo", error), "application 'demo' not started: Modbus slave 'demo' has a slave address "
                                      "out of range (1 to 247) (248, limit 247)");
    configuration.slave.address = 1;
    configuration.slave.baud = 299;
    error = configuration.check();
    expectBroken(error, ConfigurationRule::BaudOutOfRange, ObjectKind::ModbusSlave, "demo");
    EXPECT_EQ(error.value, 299u);
    configuration.slave.baud = 115200;
    EXPECT_TRUE(configuration.check().ok());
    configuration.slave.baud = 115201;
    EXPECT_EQ(configuration.check().rule, ConfigurationRule::BaudOutOfRange);
    // A slave with nothing to serve is refused rather than left answering 02 to everything.
    configuration.slave.baud = 19200;
    configuration.map.clear();
    expectBroken(configuration.check(), ConfigurationRule::SlaveWithoutMap, ObjectKind::ModbusSlave, "demo");
}

namespace {

// The valid map with a polling schedule: a drive's speed read into a
// publisher of its own ("drive", no writer), its setpoint written from the
// application's "measured".
Configuration pollingConfiguration()
{
    Configuration configuration = mappedConfiguration();
    configuration.publishers.push_back({.name = "drive"});
    configuration.polls.push_back({.name = "speed", .unit = 1, .table = ModbusTable::InputRegisters, .address = 0,
                                   .count = 8, .periodMs = 100, .object = "drive"});
    configuration.polls.push_back({.name = "setpoint", .unit = 1, .table = ModbusTable::HoldingRegisters,
                                   .write = true, .address = 10, .count = 1, .periodMs = 100, .object = "measured",
                                   .offset = 14});
    return configuration;
}

} // namespace

TEST(ConfigurationRulesTest, AValidPollingSchedulePasses)
{
    EXPECT_TRUE(pollingConfiguration().check().ok());
}

TEST(ConfigurationRulesTest, APollEntryNamesASlaveAPeriodAndARangeThatFitsItsPage)
{
    Configuration configuration = pollingConfiguration();
    configuration.polls[0].unit = 0;
    ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::SlaveAddressOutOfRange, ObjectKind::ModbusPollEntry, "speed");
    configuration.polls[0].unit = 248;
    EXPECT_EQ(configuration.check().value, 248u);
    configuration.polls[0].unit = 247;
    EXPECT_TRUE(configuration.check().ok());
    configuration.polls[0].periodMs = 0;
    expectBroken(configuration.check(), ConfigurationRule::PollPeriodOutOfRange, ObjectKind::ModbusPollEntry, "speed");
    configuration.polls[0].periodMs = 3600001;
    EXPECT_EQ(configuration.check().rule, ConfigurationRule::PollPeriodOutOfRange);
    configuration.polls[0].periodMs = 3600000;
    EXPECT_TRUE(configuration.check().ok());
    // Eight registers fill the page; nine do not.
    configuration.polls[0].count = 9;
    error = configuration.check();
    expectBroken(error, ConfigurationRule::MapTooLarge, ObjectKind::ModbusPollEntry, "speed");
    EXPECT_EQ(error.value, 18u);
    EXPECT_EQ(error.limit, 16u);
    configuration.polls[0].count = 0;
    EXPECT_EQ(configuration.check().rule, ConfigurationRule::MapRangeEmpty);
    configuration.polls[0].count = 2;
    configuration.polls[0].address = 65535;
    EXPECT_EQ(configuration.check().rule, ConfigurationRule::MapAddressPastEnd);
    configuration.polls[0].address = 0;
    configuration.polls[0].object = "pressure";
    expectBroken(configuration.check(), ConfigurationRule::MapObjectNotDeclared, ObjectKind::ModbusPollEntry, "speed");
}

TEST(ConfigurationRulesTest, APollReadIsItsPublishersOnlyWriter)
{
    // The application's own publication cannot take a slave's answers.
    Configuration owned = pollingConfiguration();
    owned.polls[0].object = "measured";
    expectBroken(owned.check(), ConfigurationRule::PollPublisherHasWriter, ObjectKind::ModbusPollEntry, "speed");
    // Nor can a publisher the slave's map writes (holding registers 0-7 are "setpoint").
    Configuration shared = pollingConfiguration();
    shared.polls[0].object = "setpoint";
    expectBroken(shared.check(), ConfigurationRule::PollPublisherHasWriter, ObjectKind::ModbusPollEntry, "speed");
    // A write reads any publisher; it only writes the slave's coils or holding registers.
    Configuration writes = pollingConfiguration();
    writes.polls[1].object = "setpoint";
    writes.polls[1].offset = 0;
    EXPECT_TRUE(writes.check().ok());
    writes.polls[1].table = ModbusTable::InputRegisters;
    expectBroken(writes.check(), ConfigurationRule::PollWritesReadOnlyTable, ObjectKind::ModbusPollEntry,
                 "setpoint");
}

TEST(ConfigurationRulesTest, TheMastersLineHasABaudRateATimeOutAndRetries)
{
    Configuration configuration = pollingConfiguration();
    configuration.master.baud = 115201;
    ConfigurationError error = configuration.check();
    expectBroken(error, ConfigurationRule::BaudOutOfRange, ObjectKind::ModbusMaster, "demo");
    configuration.master.baud = 300;
    configuration.master.timeoutMs = 0;
    expectBroken(configuration.check(), ConfigurationRule::TimeoutOutOfRange, ObjectKind::ModbusMaster, "demo");
    configuration.master.timeoutMs = 60001;
    EXPECT_EQ(configuration.check().value, 60001u);
    configuration.master.timeoutMs = 60000;
    configuration.master.retries = 16;
    error = configuration.check();
    expectBroken(error, ConfigurationRule::RetriesOutOfRange, ObjectKind::ModbusMaster, "demo");
    EXPECT_EQ(message("demo", error), "application 'demo' not started: Modbus master 'demo' has too many retries "
                                      "(at most 15) (16, limit 15)");
    configuration.master.retries = 15;
    EXPECT_TRUE(configuration.check().ok());
    // Without a schedule the master's settings are not looked at.
    configuration.polls.clear();
    configuration.master.baud = 7;
    EXPECT_TRUE(configuration.check().ok());
}

TEST(ConfigurationRulesTest, AScheduleHasAtMostSixteenUniquelyNamedEntries)
{
    Configuration twice = pollingConfiguration();
    twice.polls.push_back(twice.polls[0]);
    expectBroken(twice.check(), ConfigurationRule::DuplicateName, ObjectKind::ModbusPollEntry, "speed");
    Configuration crowd = pollingConfiguration();
    std::vector<std::string> names;
    for (size_t i = crowd.polls.size(); i <= dcos::app::kMaximumModbusPollEntries; ++i) {
        names.push_back("poll" + std::to_string(i));
    }
    for (const std::string& name : names) {
        crowd.polls.push_back(crowd.polls[0]);
        crowd.polls.back().name = name.c_str();
    }
    const ConfigurationError error = crowd.check();
    EXPECT_EQ(error.rule, ConfigurationRule::TooManyObjects);
    EXPECT_EQ(error.value, dcos::app::kMaximumModbusPollEntries + 1);
}
