// The card behind the ATA driver as a SectorStore. The disk is identified
// on first use, so a store can be made before anything is known of the card.
#pragma once

#include <boot/SectorStore.hpp>

#include <ata/AtaPioDisk.hpp>

namespace boot {

class AtaSectorStore final : public SectorStore {
public:
    explicit AtaSectorStore(ata::AtaPioDisk& disk) : disk_(disk) {}

    bool read(uint32_t lba, uint32_t count, void* buffer) override
    {
        return ready() && disk_.read(lba, count, buffer) == ata::AtaError::Ok;
    }
    bool write(uint32_t lba, uint32_t count, const void* buffer) override
    {
        return ready() && disk_.write(lba, count, buffer) == ata::AtaError::Ok;
    }

private:
    bool ready() { return disk_.sectorCount() != 0 || disk_.identify() == ata::AtaError::Ok; }

    ata::AtaPioDisk& disk_;
};

} // namespace boot
