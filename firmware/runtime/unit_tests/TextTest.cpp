// Host tests for the text helpers shared by the shell, the configuration rules and applications.
#include <runtime/Text.hpp>

#include <gtest/gtest.h>

static_assert(runtime::textLength("pump") == 4);
static_assert(runtime::textEquals("pump", "pump") && !runtime::textEquals("pump", "pumps"));

TEST(TextTest, LengthCountsUpToTheTerminator)
{
    EXPECT_EQ(runtime::textLength(""), 0u);
    EXPECT_EQ(runtime::textLength("sampler"), 7u);
    const char embedded[] = {'a', 'b', '\0', 'c', '\0'};
    EXPECT_EQ(runtime::textLength(embedded), 2u);
}

TEST(TextTest, EqualsNeedsTheSameCharactersAndTheSameLength)
{
    EXPECT_TRUE(runtime::textEquals("", ""));
    EXPECT_TRUE(runtime::textEquals("set", "set"));
    EXPECT_FALSE(runtime::textEquals("set", "se"));
    EXPECT_FALSE(runtime::textEquals("se", "set"));
    EXPECT_FALSE(runtime::textEquals("Set", "set"));
    EXPECT_FALSE(runtime::textEquals("", "x"));
}
