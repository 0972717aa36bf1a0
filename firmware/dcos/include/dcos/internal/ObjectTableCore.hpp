// The type-independent part of the static object tables (ObjectTable.hpp).
//
// Every agent keeps a table of its own object type, and the configuration
// services of a table (AddObjects, Create, Delete, rename, XferOwnership,
// NameToObject) do the same work whatever the type: they touch an object's
// bookkeeping (owner, id, visibility, name and the chains through its slot),
// never the object itself. Written in ObjectTable<T, Capacity, OwnerKeys>
// they were compiled, and inlined, once per table type: nine times over in
// the full kernel. Here they are compiled once per width of the slot numbers
// and links (two in the production kernel: tables below 256 slots, and of
// 256), out of line and for size, reaching the entries through a stride.
//
// What stays in the typed table is what the real-time services use, inline
// and with the table's own array addresses: find(), resolve(), the
// ownership and visibility checks. A core reaches the typed table's arrays
// through the pointers it is constructed with, so a table must not be copied
// or moved (ObjectTable deletes both).
//
// The table does no locking; the owning agent serialises access to it.
#pragma once

#include <dcos/ObjectId.hpp>
#include <dcos/Status.hpp>
#include <dcos/Visibility.hpp>
#include <dcos/internal/ConfigurationService.hpp>

#include <stddef.h>
#include <stdint.h>

namespace dcos::internal {

/// Bytes reserved for an object's name in a table, including the terminating NUL.
inline constexpr size_t kObjectNameCapacity = 16;

/// The bookkeeping of one slot of a table, beside the object it holds.
///
/// find() reads key: it follows the object in the entry, where the typed
/// table's fast path expects it (see ObjectTable's Entry).
struct ObjectEntryHeader {
    ObjectId owner{};
    /// The object's whole id while the slot is used, 0 (the null id) while
    /// it is free; find() refuses the null id, so no id finds a free slot.
    uint32_t key = 0;
    uint16_t ownerKey = 0; ///< The owner list the object is on.
    Visibility visibility = Visibility::Local;
    char name[kObjectNameCapacity] = {};

    uint16_t index() const { return static_cast<uint16_t>(key & ObjectId::kMaxIndex); }
};

/// One object table seen from outside its agent, for the configuration
/// services that list every object of a type (ObjectDirectory.hpp): slot
/// n's header is @p stride bytes after slot n - 1's.
struct ObjectTableView {
    const ObjectEntryHeader* first = nullptr;
    size_t stride = 0;
    size_t active = 0;   ///< Slots activated (AddObjects); only these are read.
    size_t used = 0;     ///< Slots holding an object.
    size_t capacity = 0; ///< Slots reserved at build time.

    /// Slot @p slot's header (slot below active).
    const ObjectEntryHeader& header(size_t slot) const
    {
        return *reinterpret_cast<const ObjectEntryHeader*>(reinterpret_cast<const uint8_t*>(first) + slot * stride);
    }
};

/// A link between slots: a slot number plus one, zero meaning none, so that
/// every list starts empty in zero-initialised storage.
///
/// Sixteen bits for every table, though one byte would link a table of at
/// most 128 slots: one width for all lets every table of the production
/// kernel share one compiled core, which saves more code (about 1.7 KB) than
/// the wider links cost data (five bytes a slot and one per owner list in a
/// table of at most 128 slots).
using ObjectLink = uint16_t;

/// The links of a used slot, kept apart from the entries so that the
/// entries the fast paths index stay a power of two in size.
struct ObjectChain {
    uint32_t nameHash = 0; ///< Hash of the name; meaningful only for a named object.
    ObjectLink nameNext = 0; ///< Next object in the same name bucket; 0 for none.
    ObjectLink namePrev = 0; ///< Previous one; none for the bucket's first.
    ObjectLink ownerNext = 0; ///< Next object on the same owner list.
    ObjectLink ownerPrev = 0; ///< Previous one; none for the list's first.
};

/// The configuration services of an object table, for every table whose
/// slots are numbered by SlotNumber. ObjectTable documents the services' contracts;
/// this class keeps the table's counters and does the work.
template <typename SlotNumber>
class ObjectTableCore {
public:
    static constexpr size_t kGroupSize = 8;
    static constexpr size_t kMaxNameLength = kObjectNameCapacity - 1;
    static constexpr size_t kIndexCount = size_t{1} << ObjectId::kIndexBits;
    static constexpr uint16_t kNoSlot = 0xFFFF;

    using Link = ObjectLink;
    using Chain = ObjectChain;
    static constexpr Link kNoLink = 0;

    /// The typed table's storage: @p firstHeader is the header of slot 0,
    /// and slot n's is @p stride bytes further on per slot. @p ownerHeads
    /// has @p systemOwnerKey + 1 lists, the last the system's.
    constexpr ObjectTableCore(ObjectType type, uint16_t node, size_t capacity, size_t systemOwnerKey,
        ObjectEntryHeader* firstHeader, size_t stride, Chain* chains, Link* buckets, Link* ownerHeads,
        SlotNumber* freeSlots, SlotNumber* indexSlot, uint16_t* freedIndices)
        : firstHeader_(firstHeader)
        , stride_(stride)
        , chains_(chains)
        , buckets_(buckets)
        , ownerHeads_(ownerHeads)
        , freeSlots_(freeSlots)
        , indexSlot_(indexSlot)
        , freedIndices_(freedIndices)
        , capacity_(capacity)
        , systemOwnerKey_(systemOwnerKey)
        , type_(type)
        , node_(node)
    {
    }

    ObjectTableCore(const ObjectTableCore&) = delete;
    ObjectTableCore& operator=(const ObjectTableCore&) = delete;

    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Status setNode(uint16_t node);
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Status addObjects(size_t count);
    /// Create, with the owner list @p ownerKey that the typed table's policy gave @p owner.
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Result<ObjectId> create(
        ObjectId owner, size_t ownerKey, const char* name, Visibility visibility);
    // The services on one object take the slot the typed table found for
    // its id (ObjectTable::slotOf, inline): the agent has usually resolved
    // the same id just before, and the compiler then checks it only once.

    /// Delete but for resetting the object, which the typed table does.
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] void erase(uint16_t slot);
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Status rename(uint16_t slot, const char* name);
    /// XferOwnership, with the owner list @p newOwnerKey that the typed
    /// table's policy gave @p newOwner.
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Status xferOwnership(
        uint16_t slot, ObjectId currentOwner, ObjectId newOwner, size_t newOwnerKey);
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Result<ObjectId> nameToObject(
        const char* name, Visibility askingScope) const;

    /// Why @p id names no live object of this table: InvalidId for the null
    /// id or an index never handed out, WrongType, Remote, or StaleId. The
    /// typed table's lookups check the hit inline and call this only on a
    /// miss, so the rules are compiled once and a hit costs two compares.
    DCOS_CONFIGURATION_SERVICE [[gnu::noinline]] Status missReason(ObjectId id) const;

    /// missReason's rules, inline, for the one lookup that must not call out
    /// (ObjectTable::resolve, see there).
    Status missReasonInline(ObjectId id) const
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
        return Status::StaleId; // Handed out once; its object is gone.
    }

    static bool isValidOwner(ObjectId owner) { return owner.isNull() || owner.type() == ObjectType::Task; }

private:
    template <typename, size_t, typename>
    friend class ObjectTable;

    struct NameScan {
        size_t length; ///< At most kObjectNameCapacity, which marks a name too long.
        uint32_t hash;
    };

    [[gnu::always_inline]] ObjectEntryHeader& header(uint16_t slot) const
    {
        // A constant expression may not cast, so the byte arithmetic is done here.
        return *reinterpret_cast<ObjectEntryHeader*>(reinterpret_cast<uint8_t*>(firstHeader_) + size_t{slot} * stride_);
    }

    static Link linkOf(uint16_t slot) { return static_cast<Link>(slot + 1); }
    static uint16_t slotOfLink(Link link) { return static_cast<uint16_t>(link - 1); }

    ObjectId idOf(uint16_t slot) const { return ObjectId::fromRaw(header(slot).key); }

    // FNV-1a's low bits mix poorly for short names, so the high half is
    // folded in before the mask.
    size_t bucketOf(uint32_t hash) const { return (hash ^ (hash >> 16)) & (capacity_ - 1); }

    // The name helpers are inlined into the services that use them: called
    // out of line they cost NameToObject and Create some ten instructions
    // each, and inline they take little more room than the calls.
    [[gnu::always_inline]] static NameScan scanName(const char* name);
    [[gnu::always_inline]] static void copyName(char (&destination)[kObjectNameCapacity], const char* source);
    [[gnu::always_inline]] static bool namesEqual(const char (&stored)[kObjectNameCapacity], const char* name);

    // So are the list and ring steps: each service is then one function
    // with its members loaded once, which is what keeps the services about
    // as fast as when every table had them inline.
    template <Link Chain::*Next, Link Chain::*Prev>
    [[gnu::always_inline]] void pushFront(uint16_t slot, Link& head);
    template <Link Chain::*Next, Link Chain::*Prev>
    [[gnu::always_inline]] void unlink(uint16_t slot, Link& head);
    [[gnu::always_inline]] void linkName(uint16_t slot);
    [[gnu::always_inline]] void unlinkName(uint16_t slot);
    [[gnu::always_inline]] void linkOwner(uint16_t slot, size_t key);
    [[gnu::always_inline]] void unlinkOwner(uint16_t slot);
    [[gnu::always_inline]] uint16_t takeIndex();
    [[gnu::always_inline]] void giveBackIndex(uint16_t index);
    [[gnu::always_inline]] void pushFree(uint16_t slot);
    [[gnu::always_inline]] uint16_t popFree();

    ObjectEntryHeader* firstHeader_;
    size_t stride_;
    Chain* chains_;
    // Name hash buckets: the first object of each chain, as a Link.
    Link* buckets_;
    // Owner lists: the first object of each, as a Link; the last is the system's.
    Link* ownerHeads_;
    // Free slots, oldest first: a ring of active_ - used_ entries at freeHead_.
    SlotNumber* freeSlots_;
    // Index -> slot, for every index handed out (the slot it last named).
    SlotNumber* indexSlot_;
    // Freed indices, oldest first: a ring of freedCount_ entries at
    // freedHead_, each stored as index ^ position (see takeIndex).
    uint16_t* freedIndices_;
    size_t capacity_;
    size_t systemOwnerKey_;
    size_t freeHead_ = 0;
    size_t freedHead_ = 0;
    size_t freedCount_ = kIndexCount;
    // Indices [issued_, 4096) were never handed out.
    size_t issued_ = 0;
    ObjectType type_;
    uint16_t node_;
    size_t active_ = 0;
    size_t used_ = 0;
};

// The widths the tables use, compiled once in ObjectTableCore.cpp: to 256
// slots, and above (to 4096).
extern template class ObjectTableCore<uint8_t>;
extern template class ObjectTableCore<uint16_t>;

} // namespace dcos::internal
