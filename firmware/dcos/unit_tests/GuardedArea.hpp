// A memory area for the pool and heap host tests: 8-byte aligned, with guard
// bytes on both sides, so that an algorithm writing outside its area is caught.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace dcos_test {

class GuardedArea {
public:
    /// The guards, and the area's own bytes unless @p fill says otherwise.
    static constexpr uint8_t kGuardByte = 0xA5;

    /// An area of @p bytes, each set to @p fill.
    explicit GuardedArea(size_t bytes, uint8_t fill = kGuardByte) : storage_(bytes + 2 * kGuard + 8, kGuardByte)
    {
        const uintptr_t raw = reinterpret_cast<uintptr_t>(storage_.data()) + kGuard;
        offset_ = ((raw + 7) & ~uintptr_t{7}) - reinterpret_cast<uintptr_t>(storage_.data());
        bytes_ = bytes;
        std::fill(storage_.begin() + static_cast<long>(offset_), storage_.begin() + static_cast<long>(offset_ + bytes),
                  fill);
    }
    uint8_t* data() { return storage_.data() + offset_; }
    size_t size() const { return bytes_; }
    /// Whether every byte outside the area still holds kGuardByte.
    bool guardsIntact() const
    {
        for (size_t i = 0; i < storage_.size(); ++i) {
            if ((i < offset_ || i >= offset_ + bytes_) && storage_[i] != kGuardByte) {
                return false;
            }
        }
        return true;
    }

private:
    static constexpr size_t kGuard = 32;
    std::vector<uint8_t> storage_;
    size_t offset_ = 0;
    size_t bytes_ = 0;
};

} // namespace dcos_test
