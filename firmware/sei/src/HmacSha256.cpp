#include <sei/HmacSha256.hpp>

namespace sei {

namespace {

// RFC 2104's pads, each XORed into every byte of the key block.
constexpr uint8_t kInnerPad = 0x36;
constexpr uint8_t kOuterPad = 0x5C;

// Zeroes key material so that it does not stay behind on the stack; the
// volatile store keeps the compiler from dropping the writes to memory
// that is never read again.
void wipe(uint8_t* bytes, size_t length)
{
    volatile uint8_t* out = bytes;
    for (size_t i = 0; i < length; ++i) {
        out[i] = 0;
    }
}

} // namespace

HmacSha256::HmacSha256(const uint8_t* key, size_t keyLength)
{
    uint8_t block[kBlockSize] = {};
    if (keyLength > kBlockSize) {
        uint8_t digest[kDigestSize];
        image::Sha256::digest(key, keyLength, digest);
        for (size_t i = 0; i < kDigestSize; ++i) {
            block[i] = digest[i];
        }
        wipe(digest, sizeof digest);
    } else {
        for (size_t i = 0; i < keyLength; ++i) {
            block[i] = key[i];
        }
    }
    uint8_t innerKey[kBlockSize];
    for (size_t i = 0; i < kBlockSize; ++i) {
        innerKey[i] = static_cast<uint8_t>(block[i] ^ kInnerPad);
        outerKey_[i] = static_cast<uint8_t>(block[i] ^ kOuterPad);
    }
    inner_.update(innerKey, sizeof innerKey);
    wipe(innerKey, sizeof innerKey);
    wipe(block, sizeof block);
}

HmacSha256::~HmacSha256() { wipe(outerKey_, sizeof outerKey_); }

void HmacSha256::update(const uint8_t* data, size_t length) { inner_.update(data, length); }

void HmacSha256::finish(uint8_t (&mac)[kDigestSize])
{
    uint8_t innerDigest[kDigestSize];
    inner_.finish(innerDigest);
    image::Sha256 outer;
    outer.update(outerKey_, sizeof outerKey_);
    outer.update(innerDigest, sizeof innerDigest);
    outer.finish(mac);
}

} // namespace sei
