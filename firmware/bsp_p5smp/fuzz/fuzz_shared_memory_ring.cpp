// The shared-memory ring as a reader finds it after the other node wrote it:
// any bytes at all for its indices and slots (a faulty or dying node may
// leave anything there). Reading must never go past the ring, never take
// more messages than the indices can honestly hold, and a message taken
// must be a slot's bytes, whatever they are.
#include <bsp/SharedMemoryRing.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    auto ring = std::make_unique<bsp::SharedMemoryRing>();
    const size_t bytes = size < sizeof(bsp::SharedMemoryRing) ? size : sizeof(bsp::SharedMemoryRing);
    std::memcpy(static_cast<void*>(ring.get()), data, bytes);
    bsp::SharedMemoryMessage message{};
    uint32_t taken = 0;
    for (;;) {
        const bsp::SharedMemoryRing::Pop result = ring->pop(message);
        if (result != bsp::SharedMemoryRing::Pop::Taken) {
            break;
        }
        if (++taken > bsp::SharedMemoryRing::kSlots) {
            std::abort(); // More than a ring holds from one set of indices.
        }
    }
    // The rest of the input, if any, is written as messages and read back.
    for (size_t at = bytes; at + sizeof message <= size; at += sizeof message) {
        std::memcpy(&message, data + at, sizeof message);
        if (ring->push(message)) {
            bsp::SharedMemoryMessage back{};
            if (ring->pop(back) == bsp::SharedMemoryRing::Pop::Taken && std::memcmp(&back, &message, sizeof back) != 0) {
                std::abort(); // Whatever went in must come out.
            }
        }
    }
    return 0;
}
