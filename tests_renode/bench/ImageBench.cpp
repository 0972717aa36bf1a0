// The cost of checking a controller image (docs/boot.md), on the firmware's
// own mbedTLS build (bench image only): what the stage loader spends before
// a node starts, and a flash session before it marks a slot pending.
//
//   Image.Sha256KiB        SHA-256 of one KiB of payload: an image's digest
//                          costs this once per KiB (the full 486 image is
//                          some 420 KiB)
//   Image.VerifySignature  one ECDSA P-256 verification: the header's
//                          signature, once per image
//
// Both run on fixed data, so every call counts the same; neither depends on
// the number of kernel objects (the 8 and 4096 figures must agree).
#include "BenchSupport.hpp"

#include <image/EcdsaP256.hpp>
#include <image/Sha256.hpp>

namespace bench {
namespace {

using dcos::Status;

// The header of the image fuzz target's seed (firmware/image/fuzz/corpus/
// image/signed_tiny), its signature and its key: a real signature.
constexpr uint8_t kSignedTiny[] = {
#include "../target/ImageVerifierTest.inc"
};
constexpr uint8_t kSeedKey[image::EcdsaP256::kPublicKeySize] = {
    0x04, 0xb1, 0x5c, 0xea, 0xff, 0xe7, 0x0d, 0xe4, 0xeb, 0xec, 0x0e, 0x9d, 0x77, 0xde, 0x8e, 0xb3, 0x23,
    0xe6, 0xae, 0x57, 0x65, 0x3a, 0x0b, 0xc0, 0x6e, 0x9e, 0x82, 0x80, 0xce, 0x58, 0x56, 0x66, 0x64, 0xca,
    0x9a, 0xff, 0xbc, 0xca, 0x81, 0x5a, 0xab, 0x6d, 0x3d, 0x02, 0xad, 0x8d, 0x13, 0xf4, 0xcf, 0x5e, 0x5b,
    0x34, 0xf6, 0x87, 0xba, 0xa4, 0x4a, 0xdc, 0xbd, 0xe2, 0x68, 0x47, 0xaa, 0x78, 0x84};

uint8_t block[1024];
uint8_t digest[image::EcdsaP256::kDigestSize];
uint8_t signature[image::EcdsaP256::kSignatureSize];

Status noSetup(uint32_t) { return Status::Ok; }

Status prepareSignature(uint32_t)
{
    image::Sha256::digest(kSignedTiny, 192, digest);
    for (size_t i = 0; i < sizeof signature; ++i) {
        signature[i] = kSignedTiny[192 + i];
    }
    return image::EcdsaP256::verify(kSeedKey, digest, signature) ? Status::Ok : Status::InvalidArgument;
}

void hashBlock()
{
    uint8_t out[image::Sha256::kDigestSize];
    image::Sha256::digest(block, sizeof block, out);
    asm volatile("" : : "r"(out) : "memory");
}

void verifySignature()
{
    if (!image::EcdsaP256::verify(kSeedKey, digest, signature)) {
        check(Status::InvalidArgument);
    }
}

} // namespace
} // namespace bench

DCOS_BENCHMARK(imageSha256Bench, "Image.Sha256KiB", bench::noSetup, bench::hashBlock, bench::Cost::Constant);
DCOS_BENCHMARK(imageVerifyBench, "Image.VerifySignature", bench::prepareSignature, bench::verifySignature,
               bench::Cost::Constant);
