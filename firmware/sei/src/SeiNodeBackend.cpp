#include <sei/SeiNodeBackend.hpp>

#include <boot/ConfigurationStore.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <image/ImageHeader.hpp>
#include <sja1000/BitTiming.hpp>

#include <arch_x86/Cpu.hpp>
#include <runtime/Text.hpp>
#include <dcos/BufferPoolAgent.hpp>
#include <dcos/DsmAgent.hpp>
#include <dcos/HeapAgent.hpp>
#include <dcos/MessagePortAgent.hpp>
#include <dcos/SemaphoreAgent.hpp>
#include <dcos/TaskAgent.hpp>
#include <dcos/TimerAgent.hpp>
#include <dcos/internal/KernelConfiguration.hpp>
#include <dcos/internal/NameService.hpp>
#include <dcos/internal/NetworkBootHooks.hpp>
#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/internal/PortManager.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/SemaphoreManager.hpp>
#include <dcos/internal/StackArena.hpp>
#include <dcos/internal/Task.hpp>
#include <dcos/internal/TaskManager.hpp>

namespace sei {

SeiIdentity SeiNodeBackend::identity()
{
    SeiIdentity identity;
    identity.nodeId = dcos::internal::localNode();
    identity.canNode = canNode_;
    identity.board = static_cast<uint8_t>(image::BoardType::Isa486);
    identity.serial = serial_;
    identity.versionText = versionText_;
    return identity;
}

SeiResult<SeiConfiguration> SeiNodeBackend::readConfiguration()
{
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store_);
    if (!stored.readable || !stored.present) {
        return SeiStatus::CardError;
    }
    read_ = stored.configuration;
    queriesClosed_ = read_.queriesClosed();
    queriesKnown_ = true;
    SeiConfiguration configuration;
    configuration.sequence = read_.sequence;
    configuration.nodeId = read_.nodeId;
    configuration.bitRate = read_.canBitRate;
    configuration.queriesClosed = read_.queriesClosed();
    configuration.lockoutSeconds = read_.lockoutSeconds;
    configuration.commandLine = read_.commandLine;
    return configuration;
}

template <typename Change>
SeiResult<uint32_t> SeiNodeBackend::rewrite(Change change)
{
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store_);
    if (!stored.readable || !stored.present) {
        // A node without a valid record has no keys either; it cannot be
        // here, but a record that went bad since the start is not replaced
        // by one made from nothing.
        return SeiStatus::CardError;
    }
    boot::ConfigurationBlock next = stored.configuration;
    change(next);
    uint32_t sequence = 0;
    if (!boot::ConfigurationStore::writeNext(store_, stored, next, sequence)) {
        return SeiStatus::CardError;
    }
    return sequence;
}

SeiResult<uint32_t> SeiNodeBackend::writeNodeId(uint16_t nodeId)
{
    return rewrite([nodeId](boot::ConfigurationBlock& block) { block.nodeId = nodeId; });
}

SeiResult<uint32_t> SeiNodeBackend::writeBitRate(uint32_t bitRate)
{
    return rewrite([bitRate](boot::ConfigurationBlock& block) { block.canBitRate = bitRate; });
}

bool SeiNodeBackend::bitRateValid(uint32_t bitRate)
{
    return sja1000::BitTimingCalculator::forBitRate(bitRate).ok();
}

} // namespace sei

// The management commands (seed 7.14): the kernel's own services, called by
// the system engineering interface agent's task, which is a super-user
// task. What the kernel refuses goes back to the host as its dcos::Status.
namespace sei {

namespace {

using dcos::ObjectId;
using dcos::ObjectType;
using dcos::Status;
using dcos::internal::ObjectSummary;
using dcos::internal::ObjectTableView;

constexpr uint8_t statusValue(Status status)
{
    return static_cast<uint8_t>(status);
}

// The object types the node keeps tables of, in the order NodeStatistics
// lists them.
constexpr ObjectType kListedTypes[] = {ObjectType::Task,        ObjectType::Timer,        ObjectType::Device,
                                       ObjectType::BufferPool,  ObjectType::Heap,         ObjectType::MessagePort,
                                       ObjectType::DsmPublisher, ObjectType::Semaphore};
static_assert(sizeof kListedTypes / sizeof kListedTypes[0] <= kSeiMaxTables, "NodeStatistics carries every table");

uint8_t nameLength(const char* name)
{
    uint8_t length = 0;
    while (length < kSeiMaxName && name[length] != '\0') {
        ++length;
    }
    return length;
}

// A name of @p length bytes (not terminated), terminated in @p out; false
// when it holds a NUL, which no name the kernel stores can.
bool terminatedName(const char* name, uint8_t length, char (&out)[kSeiMaxName + 1])
{
    for (uint8_t i = 0; i < length; ++i) {
        if (name[i] == '\0') {
            return false;
        }
        out[i] = name[i];
    }
    out[length] = '\0';
    return true;
}

// Whether the node already has an object of @p type named @p name: the
// bus names objects to find them again (FindObject, a restore), so it
// never makes a second one of a name, though the kernel would.
bool nameTaken(ObjectType type, const char* name)
{
    return name != nullptr && dcos::internal::localNameToObject(type, name, dcos::Visibility::Local).ok();
}

// Hands an object the agent's task created to the system, so that it lives
// until it is deleted, not until the agent's task ends.
template <typename Transfer>
uint8_t keepForSystem(const dcos::Result<ObjectId>& created, uint32_t& id, Transfer transfer)
{
    if (!created.ok()) {
        return statusValue(created.status());
    }
    (void)transfer(created.value());
    id = created.value().raw();
    return 0;
}

} // namespace

uint8_t SeiNodeBackend::listObjects(uint8_t type, uint16_t first, SeiMessage& reply)
{
    const dcos::Result<ObjectTableView> table = dcos::internal::objectTableOf(static_cast<ObjectType>(type));
    if (!table.ok()) {
        return statusValue(table.status());
    }
    // A page is a run of table slots from @p first (slots, not ids: an id's
    // index names a slot only while its object lives); the reply's "next" is
    // the slot to ask from for the rest.
    reply.entryCount = 0;
    reply.next = kSeiListEnd;
    for (size_t slot = first; slot < table.value().active; ++slot) {
        ObjectSummary summary;
        if (!dcos::internal::objectAt(table.value(), slot, summary)) {
            continue;
        }
        if (reply.entryCount == kSeiMaxListEntries) {
            reply.next = static_cast<uint16_t>(slot);
            break;
        }
        const size_t at = reply.entryCount++;
        for (size_t i = 0; i <= kSeiMaxName; ++i) {
            names_[at][i] = summary.name[i];
        }
        SeiObjectEntry& entry = reply.entries[at];
        entry.id = summary.id.raw();
        entry.owner = summary.owner.raw();
        entry.name = names_[at];
        entry.nameLength = nameLength(names_[at]);
    }
    return 0;
}

uint8_t SeiNodeBackend::findObject(uint8_t type, const char* name, uint8_t length, uint32_t& id)
{
    char terminated[kSeiMaxName + 1];
    if (length == 0 || !terminatedName(name, length, terminated)) {
        return statusValue(Status::InvalidArgument);
    }
    if (!dcos::internal::objectTableOf(static_cast<ObjectType>(type)).ok()) {
        return statusValue(Status::InvalidArgument);
    }
    // The node's own objects, whatever their visibility: the host asks this
    // node about itself, as its console would.
    const dcos::Result<ObjectId> found =
        dcos::internal::localNameToObject(static_cast<ObjectType>(type), terminated, dcos::Visibility::Local);
    if (!found.ok()) {
        return statusValue(found.status());
    }
    id = found.value().raw();
    return 0;
}

uint8_t SeiNodeBackend::objectInfo(uint32_t raw, SeiMessage& reply)
{
    const ObjectId id = ObjectId::fromRaw(raw);
    if (id.node() != dcos::internal::localNode()) {
        return statusValue(id.isNull() ? Status::InvalidId : Status::Remote);
    }
    const dcos::Result<ObjectTableView> table = dcos::internal::objectTableOf(id.type());
    if (!table.ok()) {
        return statusValue(id.isNull() ? Status::InvalidId : Status::WrongType);
    }
    size_t slot = 0;
    ObjectSummary summary;
    if (!dcos::internal::slotOfObject(table.value(), id, slot) ||
        !dcos::internal::objectAt(table.value(), slot, summary) || summary.id != id) {
        return statusValue(Status::StaleId);
    }
    for (size_t i = 0; i <= kSeiMaxName; ++i) {
        names_[0][i] = summary.name[i];
    }
    reply.objectType = static_cast<uint8_t>(id.type());
    reply.visibility = static_cast<uint8_t>(summary.visibility);
    reply.owner = summary.owner.raw();
    reply.name = names_[0];
    reply.nameLength = nameLength(names_[0]);
    reply.state = 0;
    reply.valueCount = 0;
    const auto value = [&reply](uint64_t figure) {
        if (reply.valueCount < kSeiMaxValues) {
            reply.values[reply.valueCount++] = figure;
        }
    };
    switch (id.type()) {
    case ObjectType::Task: {
        const dcos::Result<dcos::TaskState> state = dcos::TaskAgent::GetState(id);
        if (!state.ok()) {
            return statusValue(state.status());
        }
        reply.state = static_cast<uint8_t>(state.value());
        // The figures are copied whole, with interrupts held off: the task
        // runs on while they are read. Its stack's high-water mark is a scan
        // of the stack, too long to hold interrupts off for; it is taken
        // after, from the same task table entry (static memory), and is a
        // diagnostic figure should the task end in between.
        struct {
            uint8_t basePriority, priority;
            size_t stackSize;
            uint64_t executionPeriodNs, deadlinePeriodNs;
            uint32_t profileSamples;
            uint64_t profileMinimumNs, profileMaximumNs, profileTotalNs;
        } copy{};
        const dcos::internal::Task* entry = nullptr;
        {
            arch_x86::InterruptGuard guard;
            const dcos::Result<dcos::internal::Task*> task = dcos::internal::TaskManager::resolve(id);
            if (!task.ok()) {
                return statusValue(task.status());
            }
            entry = task.value();
            copy = {entry->basePriority,      entry->priority,         entry->stackSize,
                    entry->executionPeriodNs, entry->deadlinePeriodNs, entry->profileSamples,
                    entry->profileMinimumNs,  entry->profileMaximumNs, entry->profileTotalNs};
        }
        const size_t highWater = dcos::internal::TaskManager::stackHighWater(*entry);
        value(copy.basePriority);
        value(copy.priority);
        value(copy.stackSize);
        value(highWater);
        value(copy.executionPeriodNs);
        value(copy.deadlinePeriodNs);
        value(copy.profileSamples);
        value(copy.profileMinimumNs);
        value(copy.profileMaximumNs);
        value(copy.profileTotalNs);
        break;
    }
    case ObjectType::Semaphore: {
        const dcos::Result<uint32_t> count = dcos::SemaphoreAgent::GetCount(id);
        const dcos::Result<ObjectId> holder = dcos::SemaphoreAgent::GetHolder(id);
        if (!count.ok()) {
            return statusValue(count.status());
        }
        const dcos::Result<uint32_t> settings = dcos::internal::semaphoreSettings(id);
        value(count.value());
        value(holder.ok() ? holder.value().raw() : 0);
        value(settings.ok() ? settings.value() : 0);
        break;
    }
    case ObjectType::MessagePort: {
        dcos::internal::PortInfo port;
        if (!dcos::internal::PortManager::snapshot(slot, port) || port.id != id) {
            return statusValue(Status::StaleId);
        }
        value(static_cast<uint8_t>(port.order));
        value(port.queued);
        value(port.levelBits);
        value(port.receiverWaiting ? 1 : 0);
        break;
    }
    case ObjectType::BufferPool: {
        const dcos::Result<dcos::BufferPoolStatistics> pool = dcos::BufferPoolAgent::GetStatistics(id);
        if (!pool.ok()) {
            return statusValue(pool.status());
        }
        value(pool.value().bufferSize);
        value(pool.value().totalBuffers);
        value(pool.value().freeBuffers);
        value(pool.value().lowWaterMark);
        value(pool.value().allocations);
        value(pool.value().failedAllocations);
        break;
    }
    case ObjectType::Heap: {
        const dcos::Result<dcos::HeapStatistics> heap = dcos::HeapAgent::GetStatistics(id);
        if (!heap.ok()) {
            return statusValue(heap.status());
        }
        value(heap.value().heapBytes);
        value(heap.value().freeBytes);
        value(heap.value().usedBytes);
        value(heap.value().allocatedSegments);
        value(heap.value().freeSegments);
        value(heap.value().largestFreeSegment);
        break;
    }
    case ObjectType::DsmPublisher: {
        // The current page, read as any subscriber reads it.
        const dcos::Result<ObjectId> subscription = dcos::DsmAgent::Open(id);
        if (!subscription.ok()) {
            return statusValue(subscription.status());
        }
        dcos::DsmPage page{};
        const dcos::Result<uint32_t> read = dcos::DsmAgent::Read(subscription.value(), dcos::kNoDsmData, page, 0);
        (void)dcos::DsmAgent::Close(subscription.value());
        uint64_t low = 0;
        uint64_t high = 0;
        for (size_t i = 0; i < 8; ++i) {
            low |= uint64_t{page.bytes[i]} << (8 * i);
            high |= uint64_t{page.bytes[8 + i]} << (8 * i);
        }
        value(read.ok() ? read.value() : dcos::kNoDsmData);
        value(low);
        value(high);
        break;
    }
    default:
        break;
    }
    return 0;
}

uint8_t SeiNodeBackend::nodeStatistics(SeiMessage& reply)
{
    reply.uptimeNs = dcos::TimerAgent::Uptime();
    reply.taskSwitches = dcos::internal::Scheduler::switchCount();
    reply.stackFree = static_cast<uint32_t>(dcos::internal::StackArena::freeBytes());
    reply.tableCount = 0;
    for (const ObjectType type : kListedTypes) {
        const dcos::Result<ObjectTableView> table = dcos::internal::objectTableOf(type);
        if (!table.ok()) {
            continue;
        }
        SeiTableUsage& usage = reply.tables[reply.tableCount++];
        usage.type = static_cast<uint8_t>(type);
        usage.used = static_cast<uint16_t>(table.value().used);
        usage.capacity = static_cast<uint16_t>(table.value().active);
    }
    return 0;
}

uint8_t SeiNodeBackend::createTask(const SeiMessage& request, uint32_t& id)
{
    // The entry points are the image's: those its application declares
    // (seed 8.2). Until modules can be loaded (the dynamic linker, 7.12), a
    // host starts more tasks of the code the node already holds.
    char entryName[kSeiMaxName + 1];
    char taskName[kSeiMaxName + 1];
    if (request.textLength == 0 || !terminatedName(request.text, request.textLength, entryName) ||
        !terminatedName(request.name, request.nameLength, taskName)) {
        return statusValue(Status::InvalidArgument);
    }
    const dcos::app::Application* application = dcos::internal::linkedApplication();
    const dcos::app::TaskDeclaration* declaration = nullptr;
    for (size_t i = 0; application != nullptr && i < application->tasks.count; ++i) {
        const char* name = application->tasks.items[i].name;
        if (name != nullptr && runtime::textEquals(name, entryName)) {
            declaration = &application->tasks.items[i];
            break;
        }
    }
    if (declaration == nullptr) {
        return statusValue(Status::NotFound);
    }
    if (request.nameLength != 0 && nameTaken(ObjectType::Task, taskName)) {
        return statusValue(Status::AlreadyExists);
    }
    dcos::TaskAttributes attributes = declaration->attributes();
    attributes.name = request.nameLength != 0 ? taskName : nullptr;
    attributes.priority = request.priority;
    attributes.stackSize = request.stackSize;
    // A task the bus creates never gets privileges the bus cannot see.
    attributes.superUser = false;
    const dcos::Result<ObjectId> created = dcos::TaskAgent::Create(attributes, declaration->entry, request.argument);
    if (!created.ok()) {
        return statusValue(created.status());
    }
    id = created.value().raw();
    return 0;
}

uint8_t SeiNodeBackend::startTask(uint32_t id)
{
    return statusValue(dcos::TaskAgent::Resume(ObjectId::fromRaw(id)));
}

uint8_t SeiNodeBackend::stopTask(uint32_t id)
{
    const ObjectId task = ObjectId::fromRaw(id);
    // The agent's own task answers the bus: stopping it would leave the
    // node unreachable until it restarts.
    if (task == dcos::TaskAgent::IdOfSelf()) {
        return statusValue(Status::NotPermitted);
    }
    return statusValue(dcos::TaskAgent::Suspend(task));
}

uint8_t SeiNodeBackend::killTask(uint32_t id)
{
    const ObjectId task = ObjectId::fromRaw(id);
    if (task == dcos::TaskAgent::IdOfSelf()) {
        return statusValue(Status::NotPermitted);
    }
    return statusValue(dcos::TaskAgent::KillTask(task));
}

uint8_t SeiNodeBackend::createObject(const SeiMessage& request, uint32_t& id)
{
    char name[kSeiMaxName + 1];
    if (!terminatedName(request.name, request.nameLength, name) ||
        request.visibility > static_cast<uint8_t>(dcos::Visibility::Global)) {
        return statusValue(Status::InvalidArgument);
    }
    const char* named = request.nameLength != 0 ? name : nullptr;
    const dcos::Visibility visibility = static_cast<dcos::Visibility>(request.visibility);
    if (dcos::internal::objectTableOf(static_cast<ObjectType>(request.objectType)).ok() &&
        nameTaken(static_cast<ObjectType>(request.objectType), named)) {
        return statusValue(Status::AlreadyExists);
    }
    switch (static_cast<ObjectType>(request.objectType)) {
    case ObjectType::Semaphore: {
        const uint32_t flags = request.parameters[1];
        if ((flags & ~kSeiSemaphoreFlagsKnown) != 0) {
            return statusValue(Status::InvalidArgument);
        }
        dcos::SemaphoreAttributes attributes;
        attributes.name = named;
        attributes.kind = (flags & kSeiSemaphoreCounting) != 0 ? dcos::SemaphoreKind::Counting
                                                               : dcos::SemaphoreKind::Binary;
        attributes.initialCount = request.parameters[0];
        attributes.priorityInheritance = (flags & kSeiSemaphoreInheritance) != 0;
        attributes.order = (flags & kSeiSemaphoreFifo) != 0 ? dcos::WaitOrder::Fifo : dcos::WaitOrder::Priority;
        attributes.visibility = visibility;
        return keepForSystem(dcos::SemaphoreAgent::Create(attributes), id, [](ObjectId object) {
            return dcos::SemaphoreAgent::XferOwnership(object, ObjectId{});
        });
    }
    case ObjectType::MessagePort:
        if (request.parameters[0] > static_cast<uint8_t>(dcos::PortOrder::Fifo) || request.parameters[1] != 0) {
            return statusValue(Status::InvalidArgument);
        }
        return keepForSystem(
            dcos::MessagePortAgent::Create(named, visibility, static_cast<dcos::PortOrder>(request.parameters[0])),
            id, [](ObjectId object) { return dcos::MessagePortAgent::XferOwnership(object, ObjectId{}); });
    case ObjectType::DsmPublisher:
        if (request.parameters[0] != 0 || request.parameters[1] != 0) {
            return statusValue(Status::InvalidArgument);
        }
        return keepForSystem(dcos::DsmAgent::Create(named, visibility), id,
                             [](ObjectId object) { return dcos::DsmAgent::XferOwnership(object, ObjectId{}); });
    case ObjectType::BufferPool:
    case ObjectType::Heap:
        // A pool's or heap's memory is an application's static array
        // (seed 7.7, 7.8): there is none to give one from the bus.
        return statusValue(Status::NotSupported);
    default:
        return statusValue(Status::InvalidArgument);
    }
}

uint8_t SeiNodeBackend::deleteObject(uint32_t raw)
{
    const ObjectId id = ObjectId::fromRaw(raw);
    switch (id.type()) {
    case ObjectType::Task: return killTask(raw);
    case ObjectType::Semaphore: return statusValue(dcos::SemaphoreAgent::Delete(id));
    case ObjectType::MessagePort: return statusValue(dcos::MessagePortAgent::Delete(id));
    case ObjectType::DsmPublisher: return statusValue(dcos::DsmAgent::Delete(id));
    case ObjectType::BufferPool: return statusValue(dcos::BufferPoolAgent::Delete(id));
    case ObjectType::Heap: return statusValue(dcos::HeapAgent::Delete(id));
    case ObjectType::None: return statusValue(Status::InvalidId);
    default: return statusValue(Status::NotSupported);
    }
}

uint8_t SeiNodeBackend::addObjects(uint8_t type, uint16_t count)
{
    switch (static_cast<ObjectType>(type)) {
    case ObjectType::Task: return statusValue(dcos::TaskAgent::AddObjects(count));
    case ObjectType::Semaphore: return statusValue(dcos::SemaphoreAgent::AddObjects(count));
    case ObjectType::MessagePort: return statusValue(dcos::MessagePortAgent::AddObjects(count));
    case ObjectType::DsmPublisher: return statusValue(dcos::DsmAgent::AddObjects(count));
    case ObjectType::BufferPool: return statusValue(dcos::BufferPoolAgent::AddObjects(count));
    case ObjectType::Heap: return statusValue(dcos::HeapAgent::AddObjects(count));
    case ObjectType::Timer: return statusValue(dcos::TimerAgent::AddObjects(count));
    default: return statusValue(Status::InvalidArgument);
    }
}

uint8_t SeiNodeBackend::monitor(const SeiMessage& request, uint64_t nowNs)
{
    if (monitor_ == nullptr) {
        return statusValue(Status::NotSupported);
    }
    return monitor_->configure(request, nowNs);
}

SeiResult<uint32_t> SeiNodeBackend::writeConfiguration(const SeiConfiguration& configuration)
{
    const SeiResult<uint32_t> written = rewrite([&configuration](boot::ConfigurationBlock& block) {
        block.nodeId = configuration.nodeId;
        block.canBitRate = configuration.bitRate;
        block.flags = static_cast<uint8_t>((block.flags & ~boot::ConfigurationBlock::kQueriesClosed) |
                                           (configuration.queriesClosed ? boot::ConfigurationBlock::kQueriesClosed : 0));
        block.lockoutSeconds = configuration.lockoutSeconds;
        size_t i = 0;
        for (; i < configuration.commandLineLength && i + 1 < sizeof block.commandLine; ++i) {
            block.commandLine[i] = configuration.commandLine[i];
        }
        for (; i < sizeof block.commandLine; ++i) {
            block.commandLine[i] = '\0';
        }
    });
    if (written.ok()) {
        queriesClosed_ = configuration.queriesClosed;
        queriesKnown_ = true;
    }
    return written;
}

bool SeiNodeBackend::queriesClosed()
{
    // The first query reads the card; a card that cannot be read keeps the
    // queries closed, since nothing says they may be open.
    if (!queriesKnown_) {
        (void)readConfiguration();
    }
    return queriesClosed_;
}

void SeiNodeBackend::activateBitRate(uint16_t delayMs, uint64_t nowNs)
{
    // The rate is the card's, which only an authenticated command writes;
    // read now, while the agent's task holds the card for the request.
    const boot::StoredConfiguration stored = boot::ConfigurationStore::read(store_);
    if (!stored.readable || !stored.present || stored.configuration.canBitRate == 0) {
        return;
    }
    switchRate_ = stored.configuration.canBitRate;
    switchAtNs_ = nowNs + uint64_t{delayMs} * 1000000u;
}

void SeiNodeBackend::poll(uint64_t nowNs)
{
    if (switchAtNs_ == UINT64_MAX || nowNs < switchAtNs_) {
        return;
    }
    switchAtNs_ = UINT64_MAX;
    if (dcos::internal::switchCanBitRate != nullptr) {
        dcos::internal::switchCanBitRate(switchRate_);
    }
}

} // namespace sei
