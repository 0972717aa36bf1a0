#include <dcos/internal/MessageQueue.hpp>

namespace dcos::internal {

// post() and takeFirst() are inline in the header.

void MessageQueue::clear(MessageBufferPool& pool)
{
    // The levels are chained into one list, which goes back at once.
    MessageBuffer* first = nullptr;
    MessageBuffer* last = nullptr;
    for (uint8_t index = 0; index < kLevels; ++index) {
        Level& level = level_[index];
        if (level.head != nullptr) {
            if (last != nullptr) {
                last->next = level.head;
            } else {
                first = level.head;
            }
            last = level.tail;
            level = Level{};
            levels_.clear(index);
        }
    }
    if (first != nullptr) {
        pool.giveChain(*first, *last, count_);
    }
    count_ = 0;
}

} // namespace dcos::internal
