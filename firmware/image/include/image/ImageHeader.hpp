// The header of a DCOS controller image (docs/boot.md, "Controller
// images"): 256 bytes in front of the payload, little-endian, laid out as
//
//   offset size  field
//        0    8  magic "DCOS-IMG"
//        8    2  format, 1
//       10    2  header size, 256
//       12    2  board type (BoardType)
//       14    2  flags, 0 (none defined yet; a verifier refuses others)
//       16    1  version major      17  1  minor      18  2  patch
//       20    4  version build number
//       24    4  payload size in bytes
//       28    4  memory size: the payload and the zeroed memory after it
//       32    4  load address of the payload's first byte
//       36    4  entry address, within the payload
//       40   32  SHA-256 of the payload
//       72   32  key id: SHA-256 of the signing key's public point (65 bytes, uncompressed)
//      104   88  reserved, 0
//      192   64  ECDSA P-256 signature (r then s, 32 bytes each, big-endian)
//                over the SHA-256 of bytes 0 to 191
//
// The signature covers every other field and, through the payload's hash,
// the payload. Decoding checks only the structure; ImageVerifier checks the
// rest. Pure code: no I/O, no cryptography, the same on the host and in the
// stage loader.
#pragma once

#include <image/ImageError.hpp>
#include <image/ImageVersion.hpp>

#include <stddef.h>
#include <stdint.h>

namespace image {

/// The boards DCOS runs on (docs/boot.md); 0 is never a board. 2 is kept
/// for the dual-Pentium board (seed 9.2), which is not built yet.
enum class BoardType : uint16_t {
    Isa486 = 1, ///< The ISA i486 single-board controller (seed 9.2).
};

/// "isa486"; null for a number that is no board.
const char* boardName(BoardType board);
/// The board of that name; false for any other text.
bool boardFromName(const char* name, BoardType& out);

struct ImageHeader {
    static constexpr size_t kSize = 256;
    static constexpr uint16_t kFormat = 1;
    /// The signature covers bytes [0, kSignedSize) and sits right after them.
    static constexpr size_t kSignedSize = 192;
    static constexpr size_t kSignatureSize = 64;
    static constexpr size_t kDigestSize = 32;
    static constexpr char kMagic[8] = {'D', 'C', 'O', 'S', '-', 'I', 'M', 'G'};

    BoardType board = BoardType::Isa486;
    ImageVersion version;
    uint32_t payloadSize = 0;
    uint32_t memorySize = 0;
    uint32_t loadAddress = 0;
    uint32_t entry = 0;
    uint8_t payloadDigest[kDigestSize] = {};
    uint8_t keyId[kDigestSize] = {};
    uint8_t signature[kSignatureSize] = {};

    /// Writes all 256 bytes, the signature as it stands.
    void encode(uint8_t (&out)[kSize]) const;

    /// Reads a header from the first bytes of @p data and checks its
    /// structure: magic, format, reserved fields, a known board, a payload
    /// of at least one byte, memory at least the payload, the entry within
    /// the payload and no address range that wraps past 4 GiB.
    static ImageResult<ImageHeader> decode(const uint8_t* data, size_t length);
};

static_assert(ImageHeader::kSignedSize + ImageHeader::kSignatureSize == ImageHeader::kSize,
              "the signature ends the header");

} // namespace image
