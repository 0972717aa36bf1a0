// Controller images checked on the controller: the verifier of
// firmware/image with mbedTLS built for the i486 (mk/mbedtls.mk), on a real
// signed image (the fuzz seed firmware/image/fuzz/corpus/image/signed_tiny,
// whose private key was thrown away), as the stage loader will check the
// card's slots (docs/boot.md).
#include "TargetTest.hpp"

#include <image/ImageVerifier.hpp>

namespace {

// signed_tiny: a 256-byte header and a 16-byte payload (bytes 0 to 15),
// isa486 1.0.0+1, loaded at 1 MiB with 64 bytes of memory, entry at +4.
constexpr uint8_t kSignedTiny[] = {
#include "ImageVerifierTest.inc"
};

constexpr uint8_t kSeedKey[image::EcdsaP256::kPublicKeySize] = {
    0x04, 0xb1, 0x5c, 0xea, 0xff, 0xe7, 0x0d, 0xe4, 0xeb, 0xec, 0x0e, 0x9d, 0x77, 0xde, 0x8e, 0xb3, 0x23,
    0xe6, 0xae, 0x57, 0x65, 0x3a, 0x0b, 0xc0, 0x6e, 0x9e, 0x82, 0x80, 0xce, 0x58, 0x56, 0x66, 0x64, 0xca,
    0x9a, 0xff, 0xbc, 0xca, 0x81, 0x5a, 0xab, 0x6d, 0x3d, 0x02, 0xad, 0x8d, 0x13, 0xf4, 0xcf, 0x5e, 0x5b,
    0x34, 0xf6, 0x87, 0xba, 0xa4, 0x4a, 0xdc, 0xbd, 0xe2, 0x68, 0x47, 0xaa, 0x78, 0x84};

image::ImageError verdictOf(const uint8_t* bytes, size_t size)
{
    static const image::TrustedKey key = image::TrustedKey::fromPoint(kSeedKey);
    return image::ImageVerifier::verify(bytes, size, &key, 1, image::ImagePolicy::forBoard(image::BoardType::Isa486))
        .error();
}

bool check(shell::Shell& shell, const char* what, image::ImageError got, image::ImageError expected)
{
    shell.print("%s: %s\r\n", what, image::imageErrorText(got));
    return got == expected;
}

bool verifiesRealSignatures(shell::Shell& shell)
{
    static_assert(sizeof kSignedTiny == image::ImageHeader::kSize + 16, "the seed's header and payload");
    uint8_t copy[sizeof kSignedTiny];
    bool passed = check(shell, "the signed image", verdictOf(kSignedTiny, sizeof kSignedTiny), image::ImageError::Ok);
    for (size_t i = 0; i < sizeof copy; ++i) {
        copy[i] = kSignedTiny[i];
    }
    copy[20] ^= 1; // The build number: the signature no longer verifies.
    passed = check(shell, "one header bit changed", verdictOf(copy, sizeof copy), image::ImageError::BadSignature) &&
             passed;
    copy[20] ^= 1;
    copy[260] ^= 0x80; // A payload byte.
    passed = check(shell, "one payload bit changed", verdictOf(copy, sizeof copy), image::ImageError::PayloadMismatch) &&
             passed;
    copy[260] ^= 0x80;
    copy[200] ^= 1; // r.
    passed = check(shell, "one signature bit changed", verdictOf(copy, sizeof copy), image::ImageError::BadSignature) &&
             passed;
    return passed;
}

} // namespace

DCOS_TARGET_TEST(imageVerifierTest, "image",
                 "a signed controller image verifies with mbedTLS on the i486; one bit changed anywhere does not",
                 verifiesRealSignatures);
