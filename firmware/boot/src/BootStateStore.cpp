#include <boot/BootStateStore.hpp>

namespace boot {

StoredBootState BootStateStore::read(SectorStore& store)
{
    StoredBootState stored;
    uint8_t first[card::kSectorSize];
    uint8_t second[card::kSectorSize];
    stored.readable =
        store.read(card::kBootStateLba, 1, first) && store.read(card::kBootStateLba + 1, 1, second);
    stored.present = stored.readable && BootState::newest(first, second, stored.state, stored.copy);
    return stored;
}

bool BootStateStore::writeNext(SectorStore& store, const StoredBootState& stored, BootState next)
{
    next.sequence = stored.present ? stored.state.sequence + 1 : 1;
    uint8_t record[card::kSectorSize];
    next.encode(record);
    return store.write(card::kBootStateLba + (stored.present ? stored.copy ^ 1u : 0u), 1, record);
}

} // namespace boot
