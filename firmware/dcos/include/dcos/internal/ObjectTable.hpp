// Static per-type object table (dissertation section 6.4).
//
// Each system agent keeps one table per object type. Storage for the whole
// Capacity is reserved at build time, but only the first activeCount() slots
// take part in allocation; the AddObjects configuration service activates
// further slots in groups of eight, as the seed prescribes. The real-time
// services (Create, Delete, resolve, ownership checks) cost O(1) and the
// same number of instructions whatever the table holds.
//
// Names: every named object is chained, through its slot, into one of
// Capacity hash buckets, so NameToObject hashes the name once and compares
// names only with the objects whose hash matches. Its cost depends on how
// many names share a bucket, about one with a fair hash, never on how many
// objects the table holds. Unnamed objects are in no bucket.
//
// Ownership: every object is chained, through its slot, into the list of
// its owner (one list per owner key, see OwnerKeysByIndex), so forEachOwnedBy
// costs in proportion to what the owner holds, which is what lets a task's
// death be recovered without a walk over every table.
//
// The chains cost, per slot, a 32-bit hash and four links of two bytes,
// plus one link per bucket and one per owner key, and the free-slot ring:
// about 4 KiB for a kernel table of 256 slots.
//
// Stale id detection: the 12-bit index field of an ObjectId is not a slot
// number. Every table hands out all 4096 index values, each naming at most
// one live object, and maps an index to its slot in O(1). A deleted object's
// index joins the back of a FIFO of free indices, and Create takes the index
// freed longest ago (indices never issued come first), so an id kept after
// its object was deleted answers StaleId until at least 4096 - N further
// Creates in that table, N being the objects alive in it: as late as 12 bits
// allow, whatever the table's capacity or how many of its slots are active.
// Slots themselves are reused least recently freed first as well. The cost
// is two arrays of 4096 entries per table (12 KiB for a table of at most 256
// slots, 16 KiB above), and Create and Delete stay O(1).
//
// The configuration services' work is done by ObjectTableCore, compiled
// once for every table of the same slot width, not once per object type;
// this class keeps the typed storage and the real-time lookups, inline.
//
// The table does no locking; the owning agent serialises access to it.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/ObjectTableCore.hpp>

#include <bit>
#include <stddef.h>
#include <stdint.h>
#include <type_traits>

namespace dcos::internal {

/// The owner keys a table uses when nothing better is known: an owner's
/// 12-bit index, so 4096 owner lists per table. The kernel's tables key
/// owners by their task slot instead (TaskOwnerKeys), which needs only as
/// many lists as there are task slots.
///
/// An owner-key policy has kCount and keyOf(owner), which maps every task id
/// to a key below kCount. Two owners may share a key (a stale or remote task
/// id, say): the walk compares owners exactly, so sharing costs time, never
/// correctness.
struct OwnerKeysByIndex {
    static constexpr size_t kCount = size_t{1} << ObjectId::kIndexBits;
    static size_t keyOf(ObjectId owner) { return owner.index(); }
};

/// A static table of objects of one type, addressed by ObjectId.
///
/// T must be default constructible and copy-assignable: every slot holds a
/// T from the start, and a deleted object is reset to T{} so that the next
/// creator never sees the previous owner's data.
///
/// Services that implement a primitive of the seed keep its name
/// (AddObjects, Create, Delete, NameToObject, XferOwnership); kernel-internal
/// helpers use lower camel case.
template <typename T, size_t Capacity, typename OwnerKeys = OwnerKeysByIndex>
class ObjectTable {
    static_assert(Capacity >= 8 && Capacity <= 4096, "a table holds 8 to 4096 objects (12-bit index)");
    static_assert(std::has_single_bit(Capacity), "Capacity is a power of two, as the kernel configuration sizes it");
    static_assert(Capacity % 8 == 0, "objects are added in groups of eight");
    static_assert(OwnerKeys::kCount >= 1 && OwnerKeys::kCount < UINT16_MAX, "owner keys fit 16 bits with one to spare");

    // The smallest type that numbers every slot.
    using SlotNumber = std::conditional_t<(Capacity <= 256), uint8_t, uint16_t>;
    // The configuration services' work, shared by every table of the same width.
    using Core = ObjectTableCore<SlotNumber>;
    using Link = ObjectLink;

public:
    /// Objects are activated by AddObjects in multiples of this count.
    static constexpr size_t kGroupSize = Core::kGroupSize;
    /// Bytes reserved for a name, including the terminating NUL.
    static constexpr size_t kNameCapacity = kObjectNameCapacity;
    /// Longest name accepted by Create.
    static constexpr size_t kMaxNameLength = kNameCapacity - 1;
    /// Index values a table hands out: every value the 12-bit field holds.
    static constexpr size_t kIndexCount = Core::kIndexCount;

    /// Creates an empty table for objects of @p type on node @p node.
    ///
    /// The constructor is constexpr so that a static table is constant
    /// initialised and needs no start-up code before the agents run.
    constexpr ObjectTable(ObjectType type, uint16_t node)
        : core_(type, node, Capacity, kSystemOwnerKey, &entries_[0].header, sizeof(Entry), chains_, buckets_,
              ownerHeads_, freeSlots_, indexSlot_, freedIndices_)
    {
    }

    ObjectTable(const ObjectTable&) = delete;
    ObjectTable& operator=(const ObjectTable&) = delete;

    /// The object type this table manages; ids of other types are refused.
    constexpr ObjectType type() const { return core_.type_; }
    /// The node id stamped into every id this table issues.
    constexpr uint16_t node() const { return core_.node_; }
    /// Number of slots reserved at build time.
    static constexpr size_t capacity() { return Capacity; }
    /// Number of slots activated so far by AddObjects.
    constexpr size_t activeCount() const { return core_.active_; }
    /// Number of slots that currently hold a created object.
    constexpr size_t usedCount() const { return core_.used_; }
    /// Number of activated slots available to Create.
    constexpr size_t freeCount() const { return core_.active_ - core_.used_; }

    /// The table as the object directory reads it (ObjectDirectory.hpp):
    /// where its slots' headers are and how many are in use.
    ObjectTableView view() const
    {
        return ObjectTableView{&entries_[0].header, sizeof(Entry), core_.active_, core_.used_, Capacity};
    }

    /// Changes the node id, for boards that learn their logical address at boot.
    ///
    /// Refused with Busy while objects exist, because their ids already carry
    /// the old node id and would no longer resolve. Cost O(1).
    Status setNode(uint16_t node) { return core_.setNode(node); }

    /// Configuration service: activates @p count more slots.
    ///
    /// @p count must be a non-zero multiple of eight (InvalidArgument), and
    /// the active count may not exceed Capacity (TableFull); a refused
    /// request changes nothing. Cost O(count).
    Status AddObjects(size_t count) { return core_.addObjects(count); }

    /// Allocates a free slot and returns the id of the new object.
    ///
    /// @p owner is the creating task (type Task), or the null id for objects
    /// owned by the system, which resource recovery never reclaims. @p name
    /// may be null or empty for an unnamed object, otherwise at most
    /// kMaxNameLength characters. The seed leaves unique naming to the user,
    /// so duplicates are not searched for. Fails with InvalidArgument or
    /// TableFull. Cost O(1): the name's hash is taken in the same pass that
    /// measures it, and the object joins the front of its bucket and of its
    /// owner's list.
    Result<ObjectId> Create(ObjectId owner, const char* name, Visibility visibility)
    {
        return core_.create(owner, ownerKey(owner), name, visibility);
    }

    /// Deletes the object named by @p id and frees its slot.
    ///
    /// The object is reset to T{} and its index goes to the back of the free
    /// indices, so every copy of @p id turns stale for 4096 - N Creates.
    /// Ownership is checked by the agent before, because some primitives
    /// (KillTask by a super user) bypass it. Cost O(1).
    Status Delete(ObjectId id)
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        core_.erase(slot.value());
        entries_[slot.value()].object = T{};
        return Status::Ok;
    }

    /// Resolves @p id to its object.
    ///
    /// Fails with InvalidId for the null id, WrongType for an id of another
    /// type, Remote for an id of this type on another node, InvalidId for an
    /// index this table never handed out, and StaleId for one whose object
    /// was deleted. Cost O(1).
    Result<T*> resolve(ObjectId id)
    {
        // The reason of a miss is found inline here, not by the core: the
        // task agent's real-time services resolve through this after find(),
        // and a call, even one never taken, costs them two instructions of
        // stack alignment on every hit.
        Entry& entry = entries_[slotOfIndex(id.index())];
        if (entry.header.key != id.raw() || id.isNull()) {
            return core_.missReasonInline(id);
        }
        return &entry.object;
    }

    /// The real-time services' lookup: the object @p id names, or null
    /// wherever resolve() fails (call resolve() then, for the reason). It is
    /// inline and takes two compares: the slot the id's index last named
    /// keeps its live object's whole id, so node, type, index and use are
    /// checked at once (a free slot keeps 0, the null id, which the other
    /// compare refuses), which also refuses an index never handed out, since
    /// no slot holds one. Issue 14's remote ids will take the null branch,
    /// so the local path stays this short. Cost O(1).
    T* find(ObjectId id)
    {
        ObjectId unused; // Inline: the compiler drops the owner's load.
        return find(id, unused);
    }

    /// find(), also giving the object's owner, for fast paths that check
    /// ownership on the same lookup. @p owner is unchanged on a miss.
    T* find(ObjectId id, ObjectId& owner)
    {
        Entry& entry = entries_[slotOfIndex(id.index())];
        if (entry.header.key != id.raw() || id.isNull()) {
            return nullptr;
        }
        owner = entry.header.owner;
        return &entry.object;
    }

    /// The slot an id that Create returned occupies, for agents that keep
    /// their objects in an array beside the table. Cost O(1).
    size_t slotNumber(ObjectId id) const { return indexSlot_[id.index() & ObjectId::kMaxIndex]; }

    /// Returns the task that owns @p id (null for system objects). Cost O(1).
    Result<ObjectId> ownerOf(ObjectId id) const
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        return entries_[slot.value()].header.owner;
    }

    /// Succeeds when @p task owns @p id, and fails with NotOwner otherwise.
    ///
    /// This is the legality check the seed requires before any operation a
    /// task requests on an object. Cost O(1).
    Status checkOwner(ObjectId id, ObjectId task) const
    {
        const Result<ObjectId> owner = ownerOf(id);
        if (!owner.ok()) {
            return owner.status();
        }
        return owner.value() == task ? Status::Ok : Status::NotOwner;
    }

    /// Succeeds when @p task owns @p id or is @p privileged (a super user),
    /// the rule for Delete and XferOwnership in every agent; otherwise the
    /// status checkOwner gives. Cost O(1).
    Status checkOwnerOrPrivileged(ObjectId id, ObjectId task, bool privileged) const
    {
        const Status owner = checkOwner(id, task);
        return owner == Status::Ok || privileged ? Status::Ok : owner;
    }

    /// Returns the visibility @p id was created with. Cost O(1).
    Result<Visibility> visibilityOf(ObjectId id) const
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        return entries_[slot.value()].header.visibility;
    }

    /// Returns the NUL-terminated name of @p id; empty for unnamed objects. Cost O(1).
    Result<const char*> nameOf(ObjectId id) const
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        return static_cast<const char*>(entries_[slot.value()].header.name);
    }

    /// Gives @p id the name @p name (null or empty: unnamed), with Create's
    /// rules: at most kMaxNameLength characters, else InvalidArgument and no
    /// change; duplicates are not searched for. Cost O(1): the object moves
    /// to the new name's bucket.
    Status rename(ObjectId id, const char* name)
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        return core_.rename(slot.value(), name);
    }

    /// Transfers ownership of @p id from @p currentOwner to @p newOwner.
    ///
    /// Fails with NotOwner unless @p currentOwner owns the object, which
    /// stops a task from giving away objects it does not hold, and with
    /// InvalidArgument when @p newOwner is neither a task id nor null. Cost
    /// O(1): the object moves from its owner's list to the new owner's.
    Status XferOwnership(ObjectId id, ObjectId currentOwner, ObjectId newOwner)
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        // The key of an owner the core refuses is computed and unused: every
        // policy maps every id to some key.
        return core_.xferOwnership(slot.value(), currentOwner, newOwner, ownerKey(newOwner));
    }

    /// Configuration service: finds the object named @p name.
    ///
    /// Only objects visible from @p askingScope are considered, so a lookup
    /// forwarded from a remote node never finds a local object. When the
    /// user broke the uniqueness rule the lowest slot wins. An empty or null
    /// name never matches, because unnamed objects must not be findable.
    /// Fails with NotFound. Cost: one pass over @p name for its hash, then
    /// one step per object in its bucket, names compared only where the
    /// hashes match; independent of how many objects the table holds.
    Result<ObjectId> NameToObject(const char* name, Visibility askingScope) const
    {
        return core_.nameToObject(name, askingScope);
    }

    /// Calls @p visit(ObjectId, T&) for every object owned by @p owner.
    ///
    /// Resource recovery uses this when a task dies. The visitor may Delete
    /// the object it is given or transfer it to another owner, because the
    /// walk reads the next object of the list before the visit; it must not
    /// delete any other object of this table. Objects are visited newest
    /// owned first. Returns the number of objects visited. Cost O(objects on
    /// the owner's list): only owners that share its key (a stale or remote
    /// task id) lengthen the walk, and their objects are not visited.
    template <typename Visitor>
    size_t forEachOwnedBy(ObjectId owner, Visitor&& visit)
    {
        size_t visited = 0;
        Link link = ownerHeads_[ownerKey(owner)];
        while (link != Core::kNoLink) {
            const uint16_t slot = static_cast<uint16_t>(link - 1);
            link = chains_[slot].ownerNext;
            Entry& entry = entries_[slot];
            if (entry.header.owner == owner) {
                ++visited;
                visit(ObjectId::fromRaw(entry.header.key), entry.object);
            }
        }
        return visited;
    }

private:
    // The key of the list of objects the system owns (the null owner).
    static constexpr size_t kSystemOwnerKey = OwnerKeys::kCount;

    // resolve() and find() read only object and key. The entry stays 32
    // bytes for a pointer T (the key took the place of the index and the
    // use flag), so that its size, a power of two, still makes the fast
    // paths' slot-to-entry arithmetic one shift.
    struct Entry {
        T object{};
        ObjectEntryHeader header{};
    };
    static_assert(!std::is_pointer_v<T> || sizeof(Entry) == 32, "a pointer's entry stays 32 bytes");

    // The null owner has a list of its own, so that a walk for it finds the
    // system's objects as the slot-by-slot walk did.
    static size_t ownerKey(ObjectId owner) { return owner.isNull() ? kSystemOwnerKey : OwnerKeys::keyOf(owner); }

    // The slot an index last named, widened by one MOVZX: for a widening
    // load -mtune=i486 writes an XOR and a MOV into the low part, and the
    // fast paths then copy the register before scaling it, three
    // instructions for the one that takes the same three clocks on an i486.
    [[gnu::always_inline]] uint32_t slotOfIndex(uint32_t index) const
    {
#if defined(__i386__)
        uint32_t slot;
        if constexpr (sizeof(SlotNumber) == 1) {
            asm("movzbl %1, %0" : "=r"(slot) : "m"(indexSlot_[index]));
        } else {
            asm("movzwl %1, %0" : "=r"(slot) : "m"(indexSlot_[index]));
        }
        return slot;
#else
        return indexSlot_[index];
#endif
    }

    // Every accessor funnels through here. A hit is find()'s two compares:
    // the slot the id's index last named keeps its live object's whole id,
    // and a table's keys carry its own type and node (setNode is refused
    // while objects exist), so a matching key is a live object of this
    // table. A miss asks the core why, out of line, so the rejection rules
    // live in one place.
    Result<uint16_t> slotOf(ObjectId id) const
    {
        const uint16_t slot = indexSlot_[id.index()];
        if (entries_[slot].header.key != id.raw() || id.isNull()) {
            return core_.missReason(id);
        }
        return slot;
    }

    Entry entries_[Capacity] = {};
    typename Core::Chain chains_[Capacity] = {};
    // Name hash buckets: the first object of each chain, as a Link.
    Link buckets_[Capacity] = {};
    // Owner lists: the first object of each, as a Link; the last is the system's.
    Link ownerHeads_[OwnerKeys::kCount + 1] = {};
    // Free slots, oldest first: a ring the core keeps.
    SlotNumber freeSlots_[Capacity] = {};
    // Index -> slot, for every index handed out (the slot it last named).
    SlotNumber indexSlot_[kIndexCount] = {};
    // Freed indices, oldest first: a ring the core keeps (see its takeIndex).
    uint16_t freedIndices_[kIndexCount] = {};
    // Last, so that the arrays it points to are in place when it is built.
    Core core_;
};

} // namespace dcos::internal
