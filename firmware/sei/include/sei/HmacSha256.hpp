// HMAC-SHA-256 (RFC 2104, FIPS 198-1) on mbedTLS's SHA-256 (image::Sha256),
// for the configuration protocol's MACs (SeiAuthenticator).
//
// Not mbedTLS's own HMAC (mbedtls_md_hmac_*): its context comes from
// mbedtls_md_setup, which takes the SHA-256 state and the padded keys from
// mbedtls_calloc. In the firmware that is the image verifier's static
// arena (EcdsaP256.cpp), private to it, set up only by the first image
// check and refused to a second user while one runs: a MAC check there
// could fail for lack of memory and count as a wrong MAC. This class keeps
// both in itself instead, with no heap, on the host and in the node alike;
// the host tests check it against mbedtls_md_hmac and RFC 4231's vectors.
#pragma once

#include <image/Sha256.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

class HmacSha256 {
public:
    /// SHA-256's block: a longer key is hashed first (RFC 2104, section 2).
    static constexpr size_t kBlockSize = 64;
    static constexpr size_t kDigestSize = image::Sha256::kDigestSize;

    /// Begins a MAC under the @p keyLength bytes at @p key.
    HmacSha256(const uint8_t* key, size_t keyLength);
    /// Wipes the padded key, which is as secret as the key.
    ~HmacSha256();
    HmacSha256(const HmacSha256&) = delete;
    HmacSha256& operator=(const HmacSha256&) = delete;

    void update(const uint8_t* data, size_t length);
    /// Writes the MAC of everything given so far; the object is then spent.
    void finish(uint8_t (&mac)[kDigestSize]);

private:
    uint8_t outerKey_[kBlockSize];
    image::Sha256 inner_;
};

} // namespace sei
