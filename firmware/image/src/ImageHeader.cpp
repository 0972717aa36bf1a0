#include <image/ImageHeader.hpp>

namespace image {

namespace {

// Offsets of the fields (the table in ImageHeader.hpp).
constexpr size_t kFormatOffset = 8;
constexpr size_t kHeaderSizeOffset = 10;
constexpr size_t kBoardOffset = 12;
constexpr size_t kFlagsOffset = 14;
constexpr size_t kMajorOffset = 16;
constexpr size_t kMinorOffset = 17;
constexpr size_t kPatchOffset = 18;
constexpr size_t kBuildOffset = 20;
constexpr size_t kPayloadSizeOffset = 24;
constexpr size_t kMemorySizeOffset = 28;
constexpr size_t kLoadAddressOffset = 32;
constexpr size_t kEntryOffset = 36;
constexpr size_t kPayloadDigestOffset = 40;
constexpr size_t kKeyIdOffset = 72;
constexpr size_t kReservedOffset = 104;
constexpr size_t kSignatureOffset = ImageHeader::kSignedSize;
static_assert(kKeyIdOffset + ImageHeader::kDigestSize == kReservedOffset, "the reserved bytes follow the key id");

uint16_t read16(const uint8_t* at) { return static_cast<uint16_t>(at[0] | (at[1] << 8)); }

uint32_t read32(const uint8_t* at)
{
    return static_cast<uint32_t>(at[0]) | (static_cast<uint32_t>(at[1]) << 8) |
           (static_cast<uint32_t>(at[2]) << 16) | (static_cast<uint32_t>(at[3]) << 24);
}

void write16(uint8_t* at, uint16_t value)
{
    at[0] = static_cast<uint8_t>(value);
    at[1] = static_cast<uint8_t>(value >> 8);
}

void write32(uint8_t* at, uint32_t value)
{
    for (int i = 0; i < 4; ++i) {
        at[i] = static_cast<uint8_t>(value >> (8 * i));
    }
}

void copy(uint8_t* to, const uint8_t* from, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        to[i] = from[i];
    }
}

} // namespace

const char* boardName(BoardType board)
{
    switch (board) {
    case BoardType::Isa486: return "isa486";
    }
    return nullptr;
}

bool boardFromName(const char* name, BoardType& out)
{
    static constexpr BoardType kBoards[] = {BoardType::Isa486};
    for (const BoardType board : kBoards) {
        const char* known = boardName(board);
        size_t i = 0;
        while (name != nullptr && known[i] != '\0' && name[i] == known[i]) {
            ++i;
        }
        if (name != nullptr && known[i] == '\0' && name[i] == '\0') {
            out = board;
            return true;
        }
    }
    return false;
}

void ImageHeader::encode(uint8_t (&out)[kSize]) const
{
    for (size_t i = 0; i < kSize; ++i) {
        out[i] = 0;
    }
    copy(out, reinterpret_cast<const uint8_t*>(kMagic), sizeof kMagic);
    write16(out + kFormatOffset, kFormat);
    write16(out + kHeaderSizeOffset, static_cast<uint16_t>(kSize));
    write16(out + kBoardOffset, static_cast<uint16_t>(board));
    write16(out + kFlagsOffset, 0);
    out[kMajorOffset] = version.major;
    out[kMinorOffset] = version.minor;
    write16(out + kPatchOffset, version.patch);
    write32(out + kBuildOffset, version.build);
    write32(out + kPayloadSizeOffset, payloadSize);
    write32(out + kMemorySizeOffset, memorySize);
    write32(out + kLoadAddressOffset, loadAddress);
    write32(out + kEntryOffset, entry);
    copy(out + kPayloadDigestOffset, payloadDigest, kDigestSize);
    copy(out + kKeyIdOffset, keyId, kDigestSize);
    copy(out + kSignatureOffset, signature, kSignatureSize);
}

ImageResult<ImageHeader> ImageHeader::decode(const uint8_t* data, size_t length)
{
    if (data == nullptr || length < kSize) {
        return ImageError::Truncated;
    }
    for (size_t i = 0; i < sizeof kMagic; ++i) {
        if (data[i] != static_cast<uint8_t>(kMagic[i])) {
            return ImageError::BadMagic;
        }
    }
    if (read16(data + kFormatOffset) != kFormat || read16(data + kHeaderSizeOffset) != kSize) {
        return ImageError::UnsupportedFormat;
    }
    if (read16(data + kFlagsOffset) != 0) {
        return ImageError::MalformedHeader;
    }
    for (size_t i = kReservedOffset; i < kSignatureOffset; ++i) {
        if (data[i] != 0) {
            return ImageError::MalformedHeader;
        }
    }
    ImageHeader header;
    header.board = static_cast<BoardType>(read16(data + kBoardOffset));
    if (boardName(header.board) == nullptr) {
        return ImageError::UnknownBoard;
    }
    header.version.major = data[kMajorOffset];
    header.version.minor = data[kMinorOffset];
    header.version.patch = read16(data + kPatchOffset);
    header.version.build = read32(data + kBuildOffset);
    header.payloadSize = read32(data + kPayloadSizeOffset);
    header.memorySize = read32(data + kMemorySizeOffset);
    header.loadAddress = read32(data + kLoadAddressOffset);
    header.entry = read32(data + kEntryOffset);
    if (header.payloadSize == 0) {
        return ImageError::MalformedHeader;
    }
    // In 64 bits, so that no sum wraps: memory must end at or below 4 GiB.
    const uint64_t memoryEnd = uint64_t{header.loadAddress} + header.memorySize;
    if (header.memorySize < header.payloadSize || memoryEnd > (uint64_t{1} << 32) ||
        header.entry < header.loadAddress || header.entry - header.loadAddress >= header.payloadSize) {
        return ImageError::BadAddresses;
    }
    copy(header.payloadDigest, data + kPayloadDigestOffset, kDigestSize);
    copy(header.keyId, data + kKeyIdOffset, kDigestSize);
    copy(header.signature, data + kSignatureOffset, kSignatureSize);
    return header;
}

const char* imageErrorText(ImageError error)
{
    switch (error) {
    case ImageError::Ok: return "a valid image";
    case ImageError::Truncated: return "truncated: shorter than its header says";
    case ImageError::TrailingData: return "longer than its header says (bytes after the payload)";
    case ImageError::BadMagic: return "not a DCOS controller image (no DCOS-IMG magic)";
    case ImageError::UnsupportedFormat: return "an image header format this version does not know";
    case ImageError::MalformedHeader: return "malformed header (reserved fields or flags set, or an empty payload)";
    case ImageError::UnknownBoard: return "built for a board type DCOS does not have";
    case ImageError::WrongBoard: return "built for another board";
    case ImageError::Oversized: return "larger than the slot that is to hold it";
    case ImageError::BadAddresses: return "entry outside the payload, or memory outside the board's RAM";
    case ImageError::UnknownKey: return "signed by a key this controller does not trust";
    case ImageError::BadSignature: return "the signature does not verify (altered, or not signed)";
    case ImageError::PayloadMismatch: return "the payload is not the one its signed header describes";
    case ImageError::Downgrade: return "older than the installed image (a downgrade must be allowed explicitly)";
    }
    return "unknown image error";
}

} // namespace image
