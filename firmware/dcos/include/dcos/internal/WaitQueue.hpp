// Tasks blocked on one kernel object: a semaphore, a message port, a
// publisher's page (seed 7.9-7.11).
//
// The queue is intrusive (each task carries its own link), ordered by the
// waiter's running priority with first come first served among equals, or
// purely first come first served. The task agent owns the blocking and
// waking (TaskManager::blockOn, wakeFirst, wakeAll), so a time-out, a kill
// or a priority change always takes the task out of, or moves it in, the
// queue it waits on: no agent can be left holding a dead waiter.
#pragma once

#include <dcos/internal/WaitList.hpp>

#include <stdint.h>

namespace dcos::internal {

struct Task;
struct WaitQueueTag;
class WaitQueue;

/// Called when a waiter leaves a queue other than by wakeFirst/wakeAll (a
/// time-out, a kill) or its priority changes, so the owning agent can react
/// (priority inheritance recomputes the holder's priority).
using WaitQueueObserver = void (*)(WaitQueue& queue, void* context);

class WaitQueue {
public:
    enum class Order : uint8_t {
        Priority, ///< Most urgent waiter first, FIFO among equals.
        Fifo,     ///< First come first served.
    };

    explicit WaitQueue(Order order = Order::Priority) : order_(order) {}
    WaitQueue(const WaitQueue&) = delete;
    WaitQueue& operator=(const WaitQueue&) = delete;

    bool isEmpty() const { return list_.isEmpty(); }
    /// Waiters scheduled by a deadline; while there are none, the first
    /// waiter of a priority-ordered queue is its most urgent.
    unsigned deadlineWaiters() const { return deadlineWaiters_; }
    /// The waiters in queue order, for finding the most urgent in a FIFO queue.
    auto begin() { return list_.begin(); }
    auto end() { return list_.end(); }
    /// The waiter that wakeFirst() would wake; only when not empty.
    Task& first() const { return list_.front(); }
    Order order() const { return order_; }
    void setOrder(Order order) { order_ = order; }

    /// Sets the agent's observer (see WaitQueueObserver).
    void setObserver(WaitQueueObserver observer, void* context)
    {
        observer_ = observer;
        observerContext_ = context;
    }

    // Used by the task agent only.
    void add(Task& task);
    void remove(Task& task);
    void reposition(Task& task);
    void notifyObserver()
    {
        if (observer_ != nullptr) {
            observer_(*this, observerContext_);
        }
    }

private:
    WaitList<Task, WaitQueueTag> list_;
    Order order_;
    unsigned deadlineWaiters_ = 0;
    WaitQueueObserver observer_ = nullptr;
    void* observerContext_ = nullptr;
};

} // namespace dcos::internal
