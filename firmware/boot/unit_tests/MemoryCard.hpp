// A controller's card in memory for the host tests of the code that
// writes it (the boot state, the configuration, the flash session): whole
// sectors by LBA, and a power cut at any write.
#pragma once

#include <boot/BootState.hpp>
#include <boot/CardLayout.hpp>
#include <boot/SectorStore.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

namespace boot_test {

namespace card = boot::card;

// A card of the smallest size the layout takes. With a power budget, the
// writes after the first `budget` ones find no power: nothing more is
// written (with `tear`, the first half of the cut write's first sector is,
// as a write torn by the cut), and from then on every read and write fails,
// as nothing runs without power.
class MemoryCard final : public boot::SectorStore {
public:
    MemoryCard() : bytes(size_t{card::kMinimumCardSectors} * card::kSectorSize, 0) {}

    bool read(uint32_t lba, uint32_t count, void* buffer) override
    {
        if (failing || cut) {
            return false;
        }
        std::copy_n(bytes.begin() + size_t{lba} * 512, size_t{count} * 512, static_cast<uint8_t*>(buffer));
        return true;
    }
    bool write(uint32_t lba, uint32_t count, const void* buffer) override
    {
        if (failing || cut) {
            return false;
        }
        const auto* from = static_cast<const uint8_t*>(buffer);
        if (budget.has_value() && writes == *budget) {
            cut = true;
            if (tear) {
                std::copy(from, from + 256, bytes.begin() + size_t{lba} * 512);
            }
            return false;
        }
        ++writes;
        std::copy(from, from + size_t{count} * 512, bytes.begin() + size_t{lba} * 512);
        return true;
    }

    /// The power comes back: reads and writes work again, without limit.
    void powerOn()
    {
        cut = false;
        budget.reset();
    }

    std::optional<boot::BootState> state() const
    {
        boot::BootState out;
        unsigned copy = 0;
        uint8_t a[512];
        uint8_t b[512];
        std::copy_n(bytes.begin() + card::kBootStateLba * 512, 512, a);
        std::copy_n(bytes.begin() + (card::kBootStateLba + 1) * 512, 512, b);
        if (!boot::BootState::newest(a, b, out, copy)) {
            return std::nullopt;
        }
        return out;
    }

    std::vector<uint8_t> bytes;
    bool failing = false;
    unsigned writes = 0;
    std::optional<unsigned> budget;
    bool tear = false;
    bool cut = false;
};

} // namespace boot_test
