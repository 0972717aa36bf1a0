// The list of the memory one task holds, so that recovery gives back what a
// dead task held without walking every pool and heap (issue 12: "KillTask /
// Delete recovery: proportional to what the task owns, never to table
// sizes").
//
// Every task has one list of the buffers it holds and one of the heap
// segments. An item on a list is named by a 32-bit handle: the slot of its
// pool or heap in the agent's table in the high bits and the item in that
// pool or heap in the low bits (the agent chooses the split). Its two links,
// the next and the previous item's handles, are kept beside the item's own
// bookkeeping: in a pool's state table, in a heap segment's header. Those
// lie in the application's memory area, so a stray write there can damage a
// link; the agent's resolver therefore checks every handle before a link is
// followed (the slot in service, the item in range), and every operation
// checks that its neighbours link back to the item before it writes either.
// A list that fails a check is marked lost: it is no longer followed or
// changed, and recovery falls back to walking every pool or heap for the
// task's holder tag, as it did before the lists existed. A corrupted or
// deleted pool is the usual cause; the task's other memory is still given
// back, only at the old cost.
//
// The item a task took last is not linked at once: it waits in the head
// (HeldHead::newest) and goes onto the list only when the task takes
// another while still holding it. A task that takes one buffer and gives it
// back, the common pattern of a control loop, therefore touches no link at
// all; its holder's head is kernel memory, which no stray write in an
// application's area can reach.
//
// The items of the system (memory taken in an interrupt handler or before
// the scheduler starts) are on no list, and their links are never read: the
// system does not end.
//
// Take and give cost O(1); recovery walks the list, O(items held).
#pragma once

#include <stdint.h>

namespace dcos::internal {

/// The link words of one held item, at an address in application memory.
/// Moved with memcpy, like the words around them, whatever type the
/// application declared its area with.
class HeldLinks {
public:
    /// The handle of the next item, or kHeldEnd after the last.
    static uint32_t next(const uint8_t* links) { return load(links); }
    /// The handle of the previous item, kHeldFirst before the first, or kHeldUnlisted.
    static uint32_t previous(const uint8_t* links) { return load(links + 4); }
    static void setNext(uint8_t* links, uint32_t handle) { store(links, handle); }
    static void setPrevious(uint8_t* links, uint32_t handle) { store(links + 4, handle); }

    /// Bytes of the two links.
    static constexpr uint32_t kBytes = 8;

private:
    static uint32_t load(const uint8_t* at)
    {
        uint32_t word;
        __builtin_memcpy(&word, at, sizeof word);
        return word;
    }
    static void store(uint8_t* at, uint32_t word) { __builtin_memcpy(at, &word, sizeof word); }
};

/// A copy of an item's links, for remove() once the item's own are gone (a
/// heap segment merged on its return): the neighbours are checked and
/// changed against the values the links had.
struct HeldLinksCopy {
    HeldLinksCopy(uint32_t next, uint32_t previous)
    {
        HeldLinks::setNext(bytes, next);
        HeldLinks::setPrevious(bytes, previous);
    }
    uint8_t bytes[HeldLinks::kBytes];
};

/// What a task holds of one kind (buffers, or heap segments): the item it
/// took last, not yet linked, and the list of the others. Kernel memory.
struct HeldHead {
    /// The item taken last, or kHeldEnd.
    uint32_t newest;
    /// The first linked item, kHeldEnd, or kHeldLost.
    uint32_t first;
};

/// An empty list's head, and the next link of the last item.
constexpr uint32_t kHeldEnd = 0xFFFFFFFFu;
/// The previous link of the first item.
constexpr uint32_t kHeldFirst = 0xFFFFFFFEu;
/// The previous link of an item pushFront() could not take because its list
/// was lost: remove() leaves it alone. (The system's items, on no list
/// either, are never given to remove().)
constexpr uint32_t kHeldUnlisted = 0xFFFFFFFDu;
/// The head of a list that failed a check: recovery walks everything for its holder.
constexpr uint32_t kHeldLost = 0xFFFFFFFCu;
/// Every handle an agent forms lies below this.
constexpr uint32_t kHeldHandleLimit = kHeldLost;

/// The list operations. @p resolve(handle) gives the links of the item a
/// handle names, or null when the handle names no item in service (a handle
/// at or above kHeldHandleLimit included); it must never give the links of
/// memory outside a pool's or heap's bookkeeping.
class HeldList {
public:
    /// Puts the item @p handle, whose links are at @p links, first on the
    /// list headed by @p head. O(1). The item's previous neighbour to be
    /// must link back to the head; if not, the list is marked lost, and the
    /// item left on none.
    template <typename Resolve>
    [[gnu::always_inline]] static void pushFront(uint32_t& head, uint32_t handle, uint8_t* links, Resolve resolve)
    {
        const uint32_t first = head;
        if (first != kHeldEnd) {
            uint8_t* const firstLinks = resolve(first);
            if (firstLinks == nullptr || HeldLinks::previous(firstLinks) != kHeldFirst) [[unlikely]] {
                markLost(head); // A lost head resolves to nothing, so this is the lost case too.
                setUnlisted(links);
                return;
            }
            HeldLinks::setPrevious(firstLinks, handle);
        }
        HeldLinks::setNext(links, first);
        HeldLinks::setPrevious(links, kHeldFirst);
        head = handle;
    }

    /// Takes the item @p handle, whose links are at @p links, off the list
    /// headed by @p head, which must be the list of the item's holder. O(1).
    /// An unlisted item is left as it is; when a neighbour does not link
    /// back, no link is changed and the list is marked lost.
    template <typename Resolve>
    [[gnu::always_inline]] static void remove(uint32_t& head, uint32_t handle, uint8_t* links, Resolve resolve)
    {
        const uint32_t previous = HeldLinks::previous(links);
        const uint32_t next = HeldLinks::next(links);
        // A lost head needs no test of its own: it is no item's handle, so the
        // checks below fail and mark it lost again.
        if (previous == kHeldUnlisted) [[unlikely]] {
            return;
        }
        uint8_t* previousLinks = nullptr;
        if (previous == kHeldFirst) {
            if (head != handle) [[unlikely]] {
                markLost(head);
                return;
            }
        } else {
            previousLinks = resolve(previous);
            if (previousLinks == nullptr || HeldLinks::next(previousLinks) != handle) [[unlikely]] {
                markLost(head);
                return;
            }
        }
        if (next != kHeldEnd) {
            uint8_t* const nextLinks = resolve(next);
            if (nextLinks == nullptr || HeldLinks::previous(nextLinks) != handle) [[unlikely]] {
                markLost(head);
                return;
            }
            HeldLinks::setPrevious(nextLinks, previous);
        }
        if (previousLinks != nullptr) {
            HeldLinks::setNext(previousLinks, next);
        } else {
            head = next;
        }
        // The item's own links are left as they are: it is leaving its
        // holder, and whoever takes it next writes them anew.
    }

    /// Records that the holder of @p head took the item @p handle. O(1).
    /// The item becomes the newest; the one that was (if the holder still
    /// holds it) is linked first on the list, which is marked lost when the
    /// links of either do not check out.
    template <typename Resolve>
    [[gnu::always_inline]] static void take(HeldHead& head, uint32_t handle, Resolve resolve)
    {
        const uint32_t previousNewest = head.newest;
        head.newest = handle;
        if (previousNewest != kHeldEnd) [[unlikely]] {
            link(head, previousNewest, resolve);
        }
    }

    /// Records that the holder of @p head gave the item @p handle, whose
    /// links are at @p links, away (returned or handed over). O(1). The
    /// newest item is only forgotten; another is taken off the list.
    template <typename Resolve>
    [[gnu::always_inline]] static void give(HeldHead& head, uint32_t handle, uint8_t* links, Resolve resolve)
    {
        if (head.newest == handle) [[likely]] {
            head.newest = kHeldEnd;
            return;
        }
        unlink(head, handle, links, resolve);
    }

    /// forEach() over everything @p head holds: the newest item (its links
    /// are not checked: they are not in use), then the list. Returns false
    /// when the list was lost or a check failed, as forEach() does.
    template <typename Resolve, typename Visit>
    static bool forEachHeld(const HeldHead& head, Resolve resolve, Visit visit)
    {
        if (head.first == kHeldLost) {
            return false;
        }
        if (head.newest != kHeldEnd) {
            uint8_t* const links = resolve(head.newest);
            if (links == nullptr || !visit(head.newest, links)) {
                return false;
            }
        }
        return forEach(head.first, resolve, visit);
    }

    /// Marks an item as on no list, as pushFront() does when the list is lost. O(1).
    static void setUnlisted(uint8_t* links) { HeldLinks::setPrevious(links, kHeldUnlisted); }

    /// Walks the list headed by @p head from the first item: @p visit(handle,
    /// links) for each item, checked to link back to the one before, until
    /// the end, a check fails, or @p visit returns false. Returns true when
    /// the whole list was walked. @p visit may change the item (the walk has
    /// read its next link first), but no other item. O(items).
    template <typename Resolve, typename Visit>
    static bool forEach(uint32_t head, Resolve resolve, Visit visit)
    {
        if (head == kHeldLost) {
            return false;
        }
        uint32_t expectedPrevious = kHeldFirst;
        for (uint32_t handle = head; handle != kHeldEnd;) {
            uint8_t* const links = resolve(handle);
            if (links == nullptr || HeldLinks::previous(links) != expectedPrevious) {
                return false;
            }
            const uint32_t next = HeldLinks::next(links);
            if (!visit(handle, links)) {
                return false;
            }
            expectedPrevious = handle;
            handle = next;
        }
        return true;
    }

private:
    // take()'s uncommon part, out of line: links the item that was the newest.
    template <typename Resolve>
    [[gnu::noinline]] static void link(HeldHead& head, uint32_t handle, Resolve resolve)
    {
        uint8_t* const links = resolve(handle);
        if (links == nullptr) {
            markLost(head.first);
            return;
        }
        pushFront(head.first, handle, links, resolve);
    }

    // give()'s uncommon part, out of line: takes a linked item off the list.
    template <typename Resolve>
    [[gnu::noinline]] static void unlink(HeldHead& head, uint32_t handle, uint8_t* links, Resolve resolve)
    {
        remove(head.first, handle, links, resolve);
    }

    // The item's own links are left alone: when the head was the wrong one,
    // the item may well be on its own holder's list.
    [[gnu::noinline, gnu::cold]] static void markLost(uint32_t& head) { head = kHeldLost; }
};

} // namespace dcos::internal
