// Ready-queue bitmap of the static priority scheduler (dissertation 7.4.1, Fig. 7.5).
#pragma once

#include <stdint.h>

namespace dcos::internal {

/// One bit per static priority, set while that priority's ready queue is non-empty.
///
/// DCOS has 32 static priorities, 0 being the highest. Bit n stands for
/// priority n, so the highest ready priority is the lowest set bit, which
/// one count-trailing-zeros instruction (BSF on the i486) finds in constant
/// time regardless of how many tasks are ready.
class ReadyBitmap {
public:
    /// Number of static priority levels.
    static constexpr uint8_t kLevels = 32;
    /// Returned by highest() when no priority is ready.
    static constexpr uint8_t kNone = kLevels;

    /// Marks @p priority (0..31) as having ready tasks. Cost O(1).
    constexpr void set(uint8_t priority) { bits_ |= bit(priority); }
    /// Marks @p priority (0..31) as having no ready task. Cost O(1).
    constexpr void clear(uint8_t priority) { bits_ &= ~bit(priority); }
    /// clear(highest()) for a non-empty bitmap: the highest priority is the
    /// lowest set bit, which bits & (bits - 1) clears without the bit's
    /// number, so a caller need not keep it in a register. Cost O(1).
    constexpr void clearHighest() { bits_ &= bits_ - 1; }
    /// Whether @p priority (0..31) has ready tasks. Cost O(1).
    constexpr bool test(uint8_t priority) const { return (bits_ & bit(priority)) != 0; }
    /// Whether no priority has ready tasks, i.e. only the idle path can run. Cost O(1).
    constexpr bool isEmpty() const { return bits_ == 0; }
    /// The raw bit pattern, for diagnostics and the shell.
    constexpr uint32_t bits() const { return bits_; }

    /// The highest (numerically lowest) ready priority, or kNone when empty. Cost O(1).
    ///
    /// __builtin_ctz is used rather than std::countr_zero because the latter
    /// must define a result for zero, which costs an extra branch on the
    /// i486 (no CMOV); the zero case is handled once here instead.
    constexpr uint8_t highest() const
    {
        if (bits_ == 0) {
            return kNone;
        }
        return static_cast<uint8_t>(__builtin_ctz(bits_));
    }

private:
    // Callers pass validated priorities (Create and ChangePriority refuse
    // values above 31), so no masking is spent on the hot path.
    static constexpr uint32_t bit(uint8_t priority) { return uint32_t{1} << priority; }

    uint32_t bits_ = 0;
};

} // namespace dcos::internal
