// Fuzz target: the controller image verifier (docs/boot.md, "Controller
// images"), which takes every image a controller is sent.
//
// The input is an image. It is checked as a controller checks it, against
// the public key of the seed signed_tiny (its private key was thrown away
// once the seed was signed). Checks: a decoded header re-encodes to the
// input's first 256 bytes (the format has one encoding); an accepted image
// is exactly a header and the payload it describes, for the board and
// memory of the policy, signed by the key; a header checked alone agrees
// with the whole image's verdict up to the payload; the input read as a
// version text parses only to a version that formats back to it; the
// input's first sector read as the card's boot state or configuration
// (dcos-card show reads both from a card file) decodes only to a record
// that encodes back to the same sector.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <boot/BootState.hpp>
#include <boot/ConfigurationBlock.hpp>
#include <image/ImageHeader.hpp>
#include <image/ImageVerifier.hpp>
#include <image/ImageVersion.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace {

constexpr uint8_t kSeedKey[image::EcdsaP256::kPublicKeySize] = {
    0x04, 0xb1, 0x5c, 0xea, 0xff, 0xe7, 0x0d, 0xe4, 0xeb, 0xec, 0x0e, 0x9d, 0x77, 0xde, 0x8e, 0xb3, 0x23,
    0xe6, 0xae, 0x57, 0x65, 0x3a, 0x0b, 0xc0, 0x6e, 0x9e, 0x82, 0x80, 0xce, 0x58, 0x56, 0x66, 0x64, 0xca,
    0x9a, 0xff, 0xbc, 0xca, 0x81, 0x5a, 0xab, 0x6d, 0x3d, 0x02, 0xad, 0x8d, 0x13, 0xf4, 0xcf, 0x5e, 0x5b,
    0x34, 0xf6, 0x87, 0xba, 0xa4, 0x4a, 0xdc, 0xbd, 0xe2, 0x68, 0x47, 0xaa, 0x78, 0x84};

void checkVersionText(const uint8_t* data, size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size < 40 ? size : 40);
    image::ImageVersion version;
    if (!image::ImageVersion::parse(text.c_str(), version)) {
        return;
    }
    char formatted[32];
    version.format(formatted, sizeof formatted);
    image::ImageVersion again;
    FUZZ_CHECK(image::ImageVersion::parse(formatted, again));
    FUZZ_CHECK(again.compare(version) == 0);
}

} // namespace

template <typename Record>
void checkRecord(const uint8_t* data, size_t size)
{
    if (size < boot::card::kSectorSize) {
        return;
    }
    uint8_t sector[boot::card::kSectorSize];
    std::memcpy(sector, data, sizeof sector);
    Record record;
    if (!Record::decode(sector, record)) {
        return;
    }
    uint8_t again[boot::card::kSectorSize];
    record.encode(again);
    Record twice;
    FUZZ_CHECK(Record::decode(again, twice));
    uint8_t thrice[boot::card::kSectorSize];
    twice.encode(thrice);
    FUZZ_CHECK(std::memcmp(again, thrice, sizeof again) == 0);
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    checkVersionText(data, size);
    checkRecord<boot::BootState>(data, size);
    checkRecord<boot::ConfigurationBlock>(data, size);

    const image::ImageResult<image::ImageHeader> decoded = image::ImageHeader::decode(data, size);
    if (decoded.ok()) {
        uint8_t again[image::ImageHeader::kSize];
        decoded.value().encode(again);
        FUZZ_CHECK(std::memcmp(again, data, sizeof again) == 0);
    }

    static const image::TrustedKey key = image::TrustedKey::fromPoint(kSeedKey);
    const image::ImageVersion installed{1, 0, 0, 0};
    image::ImagePolicy policy = image::ImagePolicy::forBoard(image::BoardType::Isa486);
    policy.installed = &installed;
    const image::ImageResult<image::ImageHeader> verdict = image::ImageVerifier::verify(data, size, &key, 1, policy);
    const image::ImageResult<image::ImageHeader> header =
        image::ImageVerifier::checkHeader(data, size, size, &key, 1, policy);
    FUZZ_CHECK(header.ok() || header.error() == verdict.error());
    if (verdict.ok()) {
        const image::ImageHeader& accepted = verdict.value();
        FUZZ_CHECK(decoded.ok() && header.ok());
        FUZZ_CHECK(size == image::ImageHeader::kSize + accepted.payloadSize);
        FUZZ_CHECK(accepted.board == policy.board);
        FUZZ_CHECK(accepted.loadAddress >= policy.memoryStart);
        FUZZ_CHECK(uint64_t{accepted.loadAddress} + accepted.memorySize <= policy.memoryEnd);
        FUZZ_CHECK(accepted.entry >= accepted.loadAddress && accepted.entry - accepted.loadAddress < accepted.payloadSize);
        FUZZ_CHECK(std::memcmp(accepted.keyId, key.id, sizeof key.id) == 0);
        FUZZ_CHECK(accepted.version.compare(installed) >= 0);
        FUZZ_CHECK(image::ImageVerifier::checkPayload(accepted, data + image::ImageHeader::kSize,
                                                      size - image::ImageHeader::kSize) == image::ImageError::Ok);
    }
    return 0;
}
