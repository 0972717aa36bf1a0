// A controller's CompactFlash card as a file (docs/boot.md, "The card"):
// the raw image a card reader writes to the card, or the emulated board
// boots from. dcos-card makes new cards and writes images into their
// slots with it; the layout and the records are the firmware's own
// (boot/CardLayout.hpp, ConfigurationBlock, BootState), so the host writes
// exactly what the stage loader reads.
#pragma once

#include <boot/BootState.hpp>
#include <boot/SectorStore.hpp>
#include <boot/ConfigurationBlock.hpp>

#include <image/ImageHeader.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hostimage {

class CardFile final : public boot::SectorStore {
public:
    /// A new card of @p sectors sectors: the boot sector and the stage
    /// loader (flat binaries), the configuration in both copies, no boot
    /// state (the stage loader confirms the first valid image), empty slots.
    static std::optional<CardFile> create(const std::vector<uint8_t>& bootSector, const std::vector<uint8_t>& stage,
                                          const boot::ConfigurationBlock& configuration, uint32_t sectors,
                                          std::string& error);
    /// An existing card image.
    static std::optional<CardFile> open(const std::vector<uint8_t>& bytes, std::string& error);

    const std::vector<uint8_t>& bytes() const { return bytes_; }

    /// The configuration's newest valid copy, if any.
    std::optional<boot::ConfigurationBlock> configuration() const;
    /// The boot state's newest valid copy, if any (boot::BootStateStore).
    std::optional<boot::BootState> bootState();
    /// Writes @p state as the next record: sequence one past the newest,
    /// into the other copy (boot::BootStateStore::writeNext).
    void writeBootState(const boot::BootState& state);

    /// The card's sectors, as the firmware's boot code reads and writes
    /// them; false for sectors beyond the card.
    bool read(uint32_t lba, uint32_t count, void* buffer) override;
    bool write(uint32_t lba, uint32_t count, const void* buffer) override;

    /// The image in @p slot, header and payload as a file holds them;
    /// empty when the slot's first sector holds no image header.
    std::vector<uint8_t> slotImage(uint32_t slot) const;
    /// Writes an image (header and payload) into @p slot: the header in the
    /// slot's first sector, the payload from its second. False, with the
    /// reason, if it does not fit.
    bool writeSlot(uint32_t slot, const std::vector<uint8_t>& image, std::string& error);

private:
    const uint8_t* sector(uint32_t lba) const { return bytes_.data() + size_t{lba} * boot::card::kSectorSize; }
    uint8_t* sector(uint32_t lba) { return bytes_.data() + size_t{lba} * boot::card::kSectorSize; }

    std::vector<uint8_t> bytes_;
};

} // namespace hostimage
