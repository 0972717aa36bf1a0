// The configuration as the node changes it (docs/protocols/config.md):
// each change the next record in the older copy, and a power cut at any
// write, clean or tearing the sector, leaving the old record or the new
// one, never a mix.
#include <boot/ConfigurationStore.hpp>

#include "MemoryCard.hpp"

#include <gtest/gtest.h>

#include <cstring>

namespace {

using boot::ConfigurationBlock;
using boot::ConfigurationStore;
using boot::StoredConfiguration;
using boot_test::MemoryCard;

ConfigurationBlock withNode(uint16_t node, uint32_t bitRate)
{
    ConfigurationBlock block;
    block.nodeId = node;
    block.canBitRate = bitRate;
    block.serialNumber = 77;
    std::strcpy(block.commandLine, "console=quiet");
    return block;
}

TEST(ConfigurationStoreTest, ACardWithoutARecordIsReadableButHasNone)
{
    MemoryCard store;
    const StoredConfiguration stored = ConfigurationStore::read(store);
    EXPECT_TRUE(stored.readable);
    EXPECT_FALSE(stored.present);
    store.failing = true;
    EXPECT_FALSE(ConfigurationStore::read(store).readable);
}

TEST(ConfigurationStoreTest, EachChangeIsTheNextRecordInTheOtherCopy)
{
    MemoryCard store;
    uint32_t sequence = 0;
    ASSERT_TRUE(ConfigurationStore::writeNext(store, ConfigurationStore::read(store), withNode(1, 0), sequence));
    EXPECT_EQ(sequence, 1u);
    StoredConfiguration stored = ConfigurationStore::read(store);
    ASSERT_TRUE(stored.present);
    EXPECT_EQ(stored.copy, 0u);
    for (uint16_t node = 2; node < 6; ++node) {
        ASSERT_TRUE(ConfigurationStore::writeNext(store, stored, withNode(node, 500000), sequence));
        const unsigned before = stored.copy;
        stored = ConfigurationStore::read(store);
        ASSERT_TRUE(stored.present);
        EXPECT_EQ(stored.copy, before ^ 1u);
        EXPECT_EQ(stored.configuration.sequence, sequence);
        EXPECT_EQ(stored.configuration.nodeId, node);
        EXPECT_EQ(stored.configuration.canBitRate, 500000u);
        EXPECT_STREQ(stored.configuration.commandLine, "console=quiet");
    }
    store.failing = true;
    EXPECT_FALSE(ConfigurationStore::writeNext(store, stored, withNode(9, 0), sequence));
}

TEST(ConfigurationStoreTest, APowerCutDuringAStoreLeavesTheOldRecordOrTheNewNeverAMix)
{
    for (const bool tear : {false, true}) {
        for (unsigned changes = 1; changes <= 4; ++changes) {
            MemoryCard store;
            uint32_t sequence = 0;
            ASSERT_TRUE(ConfigurationStore::writeNext(store, ConfigurationStore::read(store), withNode(1, 125000),
                                                      sequence));
            // Stores that succeed, then one the power is cut in.
            for (unsigned i = 1; i < changes; ++i) {
                ASSERT_TRUE(ConfigurationStore::writeNext(store, ConfigurationStore::read(store),
                                                          withNode(static_cast<uint16_t>(1 + i), 125000), sequence));
            }
            const StoredConfiguration before = ConfigurationStore::read(store);
            store.budget = store.writes;
            store.tear = tear;
            EXPECT_FALSE(ConfigurationStore::writeNext(store, before, withNode(200, 1000000), sequence));
            store.powerOn();
            const StoredConfiguration after = ConfigurationStore::read(store);
            ASSERT_TRUE(after.present) << "tear " << tear << ", change " << changes;
            // The cut write never reached the card whole: the old record stands, whole.
            EXPECT_EQ(after.configuration.sequence, before.configuration.sequence);
            EXPECT_EQ(after.configuration.nodeId, before.configuration.nodeId);
            EXPECT_EQ(after.configuration.canBitRate, 125000u);
            // And the store, tried again, takes.
            ASSERT_TRUE(ConfigurationStore::writeNext(store, after, withNode(200, 1000000), sequence));
            const StoredConfiguration again = ConfigurationStore::read(store);
            EXPECT_EQ(again.configuration.nodeId, 200);
            EXPECT_EQ(again.configuration.canBitRate, 1000000u);
        }
    }
}

} // namespace
