#include <dcos/internal/BufferPool.hpp>

namespace dcos::internal {

namespace {

// The free key is the pool's salt; the allocated key differs from it in every
// bit of the index half, so that a free word of one buffer is an allocated
// word only of the buffer whose index is its complement (more than 32768
// buffers), and in the holder half by a constant.
constexpr uint32_t kAllocatedKeyDifference = 0x414CFFFFu; // "AL" and all ones

constexpr uintptr_t roundUp8(uintptr_t value) { return (value + 7) & ~uintptr_t{7}; }

// The inverse of an odd value modulo 2^N (N the bits of uintptr_t): Newton's
// iteration doubles the correct low bits each step, from three (odd * odd
// is 1 modulo 8).
constexpr uintptr_t inverseOf(uintptr_t odd)
{
    uintptr_t inverse = odd;
    for (int step = 0; step < 5; ++step) {
        inverse *= 2 - odd * inverse;
    }
    return inverse;
}

static_assert(inverseOf(3) * 3 == 1 && inverseOf(0x12345) * 0x12345 == 1 && inverseOf(UINTPTR_MAX) * UINTPTR_MAX == 1);

} // namespace

Status BufferPool::initialise(void* area, size_t areaBytes, size_t bufferSize, uint32_t salt)
{
    *this = BufferPool{};
    const uintptr_t begin = reinterpret_cast<uintptr_t>(area);
    if (area == nullptr || bufferSize < kMinimumBufferSize || bufferSize > areaBytes
        || areaBytes > UINTPTR_MAX - begin) {
        return Status::InvalidArgument;
    }
    const uintptr_t aligned = roundUp8(begin);
    if (aligned - begin >= areaBytes) {
        return Status::InvalidArgument;
    }
    const size_t usable = areaBytes - (aligned - begin);
    const size_t stride = BufferPoolAgent::Stride(bufferSize);
    // AreaBytes(n) lies between n * (12 + stride) and that plus 4, so the
    // estimate below is at most one too high.
    size_t count = usable / (4 + HeldLinks::kBytes + stride);
    if (count != 0 && BufferPoolAgent::AreaBytes(bufferSize, count) > usable) {
        --count;
    }
    if (count == 0 || count > kMaximumBuffers) {
        return Status::InvalidArgument;
    }

    states_ = reinterpret_cast<uint8_t*>(aligned);
    base_ = aligned + roundUp8(count * (4 + HeldLinks::kBytes));
    links_ = states_ + count * 4;
    sizeSlack_ = static_cast<uint8_t>(stride - bufferSize);
    stride_ = static_cast<uint32_t>(stride);
    shift_ = static_cast<uint8_t>(std::countr_zero(stride));
    inverse_ = inverseOf(stride >> shift_);
    count_ = static_cast<uint32_t>(count);
    limit_ = count_;
    freeKey_ = salt;
    allocatedKey_ = salt ^ kAllocatedKeyDifference;
    // Pushed from the last buffer down, so buffers leave in address order.
    for (uint32_t index = count_; index-- > 0;) {
        pushFree(index);
    }
    lowWater_ = count_; // All free: the mark is the count, none above it.
    aboveLowWater_ = 0;
    return Status::Ok;
}

Result<void*> BufferPool::allocateSlowly(uint16_t holder)
{
    if (isCorrupted()) {
        return Status::Corrupted;
    }
    if (holder == kFreeMark) {
        return Status::InvalidArgument;
    }
    if (head_ == kEndOfList) {
        if (freeCount() != 0) {
            return fail(); // Free buffers that no list reaches: a state word was overwritten.
        }
        ++failedAllocations_;
        return Status::NoMemory;
    }
    // tryAllocate() refused a head that is not the end: it is out of range,
    // or its state word does not say free.
    return fail();
}

Status BufferPool::releaseSlowly(void* buffer, uint16_t holder)
{
    if (isCorrupted()) {
        return Status::Corrupted;
    }
    const Result<uint32_t> index = allocatedIndexOf(buffer, holder);
    if (!index.ok()) {
        return index.status();
    }
    pushFree(index.value()); // A system buffer, which tryRelease() leaves to this path.
    return Status::Ok;
}

Status BufferPool::transferIndex(void* buffer, uint16_t from, uint16_t to, uint16_t& previous)
{
    if (isCorrupted()) {
        return Status::Corrupted;
    }
    if (to == kFreeMark) {
        return Status::InvalidArgument;
    }
    const Result<uint32_t> index = allocatedIndexOf(buffer, from);
    if (!index.ok()) {
        return index.status();
    }
    uint32_t next;
    (void)stateOf(index.value(), previous, next); // Checked by allocatedIndexOf: from or the system.
    storeState(index.value(), ((static_cast<uint32_t>(to) << 16) | index.value()) ^ allocatedKey_);
    return Status::Ok;
}

bool BufferPool::reclaim(uint32_t index, uint16_t holder)
{
    uint16_t current;
    uint32_t next;
    if (index >= limit_ || stateOf(index, current, next) != State::Allocated || current != holder) {
        return false;
    }
    pushFree(index);
    return true;
}

size_t BufferPool::reclaimHeldBy(uint16_t holder)
{
    size_t reclaimed = 0;
    for (uint32_t index = 0; index < count_ && !isCorrupted(); ++index) {
        uint16_t current;
        uint32_t next;
        const State state = stateOf(index, current, next);
        if (state == State::Invalid) {
            (void)fail(); // Disables the pool, which ends the walk; recovery has no one to tell.
        } else if (state == State::Allocated && current == holder) {
            pushFree(index);
            ++reclaimed;
        }
    }
    return reclaimed;
}

Status BufferPool::audit()
{
    if (isCorrupted()) {
        return Status::Corrupted;
    }
    uint32_t freeStates = 0;
    for (uint32_t index = 0; index < count_; ++index) {
        uint16_t holder;
        uint32_t next;
        const State state = stateOf(index, holder, next);
        if (state == State::Invalid) {
            return fail();
        }
        freeStates += state == State::Free ? 1 : 0;
    }
    const uint32_t free = freeCount();
    if (freeStates != free) {
        return fail();
    }
    // A list that ends within free steps visits distinct buffers, because
    // each buffer has one link; with free steps it visits them all.
    uint32_t steps = 0;
    for (uint32_t index = head_; index != kEndOfList;) {
        uint16_t holder;
        uint32_t next;
        if (index >= count_ || ++steps > free || stateOf(index, holder, next) != State::Free) {
            return fail();
        }
        index = next;
    }
    return steps == free ? Status::Ok : fail();
}

BufferPoolStatistics BufferPool::statistics() const
{
    BufferPoolStatistics statistics;
    statistics.bufferSize = stride_ - sizeSlack_;
    statistics.totalBuffers = count_;
    statistics.freeBuffers = freeCount();
    statistics.lowWaterMark = lowWater_;
    statistics.allocations = allocations_;
    statistics.failedAllocations = failedAllocations_;
    // Every buffer allocated is either still out or was returned (by Return
    // or by recovery), so the returns need no counter of their own.
    statistics.returns = allocations_ - (count_ - freeCount());
    return statistics;
}

bool BufferPool::holderOf(size_t index, uint16_t& holder) const
{
    if (index >= count_) {
        return false;
    }
    uint32_t next;
    switch (stateOf(static_cast<uint32_t>(index), holder, next)) {
    case State::Free: holder = kFreeMark; return true;
    case State::Allocated: return true;
    case State::Invalid: return false;
    }
    return false;
}

BufferPool::State BufferPool::stateOf(uint32_t index, uint16_t& holder, uint32_t& next) const
{
    const uint32_t word = loadState(index);
    if (static_cast<uint16_t>(word ^ freeKey_) == index) {
        next = (word ^ freeKey_) >> 16;
        // A free buffer's link is the end or another buffer.
        return next == kEndOfList || next < count_ ? State::Free : State::Invalid;
    }
    if (static_cast<uint16_t>(word ^ allocatedKey_) == index) {
        holder = static_cast<uint16_t>((word ^ allocatedKey_) >> 16);
        // kFreeMark is never stored as a holder (allocate and transfer refuse it).
        return holder != kFreeMark ? State::Allocated : State::Invalid;
    }
    return State::Invalid;
}

Result<uint32_t> BufferPool::allocatedIndexOf(void* buffer, uint16_t holder)
{
    const uintptr_t address = reinterpret_cast<uintptr_t>(buffer);
    if (count_ == 0 || address < base_ || address - base_ >= uintptr_t{count_} * stride_) {
        return Status::InvalidArgument; // Not this pool's memory: the pool is unharmed.
    }
    const uintptr_t index = indexOf(buffer);
    if (index >= count_) {
        return fail(); // A wild pointer into the pool.
    }
    uint16_t current;
    uint32_t next;
    if (stateOf(static_cast<uint32_t>(index), current, next) != State::Allocated) {
        return fail(); // Returned twice, or its state word was overwritten.
    }
    if (current != holder && current != kSystemHolder) {
        return Status::NotOwner;
    }
    return static_cast<uint32_t>(index);
}

Status BufferPool::fail()
{
    limit_ = 0; // The fast paths' range test now fails for every index, and isCorrupted() holds.
    return Status::Corrupted;
}

} // namespace dcos::internal
