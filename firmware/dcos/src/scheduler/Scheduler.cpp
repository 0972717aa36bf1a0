#include <dcos/internal/Scheduler.hpp>
#include <dcos/internal/TaskManager.hpp>
#include <dcos/internal/TaskContextSwitch.h>

#include <boot/Panic.hpp>

#include <arch_x86/Cpu.hpp>
#include <arch_x86/Gdt.hpp>
#include <arch_x86/Idt.hpp>
#include <arch_x86/TaskSwitch.hpp>

namespace dcos::internal {

// The layout TaskContextSwitch.S relies on, checked against the C++ one.
// offsetof on Task, which has several bases, is conditionally supported;
// GCC supports it and computes the offsets the assembler needs.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Winvalid-offsetof"
struct TaskAssemblyLayout {
    static_assert(offsetof(Task, priority) == TASK_PRIORITY);
    static_assert(offsetof(Task, resumeStack) == TASK_RESUME_STACK);
    static_assert(offsetof(Task, savedFrame) == TASK_SAVED_FRAME);
    static_assert(offsetof(Task, switchWork) == TASK_SWITCH_WORK);
    static_assert(offsetof(Task, rotatesOnYield) == TASK_ROTATES_ON_YIELD);
    static_assert(offsetof(Task, deliveryPending) == TASK_DELIVERY_PENDING);
    // The two-byte and masked four-byte tests read these as one word.
    static_assert(TASK_ROTATES_ON_YIELD == TASK_SWITCH_WORK + 1 && TASK_DELIVERY_PENDING == TASK_SWITCH_WORK + 2);
    static_assert(sizeof(bool) == 1 && sizeof(Task::priority) == 1);
    // A ring is its head pointer alone; the next link's place in the node.
    // That the node is the first base, so that a Task* is its node's
    // address, cannot be asked at compile time: setIdleTask checks it.
    static_assert(sizeof(IntrusiveRing<Task, ReadyQueueTag>) == 4);
    static_assert(offsetof(IntrusiveListNode<ReadyQueueTag>, next_) == TASK_READY_NEXT);
    static_assert(sizeof(Task*) == 4 && sizeof(uint32_t*) == 4);
    static_assert(static_cast<uint8_t>(Status::Ok) == STATUS_OK && STATUS_OK == 0);
    static_assert(static_cast<uint8_t>(Status::InInterrupt) == STATUS_IN_INTERRUPT);
};
#pragma GCC diagnostic pop

Task* Scheduler::current_ = nullptr;
Task* Scheduler::idle_ = nullptr;
volatile bool Scheduler::dispatchPending_ = false;
unsigned Scheduler::dispatchHolds_ = 0;
uint32_t Scheduler::quantumTicks_ = 10;
uint32_t Scheduler::switchCount_ = 0;
ReadyBitmap Scheduler::readyBitmap_;
IntrusiveRing<Task, ReadyQueueTag> Scheduler::readyQueues_[32];
DeadlineQueue<Task, kTaskCapacity> Scheduler::deadlineQueue_;

void Scheduler::setIdleTask(Task& idle)
{
    // TaskContextSwitch.S compares a task's address with its ring's head, which
    // points at the task's ready node: the node must be the first base.
    if (reinterpret_cast<uintptr_t>(static_cast<IntrusiveListNode<ReadyQueueTag>*>(&idle)) !=
        reinterpret_cast<uintptr_t>(&idle)) {
        dcosPanic("scheduler: the ready node is not at the start of a task");
    }
    idle.idle = true;
    idle.refreshRotatesOnYield();
    idle_ = &idle;
}

bool Scheduler::isMoreUrgent(const Task& a, const Task& b)
{
    if (b.idle) {
        return !a.idle;
    }
    if (a.idle) {
        return false;
    }
    if (a.schedulesByDeadline() != b.schedulesByDeadline()) {
        return a.schedulesByDeadline(); // Deadline-driven tasks come first (seed 7.4.1).
    }
    if (a.schedulesByDeadline()) {
        return a.deadlineKey().precedes(b.deadlineKey());
    }
    return a.priority < b.priority;
}

void Scheduler::makeReady(Task& task)
{
    // rotatesOnYield: neither the idle task nor ordered by a deadline.
    if (!task.rotatesOnYield) {
        if (!task.idle) {
            makeReadyByDeadline(task);
        }
        return;
    }
    readyQueues_[task.priority].pushBack(task);
    readyBitmap_.set(task.priority);
    // A task ordered by priority alone displaces the runner when that is the
    // idle task or of a lower priority; never one ordered by a deadline.
    Task* const running = current_;
    if (running == nullptr || &task == running) {
        return;
    }
    if (running->rotatesOnYield) {
        if (task.priority < running->priority) {
            dispatchToMoreUrgent(*running, task);
        }
    } else if (running->idle) {
        requestDispatch();
    }
}

void Scheduler::dispatchToMoreUrgent(Task& running, Task& task)
{
    if (arch_x86::Idt::nestingDepth() != 0) {
        dispatchPending_ = true; // The switch happens at the outermost interrupt's exit.
        return;
    }
    const uint32_t flags = arch_x86::saveFlagsAndDisableInterrupts();
    // With no hold, no interrupt nesting and no dispatch already pending,
    // the runner was the most urgent task, so the deadline heap is empty
    // (asked anyway: it costs two instructions) and a task more urgent than
    // the runner is the one pickNext() would choose. The switch then needs
    // no choice; a delivery on the way or a dying runner takes the general
    // path, which uses the dispatch trap.
    if (dispatchHolds_ == 0 && !dispatchPending_ && deadlineQueue_.isEmpty() && !task.hasDeliveryPending() &&
        running.state != TaskState::Terminating) {
        switchDirectly(running, task, flags);
        return;
    }
    requestDispatch();
    arch_x86::restoreFlags(flags);
}

void Scheduler::makeReadyByDeadline(Task& task)
{
    // Cannot fail: the queue holds a slot for every task, and a ready task
    // is not made ready twice.
    (void)deadlineQueue_.insert(task, urgencyKey(task));
    // The runner is the heap's head when it is ordered by a deadline, and
    // any deadline task runs before one that is not: the task displaces the
    // runner exactly when it became the head, as pickNext() will find.
    if (current_ != nullptr && &task != current_ && deadlineQueue_.peek() == &task) {
        requestDispatch();
    }
}

void Scheduler::makeUnready(Task& task)
{
    if (task.idle) {
        return;
    }
    if (task.isQueued()) {
        (void)deadlineQueue_.remove(task); // Cannot fail: it is queued.
    }
    if (static_cast<IntrusiveListNode<ReadyQueueTag>&>(task).isLinked()) {
        if (readyQueues_[task.priority].remove(task)) {
            readyBitmap_.clear(task.priority);
        }
    }
}

void Scheduler::requeue(Task& task)
{
    // The queues are keyed by priority and scope, so a change means leaving
    // under the old values; callers update the task between the two steps.
    makeReady(task);
    if (&task == current_ && pickNext() != current_) {
        requestDispatch(); // Someone else is now more urgent than the runner.
    }
}

void Scheduler::requestDispatch()
{
    dispatchPending_ = true;
    if (current_ != nullptr && dispatchHolds_ == 0 && arch_x86::Idt::nestingDepth() == 0) {
        switchFromTask();
    }
}

void Scheduler::switchFromTask()
{
    const uint32_t flags = arch_x86::saveFlagsAndDisableInterrupts();
    Task* const previous = current_;
    Task* const next = pickNext();
    if (previous->state == TaskState::Terminating || next->hasDeliveryPending()) {
        // The full path: a dying task is reaped once its stack is left, and
        // a delivery needs the interrupt frame prepareReturn works on.
        asm volatile("int %0" : : "i"(kDispatchTrapVector) : "memory");
    } else {
        dispatchPending_ = false;
        if (next != previous) {
            switchDirectly(*previous, *next, flags);
            return;
        }
    }
    arch_x86::restoreFlags(flags);
}

arch_x86::InterruptFrame* Scheduler::frameForDirectResume(Task& task)
{
    // The frame ends where the CPU would have pushed a ring change's ESP, so
    // after its IRET the stack pointer is resumeStack again. userEsp and
    // userSs are not written: they overlay the saved registers.
    auto* const top = reinterpret_cast<uint8_t*>(task.resumeStack);
    task.resumeStack = nullptr;
    auto* const frame = reinterpret_cast<arch_x86::InterruptFrame*>(top - offsetof(arch_x86::InterruptFrame, userEsp));
    frame->gs = frame->fs = frame->es = frame->ds = arch_x86::Gdt::kernelData;
    frame->edi = frame->esi = frame->ebp = frame->espAtPushal = frame->ebx = 0;
    frame->edx = frame->ecx = frame->eax = 0;
    frame->vector = kDispatchTrapVector;
    frame->errorCode = 0;
    frame->eip = static_cast<uint32_t>(reinterpret_cast<uintptr_t>(directResume));
    frame->cs = arch_x86::Gdt::kernelCode;
    // Interrupts stay disabled until the switch's caller restores its own flags.
    frame->eflags = kEflagsReservedBit;
    return frame;
}

void Scheduler::releaseDispatch()
{
    if (--dispatchHolds_ == 0 && dispatchPending_) {
        requestDispatch();
    }
}

bool Scheduler::rotateCurrent()
{
    Task& task = *current_;
    if (task.idle || task.schedulesByDeadline() || !static_cast<IntrusiveListNode<ReadyQueueTag>&>(task).isLinked()) {
        return false;
    }
    auto& queue = readyQueues_[task.priority];
    if (queue.isFront(task)) {
        // The usual case: the runner heads its queue, and the ring's step
        // puts it behind its equals.
        if (queue.rotate() == nullptr) {
            return false; // Alone at its priority.
        }
    } else {
        // A hold let a task of its priority get ahead of it.
        (void)queue.remove(task);
        queue.pushBack(task);
    }
    requestDispatch();
    return true;
}

void Scheduler::setQuantumTicks(uint32_t ticks) { quantumTicks_ = ticks == 0 ? 1 : ticks; }

void Scheduler::onTick()
{
    Task* task = current_;
    if (task == nullptr || task->idle || !task->timeSlicing) {
        return;
    }
    if (task->sliceTicksLeft > 1) {
        --task->sliceTicksLeft;
        return;
    }
    task->sliceTicksLeft = quantumTicks_;
    rotateCurrent();
}

Task* Scheduler::pickNext()
{
    if (Task* deadlineTask = deadlineQueue_.peek()) {
        return deadlineTask;
    }
    const unsigned priority = readyBitmap_.highest();
    if (priority == ReadyBitmap::kNone) {
        return idle_;
    }
    return &readyQueues_[priority].front();
}

arch_x86::InterruptFrame* Scheduler::onOutermostExit(arch_x86::InterruptFrame* frame)
{
    if (current_ == nullptr) {
        return frame;
    }
    // A hold defers the switch to releaseDispatch(), which requests it again.
    if (dispatchPending_ && dispatchHolds_ == 0) {
        dispatchPending_ = false;
        Task* next = pickNext();
        if (next != current_) {
            Task* previous = current_;
            previous->savedFrame = frame;
            current_ = next;
            ++switchCount_;
            if (previous->switchWork || next->switchWork) {
                TaskManager::switchContext(*previous, *next);
            }
            frame = next->resumeStack != nullptr ? frameForDirectResume(*next) : next->savedFrame;
        }
    }
    return TaskManager::prepareReturn(*current_, frame);
}

void Scheduler::start()
{
    arch_x86::disableInterrupts();
    Task* first = pickNext();
    current_ = first;
    arch_x86::Idt::enterTaskContext(); // Interrupts are off: no handler sees the change half made.
    dispatchPending_ = false;
    TaskManager::switchContext(*first, *first);
    resumeInterruptFrame(first->savedFrame);
}

} // namespace dcos::internal
