#include <sei/SeiAuthenticator.hpp>

#include <sei/HmacSha256.hpp>

#include <image/Sha256.hpp>

namespace sei {

namespace {

static_assert(image::Sha256::kDigestSize >= kSeiChallengeSize, "a challenge is a prefix of a SHA-256 digest");
static_assert(HmacSha256::kDigestSize >= kSeiMacSize, "a MAC is a prefix of an HMAC-SHA-256");

// The domain of the MAC: a MAC of another protocol, or of another version
// of this one, never verifies here.
constexpr uint8_t kMacDomain[] = {'D', 'C', 'O', 'S', '-', 'S', 'E', 'I', '-', '1'};

// The longest lockout the reply's 16 bits of seconds can say.
constexpr uint64_t kMaxSecondsLeft = 0xFFFF;

// Compares in a time that does not depend on where the MACs differ, so a
// host cannot learn a right MAC byte by byte from the reply's timing.
bool equalInConstantTime(const uint8_t* a, const uint8_t* b, size_t length)
{
    uint8_t difference = 0;
    for (size_t i = 0; i < length; ++i) {
        difference = static_cast<uint8_t>(difference | (a[i] ^ b[i]));
    }
    return difference == 0;
}

void wipe(uint8_t* bytes, size_t length)
{
    volatile uint8_t* out = bytes;
    for (size_t i = 0; i < length; ++i) {
        out[i] = 0;
    }
}

} // namespace

void seiMac(const uint8_t (&key)[kSeiKeySize], uint16_t nodeId, uint32_t serial,
            const uint8_t (&challenge)[kSeiChallengeSize], const uint8_t* request, size_t length,
            uint8_t (&mac)[kSeiMacSize])
{
    const uint8_t identity[6] = {static_cast<uint8_t>(nodeId),        static_cast<uint8_t>(nodeId >> 8),
                                 static_cast<uint8_t>(serial),        static_cast<uint8_t>(serial >> 8),
                                 static_cast<uint8_t>(serial >> 16), static_cast<uint8_t>(serial >> 24)};
    HmacSha256 hmac(key, sizeof key);
    hmac.update(kMacDomain, sizeof kMacDomain);
    hmac.update(identity, sizeof identity);
    hmac.update(challenge, sizeof challenge);
    hmac.update(request, length);
    uint8_t full[HmacSha256::kDigestSize];
    hmac.finish(full);
    for (size_t i = 0; i < kSeiMacSize; ++i) {
        mac[i] = full[i];
    }
}

SeiAuthenticator::SeiAuthenticator(const uint8_t* key, uint16_t nodeId, uint32_t serial, uint16_t lockoutSeconds,
                                   const uint8_t* seed, size_t seedLength)
    : hasKey_(key != nullptr), nodeId_(nodeId), serial_(serial),
      lockoutSeconds_(lockoutSeconds != 0 ? lockoutSeconds : kDefaultLockoutSeconds)
{
    static_assert(sizeof seed_ == image::Sha256::kDigestSize, "the seed is kept as its digest");
    if (hasKey_) {
        for (size_t i = 0; i < kSeiKeySize; ++i) {
            key_[i] = key[i];
        }
    }
    image::Sha256::digest(seed, seedLength, seed_);
}

SeiAuthenticator::~SeiAuthenticator() { wipe(key_, sizeof key_); }

uint16_t SeiAuthenticator::lockoutSecondsLeft(uint64_t nowNs) const
{
    if (!lockedOut(nowNs)) {
        return 0;
    }
    const uint64_t seconds = (lockedUntilNs_ - nowNs + kNanosecondsPerSecond - 1) / kNanosecondsPerSecond;
    return static_cast<uint16_t>(seconds < kMaxSecondsLeft ? seconds : kMaxSecondsLeft);
}

SeiStatus SeiAuthenticator::drawChallenge(uint64_t nowNs, uint8_t (&challenge)[kSeiChallengeSize])
{
    if (lockedOut(nowNs)) {
        return SeiStatus::LockedOut;
    }
    ++challenges_;
    const uint8_t count[4] = {static_cast<uint8_t>(challenges_), static_cast<uint8_t>(challenges_ >> 8),
                              static_cast<uint8_t>(challenges_ >> 16), static_cast<uint8_t>(challenges_ >> 24)};
    image::Sha256 hash;
    hash.update(seed_, sizeof seed_);
    hash.update(count, sizeof count);
    uint8_t digest[image::Sha256::kDigestSize];
    hash.finish(digest);
    for (size_t i = 0; i < kSeiChallengeSize; ++i) {
        challenge_[i] = digest[i];
        challenge[i] = digest[i];
    }
    challengeOutstanding_ = true;
    challengeDrawnNs_ = nowNs;
    return SeiStatus::Ok;
}

SeiStatus SeiAuthenticator::admit(uint64_t nowNs) const
{
    if (!hasKey_) {
        return SeiStatus::NoKey;
    }
    if (lockedOut(nowNs)) {
        return SeiStatus::LockedOut;
    }
    return SeiStatus::Ok;
}

SeiStatus SeiAuthenticator::verify(const uint8_t* request, size_t length, const uint8_t (&mac)[kSeiMacSize],
                                   uint64_t nowNs)
{
    const SeiStatus admitted = admit(nowNs);
    if (admitted != SeiStatus::Ok) {
        return admitted;
    }
    if (!challengeOutstanding_) {
        return SeiStatus::NoChallenge;
    }
    // One attempt per challenge, whatever its outcome: a recorded request
    // played again finds it gone.
    challengeOutstanding_ = false;
    if (nowNs - challengeDrawnNs_ > kChallengeLifetimeNs) {
        return SeiStatus::StaleChallenge;
    }
    uint8_t expected[kSeiMacSize];
    seiMac(key_, nodeId_, serial_, challenge_, request, length, expected);
    const bool right = equalInConstantTime(expected, mac, kSeiMacSize);
    wipe(expected, sizeof expected);
    if (right) {
        badMacs_ = 0;
        return SeiStatus::Ok;
    }
    if (++badMacs_ >= kBadMacLimit) {
        // The count starts again after the lockout: three more tries then.
        badMacs_ = 0;
        locked_ = true;
        lockedUntilNs_ = nowNs + uint64_t{lockoutSeconds_} * kNanosecondsPerSecond;
    }
    return SeiStatus::BadMac;
}

} // namespace sei
