#include <bsp/SharedMemoryRing.hpp>

namespace bsp {

namespace {

// Keeps the compiler from moving memory accesses across it; the processor
// keeps the order it needs by itself (see the header).
inline void compilerBarrier() { asm volatile("" ::: "memory"); }

} // namespace

void SharedMemoryRing::reset()
{
    head_ = 0;
    tail_ = 0;
    for (SharedMemoryMessage& slot : slots_) {
        slot = SharedMemoryMessage{};
    }
}

bool SharedMemoryRing::push(const SharedMemoryMessage& message)
{
    const uint32_t head = head_;
    if (head - tail_ >= kSlots) {
        return false;
    }
    slots_[head % kSlots] = message;
    compilerBarrier();
    head_ = head + 1;
    return true;
}

SharedMemoryRing::Pop SharedMemoryRing::pop(SharedMemoryMessage& message)
{
    const uint32_t tail = tail_;
    const uint32_t full = head_ - tail;
    if (full == 0) {
        return Pop::Empty;
    }
    if (full > kSlots) {
        return Pop::Corrupted;
    }
    compilerBarrier();
    message = slots_[tail % kSlots];
    compilerBarrier();
    tail_ = tail + 1;
    return Pop::Taken;
}

} // namespace bsp
