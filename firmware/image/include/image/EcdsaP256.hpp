// ECDSA over NIST P-256 with SHA-256 (FIPS 186-4), verification only, from
// mbedTLS: never home-made. Signing is the host's (host_tools/image).
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace image {

class EcdsaP256 {
public:
    /// A public point in SEC 1's uncompressed form: 0x04, X, Y.
    static constexpr size_t kPublicKeySize = 65;
    /// r then s, 32 bytes each, big-endian (IEEE P1363).
    static constexpr size_t kSignatureSize = 64;
    static constexpr size_t kDigestSize = 32;

    /// True when @p signature is a valid signature of @p digest under
    /// @p publicKey. False for a point not on the curve, r or s outside
    /// [1, n - 1], or any other failure: a verifier that cannot decide
    /// refuses. On the controller a second verification while one runs
    /// (in another task) is refused too: mbedTLS computes in one static
    /// arena there.
    static bool verify(const uint8_t (&publicKey)[kPublicKeySize], const uint8_t (&digest)[kDigestSize],
                       const uint8_t (&signature)[kSignatureSize]);

    /// True when @p publicKey is a point on the curve (not the point at infinity).
    static bool validPublicKey(const uint8_t (&publicKey)[kPublicKeySize]);
};

} // namespace image
