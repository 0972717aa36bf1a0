#include <image/ImageVersion.hpp>

#include <gtest/gtest.h>

#include <string>

namespace {

using image::ImageVersion;

ImageVersion parsed(const char* text)
{
    ImageVersion version;
    EXPECT_TRUE(ImageVersion::parse(text, version)) << text;
    return version;
}

std::string formatted(const ImageVersion& version)
{
    char text[32];
    version.format(text, sizeof text);
    return text;
}

TEST(ImageVersionTest, ParsesMajorMinorPatchAndAnOptionalBuild)
{
    const ImageVersion plain = parsed("1.2.3");
    EXPECT_EQ(plain.major, 1);
    EXPECT_EQ(plain.minor, 2);
    EXPECT_EQ(plain.patch, 3);
    EXPECT_EQ(plain.build, 0u);
    const ImageVersion largest = parsed("255.255.65535+4294967295");
    EXPECT_EQ(largest.major, 255);
    EXPECT_EQ(largest.patch, 65535);
    EXPECT_EQ(largest.build, 4294967295u);
}

TEST(ImageVersionTest, RefusesEverythingElse)
{
    for (const char* text : {"", "1", "1.2", "1.2.3.4", "256.0.0", "0.256.0", "0.0.65536", "1.2.3+", "1.2.3+4294967296",
                             "a.b.c", "1.2.3 ", " 1.2.3", "-1.2.3", "1..3", "1.2.3+1+2", "1.2.3-rc1"}) {
        ImageVersion version;
        version.major = 9;
        EXPECT_FALSE(ImageVersion::parse(text, version)) << text;
        EXPECT_EQ(version.major, 9) << "a refused text leaves the version untouched: " << text;
    }
    ImageVersion version;
    EXPECT_FALSE(ImageVersion::parse(nullptr, version));
}

TEST(ImageVersionTest, ComparesMajorThenMinorThenPatchThenBuild)
{
    EXPECT_LT(parsed("1.2.3").compare(parsed("1.2.4")), 0);
    EXPECT_LT(parsed("1.2.300").compare(parsed("1.3.0")), 0);
    EXPECT_LT(parsed("1.255.0").compare(parsed("2.0.0")), 0);
    EXPECT_LT(parsed("1.2.3").compare(parsed("1.2.3+1")), 0);
    EXPECT_GT(parsed("1.2.3+2").compare(parsed("1.2.3+1")), 0);
    EXPECT_EQ(parsed("1.2.3+5").compare(parsed("1.2.3+5")), 0);
}

TEST(ImageVersionTest, FormatsWhatParseReads)
{
    EXPECT_EQ(formatted(parsed("1.2.3")), "1.2.3");
    EXPECT_EQ(formatted(parsed("0.0.0+17")), "0.0.0+17");
    EXPECT_EQ(formatted(parsed("255.255.65535+4294967295")), "255.255.65535+4294967295");
    char small[4];
    EXPECT_EQ(parsed("10.20.30").format(small, sizeof small), 8u) << "the length it needs";
    EXPECT_STREQ(small, "10.") << "cut, and terminated";
}

} // namespace
