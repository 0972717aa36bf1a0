// Static per-type object table (dissertation section 6.4).
//
// Each system agent keeps one table per object type. Storage for the whole
// Capacity is reserved at build time, but only the first activeCount() slots
// take part in allocation; the AddObjects configuration service activates
// further slots in groups of eight, as the seed prescribes. The real-time
// services (Create, Delete, resolve, ownership checks) cost O(1); the
// configuration services (AddObjects, NameToObject, enumeration by owner)
// cost O(N), which the seed accepts for configuration-class services.
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

/// A static table of objects of one type, addressed by ObjectId.
///
/// T must be default constructible and copy-assignable: every slot holds a
/// T from the start, and a deleted object is reset to T{} so that the next
/// creator never sees the previous owner's data.
///
/// Services that implement a primitive of the seed keep its name
/// (AddObjects, Create, Delete, NameToObject, XferOwnership); kernel-internal
/// helpers use lower camel case.
template <typename T, size_t Capacity>
class ObjectTable {
    static_assert(Capacity >= 8 && Capacity <= 4096, "a table holds 8 to 4096 objects (12-bit index)");
    static_assert(std::has_single_bit(Capacity), "Capacity is a power of two, as the kernel configuration sizes it");
    static_assert(Capacity % 8 == 0, "objects are added in groups of eight");

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
    constexpr ObjectTable(ObjectType type, uint16_t node) : type_(type), node_(node), prefix_(prefixOf(type, node)) {}

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
        prefix_ = prefixOf(type_, node);
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
            pushFree(static_cast<uint16_t>(active_ + i));
        }
        active_ += count;
        return Status::Ok;
    }

    /// Allocates a free slot and returns the id of the new object.
    ///
    /// @p owner is the creating task (type Task), or the null id for objects
    /// owned by the system, which resource recovery never reclaims. @p name
    /// may be null or empty for an unnamed object, otherwise at most
    /// kMaxNameLength characters. The seed leaves unique naming to the user,
    /// so duplicates are not searched for, which keeps Create O(1).
    /// Fails with InvalidArgument or TableFull.
    Result<ObjectId> Create(ObjectId owner, const char* name, Visibility visibility)
    {
        if (!isValidOwner(owner) || nameLength(name) > kMaxNameLength
            || static_cast<uint8_t>(visibility) > static_cast<uint8_t>(Visibility::Global)) {
            return Status::InvalidArgument;
        }
        if (freeHead_ == kNoSlot) {
            return Status::TableFull;
        }
        const uint16_t slot = popFree();
        Entry& entry = entries_[slot];
        entry.index = takeIndex();
        indexSlot_[entry.index] = static_cast<SlotNumber>(slot);
        entry.used = true;
        entry.owner = owner;
        entry.visibility = visibility;
        copyName(entry.name, name);
        ++used_;
        return idOf(slot);
    }

    /// Deletes the object named by @p id and frees its slot.
    ///
    /// The object is reset to T{} and its index goes to the back of the free
    /// indices, so every copy of @p id turns stale for 4096 - N Creates. Ownership is checked by the agent before,
    /// because some primitives (KillTask by a super user) bypass it. Cost O(1).
    Status Delete(ObjectId id)
    {
        const Result<uint16_t> slot = slotOf(id);
        if (!slot.ok()) {
            return slot.status();
        }
        Entry& entry = entries_[slot.value()];
        entry.object = T{};
        entry.used = false;
        entry.owner = ObjectId::null();
        entry.name[0] = '\0';
        giveBackIndex(entry.index);
        --used_;
        pushFree(slot.value());
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
    /// inline and takes three compares: node and type in one (the id's upper
    /// 20 bits), then the slot's use and the index it holds, which also
    /// refuses an index never handed out, since no slot holds one. Issue 14's
    /// remote ids will take the null branch, so the local path stays this
    /// short. Cost O(1).
    T* find(ObjectId id)
    {
        if ((id.raw() >> ObjectId::kIndexBits) != prefix_) {
            return nullptr;
        }
        Entry& entry = entries_[indexSlot_[id.index()]];
        if (!entry.used || entry.index != id.index()) {
            return nullptr;
        }
        return &entry.object;
    }

    /// find(), also giving the object's owner, for fast paths that check
    /// ownership on the same lookup. @p owner is unchanged on a miss.
    T* find(ObjectId id, ObjectId& owner)
    {
        if ((id.raw() >> ObjectId::kIndexBits) != prefix_) {
            return nullptr;
        }
        Entry& entry = entries_[indexSlot_[id.index()]];
        if (!entry.used || entry.index != id.index()) {
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

    /// Transfers ownership of @p id from @p currentOwner to @p newOwner.
    ///
    /// Fails with NotOwner unless @p currentOwner owns the object, which
    /// stops a task from giving away objects it does not hold, and with
    /// InvalidArgument when @p newOwner is neither a task id nor null. Cost O(1).
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
        entry.owner = newOwner;
        return Status::Ok;
    }

    /// Configuration service: finds the object named @p name.
    ///
    /// Only objects visible from @p askingScope are considered, so a lookup
    /// forwarded from a remote node never finds a local object. When the
    /// user broke the uniqueness rule the lowest slot wins. An empty or null
    /// name never matches, because unnamed objects must not be findable.
    /// Fails with NotFound. Cost O(N) in the active count.
    Result<ObjectId> NameToObject(const char* name, Visibility askingScope) const
    {
        if (nameLength(name) == 0 || nameLength(name) > kMaxNameLength) {
            return Status::NotFound;
        }
        for (size_t slot = 0; slot < active_; ++slot) {
            const Entry& entry = entries_[slot];
            if (entry.used && isVisibleFrom(entry.visibility, askingScope) && namesEqual(entry.name, name)) {
                return idOf(static_cast<uint16_t>(slot));
            }
        }
        return Status::NotFound;
    }

    /// Calls @p visit(ObjectId, T&) for every object owned by @p owner.
    ///
    /// Resource recovery uses this when a task dies. The visitor may Delete
    /// the object it is given, because the walk re-reads each slot's state
    /// and a Delete touches only its own slot. Returns the number of objects
    /// visited. Cost O(N) in the active count.
    template <typename Visitor>
    size_t forEachOwnedBy(ObjectId owner, Visitor&& visit)
    {
        size_t visited = 0;
        for (size_t slot = 0; slot < active_; ++slot) {
            Entry& entry = entries_[slot];
            if (entry.used && entry.owner == owner) {
                ++visited;
                visit(idOf(static_cast<uint16_t>(slot)), entry.object);
            }
        }
        return visited;
    }

private:
    static constexpr uint16_t kNoSlot = 0xFFFF;
    // The smallest type that numbers every slot.
    using SlotNumber = std::conditional_t<(Capacity <= 256), uint8_t, uint16_t>;

    struct Entry {
        T object{};
        ObjectId owner{};
        uint16_t index = 0; ///< The id's index field while the slot is used.
        uint16_t nextFree = kNoSlot;
        bool used = false;
        Visibility visibility = Visibility::Local;
        char name[kNameCapacity] = {};
    };

    ObjectId idOf(uint16_t slot) const { return ObjectId(node_, type_, entries_[slot].index); }

    // The index freed longest ago; indices never handed out count as freed
    // before any other. There is always one: at most Capacity objects live,
    // and Capacity <= 4096.
    uint16_t takeIndex()
    {
        if (freshIndices_ < kIndexCount) {
            return static_cast<uint16_t>(freshIndices_++);
        }
        const uint16_t index = freedIndices_[freedHead_];
        freedHead_ = (freedHead_ + 1) % kIndexCount;
        --freedCount_;
        return index;
    }

    void giveBackIndex(uint16_t index)
    {
        freedIndices_[(freedHead_ + freedCount_) % kIndexCount] = index;
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
        if (id.index() >= freshIndices_) {
            return Status::InvalidId; // Never handed out: forged.
        }
        const uint16_t slot = indexSlot_[id.index()];
        const Entry& entry = entries_[slot];
        if (!entry.used || entry.index != id.index()) {
            return Status::StaleId; // Handed out once; its object is gone.
        }
        return slot;
    }

    // Freed slots join the tail so that the slot freed longest ago is reused
    // first, which spreads wear of the slots' storage evenly.
    void pushFree(uint16_t slot)
    {
        entries_[slot].nextFree = kNoSlot;
        if (freeTail_ == kNoSlot) {
            freeHead_ = slot;
        } else {
            entries_[freeTail_].nextFree = slot;
        }
        freeTail_ = slot;
    }

    uint16_t popFree()
    {
        const uint16_t slot = freeHead_;
        freeHead_ = entries_[slot].nextFree;
        if (freeHead_ == kNoSlot) {
            freeTail_ = kNoSlot;
        }
        entries_[slot].nextFree = kNoSlot;
        return slot;
    }

    static bool isValidOwner(ObjectId owner) { return owner.isNull() || owner.type() == ObjectType::Task; }

    // Counts at most kNameCapacity characters so an unterminated name cannot run away.
    static size_t nameLength(const char* name)
    {
        size_t length = 0;
        if (name != nullptr) {
            while (length < kNameCapacity && name[length] != '\0') {
                ++length;
            }
        }
        return length;
    }

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
    // Index -> slot, for every index handed out (the slot it last named).
    SlotNumber indexSlot_[kIndexCount] = {};
    // Freed indices, oldest first: a ring of freedCount_ entries at freedHead_.
    uint16_t freedIndices_[kIndexCount] = {};
    size_t freedHead_ = 0;
    size_t freedCount_ = 0;
    // Indices [freshIndices_, 4096) were never handed out.
    size_t freshIndices_ = 0;
    ObjectType type_;
    uint16_t node_;
    // The upper 20 bits (node and type) of every id this table issues.
    uint32_t prefix_;

    static constexpr uint32_t prefixOf(ObjectType type, uint16_t node)
    {
        return (static_cast<uint32_t>(node) << ObjectId::kTypeBits) | static_cast<uint32_t>(type);
    }
    size_t active_ = 0;
    size_t used_ = 0;
    uint16_t freeHead_ = kNoSlot;
    uint16_t freeTail_ = kNoSlot;
};

} // namespace dcos::internal
