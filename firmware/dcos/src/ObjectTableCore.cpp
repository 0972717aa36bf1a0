// The type-independent configuration services of the object tables
// (ObjectTableCore.hpp); ObjectTable.hpp documents their contracts.
#include <dcos/internal/ObjectTableCore.hpp>

namespace dcos::internal {

template <typename SlotNumber>
Status ObjectTableCore<SlotNumber>::setNode(uint16_t node)
{
    if (used_ != 0) {
        return Status::Busy;
    }
    node_ = node;
    return Status::Ok;
}

template <typename SlotNumber>
Status ObjectTableCore<SlotNumber>::addObjects(size_t count)
{
    if (count == 0 || count % kGroupSize != 0) {
        return Status::InvalidArgument;
    }
    if (count > capacity_ - active_) {
        return Status::TableFull;
    }
    for (size_t i = 0; i < count; ++i) {
        pushFree(static_cast<uint16_t>(active_));
        ++active_;
    }
    return Status::Ok;
}

template <typename SlotNumber>
Result<ObjectId> ObjectTableCore<SlotNumber>::create(
    ObjectId owner, size_t ownerKey, const char* name, Visibility visibility)
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
    ObjectEntryHeader& entry = header(slot);
    const uint16_t index = takeIndex();
    indexSlot_[index] = static_cast<SlotNumber>(slot);
    entry.key = ObjectId(node_, type_, index).raw();
    entry.owner = owner;
    entry.visibility = visibility;
    copyName(entry.name, name);
    ++used_;
    chains_[slot].nameHash = scan.hash;
    if (scan.length != 0) {
        linkName(slot);
    }
    linkOwner(slot, ownerKey);
    return idOf(slot);
}

template <typename SlotNumber>
void ObjectTableCore<SlotNumber>::erase(uint16_t slot)
{
    ObjectEntryHeader& entry = header(slot);
    if (entry.name[0] != '\0') {
        unlinkName(slot);
    }
    unlinkOwner(slot);
    const uint16_t index = entry.index();
    entry.key = 0;
    entry.owner = ObjectId::null();
    entry.name[0] = '\0';
    giveBackIndex(index);
    pushFree(slot);
    --used_;
}

template <typename SlotNumber>
Status ObjectTableCore<SlotNumber>::rename(uint16_t slot, const char* name)
{
    const NameScan scan = scanName(name);
    if (scan.length > kMaxNameLength) {
        return Status::InvalidArgument;
    }
    ObjectEntryHeader& entry = header(slot);
    if (entry.name[0] != '\0') {
        unlinkName(slot);
    }
    copyName(entry.name, name);
    chains_[slot].nameHash = scan.hash;
    if (scan.length != 0) {
        linkName(slot);
    }
    return Status::Ok;
}

template <typename SlotNumber>
Status ObjectTableCore<SlotNumber>::xferOwnership(
    uint16_t slot, ObjectId currentOwner, ObjectId newOwner, size_t newOwnerKey)
{
    ObjectEntryHeader& entry = header(slot);
    if (entry.owner != currentOwner) {
        return Status::NotOwner;
    }
    if (!isValidOwner(newOwner)) {
        return Status::InvalidArgument;
    }
    unlinkOwner(slot);
    entry.owner = newOwner;
    linkOwner(slot, newOwnerKey);
    return Status::Ok;
}

template <typename SlotNumber>
Result<ObjectId> ObjectTableCore<SlotNumber>::nameToObject(const char* name, Visibility askingScope) const
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
            const ObjectEntryHeader& entry = header(slot);
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

template <typename SlotNumber>
Status ObjectTableCore<SlotNumber>::missReason(ObjectId id) const
{
    return missReasonInline(id);
}

// FNV-1a over at most kObjectNameCapacity characters, in the pass that
// measures the name, so that an unterminated name cannot run away.
template <typename SlotNumber>
inline typename ObjectTableCore<SlotNumber>::NameScan ObjectTableCore<SlotNumber>::scanName(const char* name)
{
    uint32_t hash = 2166136261u;
    size_t length = 0;
    if (name != nullptr) {
        while (length < kObjectNameCapacity && name[length] != '\0') {
            hash = (hash ^ static_cast<uint8_t>(name[length])) * 16777619u;
            ++length;
        }
    }
    return NameScan{length, hash};
}

template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::copyName(char (&destination)[kObjectNameCapacity], const char* source)
{
    size_t i = 0;
    if (source != nullptr) {
        for (; i < kMaxNameLength && source[i] != '\0'; ++i) {
            destination[i] = source[i];
        }
    }
    destination[i] = '\0';
}

template <typename SlotNumber>
inline bool ObjectTableCore<SlotNumber>::namesEqual(const char (&stored)[kObjectNameCapacity], const char* name)
{
    size_t i = 0;
    for (; i < kMaxNameLength && stored[i] != '\0'; ++i) {
        if (stored[i] != name[i]) {
            return false;
        }
    }
    return name[i] == '\0';
}

// Both lists a used slot is on (its name's bucket and its owner's list) are
// doubly linked through Chain: Next and Prev pick which.
template <typename SlotNumber>
template <ObjectLink ObjectChain::*Next, ObjectLink ObjectChain::*Prev>
inline void ObjectTableCore<SlotNumber>::pushFront(uint16_t slot, Link& head)
{
    Chain& chain = chains_[slot];
    chain.*Prev = kNoLink;
    chain.*Next = head;
    if (head != kNoLink) {
        chains_[slotOfLink(head)].*Prev = linkOf(slot);
    }
    head = linkOf(slot);
}

template <typename SlotNumber>
template <ObjectLink ObjectChain::*Next, ObjectLink ObjectChain::*Prev>
inline void ObjectTableCore<SlotNumber>::unlink(uint16_t slot, Link& head)
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

template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::linkName(uint16_t slot)
{
    pushFront<&Chain::nameNext, &Chain::namePrev>(slot, buckets_[bucketOf(chains_[slot].nameHash)]);
}

template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::unlinkName(uint16_t slot)
{
    unlink<&Chain::nameNext, &Chain::namePrev>(slot, buckets_[bucketOf(chains_[slot].nameHash)]);
}

template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::linkOwner(uint16_t slot, size_t key)
{
    header(slot).ownerKey = static_cast<uint16_t>(key);
    pushFront<&Chain::ownerNext, &Chain::ownerPrev>(slot, ownerHeads_[key]);
}

// Uses the key stored at link time, not the owner's key now: the key of a
// stale owner id may have changed since.
template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::unlinkOwner(uint16_t slot)
{
    unlink<&Chain::ownerNext, &Chain::ownerPrev>(slot, ownerHeads_[header(slot).ownerKey]);
}

// The index freed longest ago; indices never handed out count as freed
// before any other. The ring starts full with every index in order, each
// stored as index ^ position so that zero-initialised storage holds it;
// Create thus takes the same path whether or not fresh indices remain, which
// keeps its cost flat. There is always one: at most capacity_ objects live,
// and capacity_ <= 4096.
template <typename SlotNumber>
inline uint16_t ObjectTableCore<SlotNumber>::takeIndex()
{
    const uint16_t index = static_cast<uint16_t>(freedIndices_[freedHead_] ^ freedHead_);
    freedHead_ = (freedHead_ + 1) & (kIndexCount - 1);
    --freedCount_;
    // Indices come out of the ring in order until each was handed out once,
    // so issued_ counts them; a comparison, not a branch.
    issued_ += static_cast<size_t>(issued_ == index);
    return index;
}

template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::giveBackIndex(uint16_t index)
{
    const size_t position = (freedHead_ + freedCount_) & (kIndexCount - 1);
    freedIndices_[position] = static_cast<uint16_t>(index ^ position);
    ++freedCount_;
}

// Free slots wait in a ring, so that the slot freed longest ago is reused
// first, which spreads wear of the slots' storage evenly. A ring, unlike a
// list, has no empty case to treat apart, so Create and Delete cost the same
// whether the table is nearly empty or nearly full. The ring holds
// active_ - used_ slots, so the caller counts the slot it adds (active_ or
// used_) only after the push.
template <typename SlotNumber>
inline void ObjectTableCore<SlotNumber>::pushFree(uint16_t slot)
{
    freeSlots_[(freeHead_ + active_ - used_) & (capacity_ - 1)] = static_cast<SlotNumber>(slot);
}

template <typename SlotNumber>
inline uint16_t ObjectTableCore<SlotNumber>::popFree()
{
    const uint16_t slot = freeSlots_[freeHead_];
    freeHead_ = (freeHead_ + 1) & (capacity_ - 1);
    return slot;
}

template class ObjectTableCore<uint8_t>;
template class ObjectTableCore<uint16_t>;

} // namespace dcos::internal
