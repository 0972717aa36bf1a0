#include <boot/ConfigurationBlock.hpp>

#include <gtest/gtest.h>

#include <cstring>

namespace {

using boot::ConfigurationBlock;

ConfigurationBlock sample()
{
    ConfigurationBlock block;
    block.sequence = 12;
    block.nodeId = 7;
    block.canBitRate = 500000;
    block.keyCount = 2;
    for (size_t key = 0; key < 2; ++key) {
        block.keys[key][0] = 0x04;
        for (size_t i = 1; i < ConfigurationBlock::kKeySize; ++i) {
            block.keys[key][i] = static_cast<uint8_t>(key * 100 + i);
        }
    }
    std::strcpy(block.commandLine, "node=7 console=quiet");
    return block;
}

TEST(ConfigurationBlockTest, RoundTripsAndRefusesEveryChangedByte)
{
    uint8_t sector[512];
    sample().encode(sector);
    ConfigurationBlock decoded;
    ASSERT_TRUE(ConfigurationBlock::decode(sector, decoded));
    EXPECT_EQ(decoded.sequence, 12u);
    EXPECT_EQ(decoded.nodeId, 7);
    EXPECT_EQ(decoded.canBitRate, 500000u);
    EXPECT_EQ(decoded.keyCount, 2);
    EXPECT_EQ(std::memcmp(decoded.keys, sample().keys, sizeof decoded.keys), 0);
    EXPECT_STREQ(decoded.commandLine, "node=7 console=quiet");
    for (size_t at = 0; at < sizeof sector; ++at) {
        uint8_t changed[512];
        std::memcpy(changed, sector, sizeof sector);
        changed[at] ^= 0x10;
        ConfigurationBlock ignored;
        EXPECT_FALSE(ConfigurationBlock::decode(changed, ignored)) << "byte " << at;
    }
}

TEST(ConfigurationBlockTest, RefusesBadFieldsEvenWithARightCrc)
{
    ConfigurationBlock tooMany = sample();
    tooMany.keyCount = 5;
    ConfigurationBlock compressed = sample();
    compressed.keys[1][0] = 0x02;
    ConfigurationBlock broadcast = sample();
    broadcast.nodeId = 0xFFFF;
    ConfigurationBlock control = sample();
    control.commandLine[3] = '\n';
    for (const ConfigurationBlock& bad : {tooMany, compressed, broadcast, control}) {
        uint8_t sector[512];
        bad.encode(sector);
        ConfigurationBlock ignored;
        EXPECT_FALSE(ConfigurationBlock::decode(sector, ignored));
    }
}

TEST(ConfigurationBlockTest, ACommandLineFillingTheFieldIsCutToLeaveItsTerminator)
{
    ConfigurationBlock full = sample();
    std::memset(full.commandLine, 'x', sizeof full.commandLine);
    uint8_t sector[512];
    full.encode(sector);
    ConfigurationBlock decoded;
    ASSERT_TRUE(ConfigurationBlock::decode(sector, decoded));
    EXPECT_EQ(std::strlen(decoded.commandLine), ConfigurationBlock::kCommandLineSize - 1);
}

TEST(ConfigurationBlockTest, TheNewerValidCopyCounts)
{
    uint8_t first[512];
    uint8_t second[512];
    ConfigurationBlock older = sample();
    ConfigurationBlock newer = sample();
    newer.sequence = 13;
    newer.nodeId = 9;
    older.encode(first);
    newer.encode(second);
    ConfigurationBlock out;
    unsigned copy = 0;
    ASSERT_TRUE(boot::newestCopy(first, second, out, copy));
    EXPECT_EQ(copy, 1u);
    EXPECT_EQ(out.nodeId, 9);
    second[100] ^= 1;
    ASSERT_TRUE(boot::newestCopy(first, second, out, copy));
    EXPECT_EQ(out.nodeId, 7) << "a torn newer copy: the older stands";
}

} // namespace

TEST(ConfigurationBlockTest, TheIdentityFieldsRoundTripAndARecordWithoutThemReadsAsDefaults)
{
    ConfigurationBlock block = sample();
    block.serialNumber = 0xA1B2C3D4;
    for (size_t i = 0; i < ConfigurationBlock::kConfigurationKeySize; ++i) {
        block.configurationKey[i] = static_cast<uint8_t>(0xF0 - i);
    }
    block.flags = ConfigurationBlock::kHasConfigurationKey | ConfigurationBlock::kQueriesClosed;
    block.lockoutSeconds = 300;
    uint8_t sector[512];
    block.encode(sector);
    // The layout of the header's table, byte for byte.
    EXPECT_EQ(sector[440], 0xD4);
    EXPECT_EQ(sector[443], 0xA1);
    EXPECT_EQ(sector[444], 0xF0);
    EXPECT_EQ(sector[475], 0xF0 - 31);
    EXPECT_EQ(sector[476], 3);
    EXPECT_EQ(sector[477] | sector[478] << 8, 300);
    ConfigurationBlock decoded;
    ASSERT_TRUE(ConfigurationBlock::decode(sector, decoded));
    EXPECT_EQ(decoded.serialNumber, 0xA1B2C3D4u);
    EXPECT_EQ(std::memcmp(decoded.configurationKey, block.configurationKey, sizeof block.configurationKey), 0);
    EXPECT_TRUE(decoded.hasConfigurationKey());
    EXPECT_TRUE(decoded.queriesClosed());
    EXPECT_EQ(decoded.effectiveLockoutSeconds(), 300);

    // A record written before these fields existed holds zeros there.
    uint8_t older[512];
    sample().encode(older);
    ASSERT_TRUE(ConfigurationBlock::decode(older, decoded));
    EXPECT_EQ(decoded.serialNumber, 0u);
    EXPECT_FALSE(decoded.hasConfigurationKey());
    EXPECT_FALSE(decoded.queriesClosed());
    EXPECT_EQ(decoded.effectiveLockoutSeconds(), ConfigurationBlock::kDefaultLockoutSeconds);
}

TEST(ConfigurationBlockTest, AKeyNotMarkedSetIsNotWrittenAndAnUnknownFlagIsRefused)
{
    ConfigurationBlock block = sample();
    block.configurationKey[0] = 0x55; // Without kHasConfigurationKey: not a key.
    uint8_t sector[512];
    block.encode(sector);
    EXPECT_EQ(sector[444], 0);
    block.flags = 0x04;
    block.encode(sector);
    ConfigurationBlock ignored;
    EXPECT_FALSE(ConfigurationBlock::decode(sector, ignored));
}
