// The image verifier's ECDSA against Project Wycheproof's P-256 SHA-256
// vectors (wycheproof/README.md): every valid signature accepted, every
// invalid one refused.
#include <image/EcdsaP256.hpp>
#include <image/Sha256.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <string>
#include <vector>

namespace {

using image::EcdsaP256;

std::vector<uint8_t> fromHex(const std::string& text)
{
    std::vector<uint8_t> bytes;
    for (size_t i = 0; i + 1 < text.size(); i += 2) {
        bytes.push_back(static_cast<uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
    }
    return bytes;
}

TEST(EcdsaP256WycheproofTest, AcceptsEveryValidSignatureAndRefusesEveryInvalidOne)
{
    const std::string path = std::string(DCOS_IMAGE_TEST_DATA) + "/wycheproof/ecdsa_secp256r1_sha256_p1363_test.json";
    std::ifstream file(path);
    ASSERT_TRUE(file) << "cannot read " << path;
    const nlohmann::json vectors = nlohmann::json::parse(file);
    ASSERT_EQ(vectors["algorithm"], "ECDSA");
    int valid = 0;
    int invalid = 0;
    int total = 0;
    for (const nlohmann::json& group : vectors["testGroups"]) {
        ASSERT_EQ(group["key"]["curve"], "secp256r1");
        ASSERT_EQ(group["sha"], "SHA-256");
        const std::vector<uint8_t> key = fromHex(group["key"]["uncompressed"]);
        ASSERT_EQ(key.size(), EcdsaP256::kPublicKeySize);
        uint8_t point[EcdsaP256::kPublicKeySize];
        std::copy(key.begin(), key.end(), point);
        for (const nlohmann::json& test : group["tests"]) {
            ++total;
            const std::vector<uint8_t> message = fromHex(test["msg"]);
            const std::vector<uint8_t> signature = fromHex(test["sig"]);
            uint8_t digest[EcdsaP256::kDigestSize];
            image::Sha256::digest(message.data(), message.size(), digest);
            // The verifier takes exactly 64 bytes: any other length is
            // refused before it is reached.
            bool accepted = false;
            if (signature.size() == EcdsaP256::kSignatureSize) {
                uint8_t rs[EcdsaP256::kSignatureSize];
                std::copy(signature.begin(), signature.end(), rs);
                accepted = EcdsaP256::verify(point, digest, rs);
            }
            const std::string result = test["result"];
            if (result == "valid") {
                EXPECT_TRUE(accepted) << "tcId " << test["tcId"] << ": " << test["comment"];
                valid += accepted ? 1 : 0;
            } else if (result == "invalid") {
                EXPECT_FALSE(accepted) << "tcId " << test["tcId"] << ": " << test["comment"];
                invalid += accepted ? 0 : 1;
            }
        }
    }
    EXPECT_EQ(total, vectors["numberOfTests"].get<int>());
    EXPECT_EQ(valid, 146);
    EXPECT_EQ(invalid, 69);
}

TEST(EcdsaP256WycheproofTest, RefusesAPointOffTheCurveOrNotUncompressed)
{
    const std::string path = std::string(DCOS_IMAGE_TEST_DATA) + "/wycheproof/ecdsa_secp256r1_sha256_p1363_test.json";
    std::ifstream file(path);
    ASSERT_TRUE(file);
    const nlohmann::json vectors = nlohmann::json::parse(file);
    const std::vector<uint8_t> key = fromHex(vectors["testGroups"][0]["key"]["uncompressed"]);
    uint8_t point[EcdsaP256::kPublicKeySize];
    std::copy(key.begin(), key.end(), point);
    EXPECT_TRUE(EcdsaP256::validPublicKey(point));
    point[64] ^= 1;
    EXPECT_FALSE(EcdsaP256::validPublicKey(point)) << "Y changed: off the curve";
    point[64] ^= 1;
    point[0] = 0x02;
    EXPECT_FALSE(EcdsaP256::validPublicKey(point)) << "not the uncompressed form";
    uint8_t zeros[EcdsaP256::kPublicKeySize] = {0x04};
    EXPECT_FALSE(EcdsaP256::validPublicKey(zeros));
}

} // namespace
