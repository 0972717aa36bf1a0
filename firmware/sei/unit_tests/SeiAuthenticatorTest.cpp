// The configuration protocol's MACs: HMAC-SHA-256 (HmacSha256) against
// RFC 4231's vectors and against mbedTLS's own HMAC, the MAC's exact byte
// string (seiMac) against a value computed apart from this code (Python's
// hmac module), and the authenticator's challenges.
#include <sei/HmacSha256.hpp>
#include <sei/SeiAuthenticator.hpp>

#include "SeiTestSupport.hpp"

#include <mbedtls/md.h>

#include <gtest/gtest.h>

#include <string>

namespace {

using namespace sei_test;

Bytes fromHex(const std::string& hex)
{
    Bytes bytes;
    for (size_t i = 0; i + 1 < hex.size(); i += 2) {
        bytes.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
    }
    return bytes;
}

Bytes hmac(const Bytes& key, const std::string& data)
{
    sei::HmacSha256 mac(key.data(), key.size());
    mac.update(reinterpret_cast<const uint8_t*>(data.data()), data.size());
    uint8_t digest[sei::HmacSha256::kDigestSize];
    mac.finish(digest);
    return Bytes(std::begin(digest), std::end(digest));
}

TEST(SeiHmacTest, Rfc4231Vectors)
{
    EXPECT_EQ(hmac(Bytes(20, 0x0b), "Hi There"),
              fromHex("b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7"))
        << "test case 1";
    EXPECT_EQ(hmac({'J', 'e', 'f', 'e'}, "what do ya want for nothing?"),
              fromHex("5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843"))
        << "test case 2";
    EXPECT_EQ(hmac(Bytes(131, 0xaa), "Test Using Larger Than Block-Size Key - Hash Key First"),
              fromHex("60e431591ee0b67f0d8a26aacbf5b77f8e0bc6213728c5140546040f0ee37f54"))
        << "test case 6: a key longer than a block is hashed first";
    EXPECT_EQ(hmac(Bytes(131, 0xaa), "This is a test using a larger than block-size key and a larger than block-size "
                                     "data. The key needs to be hashed before being used by the HMAC algorithm."),
              fromHex("9b09ffa71b942fcb27635fbcd5b0e944bfdc63644f0713938a7f51535c3a35e2"))
        << "test case 7";
}

TEST(SeiHmacTest, AgreesWithMbedTlsForEveryKeyAndMessageLength)
{
    const mbedtls_md_info_t* sha256 = mbedtls_md_info_from_type(MBEDTLS_MD_SHA256);
    ASSERT_NE(sha256, nullptr);
    for (size_t keyLength : {0, 1, 31, 32, 33, 63, 64, 65, 200}) {
        for (size_t messageLength = 0; messageLength < 150; messageLength += 7) {
            Bytes key(keyLength);
            Bytes message(messageLength);
            for (size_t i = 0; i < key.size(); ++i) {
                key[i] = static_cast<uint8_t>(i * 31 + keyLength);
            }
            for (size_t i = 0; i < message.size(); ++i) {
                message[i] = static_cast<uint8_t>(i * 17 + 3);
            }
            uint8_t expected[32];
            ASSERT_EQ(mbedtls_md_hmac(sha256, key.data(), key.size(), message.data(), message.size(), expected), 0);
            sei::HmacSha256 mac(key.data(), key.size());
            // In two pieces, to check that update() continues where it was.
            mac.update(message.data(), message.size() / 2);
            mac.update(message.data() + message.size() / 2, message.size() - message.size() / 2);
            uint8_t digest[32];
            mac.finish(digest);
            EXPECT_EQ(Bytes(std::begin(digest), std::end(digest)), Bytes(std::begin(expected), std::end(expected)))
                << "key " << keyLength << ", message " << messageLength;
        }
    }
}

TEST(SeiMacTest, CoversTheDomainTheNodeTheChallengeAndTheRequest)
{
    // Python: hmac.new(bytes(range(0x11, 0x31)), b'DCOS-SEI-1' + bytes([5, 0, 0x78, 0x56, 0x34, 0x12])
    //         + bytes(range(16)) + bytes([0x10, 9, 0]), hashlib.sha256).hexdigest()[:32]
    const Key key = keyOf(0x11);
    uint8_t keyBytes[sei::kSeiKeySize];
    std::copy(key.begin(), key.end(), keyBytes);
    uint8_t challenge[sei::kSeiChallengeSize];
    for (size_t i = 0; i < sizeof challenge; ++i) {
        challenge[i] = static_cast<uint8_t>(i);
    }
    const uint8_t request[] = {0x10, 9, 0};
    uint8_t mac[sei::kSeiMacSize];
    sei::seiMac(keyBytes, 5, 0x12345678, challenge, request, sizeof request, mac);
    EXPECT_EQ(Bytes(std::begin(mac), std::end(mac)), fromHex("d8606d09d695744b154eb7b9e7e1b4bb"));
    // Any other node id or serial number gives another MAC.
    uint8_t other[sei::kSeiMacSize];
    sei::seiMac(keyBytes, 6, 0x12345678, challenge, request, sizeof request, other);
    EXPECT_NE(Bytes(std::begin(mac), std::end(mac)), Bytes(std::begin(other), std::end(other)));
    sei::seiMac(keyBytes, 5, 0x12345679, challenge, request, sizeof request, other);
    EXPECT_NE(Bytes(std::begin(mac), std::end(mac)), Bytes(std::begin(other), std::end(other)));
}

TEST(SeiAuthenticatorTest, AChallengeIsTheDigestOfTheSeedsDigestAndTheCount)
{
    const Key key = keyOf(0x11);
    sei::SeiAuthenticator authenticator(key.data(), 5, 1, 0, reinterpret_cast<const uint8_t*>("seed"), 4);
    uint8_t challenge[sei::kSeiChallengeSize];
    ASSERT_EQ(authenticator.drawChallenge(0, challenge), SeiStatus::Ok);
    // Python: hashlib.sha256(hashlib.sha256(b'seed').digest() + (1).to_bytes(4, 'little')).hexdigest()[:32]
    EXPECT_EQ(Bytes(std::begin(challenge), std::end(challenge)), fromHex("e3acdace32862305e2aeb9473884edb9"));
    uint8_t next[sei::kSeiChallengeSize];
    ASSERT_EQ(authenticator.drawChallenge(0, next), SeiStatus::Ok);
    EXPECT_NE(Bytes(std::begin(challenge), std::end(challenge)), Bytes(std::begin(next), std::end(next)));
}

TEST(SeiAuthenticatorTest, OnlyTheLatestChallengeServes)
{
    const Key key = keyOf(0x11);
    sei::SeiAuthenticator authenticator(key.data(), 5, 1, 0, reinterpret_cast<const uint8_t*>("x"), 1);
    uint8_t first[sei::kSeiChallengeSize];
    uint8_t second[sei::kSeiChallengeSize];
    ASSERT_EQ(authenticator.drawChallenge(0, first), SeiStatus::Ok);
    ASSERT_EQ(authenticator.drawChallenge(0, second), SeiStatus::Ok);
    uint8_t keyBytes[sei::kSeiKeySize];
    std::copy(key.begin(), key.end(), keyBytes);
    const uint8_t request[] = {0x12};
    uint8_t mac[sei::kSeiMacSize];
    sei::seiMac(keyBytes, 5, 1, first, request, 1, mac);
    EXPECT_EQ(authenticator.verify(request, 1, mac, 0), SeiStatus::BadMac) << "the one before is forgotten";
    ASSERT_EQ(authenticator.drawChallenge(0, second), SeiStatus::Ok);
    sei::seiMac(keyBytes, 5, 1, second, request, 1, mac);
    EXPECT_EQ(authenticator.verify(request, 1, mac, 0), SeiStatus::Ok);
    EXPECT_EQ(authenticator.lockoutSecondsLeft(0), 0);
}

} // namespace
