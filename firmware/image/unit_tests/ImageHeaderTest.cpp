#include <image/ImageHeader.hpp>

#include <gtest/gtest.h>

#include <cstring>

namespace {

using image::BoardType;
using image::ImageError;
using image::ImageHeader;

ImageHeader sample()
{
    ImageHeader header;
    header.board = BoardType::Isa486;
    header.version = {1, 2, 3, 4};
    header.payloadSize = 1000;
    header.memorySize = 5000;
    header.loadAddress = 0x100000;
    header.entry = 0x100010;
    for (size_t i = 0; i < ImageHeader::kDigestSize; ++i) {
        header.payloadDigest[i] = static_cast<uint8_t>(i);
        header.keyId[i] = static_cast<uint8_t>(0x80 + i);
    }
    for (size_t i = 0; i < ImageHeader::kSignatureSize; ++i) {
        header.signature[i] = static_cast<uint8_t>(0x40 + i);
    }
    return header;
}

struct Bytes {
    uint8_t data[ImageHeader::kSize];
};

Bytes encoded(const ImageHeader& header)
{
    Bytes bytes;
    header.encode(bytes.data);
    return bytes;
}

ImageError decodeError(const Bytes& bytes) { return ImageHeader::decode(bytes.data, sizeof bytes.data).error(); }

TEST(ImageHeaderTest, EncodesTheDocumentedLayoutAndDecodesItBack)
{
    const Bytes bytes = encoded(sample());
    EXPECT_EQ(std::memcmp(bytes.data, "DCOS-IMG", 8), 0);
    EXPECT_EQ(bytes.data[8], 1);    // format
    EXPECT_EQ(bytes.data[10], 0);   // header size 256, little-endian
    EXPECT_EQ(bytes.data[11], 1);
    EXPECT_EQ(bytes.data[12], 1);   // board isa486
    EXPECT_EQ(bytes.data[16], 1);   // major
    EXPECT_EQ(bytes.data[17], 2);   // minor
    EXPECT_EQ(bytes.data[18], 3);   // patch
    EXPECT_EQ(bytes.data[20], 4);   // build
    EXPECT_EQ(bytes.data[24], 0xE8); // 1000 = 0x3E8
    EXPECT_EQ(bytes.data[34], 0x10); // load address 0x00100000
    EXPECT_EQ(bytes.data[40], 0);   // payload digest
    EXPECT_EQ(bytes.data[72], 0x80); // key id
    EXPECT_EQ(bytes.data[192], 0x40); // signature
    for (size_t i = 104; i < 192; ++i) {
        EXPECT_EQ(bytes.data[i], 0) << "reserved byte " << i;
    }
    const image::ImageResult<ImageHeader> decoded = ImageHeader::decode(bytes.data, sizeof bytes.data);
    ASSERT_TRUE(decoded.ok());
    const Bytes again = encoded(decoded.value());
    EXPECT_EQ(std::memcmp(bytes.data, again.data, sizeof bytes.data), 0);
    EXPECT_EQ(decoded.value().version.compare(sample().version), 0);
}

TEST(ImageHeaderTest, RefusesFewerBytesThanAHeader)
{
    const Bytes bytes = encoded(sample());
    for (size_t length : {size_t{0}, size_t{1}, size_t{8}, ImageHeader::kSize - 1}) {
        EXPECT_EQ(ImageHeader::decode(bytes.data, length).error(), ImageError::Truncated) << length;
    }
    EXPECT_EQ(ImageHeader::decode(nullptr, ImageHeader::kSize).error(), ImageError::Truncated);
}

TEST(ImageHeaderTest, RefusesAnotherMagicFormatOrHeaderSize)
{
    for (size_t i = 0; i < 8; ++i) {
        Bytes bytes = encoded(sample());
        bytes.data[i] ^= 0x20;
        EXPECT_EQ(decodeError(bytes), ImageError::BadMagic) << i;
    }
    Bytes format = encoded(sample());
    format.data[8] = 2;
    EXPECT_EQ(decodeError(format), ImageError::UnsupportedFormat);
    Bytes size = encoded(sample());
    size.data[11] = 2; // 512
    EXPECT_EQ(decodeError(size), ImageError::UnsupportedFormat);
}

TEST(ImageHeaderTest, RefusesFlagsReservedBytesAndAnEmptyPayload)
{
    Bytes flags = encoded(sample());
    flags.data[15] = 0x80;
    EXPECT_EQ(decodeError(flags), ImageError::MalformedHeader);
    for (size_t i = 104; i < 192; ++i) {
        Bytes reserved = encoded(sample());
        reserved.data[i] = 1;
        EXPECT_EQ(decodeError(reserved), ImageError::MalformedHeader) << i;
    }
    ImageHeader empty = sample();
    empty.payloadSize = 0;
    empty.entry = empty.loadAddress;
    EXPECT_EQ(decodeError(encoded(empty)), ImageError::MalformedHeader);
}

TEST(ImageHeaderTest, RefusesABoardTypeNoBoardHas)
{
    for (uint8_t board : {0, 2, 0xFF}) {
        Bytes bytes = encoded(sample());
        bytes.data[12] = board;
        EXPECT_EQ(decodeError(bytes), ImageError::UnknownBoard) << int{board};
    }
}

TEST(ImageHeaderTest, RefusesAddressesThatDoNotDescribeTheMemory)
{
    ImageHeader small = sample();
    small.memorySize = small.payloadSize - 1;
    EXPECT_EQ(decodeError(encoded(small)), ImageError::BadAddresses) << "memory smaller than the payload";
    ImageHeader before = sample();
    before.entry = before.loadAddress - 1;
    EXPECT_EQ(decodeError(encoded(before)), ImageError::BadAddresses) << "entry before the payload";
    ImageHeader after = sample();
    after.entry = after.loadAddress + after.payloadSize;
    EXPECT_EQ(decodeError(encoded(after)), ImageError::BadAddresses) << "entry just after the payload";
    ImageHeader wraps = sample();
    wraps.loadAddress = 0xFFFFF000;
    wraps.entry = wraps.loadAddress;
    EXPECT_EQ(decodeError(encoded(wraps)), ImageError::BadAddresses) << "memory past 4 GiB";
    ImageHeader last = sample();
    last.entry = last.loadAddress + last.payloadSize - 1;
    EXPECT_TRUE(ImageHeader::decode(encoded(last).data, ImageHeader::kSize).ok()) << "the payload's last byte";
}

TEST(ImageHeaderTest, NamesBoardsBothWays)
{
    BoardType board{};
    EXPECT_TRUE(image::boardFromName("isa486", board));
    EXPECT_EQ(board, BoardType::Isa486);
    EXPECT_STREQ(image::boardName(BoardType::Isa486), "isa486");
    for (const char* name : {"", "isa48", "isa4866", "ISA486", "p5smp"}) {
        EXPECT_FALSE(image::boardFromName(name, board)) << name;
    }
    EXPECT_FALSE(image::boardFromName(nullptr, board));
    EXPECT_EQ(image::boardName(static_cast<BoardType>(2)), nullptr);
}

TEST(ImageHeaderTest, EveryErrorHasItsOwnText)
{
    for (int i = 0; i <= static_cast<int>(ImageError::Downgrade); ++i) {
        for (int j = 0; j < i; ++j) {
            EXPECT_STRNE(image::imageErrorText(static_cast<ImageError>(i)),
                         image::imageErrorText(static_cast<ImageError>(j)));
        }
    }
}

} // namespace
