// Decides whether a controller image may be installed or booted
// (docs/boot.md, "Controller images"): the one place where an image is
// trusted, used by the host tools and, with the same code, by the stage
// loader.
//
// The checks run in a fixed order, cheapest and least trusting first, and
// the first that fails names the reason: the header's structure, the
// board, the size against the slot and against the bytes present, the
// addresses against the board's memory, the key, the signature, the
// version against the installed one, and last the payload against the
// signed digest. A header can be checked alone, before the payload has
// arrived, so that a transfer of the wrong image stops at its first block.
#pragma once

#include <image/EcdsaP256.hpp>
#include <image/ImageError.hpp>
#include <image/ImageHeader.hpp>

#include <stddef.h>
#include <stdint.h>

namespace image {

/// A public key the controller trusts, with its id (the SHA-256 of the point).
struct TrustedKey {
    uint8_t point[EcdsaP256::kPublicKeySize] = {};
    uint8_t id[ImageHeader::kDigestSize] = {};

    /// The key of that point, its id computed.
    static TrustedKey fromPoint(const uint8_t (&point)[EcdsaP256::kPublicKeySize]);
    /// The key among @p count @p keys whose id is @p id; null when none is.
    static const TrustedKey* find(const uint8_t (&id)[ImageHeader::kDigestSize], const TrustedKey* keys, size_t count);
};

/// What the checking side allows.
struct ImagePolicy {
    BoardType board = BoardType::Isa486;
    /// Bytes the slot holds, header included.
    uint32_t slotCapacity = 0;
    /// The image's memory, [load address, load address + memory size), must lie in [memoryStart, memoryEnd).
    uint32_t memoryStart = 0;
    uint32_t memoryEnd = 0;
    /// The installed image's version; null when none is installed.
    const ImageVersion* installed = nullptr;
    /// Take an image older than the installed one.
    bool allowDowngrade = false;

    /// The board's slot and memory (docs/boot.md): an application slot of
    /// 2 MiB of card, which holds an image of 2 MiB less 256 bytes (the
    /// card pads the header to a sector); on the 486 board the image lives between 1 MiB, where
    /// conventional memory and the BIOS end, and 16 MiB, what the ISA bus
    /// addresses. Nothing installed, no downgrade.
    static ImagePolicy forBoard(BoardType board);
};

class ImageVerifier {
public:
    /// Checks the header in @p header (at least ImageHeader::kSize bytes)
    /// of an image of @p imageLength bytes in all, against @p keys and
    /// @p policy: everything but the payload's digest.
    static ImageResult<ImageHeader> checkHeader(const uint8_t* header, size_t headerLength, uint64_t imageLength,
                                                const TrustedKey* keys, size_t keyCount, const ImagePolicy& policy);

    /// Checks @p length bytes of payload against the digest of a header
    /// checkHeader() accepted.
    static ImageError checkPayload(const ImageHeader& header, const uint8_t* payload, size_t length);

    /// Checks the SHA-256 of a payload the caller hashed itself (a payload
    /// read back from a card piece by piece) against the header's.
    static ImageError checkPayloadDigest(const ImageHeader& header, const uint8_t (&digest)[ImageHeader::kDigestSize]);

    /// Both checks on a whole image in memory.
    static ImageResult<ImageHeader> verify(const uint8_t* image, size_t length, const TrustedKey* keys,
                                           size_t keyCount, const ImagePolicy& policy);
};

} // namespace image
