// Signed images end to end on the host: made by ImageSigner with a key
// from SigningKey, checked by the controllers' ImageVerifier, and every
// kind of bad image refused with its own reason.
#include <hostimage/ImageSigner.hpp>
#include <hostimage/SigningKey.hpp>

#include <image/ImageVerifier.hpp>

#include <mbedtls/ctr_drbg.h>
#include <mbedtls/entropy.h>
#include <mbedtls/pk.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace {

using hostimage::ElfPayload;
using hostimage::ImageSigner;
using hostimage::SigningKey;
using image::BoardType;
using image::ImageError;
using image::ImageHeader;
using image::ImagePolicy;
using image::ImageVerifier;
using image::ImageVersion;
using image::TrustedKey;

const SigningKey& key(int which)
{
    static std::vector<SigningKey> keys = [] {
        std::vector<SigningKey> made;
        for (int i = 0; i < 2; ++i) {
            std::string error;
            std::optional<SigningKey> key = SigningKey::generate(error);
            EXPECT_TRUE(key.has_value()) << error;
            made.push_back(*key);
        }
        return made;
    }();
    return keys[static_cast<size_t>(which)];
}

TrustedKey trusted(const SigningKey& signer)
{
    uint8_t point[image::EcdsaP256::kPublicKeySize];
    std::copy(signer.publicPoint().begin(), signer.publicPoint().end(), point);
    return TrustedKey::fromPoint(point);
}

ElfPayload payloadOf(size_t size)
{
    std::vector<uint8_t> bytes(size);
    for (size_t i = 0; i < size; ++i) {
        bytes[i] = static_cast<uint8_t>(i * 7 + 3);
    }
    return ElfPayload(std::move(bytes), 0x100000, static_cast<uint32_t>(size + 4096), 0x100010);
}

std::vector<uint8_t> signedImage(const ElfPayload& payload, const ImageVersion& version = {1, 2, 3, 0},
                                 int signer = 0)
{
    std::string error;
    const std::optional<std::vector<uint8_t>> bytes =
        ImageSigner::sign(payload, BoardType::Isa486, version, key(signer), error);
    EXPECT_TRUE(bytes.has_value()) << error;
    return bytes.value_or(std::vector<uint8_t>{});
}

ImageError verdict(const std::vector<uint8_t>& bytes, const ImagePolicy& policy = ImagePolicy::forBoard(BoardType::Isa486),
                   int trustedKey = 0)
{
    const TrustedKey keys[] = {trusted(key(trustedKey))};
    return ImageVerifier::verify(bytes.data(), bytes.size(), keys, 1, policy).error();
}

TEST(ImageSignerTest, ASignedImageVerifiesWithItsHeaderAsSigned)
{
    const std::vector<uint8_t> bytes = signedImage(payloadOf(5000), {4, 5, 6, 7});
    ASSERT_EQ(bytes.size(), ImageHeader::kSize + 5000);
    const TrustedKey keys[] = {trusted(key(0))};
    const image::ImageResult<ImageHeader> result =
        ImageVerifier::verify(bytes.data(), bytes.size(), keys, 1, ImagePolicy::forBoard(BoardType::Isa486));
    ASSERT_TRUE(result.ok()) << image::imageErrorText(result.error());
    EXPECT_EQ(result.value().payloadSize, 5000u);
    EXPECT_EQ(result.value().memorySize, 5000u + 4096);
    EXPECT_EQ(result.value().loadAddress, 0x100000u);
    EXPECT_EQ(result.value().entry, 0x100010u);
    EXPECT_EQ(result.value().version.compare({4, 5, 6, 7}), 0);
    EXPECT_TRUE(std::equal(keys[0].id, keys[0].id + 32, result.value().keyId));
}

TEST(ImageSignerTest, SignaturesAreDeterministic)
{
    EXPECT_EQ(signedImage(payloadOf(300)), signedImage(payloadOf(300))) << "RFC 6979: the same image, the same bytes";
}

TEST(ImageSignerTest, AnyOfSeveralTrustedKeysVerifies)
{
    const std::vector<uint8_t> bytes = signedImage(payloadOf(100), {1, 0, 0, 0}, 1);
    const TrustedKey keys[] = {trusted(key(0)), trusted(key(1))};
    EXPECT_TRUE(ImageVerifier::verify(bytes.data(), bytes.size(), keys, 2, ImagePolicy::forBoard(BoardType::Isa486)).ok());
    EXPECT_EQ(ImageVerifier::verify(bytes.data(), bytes.size(), keys, 1, ImagePolicy::forBoard(BoardType::Isa486)).error(),
              ImageError::UnknownKey);
    EXPECT_EQ(ImageVerifier::verify(bytes.data(), bytes.size(), nullptr, 0, ImagePolicy::forBoard(BoardType::Isa486)).error(),
              ImageError::UnknownKey);
}

TEST(ImageSignerTest, AnUnsignedImageIsRefused)
{
    std::vector<uint8_t> bytes = signedImage(payloadOf(100));
    std::fill(bytes.begin() + ImageHeader::kSignedSize, bytes.begin() + ImageHeader::kSize, 0);
    EXPECT_EQ(verdict(bytes), ImageError::BadSignature);
    std::fill(bytes.begin() + ImageHeader::kSignedSize, bytes.begin() + ImageHeader::kSize, 0xFF);
    EXPECT_EQ(verdict(bytes), ImageError::BadSignature) << "r and s above the group's order";
}

TEST(ImageSignerTest, AnImageSignedWithAnotherKeyIsRefused)
{
    // Signed by key 1 and naming it: the controller trusts key 0 only.
    EXPECT_EQ(verdict(signedImage(payloadOf(100), {1, 2, 3, 0}, 1)), ImageError::UnknownKey);
    // Signed by key 1 but naming key 0: the signature does not verify.
    std::vector<uint8_t> forged = signedImage(payloadOf(100), {1, 2, 3, 0}, 1);
    const std::vector<uint8_t> genuine = signedImage(payloadOf(100), {1, 2, 3, 0}, 0);
    std::copy(genuine.begin() + 72, genuine.begin() + 104, forged.begin() + 72);
    EXPECT_EQ(verdict(forged), ImageError::BadSignature);
}

TEST(ImageSignerTest, EveryOneBitFlipInTheHeaderIsRefused)
{
    const std::vector<uint8_t> bytes = signedImage(payloadOf(1000));
    int refused = 0;
    for (size_t at = 0; at < ImageHeader::kSize; ++at) {
        for (int bit = 0; bit < 8; ++bit) {
            std::vector<uint8_t> flipped = bytes;
            flipped[at] ^= static_cast<uint8_t>(1u << bit);
            const ImageError error = verdict(flipped);
            EXPECT_NE(error, ImageError::Ok) << "byte " << at << " bit " << bit;
            refused += error != ImageError::Ok ? 1 : 0;
        }
    }
    EXPECT_EQ(refused, 8 * 256);
}

TEST(ImageSignerTest, AOneBitFlipInThePayloadIsRefused)
{
    const size_t size = 64 * 1024;
    const std::vector<uint8_t> bytes = signedImage(payloadOf(size));
    std::vector<size_t> offsets = {0, 1, size / 2, size - 2, size - 1};
    for (size_t at = 0; at < size; at += 997) {
        offsets.push_back(at);
    }
    for (const size_t at : offsets) {
        std::vector<uint8_t> flipped = bytes;
        flipped[ImageHeader::kSize + at] ^= static_cast<uint8_t>(1u << (at % 8));
        EXPECT_EQ(verdict(flipped), ImageError::PayloadMismatch) << "payload byte " << at;
    }
}

TEST(ImageSignerTest, ATruncatedOrExtendedImageIsRefused)
{
    const std::vector<uint8_t> bytes = signedImage(payloadOf(1000));
    for (const size_t length : {size_t{0}, size_t{100}, ImageHeader::kSize - 1, ImageHeader::kSize,
                                ImageHeader::kSize + 1, bytes.size() - 1}) {
        EXPECT_EQ(verdict(std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(length))),
                  ImageError::Truncated)
            << length;
    }
    std::vector<uint8_t> longer = bytes;
    longer.push_back(0);
    EXPECT_EQ(verdict(longer), ImageError::TrailingData);
}

TEST(ImageSignerTest, AnImageLargerThanTheSlotIsRefused)
{
    ImagePolicy policy = ImagePolicy::forBoard(BoardType::Isa486);
    const std::vector<uint8_t> bytes = signedImage(payloadOf(4096));
    policy.slotCapacity = static_cast<uint32_t>(bytes.size());
    EXPECT_EQ(verdict(bytes, policy), ImageError::Ok) << "exactly the slot";
    policy.slotCapacity = static_cast<uint32_t>(bytes.size() - 1);
    EXPECT_EQ(verdict(bytes, policy), ImageError::Oversized);
    const std::vector<uint8_t> large = signedImage(payloadOf(2u << 20));
    EXPECT_EQ(verdict(large), ImageError::Oversized) << "2 MiB of payload and a header in a 2 MiB slot";
    const std::vector<uint8_t> fits = signedImage(payloadOf((2u << 20) - 512));
    EXPECT_EQ(verdict(fits), ImageError::Ok) << "a payload of 4095 sectors fills the slot after the header's sector";
    const std::vector<uint8_t> over = signedImage(payloadOf((2u << 20) - 511));
    EXPECT_EQ(verdict(over), ImageError::Oversized);
}

TEST(ImageSignerTest, AnImageForAnotherBoardIsRefused)
{
    ImagePolicy other = ImagePolicy::forBoard(BoardType::Isa486);
    other.board = static_cast<BoardType>(2); // The dual-Pentium board's number.
    EXPECT_EQ(verdict(signedImage(payloadOf(100)), other), ImageError::WrongBoard);
}

TEST(ImageSignerTest, AnImageOutsideTheBoardsMemoryIsRefused)
{
    std::vector<uint8_t> low(100, 1);
    EXPECT_EQ(verdict(signedImage(ElfPayload(low, 0x8000, 100, 0x8000))), ImageError::BadAddresses);
    EXPECT_EQ(verdict(signedImage(ElfPayload(low, 0x100000, 15u << 20, 0x100000))), ImageError::Ok)
        << "up to 16 MiB exactly";
    EXPECT_EQ(verdict(signedImage(ElfPayload(low, 0x100000, (15u << 20) + 1, 0x100000))), ImageError::BadAddresses);
}

TEST(ImageSignerTest, ADowngradeIsRefusedUnlessAllowed)
{
    const std::vector<uint8_t> bytes = signedImage(payloadOf(100), {1, 2, 3, 0});
    ImagePolicy policy = ImagePolicy::forBoard(BoardType::Isa486);
    const ImageVersion newer{1, 2, 3, 1};
    const ImageVersion same{1, 2, 3, 0};
    const ImageVersion older{1, 1, 900, 0};
    policy.installed = &newer;
    EXPECT_EQ(verdict(bytes, policy), ImageError::Downgrade);
    policy.allowDowngrade = true;
    EXPECT_EQ(verdict(bytes, policy), ImageError::Ok);
    policy.allowDowngrade = false;
    policy.installed = &same;
    EXPECT_EQ(verdict(bytes, policy), ImageError::Ok) << "the same version again is no downgrade";
    policy.installed = &older;
    EXPECT_EQ(verdict(bytes, policy), ImageError::Ok);
}

TEST(ImageSignerTest, TheHeaderIsCheckedBeforeThePayloadArrives)
{
    const std::vector<uint8_t> bytes = signedImage(payloadOf(1000));
    const TrustedKey keys[] = {trusted(key(0))};
    const ImagePolicy policy = ImagePolicy::forBoard(BoardType::Isa486);
    const image::ImageResult<ImageHeader> header =
        ImageVerifier::checkHeader(bytes.data(), ImageHeader::kSize, bytes.size(), keys, 1, policy);
    ASSERT_TRUE(header.ok());
    EXPECT_EQ(ImageVerifier::checkHeader(bytes.data(), ImageHeader::kSize, bytes.size() + 512, keys, 1, policy).error(),
              ImageError::TrailingData)
        << "a transfer announcing more than the header describes";
    EXPECT_EQ(ImageVerifier::checkPayload(header.value(), bytes.data() + ImageHeader::kSize, 1000), ImageError::Ok);
    EXPECT_EQ(ImageVerifier::checkPayload(header.value(), bytes.data() + ImageHeader::kSize, 999), ImageError::Truncated);
}

TEST(ImageSignerTest, KeysRoundTripThroughPem)
{
    const SigningKey& original = key(0);
    std::string error;
    const std::optional<SigningKey> again = SigningKey::fromPem(original.privatePem(), error);
    ASSERT_TRUE(again.has_value()) << error;
    EXPECT_EQ(again->publicPoint(), original.publicPoint());
    const std::optional<SigningKey::PublicPoint> fromPublic = SigningKey::publicPointFromPem(original.publicPem(), error);
    ASSERT_TRUE(fromPublic.has_value()) << error;
    EXPECT_EQ(*fromPublic, original.publicPoint());
    const std::optional<SigningKey::PublicPoint> fromPrivate =
        SigningKey::publicPointFromPem(original.privatePem(), error);
    ASSERT_TRUE(fromPrivate.has_value()) << error;
    EXPECT_EQ(*fromPrivate, original.publicPoint());
    EXPECT_NE(original.privatePem().find("BEGIN EC PRIVATE KEY"), std::string::npos);
    EXPECT_NE(original.publicPem().find("BEGIN PUBLIC KEY"), std::string::npos);
}

TEST(ImageSignerTest, KeysOfAnotherCurveOrNoKeyAtAllAreRefused)
{
    std::string error;
    EXPECT_FALSE(SigningKey::fromPem("", error).has_value());
    EXPECT_FALSE(SigningKey::fromPem("-----BEGIN EC PRIVATE KEY-----\nAAAA\n-----END EC PRIVATE KEY-----\n", error));
    EXPECT_FALSE(SigningKey::fromPem(key(0).publicPem(), error).has_value()) << "a public key cannot sign";
    EXPECT_FALSE(SigningKey::publicPointFromPem("garbage", error).has_value());
    // A P-384 key, made here with mbedTLS.
    mbedtls_entropy_context entropy;
    mbedtls_ctr_drbg_context drbg;
    mbedtls_pk_context pk;
    mbedtls_entropy_init(&entropy);
    mbedtls_ctr_drbg_init(&drbg);
    mbedtls_pk_init(&pk);
    ASSERT_EQ(mbedtls_ctr_drbg_seed(&drbg, mbedtls_entropy_func, &entropy, nullptr, 0), 0);
    ASSERT_EQ(mbedtls_pk_setup(&pk, mbedtls_pk_info_from_type(MBEDTLS_PK_ECKEY)), 0);
    ASSERT_EQ(mbedtls_ecp_gen_key(MBEDTLS_ECP_DP_SECP384R1, mbedtls_pk_ec(pk), mbedtls_ctr_drbg_random, &drbg), 0);
    unsigned char pem[1024] = {};
    ASSERT_EQ(mbedtls_pk_write_key_pem(&pk, pem, sizeof pem), 0);
    mbedtls_pk_free(&pk);
    mbedtls_ctr_drbg_free(&drbg);
    mbedtls_entropy_free(&entropy);
    error.clear();
    EXPECT_FALSE(SigningKey::fromPem(reinterpret_cast<const char*>(pem), error).has_value());
    EXPECT_EQ(error, "not an ECDSA P-256 (secp256r1) key");
    EXPECT_FALSE(SigningKey::publicPointFromPem(reinterpret_cast<const char*>(pem), error).has_value());
}

} // namespace
