// Time-out queue of the timer agent (dissertation 7.5, Fig. 7.9).
//
// Instead of one delta list with O(N) insertion, time-outs are spread over a
// prime number of slots: a time-out due at absolute tick t lives in slot
// t mod Slots, and each slot is a list sorted by due tick. Every clock tick
// the wheel visits the next slot and fires the entries at its front whose
// due tick has been reached. A time-out several revolutions ahead simply
// stays behind the earlier entries of its slot until its own revolution. A
// prime slot count keeps periodic time-outs whose period shares a factor
// with the slot count from piling up in a few slots.
#pragma once

#include <dcos/Status.hpp>
#include <dcos/internal/SortedList.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// The links and due tick a timer or task embeds, by deriving from it, to wait on a TimeWheel.
template <typename Tag = void>
using TimeWheelNode = SortedListNode<uint64_t, Tag>;

/// Whether @p value is prime; used to check the slot count at compile time.
constexpr bool isPrime(size_t value)
{
    if (value < 2) {
        return false;
    }
    for (size_t divisor = 2; divisor * divisor <= value; ++divisor) {
        if (value % divisor == 0) {
            return false;
        }
    }
    return true;
}

/// A time wheel of Slots sorted lists of T, keyed by absolute due tick.
///
/// T derives from TimeWheelNode<Tag>. Expired entries are handed back to the
/// caller one at a time by popExpired (or through advance), so the timer
/// agent decides how to notify the owner and nothing is allocated. The wheel
/// does no locking; the timer agent serialises access to it.
template <typename T, size_t Slots, typename Tag = void>
class TimeWheel {
    static_assert(isPrime(Slots), "the seed requires a prime number of time wheel slots");

public:
    /// The node type T must derive from.
    using Node = TimeWheelNode<Tag>;

    /// Creates an empty wheel whose clock has reached @p startTick.
    explicit TimeWheel(uint64_t startTick = 0) : cursor_(startTick), cursorSlot_(slotOf(startTick)) {}
    TimeWheel(const TimeWheel&) = delete;
    TimeWheel& operator=(const TimeWheel&) = delete;

    /// Number of slots.
    static constexpr size_t slotCount() { return Slots; }
    /// The slot a time-out due at @p tick belongs to.
    static constexpr size_t slotOf(uint64_t tick) { return static_cast<size_t>(tick % Slots); }

    /// The tick whose slot the wheel is processing; all earlier ticks are done.
    constexpr uint64_t currentTick() const { return cursor_; }
    /// Number of pending time-outs, for tests and diagnostics. Cost
    /// O(Slots + pending time-outs): the wheel keeps no count, so that
    /// cancel is a bare unlink that needs no wheel (see cancel).
    size_t size() const
    {
        size_t pending = 0;
        for (const SortedList<T, uint64_t, Tag>& slot : slots_) {
            pending += slot.size();
        }
        return pending;
    }

    /// Arms @p item to expire at absolute tick @p dueTick.
    ///
    /// A due tick the wheel has already reached goes into the current slot,
    /// so the next popExpired or advance fires it instead of it waiting a
    /// whole revolution. Fails with InvalidArgument when @p item is already
    /// armed. Cost O(number of later entries in the slot), O(1) on average.
    Status insert(T& item, uint64_t dueTick)
    {
        if (static_cast<Node&>(item).isLinked()) {
            return Status::InvalidArgument;
        }
        const size_t slot = dueTick <= cursor_ ? cursorSlot_ : slotOf(dueTick);
        slots_[slot].insert(item, dueTick);
        return Status::Ok;
    }

    /// Disarms @p item.
    ///
    /// The wheel keeps no count and the lists are intrusive, so this only
    /// unlinks @p item from whatever list holds it: any wheel of this type,
    /// or the lists of a DayClockWheel. The timer agent relies on that to
    /// cancel a time-out without knowing where it is armed. Fails with
    /// NotFound when @p item is not armed (it may just have expired, a race
    /// the caller resolves). Cost O(1).
    Status cancel(T& item)
    {
        Node& node = item;
        if (!node.isLinked()) {
            return Status::NotFound;
        }
        node.unlink();
        return Status::Ok;
    }

    /// Moves the wheel's clock back to @p tick, for a wheel keyed by a clock
    /// that was set back. Every armed entry is due after the current tick
    /// (advance leaves none that is due), so all of them are still due after
    /// @p tick and in the slot of their due tick, where the wheel, turning on
    /// from @p tick, finds them. A @p tick not before the current one changes
    /// nothing: popExpired catches up by itself. Cost O(1).
    void rewind(uint64_t tick)
    {
        if (tick < cursor_) {
            cursor_ = tick;
            cursorSlot_ = slotOf(tick);
        }
    }

    /// Returns one entry due at or before @p nowTick and disarms it, or null when none is left.
    ///
    /// The caller loops until null after each clock tick. Entries come out in
    /// due order when the wheel is advanced every tick. When @p nowTick is
    /// more than one revolution ahead (the agent was held off), the wheel
    /// skips to the last revolution, in which every slot is visited once with
    /// a tick no earlier than any due entry in it, so nothing is lost and the
    /// catch-up costs at most one revolution; late entries may then come out
    /// in slot order. Cost O(ticks elapsed, at most Slots) + O(1) per entry.
    T* popExpired(uint64_t nowTick)
    {
        if (nowTick > cursor_ && nowTick - cursor_ > Slots) {
            cursor_ = nowTick - Slots;
            cursorSlot_ = slotOf(cursor_);
        }
        for (;;) {
            SortedList<T, uint64_t, Tag>& slot = slots_[cursorSlot_];
            if (!slot.isEmpty() && SortedList<T, uint64_t, Tag>::keyOf(slot.front()) <= cursor_) {
                return slot.popFront();
            }
            if (cursor_ >= nowTick) {
                return nullptr;
            }
            ++cursor_;
            if (++cursorSlot_ == Slots) {
                cursorSlot_ = 0;
            }
        }
    }

    /// Fires every entry due at or before @p nowTick by calling @p onExpired(T&).
    ///
    /// The entry is disarmed before the call, so the callback may re-arm it
    /// (periodic alarms) or arm others. An entry re-armed for a tick not
    /// after @p nowTick fires again within the same call, so a periodic
    /// alarm must use a period of at least one tick. Returns the number fired.
    template <typename Callback>
    size_t advance(uint64_t nowTick, Callback&& onExpired)
    {
        size_t fired = 0;
        while (T* item = popExpired(nowTick)) {
            ++fired;
            onExpired(*item);
        }
        return fired;
    }

private:
    SortedList<T, uint64_t, Tag> slots_[Slots];
    uint64_t cursor_;
    size_t cursorSlot_;
};

} // namespace dcos::internal
