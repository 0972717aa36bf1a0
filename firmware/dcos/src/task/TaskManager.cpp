#include <dcos/internal/ObjectDirectory.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/KernelContext.hpp>
#include <dcos/internal/ObjectTable.hpp>
#include <dcos/internal/ResourceRecovery.hpp>
#include <dcos/internal/RemoteForward.hpp>
#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/StackArena.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TimerManager.hpp>
#include <dcos/internal/InterruptManager.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/CpuException.hpp>
#include <arch_x86/FaultTasks.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>
#include <arch_x86/Paging.hpp>
#include <boot/Panic.hpp>
#include <bsp/Board.hpp>

#include <new>

extern "C" {
// Handler trampolines (TaskTrampolines.S).
void signalTrampoline();
void exceptionTrampoline();
void resumeTrampoline();
}

namespace dcos::internal {

namespace {

constexpr uint32_t kEflagsReservedBit = 1u << 1;
// Every stack is filled with this at creation, so the console can tell how
// deep it has been used (its high-water mark).
constexpr uint32_t kStackPaint = 0xDC05DC05u;
// A handler frame is refused when it would leave less than this below it.
constexpr size_t kHandlerStackReserve = 512;

ObjectTable<Task*, kTaskCapacity, TaskOwnerKeys> table(ObjectType::Task, 0);
Task tasks[kTaskCapacity];
// Tasks that ended while running; their stack and slot are freed once
// another task runs (the dying task's own stack is in use until then).
IntrusiveList<Task, ReadyQueueTag> reapList;

size_t slotOf(ObjectId id) { return table.slotNumber(id); }

bool inInterrupt() { return arch_x86::Idt::nestingDepth() > 0; }

arch_x86::InterruptFrame* initialFrame(uint8_t* stackTop, void (*entry)())
{
    auto* frame = reinterpret_cast<arch_x86::InterruptFrame*>(stackTop - sizeof(arch_x86::InterruptFrame));
    *frame = {};
    frame->ds = frame->es = frame->fs = frame->gs = arch_x86::Gdt::kernelData;
    frame->cs = arch_x86::Gdt::kernelCode;
    frame->eflags = arch_x86::eflagsInterruptEnable | kEflagsReservedBit;
    frame->eip = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(entry));
    return frame;
}

void paintStack(uint8_t* base, size_t bytes)
{
    auto* word = reinterpret_cast<uint32_t*>(base);
    size_t count = bytes / sizeof(uint32_t);
#if defined(DCOS_HOST_BUILD)
    for (size_t i = 0; i < count; ++i) {
        word[i] = kStackPaint;
    }
#else
    // One string store: creation is a configuration-class service, but it
    // need not cost more than the stack it fills.
    asm volatile("cld; rep stosl" : "+D"(word), "+c"(count) : "a"(kStackPaint) : "memory");
#endif
}

// The FPU state FNINIT leaves, in FSAVE's 32-bit layout: control word 0x037F
// (all exceptions masked, extended precision), all registers tagged empty.
void initialiseFpuState(FpuState& state)
{
    for (uint8_t& byte : state.bytes) {
        byte = 0;
    }
    state.bytes[0] = 0x7F;
    state.bytes[1] = 0x03;
    state.bytes[8] = 0xFF;
    state.bytes[9] = 0xFF;
}

// Where every task starts: run the entry, then end the task.
void taskEntryTrampoline()
{
    Task& task = Scheduler::current();
    task.entry(task.argument);
    TaskManager::exitCurrent();
}

void idleLoop(uintptr_t)
{
    for (;;) {
        arch_x86::enableInterruptsAndHalt();
    }
}

ExceptionClass classify(unsigned vector)
{
    switch (static_cast<arch_x86::CpuException>(vector)) {
    case arch_x86::CpuException::DivideError:
    case arch_x86::CpuException::Overflow:
    case arch_x86::CpuException::BoundRangeExceeded:
    case arch_x86::CpuException::FloatingPointError:
    case arch_x86::CpuException::AlignmentCheck:
    case arch_x86::CpuException::Breakpoint:
        return ExceptionClass::Synchronous;
    case arch_x86::CpuException::NonMaskableInterrupt:
    case arch_x86::CpuException::MachineCheck:
        return ExceptionClass::Asynchronous;
    default:
        return ExceptionClass::Fatal;
    }
}

const char* className(ExceptionClass c)
{
    switch (c) {
    case ExceptionClass::Timing: return "timing";
    case ExceptionClass::Synchronous: return "synchronous";
    case ExceptionClass::Asynchronous: return "asynchronous";
    case ExceptionClass::Fatal: return "fatal";
    }
    return "?";
}

// Turns the interrupted frame into one that runs a handler trampoline with
// eax and ebx preset, keeping the original registers in saved. The handler
// runs on the task's stack from where the task was interrupted; when it
// returns, its trap arrives with a frame at this same address, which
// restoreFrame() refills. Working in place matters: the kernel code building
// the frame is itself running on the stack just below it.
bool enterHandler(Task& task, arch_x86::InterruptFrame* frame, arch_x86::InterruptFrame& saved, uintptr_t& address,
                  void (*trampoline)(), uint32_t eax, uint32_t ebx)
{
    if (reinterpret_cast<uintptr_t>(frame) < reinterpret_cast<uintptr_t>(task.stackBase) + kHandlerStackReserve) {
        return false; // Too little stack left for a handler.
    }
    saved = *frame;
    address = reinterpret_cast<uintptr_t>(frame);
    frame->eip = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(trampoline));
    frame->eflags = arch_x86::eflagsInterruptEnable | kEflagsReservedBit;
    frame->cs = arch_x86::Gdt::kernelCode;
    frame->ds = frame->es = frame->fs = frame->gs = arch_x86::Gdt::kernelData;
    frame->eax = eax;
    frame->ebx = ebx;
    return true;
}

// Puts back the registers a handler interrupted, in the frame its trap made.
arch_x86::InterruptFrame* restoreFrame(arch_x86::InterruptFrame* trapFrame, const arch_x86::InterruptFrame& saved,
                                       uintptr_t address)
{
    if (reinterpret_cast<uintptr_t>(trapFrame) != address) {
        dcosPanicWithFrame(trapFrame, "a signal or exception handler returned with its stack unbalanced");
    }
    *trapFrame = saved;
    return trapFrame;
}

void releaseTask(Task& task)
{
    StackArena::release(task.stackBase, task.stackSize);
    (void)table.Delete(task.id); // Cannot fail: an ended task's id is still its slot's.
    task.state = TaskState::NonExistent;
}

void reapEndedTasks()
{
    while (!reapList.isEmpty() && &reapList.front() != &Scheduler::current()) {
        Task* task = reapList.popFront();
        releaseTask(*task);
    }
    TaskManager::reapPending_ = !reapList.isEmpty();
}

// Takes a task out of every structure, recovers what it owns and marks it
// as terminating. The caller frees its stack and slot, now or (for the
// running task) after the switch away.
void leaveWaitQueue(Task& task)
{
    WaitQueue* queue = task.waitingOn;
    if (queue != nullptr) {
        queue->remove(task);
        task.waitingOn = nullptr;
        queue->notifyObserver();
    }
}

// Runs a task at a new priority: moves it in its ready queue or in the wait
// queue it is blocked on (whose agent may pass the change on).
unsigned inheritanceDepth = 0;
constexpr unsigned kMaximumInheritanceDepth = 8;

bool sameKey(const DeadlineKey& a, const DeadlineKey& b)
{
    return a.encoded() == b.encoded() && a.deadline() == b.deadline();
}

void setRunningUrgency(Task& task, uint8_t priority, bool inheritsDeadline, const DeadlineKey& inheritedDeadline)
{
    if (task.priority == priority && task.inheritsDeadline == inheritsDeadline &&
        (!inheritsDeadline || sameKey(task.inheritedDeadline, inheritedDeadline))) {
        return;
    }
    const bool queued = static_cast<IntrusiveListNode<ReadyQueueTag>&>(task).isLinked() || task.isQueued();
    if (queued) {
        Scheduler::makeUnready(task);
    }
    task.priority = priority;
    task.setInheritsDeadline(inheritsDeadline);
    task.inheritedDeadline = inheritsDeadline ? inheritedDeadline : DeadlineKey{};
    if (queued) {
        Scheduler::requeue(task);
    }
    if (task.waitingOn != nullptr && inheritanceDepth < kMaximumInheritanceDepth) {
        // A blocked holder's new priority may change what it lends onwards.
        ++inheritanceDepth;
        task.waitingOn->reposition(task);
        task.waitingOn->notifyObserver();
        --inheritanceDepth;
    }
}

void terminate(Task& task)
{
    // Recovery may ready tasks more urgent than the running one; none may
    // run before the dying task is fully taken apart (if it is the running
    // task, it would never be resumed to finish).
    Scheduler::holdDispatch();
    task.state = TaskState::Terminating;
    leaveWaitQueue(task);
    Scheduler::makeUnready(task);
    TimerManager::cancel(task.wakeTimeout);
    TimerManager::cancel(task.deadlineTimeout);
    task.setDeadlineScope(false);
    task.setInheritsDeadline(false);
    task.deadlineAtNextBlock = false;
    recoverResourcesOf(task.id);
    if (&task == &Scheduler::current()) {
        // Queue it for reaping before any switch away can happen.
        reapList.pushBack(task);
        TaskManager::reapPending_ = true;
    }
    Scheduler::releaseDispatch();
}

// Cold: it prints a task's death on the console, and no real-time path
// goes through it.
[[gnu::cold]] void reportTermination(Task& task, const ExceptionInfo& info)
{
    const char* name = TaskManager::nameOf(task.id);
    if (info.vector != 0xFF) {
        runtime::format(bsp::console(), "task %s (0x%08lx) terminated: %s exception, vector %u (%s %s) at EIP=%08lx\r\n",
                        name[0] != '\0' ? name : "(unnamed)", static_cast<unsigned long>(task.id.raw()),
                        className(info.exceptionClass), info.vector, arch_x86::exceptionMnemonic(info.vector),
                        arch_x86::exceptionName(info.vector), static_cast<unsigned long>(info.instruction));
    } else {
        runtime::format(bsp::console(), "task %s (0x%08lx) terminated: %s exception, code %lu\r\n",
                        name[0] != '\0' ? name : "(unnamed)", static_cast<unsigned long>(task.id.raw()),
                        className(info.exceptionClass), static_cast<unsigned long>(info.errorCode));
    }
}

// Says what a page fault the fault task caught means, in the words an
// engineer looks for: a stack overflow (the task's own guard page), a null
// pointer, another stack's guard, or an address nothing is mapped at.
void explainPageFault(const Task& task, const arch_x86::FaultRecord& fault)
{
    runtime::CharacterSink& out = bsp::console();
    const char* access = (fault.errorCode & arch_x86::pageFaultWrite) != 0 ? "write" : "read";
    const uintptr_t address = fault.address;
    if (StackArena::isGuardOf(task.stackBase, address)) {
        runtime::format(out, "  stack overflow: the stack of %lu bytes at %08lx-%08lx ran into its guard page (%s at "
                             "%08lx, ESP=%08lx)\r\n",
                        static_cast<unsigned long>(task.stackSize),
                        static_cast<unsigned long>(reinterpret_cast<uintptr_t>(task.stackBase)),
                        static_cast<unsigned long>(reinterpret_cast<uintptr_t>(task.stackBase) + task.stackSize),
                        access, static_cast<unsigned long>(address), static_cast<unsigned long>(fault.stackPointer));
        return;
    }
    if (address < arch_x86::Paging::kPageSize) {
        runtime::format(out, "  null pointer: %s at %08lx\r\n", access, static_cast<unsigned long>(address));
        return;
    }
    for (size_t i = 0; i < kTaskCapacity; ++i) {
        const Task& other = tasks[i];
        if (other.state != TaskState::NonExistent && StackArena::isGuardOf(other.stackBase, address)) {
            runtime::format(out, "  %s at %08lx, in the guard page below the stack of task %s (0x%08lx)\r\n", access,
                            static_cast<unsigned long>(address), TaskManager::nameOf(other.id),
                            static_cast<unsigned long>(other.id.raw()));
            return;
        }
    }
    runtime::format(out, "  %s at %08lx, where no memory is mapped\r\n", access, static_cast<unsigned long>(address));
}

// Ends the running task from interrupt context (exception or trap); the
// switch away happens at the outermost exit.
void terminateCurrentFromInterrupt()
{
    terminate(Scheduler::current());
    Scheduler::requestDispatch();
}

} // namespace

void TaskManager::initialise(TaskEntry rootEntry)
{
    if (table.setNode(bsp::nodeId()) != Status::Ok || table.AddObjects(kTasksActiveAtBoot) != Status::Ok) {
        dcosPanic("cannot set up the task table (node %u, %lu tasks)", static_cast<unsigned>(bsp::nodeId()),
                  static_cast<unsigned long>(kTasksActiveAtBoot));
    }

    TaskAttributes idle;
    idle.name = kIdleTaskName;
    idle.priority = kLowestPriority;
    idle.stackSize = kIdleStackSize;
    idle.superUser = true;
    const Result<ObjectId> idleId = create(idle, idleLoop, 0);
    if (!idleId.ok()) {
        dcosPanic("cannot create the idle task: %s", statusName(idleId.status()));
    }
    Task& idleTask = tasks[slotOf(idleId.value())];
    idleTask.kernelTask = true;
    Scheduler::makeUnready(idleTask);
    Scheduler::setIdleTask(idleTask);

    TaskAttributes root;
    root.name = kRootTaskName;
    root.priority = kRootTaskPriority;
    root.stackSize = kRootStackSize;
    root.superUser = true;
    const Result<ObjectId> rootId = create(root, rootEntry, 0);
    if (!rootId.ok()) {
        dcosPanic("cannot create the root task: %s", statusName(rootId.status()));
    }
    tasks[slotOf(rootId.value())].kernelTask = true;
}

Result<Task*> TaskManager::resolve(ObjectId id)
{
    Task* const* found = table.find(id);
    if (found != nullptr) [[likely]] {
        return *found;
    }
    const Result<Task**> entry = table.resolve(id); // Says why not.
    if (!entry.ok()) {
        return entry.status();
    }
    return *entry.value();
}

Status TaskManager::checkNewOwner(ObjectId newOwner)
{
    return newOwner.isNull() ? Status::Ok : resolve(newOwner).status();
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TaskManager::create(const TaskAttributes& attributes, TaskEntry entry, uintptr_t argument)
{
    if (entry == nullptr || attributes.priority > kLowestPriority || attributes.stackSize < kMinimumStackSize ||
        attributes.stackSize > kStackArenaBytes) {
        return Status::InvalidArgument;
    }
    const bool started = Scheduler::started();
    if (attributes.superUser && started && !Scheduler::current().superUser) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    const ObjectId creator = started ? Scheduler::current().id : ObjectId::null();
    const Result<ObjectId> id = table.Create(creator, attributes.name, attributes.visibility);
    if (!id.ok()) {
        return id.status();
    }
    const size_t stackSize = StackArena::usableSize(attributes.stackSize);
    const Result<uint8_t*> stack = StackArena::allocate(stackSize);
    if (!stack.ok()) {
        (void)table.Delete(id.value()); // Cannot fail: created just above, under the same lock.
        return stack.status();
    }
    // A task owns itself, so that its creator's death does not end it. Cannot
    // fail: the creator owns the id it has just created.
    (void)table.XferOwnership(id.value(), creator, id.value());

    Task& task = tasks[slotOf(id.value())];
    task.~Task();
    new (&task) Task();
    *table.resolve(id.value()).value() = &task;
    task.id = id.value();
    task.state = TaskState::Spawning;
    task.basePriority = task.priority = attributes.priority;
    task.timeSlicing = attributes.timeSlicing;
    task.floatingPoint = attributes.floatingPoint;
    task.superUser = attributes.superUser;
    task.process = attributes.newProcess || !started ? task.id : Scheduler::current().process;
    task.stackBase = stack.value();
    task.stackSize = stackSize;
    paintStack(task.stackBase, task.stackSize - sizeof(arch_x86::InterruptFrame));
    task.entry = entry;
    task.argument = argument;
    task.sliceTicksLeft = Scheduler::quantumTicks();
    task.refreshSwitchWork();
    if (task.floatingPoint) {
        initialiseFpuState(task.fpu);
    }
    task.savedFrame = initialFrame(task.stackBase + task.stackSize, taskEntryTrampoline);
    task.state = TaskState::Ready;
    Scheduler::makeReady(task);
    return task.id;
}

DCOS_CONFIGURATION_SERVICE Status TaskManager::kill(Task& task)
{
    if (task.idle) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    if (&task == &Scheduler::current()) {
        if (inInterrupt()) {
            terminateCurrentFromInterrupt();
            return Status::Ok;
        }
        exitCurrent();
    }
    Scheduler::holdDispatch();
    terminate(task);
    releaseTask(task);
    Scheduler::releaseDispatch();
    return Status::Ok;
}

void TaskManager::exitCurrent()
{
    arch_x86::disableInterrupts();
    terminate(Scheduler::current());
    Scheduler::requestDispatch();
    dcosPanic("a deleted task was resumed");
}

Status TaskManager::suspend(Task& task)
{
    if (task.idle) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    if (task.suspended) {
        return Status::Ok;
    }
    task.suspended = true;
    if (task.state == TaskState::Ready) {
        Scheduler::makeUnready(task);
        task.state = TaskState::Suspended;
        if (&task == &Scheduler::current()) {
            Scheduler::requestDispatch();
        }
    }
    return Status::Ok;
}

Status TaskManager::resume(Task& task)
{
    arch_x86::InterruptGuard guard;
    if (!task.suspended) {
        return Status::InvalidArgument;
    }
    task.suspended = false;
    if (task.state == TaskState::Suspended) {
        task.state = TaskState::Ready;
        Scheduler::makeReady(task);
    }
    return Status::Ok;
}

Status TaskManager::changePriority(Task& task, uint8_t priority)
{
    if (priority > kLowestPriority) {
        return Status::InvalidArgument;
    }
    if (task.idle) {
        return Status::NotPermitted;
    }
    arch_x86::InterruptGuard guard;
    task.basePriority = priority;
    recomputePriority(task);
    return Status::Ok;
}

void TaskManager::recomputePriority(Task& task)
{
    uint8_t priority = task.basePriority;
    bool inheritsDeadline = false;
    DeadlineKey inheritedDeadline{};
    for (InheritanceSource& source : task.heldSources) {
        WaitQueue& waiters = source.waiters;
        if (!source.lendsPriority || waiters.isEmpty()) {
            continue;
        }
        if (waiters.order() == WaitQueue::Order::Priority && waiters.deadlineWaiters() == 0) {
            // The queue's first waiter is its most urgent: O(1).
            priority = waiters.first().priority < priority ? waiters.first().priority : priority;
            continue;
        }
        // A FIFO queue's first waiter is its oldest, and a deadline waiter
        // may be more urgent than its static priority says: the holder must
        // run with the most urgent waiter's urgency, so look at them all.
        for (Task& waiter : waiters) {
            priority = waiter.priority < priority ? waiter.priority : priority;
            if (waiter.schedulesByDeadline()) {
                const DeadlineKey key = Scheduler::urgencyKey(waiter);
                if (!inheritsDeadline || key.precedes(inheritedDeadline)) {
                    inheritsDeadline = true;
                    inheritedDeadline = key;
                }
            }
        }
    }
    setRunningUrgency(task, priority, inheritsDeadline, inheritedDeadline);
}

Status TaskManager::blockOn(WaitQueue& queue, uint64_t timeoutNs)
{
    Task& task = Scheduler::current();
    queue.add(task);
    task.waitingOn = &queue;
    return blockCurrent(WaitReason::Object, timeoutNs);
}

Task* TaskManager::wakeFirst(WaitQueue& queue, Status result)
{
    if (queue.isEmpty()) {
        return nullptr;
    }
    Task& task = queue.first();
    queue.remove(task);
    task.waitingOn = nullptr;
    wake(task, result);
    return &task;
}

void TaskManager::wakeAll(WaitQueue& queue, Status result)
{
    // Every waiter is woken before the most urgent of them runs.
    Scheduler::holdDispatch();
    while (wakeFirst(queue, result) != nullptr) {
    }
    Scheduler::releaseDispatch();
}

Status TaskManager::blockCurrent(WaitReason reason, uint64_t timeoutNs)
{
    Task& task = Scheduler::current();
    task.state = TaskState::Blocked;
    task.waitReason = reason;
    task.wakeStatus = Status::Ok;
    Scheduler::makeUnready(task);
    if (timeoutNs != kWaitForever) {
        TimerManager::arm(task.wakeTimeout, TimerManager::tickAfter(timeoutNs));
    }
    Scheduler::requestDispatch();
    return task.wakeStatus;
}

Status TaskManager::blockCurrentTillTimeOfDay(uint64_t timeOfDayNs)
{
    Task& task = Scheduler::current();
    task.state = TaskState::Blocked;
    task.waitReason = WaitReason::Sleep;
    task.wakeStatus = Status::Ok;
    task.sleepsTillTimeOfDay = true;
    task.wakeTimeOfDayNs = timeOfDayNs;
    Scheduler::makeUnready(task);
    TimerManager::armAtTimeOfDay(task.wakeTimeout, timeOfDayNs);
    Scheduler::requestDispatch();
    task.sleepsTillTimeOfDay = false;
    return task.wakeStatus;
}

void TaskManager::wake(Task& task, Status result)
{
    if (task.state != TaskState::Blocked) {
        return;
    }
    TimerManager::cancel(task.wakeTimeout);
    task.waitReason = WaitReason::None;
    task.sleepsTillTimeOfDay = false;
    task.wakeStatus = result;
    // Leaving by time-out (not through wakeFirst): tell the object's agent.
    leaveWaitQueue(task);
    if (task.deadlineAtNextBlock) {
        // "Set later": the real-time scope starts as the task is readied.
        task.deadlineAtNextBlock = false;
        task.setDeadlineScope(true);
        task.deadlineNs = TimerManager::uptimeNs() + task.deadlinePeriodNs;
        TimerManager::arm(task.deadlineTimeout, TimerManager::tickAfter(task.deadlinePeriodNs));
    }
    if (task.suspended) {
        task.state = TaskState::Suspended;
        return;
    }
    task.state = TaskState::Ready;
    Scheduler::makeReady(task);
}

// Posts with interrupts already off; both PostEvent paths share it.
[[gnu::always_inline]] inline void TaskManager::postEventLocked(Task& task, uint32_t events)
{
    task.events |= events;
    if (task.state != TaskState::Blocked || task.waitReason != WaitReason::Events) {
        return;
    }
    const uint32_t present = task.events & task.awaitedEvents;
    const bool satisfied = task.awaitedMode == EventWait::All ? present == task.awaitedEvents : present != 0;
    if (satisfied) {
        task.events &= ~present;
        task.receivedEvents = present;
        wake(task, Status::Ok);
    }
}

void TaskManager::postEvent(Task& task, uint32_t events)
{
    arch_x86::InterruptGuard guard;
    postEventLocked(task, events);
}

namespace {

// PostEvent's miss path: the id's error, or for another node's task the
// remote transaction, with interrupts enabled again (it blocks). The id is
// resolved again under a guard of its own, so a task that came to be
// between the two guards still gets its events, as before this path split.
[[gnu::noinline]] Status postEventMissed(ObjectId id, uint32_t events)
{
    const Status missed = [id, events] {
        arch_x86::InterruptGuard guard;
        const Result<Task*> task = TaskManager::resolve(id);
        if (task.ok()) {
            TaskManager::postEvent(*task.value(), events);
        }
        return task.status();
    }();
    return orRemote(missed, RemoteService::PostEvent, id, events);
}

} // namespace

Status TaskManager::postEvent(ObjectId id, uint32_t events)
{
    {
        arch_x86::InterruptGuard guard;
        Task* const* found = table.find(id);
        if (found != nullptr) [[likely]] {
            postEventLocked(**found, events);
            return Status::Ok;
        }
    }
    return postEventMissed(id, events);
}

void TaskManager::sendSignal(Task& task, unsigned signal)
{
    arch_x86::InterruptGuard guard;
    task.postSignal(signal);
    // A signal readies a suspended task (seed 7.6.1).
    if (task.suspended) {
        task.suspended = false;
        if (task.state == TaskState::Suspended) {
            task.state = TaskState::Ready;
            Scheduler::makeReady(task);
        }
    }
    if (&task == &Scheduler::current()) {
        Scheduler::requestDispatch(); // Deliver on the way back to the task.
    }
}

void TaskManager::raiseException(Task& task, const ExceptionInfo& info)
{
    arch_x86::InterruptGuard guard;
    if (info.exceptionClass == ExceptionClass::Fatal) {
        reportTermination(task, info);
        if (kill(task) != Status::Ok) {
            // Only the idle task cannot be ended, and without it nothing can run.
            dcosPanic("fatal exception in the idle task, which cannot be ended");
        }
        return;
    }
    task.setExceptionPending(true);
    task.pendingException = info;
    if (&task == &Scheduler::current()) {
        Scheduler::requestDispatch();
    }
}

void TaskManager::switchContext(Task& from, Task& to)
{
    if (&from != &to && from.floatingPoint && from.state != TaskState::Terminating) {
        asm volatile("fnsave %0" : "=m"(from.fpu) : : "memory");
    }
    if (to.floatingPoint) {
        asm volatile("frstor %0" : : "m"(to.fpu) : "memory");
    }
    if (from.profiling || to.profiling) {
        const uint64_t now = TimerManager::preciseUptimeNs();
        if (from.profiling && &from != &to) {
            from.profileAccumulatedNs += now - from.runStartedNs;
        }
        to.runStartedNs = now;
    }
    if (from.interruptLevel != to.interruptLevel || &from == &to) {
        InterruptManager::applyTaskLevel(to.interruptLevel);
    }
    if (to.sliceTicksLeft == 0) {
        to.sliceTicksLeft = Scheduler::quantumTicks();
    }
}

bool TaskManager::reapPending_ = false;

arch_x86::InterruptFrame* TaskManager::prepareReturnWithWork(Task& task, arch_x86::InterruptFrame* frame)
{
    reapEndedTasks();
    if (task.idle || task.state == TaskState::Terminating) {
        return frame;
    }
    if (task.exceptionPending && !task.inExceptionHandler) {
        task.setExceptionPending(false);
        if (task.exceptionHandler == nullptr) {
            if (task.pendingException.exceptionClass == ExceptionClass::Timing) {
                return frame; // Ignored without a handler (seed 7.4.2).
            }
            reportTermination(task, task.pendingException);
            terminateCurrentFromInterrupt();
            return Scheduler::onOutermostExit(frame);
        }
        task.activeException = task.pendingException;
        if (enterHandler(task, frame, task.exceptionSavedFrame, task.exceptionFrameAddress, exceptionTrampoline,
                         static_cast<uint32_t>(reinterpret_cast<uintptr_t>(&task.activeException)),
                         static_cast<uint32_t>(reinterpret_cast<uintptr_t>(task.exceptionHandler)))) {
            task.inExceptionHandler = true;
            task.exceptionSavedWakeStatus = task.wakeStatus;
            return frame;
        }
        reportTermination(task, task.activeException);
        terminateCurrentFromInterrupt();
        return Scheduler::onOutermostExit(frame);
    }
    const uint32_t deliverable = task.pendingSignals & ~task.signalMask;
    if (deliverable != 0 && task.signalHandler != nullptr && !task.inSignalHandler && !task.inExceptionHandler) {
        // Signal 0 has the highest priority; one handler runs at a time.
        const unsigned signal = static_cast<unsigned>(__builtin_ctz(deliverable));
        if (enterHandler(task, frame, task.signalSavedFrame, task.signalFrameAddress, signalTrampoline, signal,
                         static_cast<uint32_t>(reinterpret_cast<uintptr_t>(task.signalHandler)))) {
            task.clearSignal(signal);
            task.inSignalHandler = true;
            task.signalSavedWakeStatus = task.wakeStatus;
        }
    }
    return frame;
}

// Cold: a CPU exception is a task's error (a fault, a divide error, a
// bound), which it ends with or handles in its exception handler; no
// real-time path takes it (the FPU context is switched eagerly, so device
// not available never occurs), so it is compiled for size.
[[gnu::cold]] arch_x86::InterruptFrame* TaskManager::onCpuException(arch_x86::InterruptFrame* frame)
{
    // Exceptions in interrupt handlers, before scheduling starts, or in the
    // idle task are kernel faults.
    if (!Scheduler::started() || arch_x86::Idt::nestingDepth() > 1 || Scheduler::current().idle) {
        dcosPanicWithFrame(frame, "CPU exception in kernel context");
    }
    Task& task = Scheduler::current();
    if (arch_x86::FaultTasks::isFaultFrame(frame)) {
        // A page fault: its frame was rebuilt on the recovery stack, because
        // the task's own stack may be the very thing that failed. Inside a
        // kernel critical section (interrupts off, or dispatch held) the
        // kernel's lists may be half updated, so only a halt is safe.
        if ((frame->eflags & arch_x86::eflagsInterruptEnable) == 0 || Scheduler::dispatchHeld()) {
            dcosPanicWithFrame(frame, "page fault in a kernel critical section");
        }
        const ExceptionInfo info{ExceptionClass::Fatal, static_cast<uint8_t>(frame->vector), frame->errorCode,
                                 frame->eip, nullptr};
        reportTermination(task, info);
        explainPageFault(task, arch_x86::FaultTasks::lastFault());
        terminateCurrentFromInterrupt();
        // The fault may have hit while the processor pushed an interrupt's
        // frame onto the task's stack: deliver that interrupt now, on the
        // recovery stack, or its line would stay in service for good.
        unsigned line = 0;
        if (bsp::interruptCutShort(line)) {
            arch_x86::Idt::dispatchInterrupt(line);
        }
        return frame;
    }
    ExceptionInfo info{classify(frame->vector), static_cast<uint8_t>(frame->vector), frame->errorCode, frame->eip,
                       nullptr};
    if (info.exceptionClass == ExceptionClass::Fatal || task.exceptionHandler == nullptr || task.inExceptionHandler) {
        // No handler, or an exception inside the exception handler (a double
        // exception): the task ends, the node carries on.
        reportTermination(task, info);
        terminateCurrentFromInterrupt();
        return frame;
    }
    task.activeException = info;
    if (!enterHandler(task, frame, task.exceptionSavedFrame, task.exceptionFrameAddress, exceptionTrampoline,
                      static_cast<uint32_t>(reinterpret_cast<uintptr_t>(&task.activeException)),
                      static_cast<uint32_t>(reinterpret_cast<uintptr_t>(task.exceptionHandler)))) {
        reportTermination(task, info);
        terminateCurrentFromInterrupt();
        return frame;
    }
    task.inExceptionHandler = true;
    task.exceptionSavedWakeStatus = task.wakeStatus;
    return frame;
}

arch_x86::InterruptFrame* TaskManager::onTrap(arch_x86::InterruptFrame* frame)
{
    if (!Scheduler::started()) {
        dcosPanicWithFrame(frame, "software trap before scheduling started");
    }
    Task& task = Scheduler::current();
    switch (frame->vector) {
    case Scheduler::kDispatchTrapVector:
        return frame; // The switch itself happens at the outermost exit.
    case kSignalReturnVector: {
        if (!task.inSignalHandler) {
            dcosPanicWithFrame(frame, "signal return without a signal");
        }
        task.inSignalHandler = false;
        task.wakeStatus = task.signalSavedWakeStatus;
        return restoreFrame(frame, task.signalSavedFrame, task.signalFrameAddress);
    }
    case kExceptionReturnVector: {
        if (!task.inExceptionHandler) {
            dcosPanicWithFrame(frame, "exception return without an exception");
        }
        task.inExceptionHandler = false;
        task.wakeStatus = task.exceptionSavedWakeStatus;
        const auto action = static_cast<ExceptionAction>(frame->eax & 0xFF);
        arch_x86::InterruptFrame* resumed = restoreFrame(frame, task.exceptionSavedFrame, task.exceptionFrameAddress);
        const ExceptionInfo& info = task.activeException;
        if (action == ExceptionAction::Terminate) {
            terminateCurrentFromInterrupt();
            return resumed;
        }
        if (info.exceptionClass == ExceptionClass::Synchronous) {
            if (info.resumeIn == nullptr) {
                // Retrying the faulting instruction would fault again.
                terminateCurrentFromInterrupt();
                return resumed;
            }
            resumed->eip = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(resumeTrampoline));
            resumed->ebx = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(info.resumeIn));
        }
        return resumed;
    }
    default:
        dcosPanicWithFrame(frame, "unknown software trap");
    }
}

size_t TaskManager::stackHighWater(const Task& task)
{
    const auto* word = reinterpret_cast<const uint32_t*>(task.stackBase);
    const size_t words = task.stackSize / sizeof(uint32_t);
    size_t untouched = 0;
    while (untouched < words && word[untouched] == kStackPaint) {
        ++untouched;
    }
    return task.stackSize - untouched * sizeof(uint32_t);
}

size_t TaskManager::taskCount() { return table.usedCount(); }

DCOS_CONFIGURATION_SERVICE Status TaskManager::addObjects(size_t count)
{
    arch_x86::InterruptGuard guard;
    return table.AddObjects(count);
}

DCOS_CONFIGURATION_SERVICE Result<ObjectId> TaskManager::nameToObject(const char* name, Visibility askingScope)
{
    arch_x86::InterruptGuard guard;
    return table.NameToObject(name, askingScope);
}

const char* TaskManager::nameOf(ObjectId id)
{
    const Result<const char*> name = table.nameOf(id);
    return name.ok() ? name.value() : "";
}

Task* TaskManager::taskArray() { return tasks; }

size_t TaskManager::taskArraySize() { return kTaskCapacity; }

// The caller questions every agent asks (KernelContext.hpp).
ObjectId currentTaskId() { return Scheduler::started() ? Scheduler::current().id : ObjectId::null(); }

bool currentTaskIsSuperUser() { return !Scheduler::started() || Scheduler::current().superUser; }

uint16_t localNode() { return bsp::nodeId(); }

size_t taskSlotOf(ObjectId task) { return table.slotNumber(task); }

ObjectTableView taskTableView()
{
    return table.view();
}

} // namespace dcos::internal

extern "C" void taskExitFromTrampoline() { dcos::internal::TaskManager::exitCurrent(); }
