#include <boot/ConfigurationStore.hpp>

#include <boot/RecordCopies.hpp>

namespace boot {

StoredConfiguration ConfigurationStore::read(SectorStore& store)
{
    StoredConfiguration stored;
    uint8_t first[card::kSectorSize];
    uint8_t second[card::kSectorSize];
    stored.readable = store.read(card::kConfigurationLba, 1, first) &&
                      store.read(card::kConfigurationLba + 1, 1, second);
    stored.present = stored.readable && newestCopy(first, second, stored.configuration, stored.copy);
    return stored;
}

bool ConfigurationStore::writeNext(SectorStore& store, const StoredConfiguration& stored, ConfigurationBlock next,
                                   uint32_t& sequence)
{
    next.sequence = stored.present ? stored.configuration.sequence + 1 : 1;
    uint8_t record[card::kSectorSize];
    next.encode(record);
    sequence = next.sequence;
    return store.write(card::kConfigurationLba + (stored.present ? stored.copy ^ 1u : 0u), 1, record);
}

} // namespace boot
