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
