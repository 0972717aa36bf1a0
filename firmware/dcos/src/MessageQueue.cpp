#include <dcos/internal/MessageQueue.hpp>

namespace dcos::internal {

void MessageQueue::post(MessageBuffer& buffer, int priority)
{
    const Placement placement = placementOf(order_, priority);
    Level& level = level_[placement.level];
    if (level.head == nullptr) {
        buffer.next = nullptr;
        level.head = level.tail = &buffer;
        levels_.set(placement.level);
    } else if (placement.lifo) {
        buffer.next = level.head;
        level.head = &buffer;
    } else {
        buffer.next = nullptr;
        level.tail->next = &buffer;
        level.tail = &buffer;
    }
    ++level.count;
    ++count_;
}

MessageBuffer* MessageQueue::takeFirst()
{
    const uint8_t first = levels_.highest();
    if (first == ReadyBitmap::kNone) {
        return nullptr;
    }
    Level& level = level_[first];
    MessageBuffer* buffer = level.head;
    level.head = buffer->next;
    if (level.head == nullptr) {
        level.tail = nullptr;
        levels_.clear(first);
    }
    buffer->next = nullptr;
    --level.count;
    --count_;
    return buffer;
}

void MessageQueue::clear(MessageBufferPool& pool)
{
    for (uint8_t index = 0; index < kLevels; ++index) {
        Level& level = level_[index];
        if (level.head != nullptr) {
            pool.giveChain(*level.head, *level.tail, level.count);
            level = Level{};
            levels_.clear(index);
        }
    }
    count_ = 0;
}

} // namespace dcos::internal
