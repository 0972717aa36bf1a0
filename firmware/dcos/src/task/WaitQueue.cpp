#include <dcos/internal/Task.hpp>
#include <dcos/internal/WaitQueue.hpp>

namespace dcos::internal {

// In FIFO order every waiter gets the same key, so the sorted list keeps
// arrival order.
void WaitQueue::add(Task& task) { list_.insert(task, order_ == Order::Priority ? task.priority : uint8_t{0}); }

void WaitQueue::remove(Task& task) { list_.remove(task); }

void WaitQueue::reposition(Task& task)
{
    if (order_ == Order::Priority) {
        list_.reposition(task, task.priority);
    }
}

} // namespace dcos::internal
