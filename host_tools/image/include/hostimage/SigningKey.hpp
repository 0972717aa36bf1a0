// An ECDSA P-256 key pair that signs controller images, kept by the user
// as a PEM file (docs/guide/signing-images.md). mbedTLS does every
// operation: generation from the system's entropy, PEM in and out, and
// deterministic signatures (RFC 6979), so no signature depends on a
// random number generator's quality.
#pragma once

#include <image/EcdsaP256.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace hostimage {

class SigningKey {
public:
    using PublicPoint = std::array<uint8_t, image::EcdsaP256::kPublicKeySize>;

    /// A new key from the system's entropy (getrandom).
    static std::optional<SigningKey> generate(std::string& error);
    /// A private key from PEM text (SEC 1 "EC PRIVATE KEY" or PKCS #8),
    /// which must be on P-256.
    static std::optional<SigningKey> fromPem(const std::string& pem, std::string& error);

    /// The private key as PEM (SEC 1), for a file only its owner reads.
    std::string privatePem() const;
    /// The public key as PEM (SubjectPublicKeyInfo), for the controllers.
    std::string publicPem() const;
    const PublicPoint& publicPoint() const { return point_; }

    /// Signs a SHA-256 digest: r then s, big-endian.
    bool sign(const uint8_t (&digest)[32], uint8_t (&signature)[image::EcdsaP256::kSignatureSize],
              std::string& error) const;

    /// The public point of a PEM public key (or of a private key's PEM),
    /// which must be on P-256.
    static std::optional<PublicPoint> publicPointFromPem(const std::string& pem, std::string& error);

private:
    struct Context;
    explicit SigningKey(std::shared_ptr<Context> context);

    std::shared_ptr<Context> context_;
    PublicPoint point_{};
};

} // namespace hostimage
