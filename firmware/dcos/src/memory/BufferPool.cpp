#include <dcos/internal/BufferPool.hpp>

namespace dcos::internal {

namespace {

// Distinct constants for the three kinds of word, so that a state word can
// never pass as a link word or the other way round.
constexpr uint32_t kFreeKind = 0x46524545u;      // "FREE"
constexpr uint32_t kAllocatedKind = 0x414C4F43u; // "ALOC"
constexpr uint32_t kLinkKind = 0x4C494E4Bu;      // "LINK"

// The area belongs to the application, which may declare it as bytes of any
// type; words are therefore moved with memcpy, which the compiler turns into
// a single load or store and which is valid whatever the declared type.
uint32_t loadWord(const void* address)
{
    uint32_t word;
    __builtin_memcpy(&word, address, sizeof word);
    return word;
}

void storeWord(void* address, uint32_t word) { __builtin_memcpy(address, &word, sizeof word); }

constexpr uintptr_t roundUp8(uintptr_t value) { return (value + 7) & ~uintptr_t{7}; }

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
    // AreaBytes(n) lies between n * (4 + stride) and that plus 4, so the
    // estimate below is at most one too high.
    size_t count = usable / (4 + stride);
    if (count != 0 && BufferPoolAgent::AreaBytes(bufferSize, count) > usable) {
        --count;
    }
    if (count == 0 || count > kMaximumBuffers) {
        return Status::InvalidArgument;
    }

    states_ = reinterpret_cast<uint8_t*>(aligned);
    buffers_ = reinterpret_cast<uint8_t*>(aligned + roundUp8(count * 4));
    areaBegin_ = begin;
    areaEnd_ = begin + areaBytes;
    bufferSize_ = static_cast<uint32_t>(bufferSize);
    stride_ = static_cast<uint32_t>(stride);
    count_ = static_cast<uint32_t>(count);
    salt_ = salt;
    // Pushed from the last buffer down, so buffers leave in address order.
    for (uint32_t index = count_; index-- > 0;) {
        pushFree(index);
    }
    free_ = count_;
    lowWater_ = count_;
    return Status::Ok;
}

Result<void*> BufferPool::allocate(uint16_t holder)
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    if (holder == kFreeMark) {
        return Status::InvalidArgument;
    }
    if (head_ == kEndOfList) {
        if (free_ != 0) {
            return fail(); // Free buffers that no list reaches: the head was overwritten.
        }
        ++failedAllocations_;
        return Status::NoMemory;
    }
    const uint32_t index = head_;
    uint16_t ignored;
    if (index >= count_ || free_ == 0 || stateOf(index, ignored) != State::Free) {
        return fail();
    }
    void* buffer = bufferAt(index);
    const uint32_t link = loadWord(buffer);
    const uint16_t next = static_cast<uint16_t>(link);
    if ((link >> 16) != seal(kLinkKind, index, next) || (next != kEndOfList && next >= count_)
        || ((next == kEndOfList) != (free_ == 1))) {
        return fail();
    }
    // Every word was checked before this point; now the buffer changes hands.
    storeWord(buffer, 0); // An allocated buffer never holds a valid link.
    storeWord(states_ + index * 4, allocatedWord(index, holder));
    head_ = next;
    --free_;
    if (free_ < lowWater_) {
        lowWater_ = free_;
    }
    ++allocations_;
    return buffer;
}

Status BufferPool::release(void* buffer, uint16_t holder)
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    const Result<uint32_t> index = allocatedIndexOf(buffer, holder);
    if (!index.ok()) {
        return index.status();
    }
    pushFree(index.value());
    ++free_;
    ++returns_;
    return Status::Ok;
}

Status BufferPool::transfer(void* buffer, uint16_t from, uint16_t to)
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    if (to == kFreeMark) {
        return Status::InvalidArgument;
    }
    const Result<uint32_t> index = allocatedIndexOf(buffer, from);
    if (!index.ok()) {
        return index.status();
    }
    storeWord(states_ + index.value() * 4, allocatedWord(index.value(), to));
    return Status::Ok;
}

size_t BufferPool::reclaimHeldBy(uint16_t holder)
{
    size_t reclaimed = 0;
    for (uint32_t index = 0; index < count_ && !corrupted_; ++index) {
        uint16_t current;
        const State state = stateOf(index, current);
        if (state == State::Invalid) {
            (void)fail(); // Disables the pool, which ends the walk; recovery has no one to tell.
        } else if (state == State::Allocated && current == holder) {
            pushFree(index);
            ++free_;
            ++returns_;
            ++reclaimed;
        }
    }
    return reclaimed;
}

Status BufferPool::audit()
{
    if (corrupted_) {
        return Status::Corrupted;
    }
    uint32_t freeStates = 0;
    for (uint32_t index = 0; index < count_; ++index) {
        uint16_t holder;
        const State state = stateOf(index, holder);
        if (state == State::Invalid) {
            return fail();
        }
        freeStates += state == State::Free ? 1 : 0;
    }
    if (freeStates != free_) {
        return fail();
    }
    // A list that ends within free_ steps visits distinct buffers, because
    // each buffer has one link; with free_ steps it visits them all.
    uint32_t steps = 0;
    for (uint32_t index = head_; index != kEndOfList;) {
        uint16_t holder;
        if (index >= count_ || ++steps > free_ || stateOf(index, holder) != State::Free) {
            return fail();
        }
        const uint32_t link = loadWord(bufferAt(index));
        const uint16_t next = static_cast<uint16_t>(link);
        if ((link >> 16) != seal(kLinkKind, index, next)) {
            return fail();
        }
        index = next;
    }
    return steps == free_ ? Status::Ok : fail();
}

BufferPoolStatistics BufferPool::statistics() const
{
    BufferPoolStatistics statistics;
    statistics.bufferSize = bufferSize_;
    statistics.totalBuffers = count_;
    statistics.freeBuffers = free_;
    statistics.lowWaterMark = lowWater_;
    statistics.allocations = allocations_;
    statistics.failedAllocations = failedAllocations_;
    statistics.returns = returns_;
    return statistics;
}

bool BufferPool::holderOf(size_t index, uint16_t& holder) const
{
    if (index >= count_) {
        return false;
    }
    switch (stateOf(static_cast<uint32_t>(index), holder)) {
    case State::Free: holder = kFreeMark; return true;
    case State::Allocated: return true;
    case State::Invalid: return false;
    }
    return false;
}

uint16_t BufferPool::seal(uint32_t kind, uint32_t index, uint32_t value) const
{
    return static_cast<uint16_t>(
        mixBits(salt_ ^ kind ^ multiplyWord(index, 0x9E3779B1u) ^ multiplyWord(value, 0x85EBCA77u)) >> 16);
}

uint32_t BufferPool::freeWord(uint32_t index) const
{
    return (static_cast<uint32_t>(seal(kFreeKind, index, kFreeMark)) << 16) | kFreeMark;
}

uint32_t BufferPool::allocatedWord(uint32_t index, uint16_t holder) const
{
    return (static_cast<uint32_t>(seal(kAllocatedKind, index, holder)) << 16) | holder;
}

uint32_t BufferPool::linkWord(uint32_t index, uint16_t next) const
{
    return (static_cast<uint32_t>(seal(kLinkKind, index, next)) << 16) | next;
}

BufferPool::State BufferPool::stateOf(uint32_t index, uint16_t& holder) const
{
    const uint32_t word = loadWord(states_ + index * 4);
    holder = static_cast<uint16_t>(word);
    if (holder == kFreeMark) {
        return word == freeWord(index) ? State::Free : State::Invalid;
    }
    return word == allocatedWord(index, holder) ? State::Allocated : State::Invalid;
}

Result<uint32_t> BufferPool::allocatedIndexOf(void* buffer, uint16_t holder)
{
    const uintptr_t address = reinterpret_cast<uintptr_t>(buffer);
    const uintptr_t base = reinterpret_cast<uintptr_t>(buffers_);
    if (count_ == 0 || address < base || address - base >= size_t{count_} * stride_) {
        return Status::InvalidArgument; // Not this pool's memory: the pool is unharmed.
    }
    const uintptr_t offset = address - base;
    if (offset % stride_ != 0) {
        return fail(); // A wild pointer into the pool.
    }
    const uint32_t index = static_cast<uint32_t>(offset / stride_);
    uint16_t current;
    if (stateOf(index, current) != State::Allocated) {
        return fail(); // Returned twice, or its state word was overwritten.
    }
    if (current != holder && current != kSystemHolder) {
        return Status::NotOwner;
    }
    return index;
}

void BufferPool::pushFree(uint32_t index)
{
    storeWord(bufferAt(index), linkWord(index, head_));
    storeWord(states_ + index * 4, freeWord(index));
    head_ = static_cast<uint16_t>(index);
}

Status BufferPool::fail()
{
    corrupted_ = true;
    return Status::Corrupted;
}

} // namespace dcos::internal
