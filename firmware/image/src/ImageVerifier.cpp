#include <image/ImageVerifier.hpp>
#include <image/Sha256.hpp>

namespace image {

namespace {

bool sameDigest(const uint8_t (&a)[ImageHeader::kDigestSize], const uint8_t (&b)[ImageHeader::kDigestSize])
{
    // Not secret: both digests are public, so an early exit leaks nothing.
    for (size_t i = 0; i < ImageHeader::kDigestSize; ++i) {
        if (a[i] != b[i]) {
            return false;
        }
    }
    return true;
}

} // namespace

const TrustedKey* TrustedKey::find(const uint8_t (&id)[ImageHeader::kDigestSize], const TrustedKey* keys,
                                   size_t count)
{
    for (size_t i = 0; keys != nullptr && i < count; ++i) {
        if (sameDigest(keys[i].id, id)) {
            return &keys[i];
        }
    }
    return nullptr;
}

TrustedKey TrustedKey::fromPoint(const uint8_t (&point)[EcdsaP256::kPublicKeySize])
{
    TrustedKey key;
    for (size_t i = 0; i < sizeof point; ++i) {
        key.point[i] = point[i];
    }
    Sha256::digest(key.point, sizeof key.point, key.id);
    return key;
}

ImagePolicy ImagePolicy::forBoard(BoardType board)
{
    ImagePolicy policy;
    policy.board = board;
    // A slot is 2 MiB of card; the card keeps the 256-byte header in a
    // sector of its own (docs/boot.md, "The card"), which costs 256 bytes.
    policy.slotCapacity = (2u << 20) - 256;
    policy.memoryStart = 1u << 20;
    policy.memoryEnd = 16u << 20;
    return policy;
}

ImageResult<ImageHeader> ImageVerifier::checkHeader(const uint8_t* bytes, size_t headerLength, uint64_t imageLength,
                                                    const TrustedKey* keys, size_t keyCount,
                                                    const ImagePolicy& policy)
{
    const ImageResult<ImageHeader> decoded = ImageHeader::decode(bytes, headerLength);
    if (!decoded.ok()) {
        return decoded;
    }
    const ImageHeader& header = decoded.value();
    if (header.board != policy.board) {
        return ImageError::WrongBoard;
    }
    const uint64_t declared = uint64_t{ImageHeader::kSize} + header.payloadSize;
    if (declared > policy.slotCapacity) {
        return ImageError::Oversized;
    }
    if (imageLength < declared) {
        return ImageError::Truncated;
    }
    if (imageLength > declared) {
        return ImageError::TrailingData;
    }
    if (header.loadAddress < policy.memoryStart ||
        uint64_t{header.loadAddress} + header.memorySize > policy.memoryEnd) {
        return ImageError::BadAddresses;
    }
    const TrustedKey* key = TrustedKey::find(header.keyId, keys, keyCount);
    if (key == nullptr) {
        return ImageError::UnknownKey;
    }
    uint8_t signedDigest[ImageHeader::kDigestSize];
    Sha256::digest(bytes, ImageHeader::kSignedSize, signedDigest);
    if (!EcdsaP256::verify(key->point, signedDigest, header.signature)) {
        return ImageError::BadSignature;
    }
    if (policy.installed != nullptr && !policy.allowDowngrade && header.version.compare(*policy.installed) < 0) {
        return ImageError::Downgrade;
    }
    return header;
}

ImageError ImageVerifier::checkPayload(const ImageHeader& header, const uint8_t* payload, size_t length)
{
    if (length != header.payloadSize) {
        return length < header.payloadSize ? ImageError::Truncated : ImageError::TrailingData;
    }
    uint8_t digest[ImageHeader::kDigestSize];
    Sha256::digest(payload, length, digest);
    return checkPayloadDigest(header, digest);
}

ImageError ImageVerifier::checkPayloadDigest(const ImageHeader& header, const uint8_t (&digest)[ImageHeader::kDigestSize])
{
    return sameDigest(digest, header.payloadDigest) ? ImageError::Ok : ImageError::PayloadMismatch;
}

ImageResult<ImageHeader> ImageVerifier::verify(const uint8_t* image, size_t length, const TrustedKey* keys,
                                               size_t keyCount, const ImagePolicy& policy)
{
    const ImageResult<ImageHeader> header = checkHeader(image, length, length, keys, keyCount, policy);
    if (!header.ok()) {
        return header;
    }
    const ImageError payload =
        checkPayload(header.value(), image + ImageHeader::kSize, length - ImageHeader::kSize);
    if (payload != ImageError::Ok) {
        return payload;
    }
    return header;
}

} // namespace image
