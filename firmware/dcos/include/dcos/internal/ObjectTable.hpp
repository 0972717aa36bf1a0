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
// The chains cost, per slot, a 32-bit hash and four links of one byte (a
// table of at most 128 slots) or two, plus one link per bucket and one per
// owner key, and the free-slot ring: about 4 KiB for a kernel table of 256
// slots.
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
// The table does no locking; the owning agent serialises access to it.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>

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

public:
    /// Objects are activated by AddObjects in multiples of this count.
    static constexpr size_t kGroupSize = 8;
    /// Bytes reserved for a name, including the terminating NUL.
    static constexpr size_t kNameCapacity = 16;
    /// Longest name accepted by Create.
    static constexpr size_t kMaxNameLength = kNameCapacity - 1;
    /// Index values a table hands out: every value the 12-bit field holds.
    static constexpr size_t kIndexCount = size_t{1} << ObjectId::kIndexBits;

    /// Creates an empty table for objects of @p type on node @p node.
    ///
    /// The constructor is constexpr so that a static table is constant
    /// initialised and needs no start-up code before the agents run.
    constexpr ObjectTable(ObjectType type, uint16_t node) : type_(type), node_(node) {}

    ObjectTable(const ObjectTable&) = delete;
    ObjectTable& operator=(const ObjectTable&) = delete;

    /// The object type this table manages; ids of other types are refused.
    constexpr ObjectType type() const { return type_; }
    /// The node id stamped into every id this table issues.
    constexpr uint16_t node() const { return node_; }
    /// Number of slots reserved at build time.
    static constexpr size_t capacity() { return Capacity; }
    /// Number of slots activated so far by AddObjects.
    constexpr size_t activeCount() const { return active_; }
    /// Number of slots that currently hold a created object.
    constexpr size_t usedCount() const { return used_; }
    /// Number of activated slots available to Create.
    constexpr size_t freeCount() const { return active_ - used_; }

    /// Changes the node id, for boards that learn their logical address at boot.
    ///
    /// Refused with Busy while objects exist, because their ids already carry
    /// the old node id and would no longer resolve. Cost O(1).
    Status setNode(uint16_t node)
    {
        if (used_ != 0) {
            return Status::Busy;
        }
        node_ = node;
        return Status::Ok;
    }

    /// Configuration service: activates @p count more slots.
    ///
    /// @p count must be a non-zero multiple of eight (InvalidArgument), and
    /// the active count may not exceed Capacity (TableFull); a refused
    /// request changes nothing. Cost O(count).
    Status AddObjects(size_t count)
    {
        if (count == 0 || count % kGroupSize != 0) {
            return Status::InvalidArgument;
        }
        if (count > Capacity - active_) {
            return Status::TableFull;
        }
        for (size_t i = 0; i < count; ++i) {
            pushFree(static_cast<uint16_t>(active_));
            ++active_;
        }
        return Status::Ok;
    }

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
        const NameScan scan = scanName(name);
        if (!isValidOwner(owner) || scan.length > kMaxNameLength
            || static_cast<uint8_t>(visibility) > static_cast<uint8_t>(Visibility::Global)) {
            return Status::InvalidArgument;
        }
        if (used_ == active_) {
            return Status::TableFull;
        }
        const uint16_t slot = popFree();
        Entry& entry = entries_[slot];
        const uint16_t index = takeIndex();
        indexSlot_[index] = static_cast<SlotNumber>(slot);
        entry.key = ObjectId(node_, type_, index).raw();
        entry.owner = owner;
        entry.visibility = visibility;
        copyName(entry.name, name);
        ++used_;
        Chain& chain = chains_[slot];
        chain.nameHash = scan.hash;
        if (scan.length != 0) {
            linkName(slot);
        }
        linkOwner(slot, ownerKey(owner));
        return idOf(slot);
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
        Entry& entry = entries_[slot.value()];
        if (entry.name[0] != '\0') {
            unlinkName(slot.value());
        }
        unlinkOwner(slot.value());
        entry.object = T{};
        const uint16_t index = entry.index();
        entry.key = 0;
        entry.owner = ObjectId::null();
        entry.name[0] = '\0';
        giveBackIndex(index);
        pushFree(slot.value());
        --used_;
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
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        return &entries_[slot.value()].object;
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
        Entry& entry = entries_[indexSlot_[id.index()]];
        if (entry.key != id.raw() || id.isNull()) {
            return nullptr;
        }
        owner = entry.owner;
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
        return entries_[slot.value()].owner;
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
        return entries_[slot.value()].visibility;
    }

    /// Returns the NUL-terminated name of @p id; empty for unnamed objects. Cost O(1).
    Result<const char*> nameOf(ObjectId id) const
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        return static_cast<const char*>(entries_[slot.value()].name);
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
        const NameScan scan = scanName(name);
        if (scan.length > kMaxNameLength) {
            return Status::InvalidArgument;
        }
        Entry& entry = entries_[slot.value()];
        if (entry.name[0] != '\0') {
            unlinkName(slot.value());
        }
        copyName(entry.name, name);
        chains_[slot.value()].nameHash = scan.hash;
        if (scan.length != 0) {
            linkName(slot.value());
        }
        return Status::Ok;
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
        Entry& entry = entries_[slot.value()];
        if (entry.owner != currentOwner) {
            return Status::NotOwner;
        }
        if (!isValidOwner(newOwner)) {
            return Status::InvalidArgument;
        }
        unlinkOwner(slot.value());
        entry.owner = newOwner;
        linkOwner(slot.value(), ownerKey(newOwner));
        return Status::Ok;
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
        const NameScan scan = scanName(name);
        if (scan.length == 0 || scan.length > kMaxNameLength) {
            return Status::NotFound;
        }
        // The whole bucket is walked, because a duplicate name may sit in a
        // lower slot than the first match and the lowest slot must win.
        uint16_t found = kNoSlot;
        for (Link link = buckets_[bucketOf(scan.hash)]; link != kNoLink; link = chains_[slotOfLink(link)].nameNext) {
            const uint16_t slot = slotOfLink(link);
            if (chains_[slot].nameHash == scan.hash && slot < found) {
                const Entry& entry = entries_[slot];
                if (isVisibleFrom(entry.visibility, askingScope) && namesEqual(entry.name, name)) {
                    found = slot;
                }
            }
        }
        if (found == kNoSlot) {
            return Status::NotFound;
        }
        return idOf(found);
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
        while (link != kNoLink) {
            const uint16_t slot = slotOfLink(link);
            link = chains_[slot].ownerNext;
            Entry& entry = entries_[slot];
            if (entry.owner == owner) {
                ++visited;
                visit(idOf(slot), entry.object);
            }
        }
        return visited;
    }

private:
    static constexpr uint16_t kNoSlot = 0xFFFF;
    // The smallest type that numbers every slot.
    using SlotNumber = std::conditional_t<(Capacity <= 256), uint8_t, uint16_t>;
    // A slot number plus one, zero meaning none, so that every list starts
    // empty in zero-initialised storage; the smallest type that holds it.
    using Link = std::conditional_t<(Capacity < 256), uint8_t, uint16_t>;
    static constexpr Link kNoLink = 0;
    // The key of the list of objects the system owns (the null owner).
    static constexpr size_t kSystemOwnerKey = OwnerKeys::kCount;

    // resolve() and find() read only object and key. The entry stays 32
    // bytes for a pointer T (the key took the place of the index and the
    // use flag), so that its size, a power of two, still makes the fast
    // paths' slot-to-entry arithmetic one shift.
    struct Entry {
        T object{};
        ObjectId owner{};
        /// The object's whole id while the slot is used, 0 (the null id) while
        /// it is free; find() refuses the null id, so no id finds a free slot.
        uint32_t key = 0;
        uint16_t ownerKey = 0; ///< The owner list the object is on.
        Visibility visibility = Visibility::Local;
        char name[kNameCapacity] = {};

        uint16_t index() const { return static_cast<uint16_t>(key & ObjectId::kMaxIndex); }
    };

    // The links of a used slot, kept apart from Entry for the reason above.
    struct Chain {
        uint32_t nameHash = 0; ///< Hash of the name; meaningful only for a named object.
        Link nameNext = kNoLink; ///< Next object in the same name bucket.
        Link namePrev = kNoLink; ///< Previous one; none for the bucket's first.
        Link ownerNext = kNoLink; ///< Next object on the same owner list.
        Link ownerPrev = kNoLink; ///< Previous one; none for the list's first.
    };

    struct NameScan {
        size_t length; ///< At most kNameCapacity, which marks a name too long.
        uint32_t hash;
    };

    static Link linkOf(uint16_t slot) { return static_cast<Link>(slot + 1); }
    static uint16_t slotOfLink(Link link) { return static_cast<uint16_t>(link - 1); }

    ObjectId idOf(uint16_t slot) const { return ObjectId::fromRaw(entries_[slot].key); }

    // The null owner has a list of its own, so that a walk for it finds the
    // system's objects as the slot-by-slot walk did.
    static size_t ownerKey(ObjectId owner) { return owner.isNull() ? kSystemOwnerKey : OwnerKeys::keyOf(owner); }

    // FNV-1a over at most kNameCapacity characters, in the pass that measures
    // the name, so that an unterminated name cannot run away.
    static NameScan scanName(const char* name)
    {
        uint32_t hash = 2166136261u;
        size_t length = 0;
        if (name != nullptr) {
            while (length < kNameCapacity && name[length] != '\0') {
                hash = (hash ^ static_cast<uint8_t>(name[length])) * 16777619u;
                ++length;
            }
        }
        return NameScan{length, hash};
    }

    // FNV-1a's low bits mix poorly for short names, so the high half is
    // folded in before the mask.
    static size_t bucketOf(uint32_t hash) { return (hash ^ (hash >> 16)) & (Capacity - 1); }

    // Both lists a used slot is on (its name's bucket and its owner's list)
    // are doubly linked through Chain: Next and Prev pick which.
    template <Link Chain::*Next, Link Chain::*Prev>
    void pushFront(uint16_t slot, Link& head)
    {
        Chain& chain = chains_[slot];
        chain.*Prev = kNoLink;
        chain.*Next = head;
        if (head != kNoLink) {
            chains_[slotOfLink(head)].*Prev = linkOf(slot);
        }
        head = linkOf(slot);
    }

    template <Link Chain::*Next, Link Chain::*Prev>
    void unlink(uint16_t slot, Link& head)
    {
        Chain& chain = chains_[slot];
        if (chain.*Next != kNoLink) {
            chains_[slotOfLink(chain.*Next)].*Prev = chain.*Prev;
        }
        if (chain.*Prev != kNoLink) {
            chains_[slotOfLink(chain.*Prev)].*Next = chain.*Next;
        } else {
            head = chain.*Next;
        }
        chain.*Next = chain.*Prev = kNoLink;
    }

    void linkName(uint16_t slot)
    {
        pushFront<&Chain::nameNext, &Chain::namePrev>(slot, buckets_[bucketOf(chains_[slot].nameHash)]);
    }

    void unlinkName(uint16_t slot)
    {
        unlink<&Chain::nameNext, &Chain::namePrev>(slot, buckets_[bucketOf(chains_[slot].nameHash)]);
    }

    void linkOwner(uint16_t slot, size_t key)
    {
        entries_[slot].ownerKey = static_cast<uint16_t>(key);
        pushFront<&Chain::ownerNext, &Chain::ownerPrev>(slot, ownerHeads_[key]);
    }

    // Uses the key stored at link time, not the owner's key now: the key of
    // a stale owner id may have changed since.
    void unlinkOwner(uint16_t slot)
    {
        unlink<&Chain::ownerNext, &Chain::ownerPrev>(slot, ownerHeads_[entries_[slot].ownerKey]);
    }

    // The index freed longest ago; indices never handed out count as freed
    // before any other. The ring starts full with every index in order, each
    // stored as index ^ position so that zero-initialised storage holds it;
    // Create thus takes the same path whether or not fresh indices remain,
    // which keeps its cost flat. There is always one: at most Capacity
    // objects live, and Capacity <= 4096.
    uint16_t takeIndex()
    {
        const uint16_t index = static_cast<uint16_t>(freedIndices_[freedHead_] ^ freedHead_);
        freedHead_ = (freedHead_ + 1) & (kIndexCount - 1);
        --freedCount_;
        // Indices come out of the ring in order until each was handed out
        // once, so issued_ counts them; a comparison, not a branch.
        issued_ += static_cast<size_t>(issued_ == index);
        return index;
    }

    void giveBackIndex(uint16_t index)
    {
        const size_t position = (freedHead_ + freedCount_) & (kIndexCount - 1);
        freedIndices_[position] = static_cast<uint16_t>(index ^ position);
        ++freedCount_;
    }

    // Every accessor funnels through here so the rejection rules live in one place.
    Result<uint16_t> slotOf(ObjectId id) const
    {
        if (id.isNull()) {
            return Status::InvalidId;
        }
        if (id.type() != type_) {
            return Status::WrongType;
        }
        if (id.node() != node_) {
            // An object of this type on another node: the agents will hand
            // such ids to the network interfaces manager; until it exists
            // the object is unreachable.
            return Status::Remote;
        }
        if (id.index() >= issued_) {
            return Status::InvalidId; // Never handed out: forged.
        }
        const uint16_t slot = indexSlot_[id.index()];
        const Entry& entry = entries_[slot];
        if (entry.key != id.raw()) {
            return Status::StaleId; // Handed out once; its object is gone.
        }
        return slot;
    }

    // Free slots wait in a ring, so that the slot freed longest ago is
    // reused first, which spreads wear of the slots' storage evenly. A ring,
    // unlike a list, has no empty case to treat apart, so Create and Delete
    // cost the same whether the table is nearly empty or nearly full.
    // The ring holds freeCount() slots, so the caller counts the slot it
    // adds (active_ or used_) only after the push.
    void pushFree(uint16_t slot)
    {
        freeSlots_[(freeHead_ + active_ - used_) & (Capacity - 1)] = static_cast<SlotNumber>(slot);
    }

    uint16_t popFree()
    {
        const uint16_t slot = freeSlots_[freeHead_];
        freeHead_ = (freeHead_ + 1) & (Capacity - 1);
        return slot;
    }

    static bool isValidOwner(ObjectId owner) { return owner.isNull() || owner.type() == ObjectType::Task; }

    static void copyName(char (&destination)[kNameCapacity], const char* source)
    {
        size_t i = 0;
        if (source != nullptr) {
            for (; i < kMaxNameLength && source[i] != '\0'; ++i) {
                destination[i] = source[i];
            }
        }
        destination[i] = '\0';
    }

    static bool namesEqual(const char (&stored)[kNameCapacity], const char* name)
    {
        size_t i = 0;
        for (; i < kMaxNameLength && stored[i] != '\0'; ++i) {
            if (stored[i] != name[i]) {
                return false;
            }
        }
        return name[i] == '\0';
    }

    Entry entries_[Capacity] = {};
    Chain chains_[Capacity] = {};
    // Name hash buckets: the first object of each chain, as a Link.
    Link buckets_[Capacity] = {};
    // Owner lists: the first object of each, as a Link; the last is the system's.
    Link ownerHeads_[OwnerKeys::kCount + 1] = {};
    // Free slots, oldest first: a ring of active_ - used_ entries at freeHead_.
    SlotNumber freeSlots_[Capacity] = {};
    size_t freeHead_ = 0;
    // Index -> slot, for every index handed out (the slot it last named).
    SlotNumber indexSlot_[kIndexCount] = {};
    // Freed indices, oldest first: a ring of freedCount_ entries at
    // freedHead_, each stored as index ^ position (see takeIndex).
    uint16_t freedIndices_[kIndexCount] = {};
    size_t freedHead_ = 0;
    size_t freedCount_ = kIndexCount;
    // Indices [issued_, 4096) were never handed out.
    size_t issued_ = 0;
    ObjectType type_;
    uint16_t node_;
    size_t active_ = 0;
    size_t used_ = 0;
};

} // namespace dcos::internal
