// The controller's own ECDSA against Project Wycheproof's 219 P-256
// SHA-256 cases (firmware/image/unit_tests/wycheproof): mbedTLS as it is
// built for the i486 (mk/mbedtls.mk, a configuration of its own: NIST
// reduction, a window of 2, no internal random generator), not the host's
// Debian library. Every valid signature accepted, every invalid one
// refused; a signature that is not 64 bytes never reaches the verifier.
#include "TargetTest.hpp"

#include <image/EcdsaP256.hpp>
#include <image/Sha256.hpp>

#include <stddef.h>
#include <stdint.h>

namespace {

struct WycheproofCase {
    uint16_t id;
    uint8_t result; // 0 valid, 1 invalid, 2 acceptable
    uint8_t key;
    uint8_t messageLength;
    uint8_t message[32];
    uint8_t signatureLength;
    uint8_t signature[66];
};

#include "WycheproofVectors.inc"

bool wycheproof(shell::Shell& shell)
{
    unsigned accepted = 0;
    unsigned refused = 0;
    unsigned acceptable = 0;
    unsigned wrong = 0;
    for (const WycheproofCase& vector : kWycheproof) {
        bool verified = false;
        if (vector.signatureLength == image::EcdsaP256::kSignatureSize) {
            uint8_t digest[image::EcdsaP256::kDigestSize];
            image::Sha256::digest(vector.message, vector.messageLength, digest);
            uint8_t signature[image::EcdsaP256::kSignatureSize];
            for (size_t i = 0; i < sizeof signature; ++i) {
                signature[i] = vector.signature[i];
            }
            verified = image::EcdsaP256::verify(kWycheproofKey[vector.key], digest, signature);
        }
        if (vector.result == 2) {
            ++acceptable;
        } else if ((vector.result == 0) == verified) {
            vector.result == 0 ? ++accepted : ++refused;
        } else {
            if (wrong++ < 5) {
                shell.print("tcId %u: %s but %s\r\n", static_cast<unsigned>(vector.id),
                            vector.result == 0 ? "valid" : "invalid", verified ? "accepted" : "refused");
            }
        }
    }
    shell.print("%u vectors: %u valid accepted, %u invalid refused, %u acceptable, %u wrong\r\n",
                static_cast<unsigned>(kWycheproofCases), accepted, refused, acceptable, wrong);
    return wrong == 0 && accepted == 146 && refused == 69;
}

} // namespace

DCOS_TARGET_TEST(wycheproofTest, "wycheproof",
                 "the i486 build of mbedTLS takes every valid Wycheproof P-256 signature and no invalid one",
                 wycheproof);
