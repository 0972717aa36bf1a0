// The checks node 2 makes of node 3's image before loading it: a good image
// passes and gives its segments, and every kind of bad one is refused.
#include <bsp/ElfImage.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace {

using bsp::ElfImage;

constexpr uint32_t kBase = 0x0100'0000;
constexpr uint32_t kEnd = 0x0200'0000;

void put16(std::vector<uint8_t>& bytes, size_t at, uint16_t value) { std::memcpy(&bytes[at], &value, 2); }
void put32(std::vector<uint8_t>& bytes, size_t at, uint32_t value) { std::memcpy(&bytes[at], &value, 4); }

struct SegmentSpec {
    uint32_t type;
    uint32_t fileOffset;
    uint32_t physical;
    uint32_t fileBytes;
    uint32_t memoryBytes;
};

// A 32-bit i386 executable: the header, program headers at 52, then file bytes up to @p fileBytes.
std::vector<uint8_t> image(uint32_t entry, const std::vector<SegmentSpec>& segments, size_t fileBytes = 0x3000)
{
    std::vector<uint8_t> bytes(fileBytes, 0xAB);
    std::memset(bytes.data(), 0, 52 + 32 * segments.size());
    const uint8_t ident[] = {0x7F, 'E', 'L', 'F', 1, 1, 1};
    std::memcpy(bytes.data(), ident, sizeof ident);
    put16(bytes, 16, 2);  // executable
    put16(bytes, 18, 3);  // i386
    put32(bytes, 24, entry);
    put32(bytes, 28, 52); // program headers
    put16(bytes, 42, 32);
    put16(bytes, 44, static_cast<uint16_t>(segments.size()));
    for (size_t i = 0; i < segments.size(); ++i) {
        const size_t at = 52 + 32 * i;
        put32(bytes, at + 0, segments[i].type);
        put32(bytes, at + 4, segments[i].fileOffset);
        put32(bytes, at + 8, segments[i].physical);
        put32(bytes, at + 12, segments[i].physical);
        put32(bytes, at + 16, segments[i].fileBytes);
        put32(bytes, at + 20, segments[i].memoryBytes);
    }
    return bytes;
}

const std::vector<SegmentSpec> kGood = {{1, 0x1000, kBase, 0x800, 0x800}, {4, 0, 0, 0, 0},
                                        {1, 0x2000, kBase + 0x1000, 0x400, 0x9000}};

bool passes(const std::vector<uint8_t>& bytes, uint32_t& entry)
{
    return ElfImage::check(bytes.data(), bytes.size(), kBase, kEnd, entry);
}

TEST(ElfImage, AGoodImagePassesAndGivesItsLoadableSegments)
{
    const std::vector<uint8_t> bytes = image(kBase + 0x10, kGood);
    uint32_t entry = 0;
    ASSERT_TRUE(passes(bytes, entry));
    EXPECT_EQ(entry, kBase + 0x10);
    std::vector<ElfImage::Segment> seen;
    ElfImage::forEachLoadable(bytes.data(), [&](const ElfImage::Segment& segment) { seen.push_back(segment); });
    ASSERT_EQ(seen.size(), 2u); // The note segment is not loadable.
    EXPECT_EQ(seen[1].physical, kBase + 0x1000);
    EXPECT_EQ(seen[1].fileBytes, 0x400u);
    EXPECT_EQ(seen[1].memoryBytes, 0x9000u);
}

TEST(ElfImage, AHeaderThatIsNotA32BitI386ExecutableIsRefused)
{
    uint32_t entry = 0;
    const std::vector<uint8_t> good = image(kBase, kGood);
    for (const auto& [offset, value] : std::vector<std::pair<size_t, uint8_t>>{
             {0, 0x7E}, {4, 2}, {5, 2}, {16, 1}, {18, 62}, {42, 56}}) {
        std::vector<uint8_t> bad = good;
        bad[offset] = value;
        EXPECT_FALSE(passes(bad, entry)) << "byte " << offset;
    }
    EXPECT_FALSE(ElfImage::check(good.data(), 51, kBase, kEnd, entry)) << "shorter than a header";
    EXPECT_FALSE(ElfImage::check(nullptr, 0, kBase, kEnd, entry));
}

TEST(ElfImage, ProgramHeadersOutsideTheFileOrTooManyAreRefused)
{
    uint32_t entry = 0;
    std::vector<uint8_t> bytes = image(kBase, kGood);
    put16(bytes, 44, 0);
    EXPECT_FALSE(passes(bytes, entry)) << "no segment";
    put16(bytes, 44, ElfImage::kMaximumSegments + 1);
    EXPECT_FALSE(passes(bytes, entry)) << "too many";
    bytes = image(kBase, kGood);
    put32(bytes, 28, static_cast<uint32_t>(bytes.size()) - 40);
    EXPECT_FALSE(passes(bytes, entry)) << "headers run past the file";
}

TEST(ElfImage, ASegmentOutsideNode3sMemoryOrTheFileIsRefused)
{
    uint32_t entry = 0;
    const std::vector<std::pair<const char*, SegmentSpec>> cases = {
        {"below the base", {1, 0x1000, kBase - 0x1000, 0x800, 0x800}},
        {"at the end", {1, 0x1000, kEnd, 0x800, 0x800}},
        {"running past the end", {1, 0x1000, kEnd - 0x800, 0x800, 0x1000}},
        {"file bytes past the file", {1, 0x2800, kBase, 0x1000, 0x1000}},
        {"offset past the file", {1, 0x4000, kBase, 0x10, 0x10}},
        {"more file bytes than memory", {1, 0x1000, kBase, 0x800, 0x400}},
    };
    for (const auto& [what, segment] : cases) {
        EXPECT_FALSE(passes(image(kBase + 0x10, {kGood[0], segment}), entry)) << what;
    }
}

TEST(ElfImage, AnEntryOutsideEverySegmentsBytesIsRefused)
{
    uint32_t entry = 0;
    EXPECT_FALSE(passes(image(kBase + 0x800, kGood), entry)) << "just past the first segment";
    EXPECT_FALSE(passes(image(kBase + 0x1400, kGood), entry)) << "in the second's zeroed part";
    EXPECT_FALSE(passes(image(0x0010'0000, kGood), entry)) << "in node 2's memory";
    EXPECT_TRUE(passes(image(kBase + 0x13FF, kGood), entry));
}

} // namespace
