#include <dcos/internal/Task.hpp>
#include <dcos/internal/WaitQueue.hpp>

namespace dcos::internal {

// In FIFO order every waiter gets the same key, so the sorted list keeps
// arrival order.
void WaitQueue::add(Task& task)
{
    list_.insert(task, order_ == Order::Priority ? task.priority : uint8_t{0});
    task.queuedWithDeadline = task.schedulesByDeadline();
    deadlineWaiters_ += task.queuedWithDeadline ? 1 : 0;
}

void WaitQueue::remove(Task& task)
{
    list_.remove(task);
    deadlineWaiters_ -= task.queuedWithDeadline ? 1 : 0;
    task.queuedWithDeadline = false;
}

void WaitQueue::reposition(Task& task)
{
    if (order_ == Order::Priority) {
        list_.reposition(task, task.priority);
    }
    // A waiter that holds a semaphore itself may have been lent a deadline
    // (or lost one) while it waits.
    deadlineWaiters_ -= task.queuedWithDeadline ? 1 : 0;
    task.queuedWithDeadline = task.schedulesByDeadline();
    deadlineWaiters_ += task.queuedWithDeadline ? 1 : 0;
}

} // namespace dcos::internal
