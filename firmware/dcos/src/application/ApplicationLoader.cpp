// The application loader: all of an application's objects, or none of them.
#include <dcos/internal/ApplicationLoader.hpp>
#include <dcos/internal/ApplicationService.hpp>

#include <dcos/BufferPoolAgent.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/internal/ConfigurationReport.hpp>
#include <dcos/internal/KernelConfiguration.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/Scheduler.hpp>

#include <bsp/Board.hpp>

// Provided by the linker: the bounds of the dcos_application_services section.
extern const dcos::internal::ApplicationService __start_dcos_application_services[];
extern const dcos::internal::ApplicationService __stop_dcos_application_services[];

namespace dcos::internal {

const ApplicationService* applicationServicesBegin() { return __start_dcos_application_services; }
const ApplicationService* applicationServicesEnd() { return __stop_dcos_application_services; }

ApplicationLoader::State ApplicationLoader::state_ = ApplicationLoader::State::None;
app::ConfigurationError ApplicationLoader::lastError_{};

namespace {

using app::ConfigurationError;
using app::ConfigurationRule;
using app::ObjectKind;
using app::rules::broken;

// What the loader does with each kind of declaration. Every agent names its
// objects and hands them over the same way; only Create's arguments differ.
Result<ObjectId> createObject(const app::SemaphoreDeclaration& declaration)
{
    SemaphoreAttributes attributes;
    attributes.name = declaration.name;
    attributes.kind = declaration.kind;
    attributes.initialCount = declaration.initialCount;
    attributes.maximumCount = declaration.maximumCount;
    attributes.priorityInheritance = declaration.priorityInheritance;
    attributes.order = declaration.order;
    attributes.visibility = declaration.visibility;
    return semaphoreAgent.Create(attributes);
}

Result<ObjectId> createObject(const app::MessagePortDeclaration& declaration)
{
    return messagePortAgent.Create(declaration.name, declaration.visibility, declaration.order);
}

Result<ObjectId> createObject(const app::PublisherDeclaration& declaration)
{
    return dsmAgent.Create(declaration.name, declaration.visibility);
}

Result<ObjectId> createObject(const app::BufferPoolDeclaration& declaration)
{
    return bufferPoolAgent.Create(declaration.area, declaration.areaBytes, declaration.bufferSize, declaration.name,
                                  declaration.visibility);
}

Result<ObjectId> createObject(const app::HeapDeclaration& declaration)
{
    return heapAgent.Create(declaration.area, declaration.areaBytes, declaration.name, declaration.visibility);
}

Result<ObjectId> createObject(const app::TaskDeclaration& declaration)
{
    return taskAgent.Create(declaration.attributes(), declaration.entry, declaration.argument);
}

struct KindServices {
    ObjectKind kind;
    Result<ObjectId> (*nameToObject)(const char* name);
    Status (*remove)(ObjectId id);
    Status (*addObjects)(size_t count);
    Status (*transfer)(ObjectId id, ObjectId newOwner);
    size_t capacity; ///< The table's size, for the message when it is full.
};

// The services of an agent whose objects are named, deleted, added and
// handed over the same way (all but the task agent).
template <const auto& agent>
constexpr KindServices servicesOf(ObjectKind kind, size_t capacity)
{
    return KindServices{kind,
                        [](const char* name) { return agent.NameToObject(name); },
                        [](ObjectId id) { return agent.Delete(id); },
                        [](size_t count) { return agent.AddObjects(count); },
                        [](ObjectId id, ObjectId owner) { return agent.XferOwnership(id, owner); },
                        capacity};
}

// A declaration type with no services below is a compile-time error.
template <class Declaration>
consteval KindServices noServicesFor()
{
    static_assert(sizeof(Declaration) == 0, "the loader has no services for this kind of declaration");
    return {};
}

// The services of each kind of declaration.
template <class Declaration>
constexpr KindServices kindServices = noServicesFor<Declaration>();

// A task is ended with KillTask, and the loader never hands one over.
template <>
constexpr KindServices kindServices<app::TaskDeclaration>{
    ObjectKind::Task, [](const char* name) { return taskAgent.NameToObject(name); },
    [](ObjectId id) { return taskAgent.KillTask(id); }, [](size_t count) { return taskAgent.AddObjects(count); },
    nullptr, kTaskCapacity};
template <>
constexpr KindServices kindServices<app::SemaphoreDeclaration> =
    servicesOf<semaphoreAgent>(ObjectKind::Semaphore, kSemaphoreCapacity);
template <>
constexpr KindServices kindServices<app::MessagePortDeclaration> =
    servicesOf<messagePortAgent>(ObjectKind::MessagePort, kPortCapacity);
template <>
constexpr KindServices kindServices<app::PublisherDeclaration> =
    servicesOf<dsmAgent>(ObjectKind::Publisher, kPublisherCapacity);
template <>
constexpr KindServices kindServices<app::BufferPoolDeclaration> =
    servicesOf<bufferPoolAgent>(ObjectKind::BufferPool, kPoolCapacity);
template <>
constexpr KindServices kindServices<app::HeapDeclaration> = servicesOf<heapAgent>(ObjectKind::Heap, kHeapCapacity);

// Slots are activated in groups of eight (ObjectTable::AddObjects).
constexpr size_t kSlotGroup = 8;


template <class Declaration>
ConfigurationError checkNamesUnused(const app::DeclarationList<Declaration>& list)
{
    const KindServices& services = kindServices<Declaration>;
    for (const Declaration& declaration : list) {
        if (services.nameToObject(declaration.name).ok()) {
            return broken(ConfigurationRule::NameInUse, services.kind, declaration.name);
        }
    }
    return {};
}

// Creates the objects of one list; @p created counts those that exist, for the roll-back.
template <class Declaration>
ConfigurationError createAll(const app::DeclarationList<Declaration>& list, size_t& created)
{
    const KindServices& services = kindServices<Declaration>;
    for (const Declaration& declaration : list) {
        Result<ObjectId> id = createObject(declaration);
        if (!id.ok() && id.status() == Status::TableFull) {
            // The table has room beyond its active slots: activate a group
            // (a configuration service, which the loader may use as root).
            const Status added = services.addObjects(kSlotGroup);
            if (added != Status::Ok) {
                // value: the table's used slots with this object; limit: its size.
                return broken(ConfigurationRule::TooManyObjects, services.kind, declaration.name,
                              services.capacity + 1, services.capacity);
            }
            id = createObject(declaration);
        }
        if (!id.ok()) {
            return broken(ConfigurationRule::CreateFailed, services.kind, declaration.name,
                          static_cast<size_t>(id.status()));
        }
        ++created;
    }
    return {};
}

// Hands every object to its declared owner and stores the ids.
template <class Declaration>
ConfigurationError handOver(const app::DeclarationList<Declaration>& list)
{
    const KindServices& services = kindServices<Declaration>;
    for (const Declaration& declaration : list) {
        const ObjectId id = services.nameToObject(declaration.name).value();
        if (const char* owner = app::ownerOf(declaration); owner != nullptr) {
            const Result<ObjectId> task = taskAgent.NameToObject(owner);
            const Status transferred = task.ok() ? services.transfer(id, task.value()) : task.status();
            if (transferred != Status::Ok) {
                return broken(ConfigurationRule::CreateFailed, services.kind, declaration.name,
                              static_cast<size_t>(transferred));
            }
        }
        if (declaration.id != nullptr) {
            *declaration.id = id;
        }
    }
    return {};
}

// Deletes the first @p count objects of a list, last first. The names were
// checked unused before any was created, so each name finds the loader's object.
template <class Declaration>
unsigned removeFirst(const app::DeclarationList<Declaration>& list, size_t count)
{
    const KindServices& services = kindServices<Declaration>;
    unsigned removed = 0;
    for (size_t i = count; i-- > 0;) {
        const Result<ObjectId> id = services.nameToObject(list[i].name);
        if (id.ok() && services.remove(id.value()) == Status::Ok) {
            ++removed;
        }
        if (list[i].id != nullptr) {
            *list[i].id = ObjectId{};
        }
    }
    return removed;
}

// How far creation got, for the roll-back.
struct Progress {
    size_t semaphores = 0;
    size_t ports = 0;
    size_t publishers = 0;
    size_t pools = 0;
    size_t heaps = 0;
    size_t tasks = 0;
};

unsigned rollBack(const app::Application& application, const Progress& progress)
{
    // Tasks first: none has run yet, and killing them first means no task
    // ever sees one of its objects vanish.
    return removeFirst(application.tasks, progress.tasks) + removeFirst(application.heaps, progress.heaps)
         + removeFirst(application.bufferPools, progress.pools) + removeFirst(application.publishers, progress.publishers)
         + removeFirst(application.messagePorts, progress.ports) + removeFirst(application.semaphores, progress.semaphores);
}

ConfigurationError createEverything(const app::Application& application, Progress& progress)
{
    // One step after the other, stopping at the first failure. Tasks come
    // last, so that every object a task is handed exists.
    ConfigurationError error = createAll(application.semaphores, progress.semaphores);
    if (error.ok()) error = createAll(application.messagePorts, progress.ports);
    if (error.ok()) error = createAll(application.publishers, progress.publishers);
    if (error.ok()) error = createAll(application.bufferPools, progress.pools);
    if (error.ok()) error = createAll(application.heaps, progress.heaps);
    if (error.ok()) error = createAll(application.tasks, progress.tasks);
    if (error.ok()) error = handOver(application.tasks);
    if (error.ok()) error = handOver(application.semaphores);
    if (error.ok()) error = handOver(application.messagePorts);
    if (error.ok()) error = handOver(application.publishers);
    if (error.ok()) error = handOver(application.bufferPools);
    if (error.ok()) error = handOver(application.heaps);
    return error;
}

ConfigurationError checkOnNode(const app::Application& application)
{
    ConfigurationError error = app::findConfigurationError(application);
    if (error.ok()) error = checkNamesUnused(application.tasks);
    if (error.ok()) error = checkNamesUnused(application.semaphores);
    if (error.ok()) error = checkNamesUnused(application.messagePorts);
    if (error.ok()) error = checkNamesUnused(application.publishers);
    if (error.ok()) error = checkNamesUnused(application.bufferPools);
    if (error.ok()) error = checkNamesUnused(application.heaps);
    return error;
}

void printCount(runtime::CharacterSink& console, size_t count, const char* kind, bool& first)
{
    if (count == 0) {
        return;
    }
    runtime::format(console, "%s%lu %s%s", first ? "" : ", ", static_cast<unsigned long>(count), kind,
                    count == 1 ? "" : "s");
    first = false;
}

// Stops the services before @p end, last first.
void stopServices(const app::Application& application, const ApplicationService* end)
{
    for (const ApplicationService* service = end; service-- != applicationServicesBegin();) {
        service->stop(application);
    }
}

// Starts every driver's service; when one refuses, those before it are
// stopped again and its error is the application's.
ConfigurationError startServices(const app::Application& application)
{
    for (const ApplicationService* service = applicationServicesBegin(); service != applicationServicesEnd();
         ++service) {
        if (ConfigurationError error = service->start(application); !error.ok()) {
            stopServices(application, service);
            return error;
        }
    }
    return {};
}

} // namespace

app::ConfigurationError ApplicationLoader::start(const app::Application& application)
{
    if (!currentTaskIsSuperUser()) {
        return broken(ConfigurationRule::CreateFailed, ObjectKind::Application, application.name,
                      static_cast<size_t>(Status::NotPermitted));
    }
    if (ConfigurationError error = checkOnNode(application); !error.ok()) {
        return error;
    }
    // No new task may run before every object exists and every id is
    // stored: a task would otherwise find its port's id still null.
    Scheduler::holdDispatch();
    Progress progress;
    ConfigurationError error = createEverything(application, progress);
    if (error.ok()) {
        error = startServices(application);
    }
    if (!error.ok()) {
        rollBack(application, progress);
    }
    Scheduler::releaseDispatch();
    return error;
}

unsigned ApplicationLoader::stop(const app::Application& application)
{
    Progress all;
    all.tasks = application.tasks.count;
    all.semaphores = application.semaphores.count;
    all.ports = application.messagePorts.count;
    all.publishers = application.publishers.count;
    all.pools = application.bufferPools.count;
    all.heaps = application.heaps.count;
    Scheduler::holdDispatch();
    stopServices(application, applicationServicesEnd());
    const unsigned removed = rollBack(application, all);
    Scheduler::releaseDispatch();
    return removed;
}

Result<ObjectId> ApplicationLoader::find(app::ObjectKind kind, const char* name)
{
    switch (kind) {
    case ObjectKind::Task: return kindServices<app::TaskDeclaration>.nameToObject(name);
    case ObjectKind::Semaphore: return kindServices<app::SemaphoreDeclaration>.nameToObject(name);
    case ObjectKind::MessagePort: return kindServices<app::MessagePortDeclaration>.nameToObject(name);
    case ObjectKind::Publisher: return kindServices<app::PublisherDeclaration>.nameToObject(name);
    case ObjectKind::BufferPool: return kindServices<app::BufferPoolDeclaration>.nameToObject(name);
    case ObjectKind::Heap: return kindServices<app::HeapDeclaration>.nameToObject(name);
    case ObjectKind::Application:
    case ObjectKind::ModbusMapEntry:
    case ObjectKind::ModbusSlave:
    case ObjectKind::ModbusPollEntry:
    case ObjectKind::ModbusMaster: break; // None is an object of the node.
    }
    return Status::InvalidArgument;
}

const app::Application* ApplicationLoader::linked() { return linkedApplication(); }

void ApplicationLoader::startLinked()
{
    const app::Application* application = linked();
    if (application == nullptr) {
        return;
    }
    runtime::CharacterSink& console = bsp::console();
    // Held over the report too, so that the line saying the application
    // started comes before anything its tasks print.
    Scheduler::holdDispatch();
    lastError_ = start(*application);
    if (!lastError_.ok()) {
        state_ = State::Rejected;
        formatConfigurationError(console, application->name, lastError_);
        runtime::format(console, "\r\n");
    } else {
        state_ = State::Running;
        runtime::format(console, "application '%s' started: ", application->name);
        bool first = true;
        printCount(console, application->tasks.count, "task", first);
        printCount(console, application->semaphores.count, "semaphore", first);
        printCount(console, application->messagePorts.count, "message port", first);
        printCount(console, application->publishers.count, "publisher", first);
        printCount(console, application->bufferPools.count, "buffer pool", first);
        printCount(console, application->heaps.count, "heap", first);
        runtime::format(console, "%s\r\n", first ? "no objects" : "");
    }
    Scheduler::releaseDispatch();
}

} // namespace dcos::internal
