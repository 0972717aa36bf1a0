// Host tests for the deadline scheduler's binary heap (dissertation Fig. 7.7).
#include <dcos/internal/DeadlineQueue.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

using dcos::Status;
using dcos::internal::DeadlineKey;
using dcos::internal::DeadlineQueue;
using dcos::internal::DeadlineQueueNode;

namespace {

struct Task : DeadlineQueueNode {
    int id = 0;
};

} // namespace

TEST(DeadlineQueueTest, EmptyQueue)
{
    DeadlineQueue<Task, 4> queue;
    EXPECT_TRUE(queue.isEmpty());
    EXPECT_EQ(queue.peek(), nullptr);
    EXPECT_EQ(queue.pop(), nullptr);
}

TEST(DeadlineQueueTest, PopsInKeyThenTieBreakThenArrivalOrder)
{
    DeadlineQueue<Task, 8> queue;
    Task tasks[6];
    for (int i = 0; i < 6; ++i) {
        tasks[i].id = i;
    }
    // Inserted in an order unrelated to the expected result.
    ASSERT_EQ(queue.insert(tasks[0], DeadlineKey::make(1, 0, 1000, 0)), Status::Ok);   // key 1000, dl 1000
    ASSERT_EQ(queue.insert(tasks[1], DeadlineKey::make(0, 0, 5000, 0)), Status::Ok);   // priority 0 first
    ASSERT_EQ(queue.insert(tasks[2], DeadlineKey::make(1, 500, 500, 0)), Status::Ok);  // key 1000, dl 500
    ASSERT_EQ(queue.insert(tasks[3], DeadlineKey::make(1, 400, 700, 100)), Status::Ok); // key 1000, dl 700, ex 100
    ASSERT_EQ(queue.insert(tasks[4], DeadlineKey::make(1, 300, 700, 0)), Status::Ok);  // key 1000, dl 700, ex 0
    ASSERT_EQ(queue.insert(tasks[5], DeadlineKey::make(1, 500, 500, 0)), Status::Ok);  // full tie with 2, later
    std::vector<int> order;
    while (Task* task = queue.pop()) {
        order.push_back(task->id);
        EXPECT_FALSE(task->isQueued());
    }
    EXPECT_EQ(order, (std::vector<int>{1, 2, 5, 4, 3, 0}));
}

TEST(DeadlineQueueTest, RejectsDoubleInsertFullQueueAndForeignRemove)
{
    DeadlineQueue<Task, 2> queue;
    DeadlineQueue<Task, 2> other;
    Task a, b, c, d;
    ASSERT_EQ(other.insert(d, DeadlineKey::make(0, 0, 1, 0)), Status::Ok);
    ASSERT_EQ(queue.insert(a, DeadlineKey::make(0, 0, 1, 0)), Status::Ok);
    EXPECT_EQ(queue.insert(a, DeadlineKey::make(0, 0, 1, 0)), Status::InvalidArgument);
    ASSERT_EQ(queue.insert(b, DeadlineKey::make(0, 0, 2, 0)), Status::Ok);
    EXPECT_EQ(queue.insert(c, DeadlineKey::make(0, 0, 3, 0)), Status::TableFull);
    EXPECT_EQ(queue.remove(c), Status::NotFound);
    // a sits at index 0 of queue, and index 0 of other holds d: still refused.
    EXPECT_EQ(other.remove(a), Status::NotFound);
    EXPECT_EQ(other.peek(), &d);
    EXPECT_EQ(queue.size(), 2u);
    EXPECT_EQ(queue.remove(a), Status::Ok);
    EXPECT_EQ(queue.remove(a), Status::NotFound);
    EXPECT_EQ(queue.peek(), &b);
}

TEST(DeadlineQueueTest, ReinsertAfterRemoveGoesBehindEquals)
{
    DeadlineQueue<Task, 4> queue;
    Task a, b;
    a.id = 1;
    b.id = 2;
    const DeadlineKey same = DeadlineKey::make(3, 0, 100, 10);
    ASSERT_EQ(queue.insert(a, same), Status::Ok);
    ASSERT_EQ(queue.insert(b, same), Status::Ok);
    EXPECT_EQ(queue.peek(), &a);
    ASSERT_EQ(queue.remove(a), Status::Ok);
    ASSERT_EQ(queue.insert(a, same), Status::Ok);
    EXPECT_EQ(queue.peek(), &b);
    EXPECT_EQ(a.deadlineKey().deadline(), 100u);
}

TEST(DeadlineQueueTest, RandomInsertRemoveMatchesSortedReferenceModel)
{
    constexpr int kTasks = 64;
    DeadlineQueue<Task, kTasks> queue;
    Task tasks[kTasks];
    std::mt19937_64 random(42);
    // Reference: (key, arrival sequence) per queued task; sorting it gives the expected pop order.
    std::vector<std::pair<DeadlineKey, uint64_t>> model(kTasks);
    std::vector<bool> queued(kTasks, false);
    uint64_t sequence = 0;

    auto referenceMin = [&]() {
        int best = -1;
        for (int i = 0; i < kTasks; ++i) {
            if (!queued[i]) {
                continue;
            }
            if (best < 0 || model[i].first.precedes(model[best].first)
                || (!model[best].first.precedes(model[i].first) && model[i].second < model[best].second)) {
                best = i;
            }
        }
        return best;
    };

    for (int step = 0; step < 20000; ++step) {
        const int i = static_cast<int>(random() % kTasks);
        tasks[i].id = i;
        const unsigned action = static_cast<unsigned>(random() % 3);
        if (!queued[i] && action != 2) {
            // Small value ranges make ties on every rule frequent.
            const DeadlineKey key = DeadlineKey::make(static_cast<uint8_t>(random() % 3), random() % 8,
                                                      random() % 8, random() % 4);
            ASSERT_EQ(queue.insert(tasks[i], key), Status::Ok);
            model[i] = {key, sequence++};
            queued[i] = true;
        } else if (queued[i] && action == 0) {
            ASSERT_EQ(queue.remove(tasks[i]), Status::Ok);
            queued[i] = false;
        } else if (action == 2) {
            const int expected = referenceMin();
            Task* popped = queue.pop();
            if (expected < 0) {
                ASSERT_EQ(popped, nullptr);
            } else {
                ASSERT_NE(popped, nullptr);
                ASSERT_EQ(popped->id, expected) << "step " << step;
                queued[expected] = false;
            }
        }
        ASSERT_EQ(queue.size(), static_cast<size_t>(std::count(queued.begin(), queued.end(), true)));
        const int expected = referenceMin();
        ASSERT_EQ(queue.peek() == nullptr ? -1 : queue.peek()->id, expected) << "step " << step;
    }

    // Drain and compare with a full sort of the remaining model.
    std::vector<int> remaining;
    for (int i = 0; i < kTasks; ++i) {
        if (queued[i]) {
            remaining.push_back(i);
        }
    }
    std::sort(remaining.begin(), remaining.end(), [&](int a, int b) {
        if (model[a].first.precedes(model[b].first)) {
            return true;
        }
        if (model[b].first.precedes(model[a].first)) {
            return false;
        }
        return model[a].second < model[b].second;
    });
    std::vector<int> drained;
    while (Task* task = queue.pop()) {
        drained.push_back(task->id);
    }
    EXPECT_EQ(drained, remaining);
}
