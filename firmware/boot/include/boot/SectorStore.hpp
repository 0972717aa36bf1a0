// The card as the boot code reads and writes it: whole 512-byte sectors by
// LBA. The stage loader and a running node pass the ATA driver
// (AtaSectorStore); the host tests pass a card in memory, which can also
// lose its power at any write (PowerCutTest).
#pragma once

#include <stdint.h>

namespace boot {

class SectorStore {
public:
    /// False when the sectors cannot be read.
    virtual bool read(uint32_t lba, uint32_t count, void* buffer) = 0;
    /// False when the sectors cannot be written; true once they are on the card.
    virtual bool write(uint32_t lba, uint32_t count, const void* buffer) = 0;

protected:
    ~SectorStore() = default;
};

} // namespace boot
