#include <boot/BootInfo.hpp>

#include <gtest/gtest.h>

namespace {

TEST(CommandLine, FindsKeyValuePairsAnywhere)
{
    char value[16];
    EXPECT_TRUE(boot::findCommandLineOption("/boot/dcos.elf tick_hz=250 node=3", "tick_hz", value, sizeof value));
    EXPECT_STREQ(value, "250");
    EXPECT_TRUE(boot::findCommandLineOption("/boot/dcos.elf tick_hz=250 node=3", "node", value, sizeof value));
    EXPECT_STREQ(value, "3");
}

TEST(CommandLine, KeyMustMatchWholly)
{
    char value[16];
    EXPECT_FALSE(boot::findCommandLineOption("tick_hz_max=5", "tick_hz", value, sizeof value));
    EXPECT_FALSE(boot::findCommandLineOption("tick=5", "tick_hz", value, sizeof value));
    EXPECT_FALSE(boot::findCommandLineOption("", "tick_hz", value, sizeof value));
}

TEST(CommandLine, BareKeyHasEmptyValue)
{
    char value[16] = "junk";
    EXPECT_TRUE(boot::findCommandLineOption("a verbose b", "verbose", value, sizeof value));
    EXPECT_STREQ(value, "");
}

TEST(CommandLine, LongValueIsTruncatedAndTerminated)
{
    char value[4];
    EXPECT_TRUE(boot::findCommandLineOption("key=123456", "key", value, sizeof value));
    EXPECT_STREQ(value, "123");
}

} // namespace

TEST(CommandLine, NodeIdsAreOneTo65534InAtMostFiveDigits)
{
    uint16_t node = 9;
    EXPECT_TRUE(boot::parseNodeId("4", node));
    EXPECT_EQ(node, 4);
    EXPECT_TRUE(boot::parseNodeId("65534", node));
    EXPECT_EQ(node, 65534);
    EXPECT_TRUE(boot::parseNodeId("00012", node));
    EXPECT_EQ(node, 12);
    for (const char* text : {"", "0", "65535", "99999", "000001", "4x", "-4", " 4", "4 "}) {
        node = 9;
        EXPECT_FALSE(boot::parseNodeId(text, node)) << text;
        EXPECT_EQ(node, 9) << "unchanged: " << text;
    }
}
