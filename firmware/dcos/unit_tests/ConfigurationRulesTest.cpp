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
    static std::vector<std::string> names;
    names.clear();
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
