// The card's configuration as it is read and changed (docs/boot.md, "The
// card"): the newer valid of its two copies, and a change written as the
// next record into the other copy, so that a power cut during the write
// leaves the record before it (RecordCopies.hpp). The kernel's flash
// service reads its trusted keys here, and the configuration protocol's
// server (docs/protocols/config.md) reads and changes the node's identity
// here. The stage loader reads the copies itself, to name the ATA error
// of a failed read.
#pragma once

#include <boot/ConfigurationBlock.hpp>
#include <boot/SectorStore.hpp>

namespace boot {

/// What a read of the configuration found.
struct StoredConfiguration {
    /// Both copies could be read.
    bool readable = false;
    /// One of them is valid: configuration and copy hold the newer valid one.
    bool present = false;
    ConfigurationBlock configuration;
    unsigned copy = 0;
};

class ConfigurationStore {
public:
    static StoredConfiguration read(SectorStore& store);

    /// Writes @p next as the record after @p stored: the sequence one past
    /// its (1 on a card with none), into the copy that does not hold it
    /// (copy 0 on a card with none). @p next's own sequence is ignored; the
    /// one written is returned in @p sequence. False when the write failed.
    static bool writeNext(SectorStore& store, const StoredConfiguration& stored, ConfigurationBlock next,
                          uint32_t& sequence);
};

} // namespace boot
