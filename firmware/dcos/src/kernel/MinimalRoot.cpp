// The root task of the minimal kernel configuration (dcos/internal/KernelConfiguration.hpp).
//
// The minimal kernel is the core alone: the system, scheduler, task and
// timer agents. It has no application loader, no console shell and none of
// the memory, port, DSM and semaphore agents, so the root task starts the
// linked application the simplest way: it creates the application's
// declared tasks, with dispatching held so that none runs before every id is
// stored, most urgent first once released. An application that declares an
// object of an agent this configuration leaves out (a semaphore, a message
// port, a publisher, a buffer pool, a heap, a Modbus map) is refused as a
// whole: none of its tasks starts, and the console says why. A call to such
// an agent's primitive cannot even be linked (see the guide,
// docs/guide/kernel-configurations.md).
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/KernelConfiguration.hpp>
#include <dcos/internal/Scheduler.hpp>

#include <bsp/Board.hpp>

namespace dcos::internal {

const char* const kKernelConfiguration = "minimal";

namespace {

// What the minimal configuration leaves out, by the declarations that need it.
const char* leftOutDeclaration(const app::Application& application)
{
    if (application.semaphores.count != 0) return "semaphores";
    if (application.messagePorts.count != 0) return "message ports";
    if (application.publishers.count != 0) return "DSM publishers";
    if (application.bufferPools.count != 0) return "buffer pools";
    if (application.heaps.count != 0) return "heaps";
    if (application.modbusMap.count != 0) return "a Modbus map";
    return nullptr;
}

Result<ObjectId> createTask(const app::TaskDeclaration& declaration)
{
    const TaskAttributes attributes = declaration.attributes();
    Result<ObjectId> task = taskAgent.Create(attributes, declaration.entry, declaration.argument);
    // The compiler checked the total against the table's capacity; the
    // slots beyond those active at boot are activated as they are needed.
    if (task.status() == Status::TableFull && taskAgent.AddObjects(8) == Status::Ok) {
        task = taskAgent.Create(attributes, declaration.entry, declaration.argument);
    }
    return task;
}

// Creates every declared task, or none: on a failure the ones created are ended.
Status startTasks(const app::Application& application, const char*& failed)
{
    size_t created = 0;
    Status status = Status::Ok;
    for (; created < application.tasks.count; ++created) {
        const app::TaskDeclaration& declaration = application.tasks[created];
        const Result<ObjectId> task = createTask(declaration);
        if (!task.ok()) {
            failed = declaration.name;
            status = task.status();
            break;
        }
        if (declaration.id != nullptr) {
            *declaration.id = task.value();
        }
    }
    if (status != Status::Ok) {
        while (created-- > 0) {
            const app::TaskDeclaration& declaration = application.tasks[created];
            const Result<ObjectId> task = taskAgent.NameToObject(declaration.name);
            if (task.ok()) {
                (void)taskAgent.KillTask(task.value());
            }
        }
    }
    return status;
}

void startLinkedApplication()
{
    runtime::CharacterSink& console = bsp::console();
    const app::Application* application = linkedApplication();
    if (application == nullptr) {
        runtime::format(console, "no application linked: the minimal kernel has nothing to run\r\n");
        return;
    }
    if (const char* leftOut = leftOutDeclaration(*application); leftOut != nullptr) {
        runtime::format(console, "application '%s' not started: it declares %s, which the minimal kernel "
                                 "configuration leaves out\r\n", application->name, leftOut);
        return;
    }
    // Held over the report too, so that the line saying the application
    // started comes before anything its tasks print.
    Scheduler::holdDispatch();
    const char* failed = nullptr;
    const Status started = startTasks(*application, failed);
    if (started == Status::Ok) {
        const size_t tasks = application->tasks.count;
        runtime::format(console, "application '%s' started: %u task%s\r\n", application->name,
                        static_cast<unsigned>(tasks), tasks == 1 ? "" : "s");
    } else {
        runtime::format(console, "application '%s' not started: task '%s': %s\r\n", application->name, failed,
                        statusName(started));
    }
    Scheduler::releaseDispatch();
}

} // namespace

void rootTaskEntry(uintptr_t)
{
    startLinkedApplication();
    // Nothing is left to do: wait for an event nobody posts to this task.
    for (;;) {
        (void)taskAgent.ReceiveEvent(1u << 0, EventWait::Any, kWaitForever);
    }
}

} // namespace dcos::internal
