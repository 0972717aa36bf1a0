#include <hostimage/ElfPayload.hpp>

#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

namespace {

using hostimage::ElfPayload;

struct SegmentSpec {
    uint32_t type = 1; // PT_LOAD
    uint32_t address = 0;
    std::vector<uint8_t> bytes;
    uint32_t memorySize = 0;
};

void put16(std::vector<uint8_t>& file, size_t at, uint16_t value)
{
    file[at] = static_cast<uint8_t>(value);
    file[at + 1] = static_cast<uint8_t>(value >> 8);
}

void put32(std::vector<uint8_t>& file, size_t at, uint32_t value)
{
    for (int i = 0; i < 4; ++i) {
        file[at + i] = static_cast<uint8_t>(value >> (8 * i));
    }
}

// A minimal ELF32 i386 executable: header, program headers, then each
// segment's bytes in order.
std::vector<uint8_t> elf(const std::vector<SegmentSpec>& segments, uint32_t entry)
{
    const size_t headers = 52 + 32 * segments.size();
    std::vector<uint8_t> file(headers, 0);
    file[0] = 0x7F;
    file[1] = 'E';
    file[2] = 'L';
    file[3] = 'F';
    file[4] = 1; // ELFCLASS32
    file[5] = 1; // ELFDATA2LSB
    file[6] = 1; // EV_CURRENT
    put16(file, 16, 2); // ET_EXEC
    put16(file, 18, 3); // EM_386
    put32(file, 20, 1);
    put32(file, 24, entry);
    put32(file, 28, 52);
    put16(file, 40, 52);
    put16(file, 42, 32);
    put16(file, 44, static_cast<uint16_t>(segments.size()));
    for (size_t i = 0; i < segments.size(); ++i) {
        const size_t at = 52 + 32 * i;
        put32(file, at, segments[i].type);
        put32(file, at + 4, static_cast<uint32_t>(file.size()));
        put32(file, at + 8, segments[i].address);
        put32(file, at + 12, segments[i].address);
        put32(file, at + 16, static_cast<uint32_t>(segments[i].bytes.size()));
        put32(file, at + 20, segments[i].memorySize);
        file.insert(file.end(), segments[i].bytes.begin(), segments[i].bytes.end());
    }
    return file;
}

std::string refusal(const std::vector<uint8_t>& file)
{
    std::string error;
    const std::optional<ElfPayload> payload = ElfPayload::fromElf(file, error);
    EXPECT_FALSE(payload.has_value());
    EXPECT_FALSE(error.empty());
    return error;
}

TEST(ElfPayloadTest, LaysTheSegmentsOutFromTheLowestAddressWithZeroedGapsAndTheBssAtTheEnd)
{
    // Given out of order: text at 1 MiB, data 16 bytes after its end, bss after.
    const std::vector<uint8_t> file = elf({{1, 0x100020, {9, 8, 7}, 8},
                                           {1, 0x100000, {1, 2, 3, 4}, 4},
                                           {6, 0x200000, {0xEE}, 1}}, // PT_PHDR: ignored
                                          0x100002);
    std::string error;
    const std::optional<ElfPayload> payload = ElfPayload::fromElf(file, error);
    ASSERT_TRUE(payload.has_value()) << error;
    EXPECT_EQ(payload->loadAddress(), 0x100000u);
    EXPECT_EQ(payload->entry(), 0x100002u);
    EXPECT_EQ(payload->memorySize(), 0x28u);
    std::vector<uint8_t> expected(0x23, 0);
    expected[0] = 1;
    expected[1] = 2;
    expected[2] = 3;
    expected[3] = 4;
    expected[0x20] = 9;
    expected[0x21] = 8;
    expected[0x22] = 7;
    EXPECT_EQ(payload->bytes(), expected);
}

TEST(ElfPayloadTest, RefusesWhatIsNotAn386Executable)
{
    const std::vector<uint8_t> good = elf({{1, 0x100000, {1, 2, 3, 4}, 4}}, 0x100000);
    EXPECT_EQ(refusal({}), "not an ELF file");
    EXPECT_EQ(refusal(std::vector<uint8_t>(good.begin(), good.begin() + 51)), "not an ELF file");
    std::vector<uint8_t> wide = good;
    wide[4] = 2;
    EXPECT_EQ(refusal(wide), "not a 32-bit little-endian ELF file");
    std::vector<uint8_t> big = good;
    big[5] = 2;
    EXPECT_EQ(refusal(big), "not a 32-bit little-endian ELF file");
    std::vector<uint8_t> relocatable = good;
    relocatable[16] = 1;
    EXPECT_NE(refusal(relocatable).find("not an i386 executable"), std::string::npos);
    std::vector<uint8_t> arm = good;
    arm[18] = 40;
    EXPECT_NE(refusal(arm).find("not an i386 executable"), std::string::npos);
}

TEST(ElfPayloadTest, RefusesHeadersAndSegmentsOutsideTheFile)
{
    std::vector<uint8_t> table = elf({{1, 0x100000, {1, 2, 3, 4}, 4}}, 0x100000);
    put32(table, 28, 0xFFFFFFF0);
    EXPECT_EQ(refusal(table), "program headers outside the file");
    std::vector<uint8_t> small = elf({{1, 0x100000, {1, 2, 3, 4}, 4}}, 0x100000);
    put16(small, 42, 16);
    EXPECT_EQ(refusal(small), "program headers outside the file");
    std::vector<uint8_t> segment = elf({{1, 0x100000, {1, 2, 3, 4}, 4}}, 0x100000);
    put32(segment, 52 + 16, 5); // p_filesz one past the file's end
    put32(segment, 52 + 20, 5);
    EXPECT_NE(refusal(segment).find("outside the file"), std::string::npos);
    std::vector<uint8_t> wraps = elf({{1, 0xFFFFFFFE, {1, 2, 3, 4}, 4}}, 0xFFFFFFFE);
    EXPECT_NE(refusal(wraps).find("address space"), std::string::npos);
    std::vector<uint8_t> fileLarger = elf({{1, 0x100000, {1, 2, 3, 4}, 2}}, 0x100000);
    EXPECT_NE(refusal(fileLarger).find("outside"), std::string::npos) << "p_filesz above p_memsz";
}

TEST(ElfPayloadTest, RefusesOverlapsNothingToLoadAndAnEntryOutside)
{
    EXPECT_EQ(refusal(elf({{1, 0x100000, {1, 2, 3, 4}, 4}, {1, 0x100003, {5}, 1}}, 0x100000)),
              "loadable segments overlap");
    EXPECT_EQ(refusal(elf({{6, 0x100000, {1}, 1}}, 0x100000)), "no loadable segment");
    EXPECT_EQ(refusal(elf({{1, 0x100000, {}, 64}}, 0x100000)), "the loadable segments hold no bytes");
    EXPECT_EQ(refusal(elf({{1, 0x100000, {1, 2, 3, 4}, 16}}, 0x100004)),
              "the entry point lies outside the loaded bytes");
    EXPECT_EQ(refusal(elf({{1, 0x100000, {1, 2, 3, 4}, 4}}, 0xFFFFF)), "the entry point lies outside the loaded bytes");
}

TEST(ElfPayloadTest, RefusesASpanLargerThanAnImageMayHold)
{
    EXPECT_NE(refusal(elf({{1, 0x100000, {1}, 1}, {1, 0x100000 + ElfPayload::kMaximumPayload, {2}, 1}}, 0x100000))
                  .find("span more"),
              std::string::npos);
    EXPECT_NE(refusal(elf({{1, 0x100000, {1}, ElfPayload::kMaximumMemory + 1}}, 0x100000)).find("span more"),
              std::string::npos);
}

} // namespace
