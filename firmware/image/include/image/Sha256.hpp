// SHA-256 (FIPS 180-4), incremental, from mbedTLS: never home-made.
#pragma once

#include <mbedtls/sha256.h>

#include <stddef.h>
#include <stdint.h>

namespace image {

class Sha256 {
public:
    static constexpr size_t kDigestSize = 32;

    Sha256();
    ~Sha256();
    Sha256(const Sha256&) = delete;
    Sha256& operator=(const Sha256&) = delete;

    void update(const uint8_t* data, size_t length);
    /// Writes the digest of everything given so far; the object is then
    /// spent (start a new one for another message).
    void finish(uint8_t (&digest)[kDigestSize]);

    /// The digest of one buffer.
    static void digest(const uint8_t* data, size_t length, uint8_t (&out)[kDigestSize]);

private:
    mbedtls_sha256_context context_;
};

} // namespace image
