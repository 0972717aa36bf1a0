// The card's boot state as it is read and changed (docs/boot.md, "The
// card"): the newer valid of its two copies, and a change written as the
// next record into the other copy, so that a power cut during the write
// leaves the record before it (RecordCopies.hpp). One place for it: the
// stage loader's decision (BootSequence), the confirmation (BootControl),
// the flash session's pending mark and the host's card tool all go through
// here.
#pragma once

#include <boot/BootState.hpp>
#include <boot/SectorStore.hpp>

namespace boot {

/// What a read of the boot state found.
struct StoredBootState {
    /// Both copies could be read.
    bool readable = false;
    /// One of them is valid: state and copy hold the newer valid one.
    bool present = false;
    BootState state;
    unsigned copy = 0;
};

class BootStateStore {
public:
    static StoredBootState read(SectorStore& store);

    /// Writes @p next as the record after @p stored: the sequence one past
    /// its (1 on a card with none), into the copy that does not hold it
    /// (copy 0 on a card with none). @p next's own sequence is ignored.
    static bool writeNext(SectorStore& store, const StoredBootState& stored, BootState next);
};

} // namespace boot
