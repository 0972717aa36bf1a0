// The application loader on the target: configurations built at run time,
// which the compiler never checked, are created all or nothing; the ids are
// stored before any task runs; objects go to their declared owners; and a
// failure part way names the object and leaves the node as it was.
#include "KernelTestSupport.hpp"

#include <dcos/Application.hpp>
#include <dcos/BufferPoolAgent.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/internal/ApplicationLoader.hpp>
#include <dcos/internal/ConfigurationReport.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/StackArena.hpp>

#include <runtime/Text.hpp>

namespace target_test {

namespace {

using dcos::Message;
using dcos::messagePortAgent;
using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using dcos::taskAgent;
using dcos::app::ConfigurationError;
using dcos::app::ConfigurationRule;
using dcos::app::ObjectKind;
using dcos::internal::ApplicationLoader;

constexpr uint64_t kSecond = 1000000000ull;

// Prints the loader's message and checks the rule and the object it names.
bool expectRejected(shell::Shell& shell, const ConfigurationError& error, ConfigurationRule rule, ObjectKind kind,
                    const char* object)
{
    dcos::internal::formatConfigurationError(shell.output(), "loadertest", error);
    shell.print("\r\n");
    bool ok = check(shell, error.rule == rule, "the rule broken");
    ok &= check(shell, error.kind == kind, "the kind of object named");
    ok &= check(shell, error.object != nullptr && runtime::textEquals(error.object, object),
                "the object named");
    return ok;
}

// Whether any object of the configuration is left on the node.
template <class Declaration>
bool noneLeft(shell::Shell& shell, ObjectKind kind, const dcos::app::DeclarationList<Declaration>& list)
{
    bool ok = true;
    for (const Declaration& declaration : list) {
        if (ApplicationLoader::find(kind, declaration.name).ok()) {
            shell.print("left behind: %s '%s'\r\n", dcos::app::objectKindName(kind), declaration.name);
            ok = false;
        }
    }
    return ok;
}

bool nothingLeft(shell::Shell& shell, const dcos::app::Application& application)
{
    return noneLeft(shell, ObjectKind::Task, application.tasks)
         & noneLeft(shell, ObjectKind::Semaphore, application.semaphores)
         & noneLeft(shell, ObjectKind::MessagePort, application.messagePorts)
         & noneLeft(shell, ObjectKind::Publisher, application.publishers)
         & noneLeft(shell, ObjectKind::BufferPool, application.bufferPools)
         & noneLeft(shell, ObjectKind::Heap, application.heaps);
}

// --- A whole application, started and stopped --------------------------------

ObjectId commandsPort;
ObjectId levelPublisher;
ObjectId busSemaphore;
ObjectId framesPool;
ObjectId workHeap;
ObjectId controllerTask;
ObjectId operatorTask;
// What the controller saw when it first ran: every id already stored.
bool idsStoredBeforeFirstRun;
uint32_t receivedCommand;
Status writeStatus;

alignas(8) uint8_t framesArea[dcos::BufferPoolAgent::AreaBytes(32, 8)];
alignas(8) uint8_t workArea[1024];

void controller(uintptr_t)
{
    idsStoredBeforeFirstRun = !commandsPort.isNull() && !levelPublisher.isNull() && !busSemaphore.isNull()
                            && !framesPool.isNull() && !workHeap.isNull() && !operatorTask.isNull();
    // The port was handed to this task: only its owner may receive.
    Message message{};
    if (messagePortAgent.Receive(commandsPort, message, 2 * kSecond) == Status::Ok) {
        receivedCommand = message.bytes[0];
    }
    // The publisher was handed to this task: only its writer may write.
    dcos::DsmPage page{};
    writeStatus = dcos::dsmAgent.Write(levelPublisher, page).status();
    finished();
    (void)taskAgent.ReceiveEvent(1u << 3, dcos::EventWait::Any, dcos::kWaitForever);
}

void operatorEntry(uintptr_t)
{
    Message message{};
    message.bytes[0] = 42;
    (void)messagePortAgent.Send(commandsPort, message, 0);
    finished();
    (void)taskAgent.ReceiveEvent(1u << 3, dcos::EventWait::Any, dcos::kWaitForever);
}

constexpr dcos::app::TaskDeclaration wholeTasks[] = {
    {.name = "ldcontroller", .entry = controller, .priority = 2, .id = &controllerTask},
    {.name = "ldoperator", .entry = operatorEntry, .priority = 3, .id = &operatorTask},
};
constexpr dcos::app::SemaphoreDeclaration wholeSemaphores[] = {
    {.name = "ldbus", .owner = "ldoperator", .id = &busSemaphore}};
constexpr dcos::app::MessagePortDeclaration wholePorts[] = {
    {.name = "ldcommands", .receiver = "ldcontroller", .id = &commandsPort}};
constexpr dcos::app::PublisherDeclaration wholePublishers[] = {
    {.name = "ldlevel", .writer = "ldcontroller", .id = &levelPublisher}};
constexpr dcos::app::BufferPoolDeclaration wholePools[] = {
    {.name = "ldframes", .area = framesArea, .areaBytes = sizeof framesArea, .bufferSize = 32, .id = &framesPool}};
constexpr dcos::app::HeapDeclaration wholeHeaps[] = {
    {.name = "ldwork", .area = workArea, .areaBytes = sizeof workArea, .owner = "ldcontroller", .id = &workHeap}};
constexpr dcos::app::Application whole{.name = "loadertest",
                                       .tasks = wholeTasks,
                                       .semaphores = wholeSemaphores,
                                       .messagePorts = wholePorts,
                                       .publishers = wholePublishers,
                                       .bufferPools = wholePools,
                                       .heaps = wholeHeaps};
static_assert(dcos::internal::ConfigurationCheck<whole>::passed);

bool startAndStop(shell::Shell& shell)
{
    const size_t stackBytesBefore = dcos::internal::StackArena::freeBytes();
    // The test task runs at priority 24, below the new tasks: they would
    // run at once if the loader did not hold them until every id is stored.
    const ConfigurationError error = ApplicationLoader::start(whole);
    bool ok = check(shell, error.ok(), "the application starts");
    ok &= waitForDone(shell, 2);
    ok &= check(shell, idsStoredBeforeFirstRun, "every id is stored before the first task runs");
    ok &= check(shell, receivedCommand == 42, "the port was handed to its receiver");
    ok &= checkStatus(shell, writeStatus, Status::Ok, "the publisher was handed to its writer");
    // Objects with an owner moved to it; the test task may not delete them.
    ok &= checkStatus(shell, messagePortAgent.Delete(commandsPort), Status::Ok, "a super user may still delete");
    ok &= checkStatus(shell, messagePortAgent.XferOwnership(commandsPort, ObjectId{}), Status::StaleId,
                      "the deleted port's id is stale");
    // The semaphore went to its declared owner: it goes when its owner ends.
    ok &= checkStatus(shell, taskAgent.KillTask(operatorTask), Status::Ok, "the operator task ends");
    ok &= checkStatus(shell, dcos::semaphoreAgent.GetCount(busSemaphore).status(), Status::StaleId,
                      "its owner's end took the semaphore with it");
    // The pool has no owner: it is the system's and outlives every task.
    ok &= checkStatus(shell, dcos::bufferPoolAgent.GetStatistics(framesPool).status(), Status::Ok,
                      "the system's pool is still there");

    const unsigned removed = ApplicationLoader::stop(whole);
    shell.print("stop removed %u objects\r\n", removed);
    // Stop kills the controller first, and the recovery of its objects takes
    // the publisher and the heap it owns; stop itself deletes the system's pool.
    ok &= check(shell, removed == 2, "stop removes the controller task and the pool; recovery the rest");
    ok &= nothingLeft(shell, whole);
    ok &= check(shell, commandsPort.isNull() && controllerTask.isNull(), "stop clears the stored ids");
    ok &= check(shell, dcos::internal::StackArena::freeBytes() == stackBytesBefore, "every stack is returned");
    return ok;
}

// --- Rules the compiler checks, checked again at run time --------------------

void idle(uintptr_t) { (void)taskAgent.ReceiveEvent(1, dcos::EventWait::Any, dcos::kWaitForever); }

bool rulesAtRunTime(shell::Shell& shell)
{
    bool ok = true;
    dcos::app::TaskDeclaration tasks[] = {
        {.name = "ldfirst", .entry = idle, .priority = 10},
        {.name = "ldsecond", .entry = idle, .priority = 10},
    };
    dcos::app::Application application{.name = "loadertest", .tasks = tasks};

    tasks[1].priority = 32;
    ok &= expectRejected(shell, ApplicationLoader::start(application), ConfigurationRule::PriorityOutOfRange,
                         ObjectKind::Task, "ldsecond");
    tasks[1].priority = 10;
    tasks[1].stackSize = 512;
    ok &= expectRejected(shell, ApplicationLoader::start(application), ConfigurationRule::StackTooSmall,
                         ObjectKind::Task, "ldsecond");
    tasks[1].stackSize = 4096;
    tasks[1].name = "ldfirst";
    ok &= expectRejected(shell, ApplicationLoader::start(application), ConfigurationRule::DuplicateName,
                         ObjectKind::Task, "ldfirst");
    tasks[1].name = "shell";
    ok &= expectRejected(shell, ApplicationLoader::start(application), ConfigurationRule::ReservedName,
                         ObjectKind::Task, "shell");
    tasks[1].name = "ldsecond";
    ok &= nothingLeft(shell, application);
    return ok;
}

// --- Failures only the running node finds ------------------------------------

bool nameInUse(shell::Shell& shell)
{
    // A semaphore of the node already has the name the configuration wants.
    dcos::SemaphoreAttributes attributes;
    attributes.name = "ldtaken";
    const ObjectId existing = dcos::semaphoreAgent.Create(attributes).value();
    dcos::app::TaskDeclaration tasks[] = {{.name = "ldfirst", .entry = idle}};
    dcos::app::SemaphoreDeclaration semaphores[] = {{.name = "ldfree"}, {.name = "ldtaken"}};
    dcos::app::Application application{.name = "loadertest", .tasks = tasks, .semaphores = semaphores};
    bool ok = expectRejected(shell, ApplicationLoader::start(application), ConfigurationRule::NameInUse,
                             ObjectKind::Semaphore, "ldtaken");
    ok &= noneLeft(shell, ObjectKind::Task, application.tasks);
    ok &= check(shell, !ApplicationLoader::find(ObjectKind::Semaphore, "ldfree").ok(), "nothing was created");
    ok &= checkStatus(shell, dcos::semaphoreAgent.Delete(existing), Status::Ok, "the node's own semaphore is kept");
    return ok;
}

bool fullTableRollsBack(shell::Shell& shell)
{
    // Fill the port table but for three slots; the configuration wants five.
    static ObjectId filler[dcos::internal::kPortCapacity];
    size_t made = 0;
    for (; made < dcos::internal::kPortCapacity; ++made) {
        Result<ObjectId> port = messagePortAgent.Create(nullptr, dcos::Visibility::Local);
        if (!port.ok() && port.status() == Status::TableFull && messagePortAgent.AddObjects(8) == Status::Ok) {
            port = messagePortAgent.Create(nullptr, dcos::Visibility::Local);
        }
        if (!port.ok()) {
            break;
        }
        filler[made] = port.value();
    }
    bool ok = check(shell, made == dcos::internal::kPortCapacity, "the port table fills up");
    for (size_t i = 0; i < 3; ++i) {
        (void)messagePortAgent.Delete(filler[--made]);
    }
    const size_t stackBytesBefore = dcos::internal::StackArena::freeBytes();
    dcos::app::TaskDeclaration tasks[] = {{.name = "ldfirst", .entry = idle}};
    dcos::app::SemaphoreDeclaration semaphores[] = {{.name = "ldsem"}};
    dcos::app::MessagePortDeclaration ports[] = {
        {.name = "ldp1", .receiver = "ldfirst"}, {.name = "ldp2", .receiver = "ldfirst"},
        {.name = "ldp3", .receiver = "ldfirst"}, {.name = "ldp4", .receiver = "ldfirst"},
        {.name = "ldp5", .receiver = "ldfirst"},
    };
    dcos::app::Application application{
        .name = "loadertest", .tasks = tasks, .semaphores = semaphores, .messagePorts = ports};
    const ConfigurationError error = ApplicationLoader::start(application);
    ok &= expectRejected(shell, error, ConfigurationRule::TooManyObjects, ObjectKind::MessagePort, "ldp4");
    ok &= check(shell, error.limit == dcos::internal::kPortCapacity, "the limit is the table's size");
    ok &= nothingLeft(shell, application);
    ok &= check(shell, dcos::internal::StackArena::freeBytes() == stackBytesBefore, "no stack was taken");
    while (made > 0) {
        (void)messagePortAgent.Delete(filler[--made]);
    }
    return ok;
}

bool stackArenaExhausted(shell::Shell& shell)
{
    // A task of the node holds all but 20 KiB of the stack arena: room for
    // two of the configuration's 4 KiB stacks with their guard pages (8 KiB
    // each), not three, which pass the rules but not the node.
    const size_t free = dcos::internal::StackArena::largestFreeBlock();
    dcos::TaskAttributes hog;
    hog.name = "ldhog";
    hog.priority = 30;
    hog.stackSize = free - dcos::internal::StackArena::kPageSize - 20 * 1024;
    const Result<ObjectId> hogTask = taskAgent.Create(hog, idle, 0);
    bool ok = check(shell, hogTask.ok(), "the hog task takes the arena");
    const size_t stackBytesBefore = dcos::internal::StackArena::freeBytes();
    dcos::app::TaskDeclaration tasks[] = {
        {.name = "ldone", .entry = idle, .priority = 1},
        {.name = "ldtwo", .entry = idle, .priority = 1},
        {.name = "ldthree", .entry = idle, .priority = 1},
    };
    dcos::app::PublisherDeclaration publishers[] = {{.name = "ldpub", .writer = "ldone"}};
    dcos::app::Application application{.name = "loadertest", .tasks = tasks, .publishers = publishers};
    const ConfigurationError error = ApplicationLoader::start(application);
    ok &= expectRejected(shell, error, ConfigurationRule::CreateFailed, ObjectKind::Task, "ldthree");
    ok &= check(shell, static_cast<Status>(error.value) == Status::NoMemory, "the agent said out of memory");
    ok &= nothingLeft(shell, application);
    ok &= check(shell, dcos::internal::StackArena::freeBytes() == stackBytesBefore, "the created stacks came back");
    if (hogTask.ok()) {
        ok &= checkStatus(shell, taskAgent.KillTask(hogTask.value()), Status::Ok, "the hog task ends");
    }
    return ok;
}

bool overlappingAreas(shell::Shell& shell)
{
    // Two pools declared over one area: the pool agent refuses the second.
    alignas(8) static uint8_t sharedArea[dcos::BufferPoolAgent::AreaBytes(16, 4)];
    dcos::app::TaskDeclaration tasks[] = {{.name = "ldfirst", .entry = idle}};
    dcos::app::BufferPoolDeclaration pools[] = {
        {.name = "ldpoola", .area = sharedArea, .areaBytes = sizeof sharedArea, .bufferSize = 16},
        {.name = "ldpoolb", .area = sharedArea, .areaBytes = sizeof sharedArea, .bufferSize = 16},
    };
    dcos::app::Application application{.name = "loadertest", .tasks = tasks, .bufferPools = pools};
    const ConfigurationError error = ApplicationLoader::start(application);
    bool ok = expectRejected(shell, error, ConfigurationRule::CreateFailed, ObjectKind::BufferPool, "ldpoolb");
    ok &= check(shell, static_cast<Status>(error.value) == Status::AlreadyExists, "the agent said already exists");
    ok &= nothingLeft(shell, application);
    return ok;
}

bool failuresOnTheNode(shell::Shell& shell)
{
    bool ok = nameInUse(shell);
    ok &= fullTableRollsBack(shell);
    ok &= stackArenaExhausted(shell);
    ok &= overlappingAreas(shell);
    return ok;
}

} // namespace

DCOS_TARGET_TEST(applicationStartTest, "appstart",
                 "application loader: every kind created, ids stored before tasks run, owners, stop", startAndStop);
DCOS_TARGET_TEST(applicationRulesTest, "apprules", "application loader: the compiler's rules, checked at run time",
                 rulesAtRunTime);
DCOS_TARGET_TEST(applicationFailureTest, "appfail",
                 "application loader: name in use, full table, no stack, overlapping areas; all rolled back",
                 failuresOnTheNode);

} // namespace target_test
