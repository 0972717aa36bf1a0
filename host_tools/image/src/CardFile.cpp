#include <hostimage/CardFile.hpp>

#include <boot/BootStateStore.hpp>

#include <algorithm>
#include <cstring>

namespace hostimage {

namespace card = boot::card;

namespace {

using Sector = uint8_t[card::kSectorSize];

const Sector& asSector(const uint8_t* at) { return *reinterpret_cast<const Sector*>(at); }

} // namespace

std::optional<CardFile> CardFile::create(const std::vector<uint8_t>& bootSector, const std::vector<uint8_t>& stage,
                                         const boot::ConfigurationBlock& configuration, uint32_t sectors,
                                         std::string& error)
{
    if (bootSector.size() != card::kSectorSize || bootSector[510] != 0x55 || bootSector[511] != 0xAA) {
        error = "the boot sector is not 512 bytes ending in the boot signature 55 AA";
        return std::nullopt;
    }
    if (stage.empty() || stage.size() > size_t{card::kStageSectors} * card::kSectorSize) {
        error = "the stage loader is empty or larger than its 255 sectors";
        return std::nullopt;
    }
    if (sectors < card::kMinimumCardSectors) {
        error = "a card needs at least " + std::to_string(card::kMinimumCardSectors) + " sectors";
        return std::nullopt;
    }
    CardFile made;
    made.bytes_.assign(size_t{sectors} * card::kSectorSize, 0);
    std::copy(bootSector.begin(), bootSector.end(), made.sector(card::kBootSectorLba));
    std::copy(stage.begin(), stage.end(), made.sector(card::kStageLba));
    for (uint32_t copy = 0; copy < card::kCopies; ++copy) {
        Sector record;
        configuration.encode(record);
        std::copy(std::begin(record), std::end(record), made.sector(card::kConfigurationLba + copy));
    }
    return made;
}

std::optional<CardFile> CardFile::open(const std::vector<uint8_t>& bytes, std::string& error)
{
    if (bytes.size() % card::kSectorSize != 0 || bytes.size() < size_t{card::kMinimumCardSectors} * card::kSectorSize) {
        error = "not a card image: its size is not a whole number of sectors of at least the layout's 5 MiB";
        return std::nullopt;
    }
    if (bytes[510] != 0x55 || bytes[511] != 0xAA) {
        error = "not a card image: sector 0 has no boot signature";
        return std::nullopt;
    }
    CardFile opened;
    opened.bytes_ = bytes;
    return opened;
}

std::optional<boot::ConfigurationBlock> CardFile::configuration() const
{
    boot::ConfigurationBlock block;
    unsigned copy = 0;
    if (!boot::newestCopy(asSector(sector(card::kConfigurationLba)), asSector(sector(card::kConfigurationLba + 1)),
                          block, copy)) {
        return std::nullopt;
    }
    return block;
}

std::optional<boot::BootState> CardFile::bootState()
{
    const boot::StoredBootState stored = boot::BootStateStore::read(*this);
    if (!stored.present) {
        return std::nullopt;
    }
    return stored.state;
}

void CardFile::writeBootState(const boot::BootState& state)
{
    (void)boot::BootStateStore::writeNext(*this, boot::BootStateStore::read(*this), state);
}

bool CardFile::read(uint32_t lba, uint32_t count, void* buffer)
{
    if (uint64_t{lba} + count > bytes_.size() / card::kSectorSize) {
        return false;
    }
    std::copy_n(sector(lba), size_t{count} * card::kSectorSize, static_cast<uint8_t*>(buffer));
    return true;
}

bool CardFile::write(uint32_t lba, uint32_t count, const void* buffer)
{
    if (uint64_t{lba} + count > bytes_.size() / card::kSectorSize) {
        return false;
    }
    const auto* from = static_cast<const uint8_t*>(buffer);
    std::copy(from, from + size_t{count} * card::kSectorSize, sector(lba));
    return true;
}

std::vector<uint8_t> CardFile::slotImage(uint32_t slot) const
{
    const uint8_t* header = sector(card::kSlotLba[slot]);
    const image::ImageResult<image::ImageHeader> decoded = image::ImageHeader::decode(header, image::ImageHeader::kSize);
    if (!decoded.ok() || decoded.value().payloadSize > (card::kSlotSectors - 1) * card::kSectorSize) {
        return {};
    }
    std::vector<uint8_t> out(header, header + image::ImageHeader::kSize);
    const uint8_t* payload = sector(card::kSlotLba[slot] + 1);
    out.insert(out.end(), payload, payload + decoded.value().payloadSize);
    return out;
}

bool CardFile::writeSlot(uint32_t slot, const std::vector<uint8_t>& imageBytes, std::string& error)
{
    if (imageBytes.size() < image::ImageHeader::kSize ||
        imageBytes.size() - image::ImageHeader::kSize > size_t{card::kSlotSectors - 1} * card::kSectorSize) {
        error = "the image does not fit a slot (a header and at most 4,095 sectors of payload)";
        return false;
    }
    uint8_t* first = sector(card::kSlotLba[slot]);
    std::fill(first, first + size_t{card::kSlotSectors} * card::kSectorSize, 0);
    std::copy(imageBytes.begin(), imageBytes.begin() + image::ImageHeader::kSize, first);
    std::copy(imageBytes.begin() + image::ImageHeader::kSize, imageBytes.end(), sector(card::kSlotLba[slot] + 1));
    return true;
}

} // namespace hostimage
