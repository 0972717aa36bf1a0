// The configuration protocol's authentication (docs/protocols/config.md,
// "Authentication"): the node's half. Every command that changes anything
// carries a MAC, the first 16 bytes of HMAC-SHA-256 under the node's
// 32-byte configuration key over
//
//     "DCOS-SEI-1" | node id (16) | serial number (32) | challenge (16 bytes) | the request without its MAC
//
// (seiMac, which the host tool computes the same way). A challenge serves
// one attempt, right or wrong, and no longer than 30 s; three wrong MACs in
// a row lock the node out for its configured time, during which Challenge
// and every command that needs a MAC are refused. The count and the
// lockout live in memory only: a node that restarts starts unlocked, and
// only an authenticated Restart, or a power cut on site, restarts it.
//
// Pure code with no clock: the caller passes the time (a monotonic count of
// nanoseconds) to every call that needs it.
#pragma once

#include <sei/SeiMessage.hpp>
#include <sei/SeiStatus.hpp>

#include <stddef.h>
#include <stdint.h>

namespace sei {

/// The MAC over @p length bytes of @p request (the request without its
/// MAC) for the node @p nodeId with serial number @p serial, under @p key
/// and @p challenge: what the node checks and the host tool sends.
void seiMac(const uint8_t (&key)[kSeiKeySize], uint16_t nodeId, uint32_t serial,
            const uint8_t (&challenge)[kSeiChallengeSize], const uint8_t* request, size_t length,
            uint8_t (&mac)[kSeiMacSize]);

class SeiAuthenticator {
public:
    /// How long a challenge serves.
    static constexpr uint64_t kChallengeLifetimeNs = 30ull * 1000000000ull;
    /// Wrong MACs in a row that lock the node out.
    static constexpr unsigned kBadMacLimit = 3;
    /// The lockout when the configuration names none (boot::ConfigurationBlock).
    static constexpr uint16_t kDefaultLockoutSeconds = 60;
    static constexpr uint64_t kNanosecondsPerSecond = 1000000000ull;

    /// The node @p nodeId with serial number @p serial (as Identify gives
    /// them), holding the kSeiKeySize bytes at @p key, or no key when @p key
    /// is null. @p lockoutSeconds is the lockout after kBadMacLimit wrong
    /// MACs (0: kDefaultLockoutSeconds). @p seed makes the challenges unique
    /// to this node and start: bytes that differ from one start to the next
    /// (the clock, the uptime); they need not be secret.
    SeiAuthenticator(const uint8_t* key, uint16_t nodeId, uint32_t serial, uint16_t lockoutSeconds,
                     const uint8_t* seed, size_t seedLength);
    /// Wipes the key.
    ~SeiAuthenticator();
    SeiAuthenticator(const SeiAuthenticator&) = delete;
    SeiAuthenticator& operator=(const SeiAuthenticator&) = delete;

    bool hasKey() const { return hasKey_; }
    bool lockedOut(uint64_t nowNs) const { return locked_ && nowNs < lockedUntilNs_; }
    /// The whole seconds left of the lockout, rounded up; 0 when not locked out.
    uint16_t lockoutSecondsLeft(uint64_t nowNs) const;
    /// Wrong MACs since the last right one or the last lockout.
    unsigned badMacs() const { return badMacs_; }

    /// Draws a new challenge into @p challenge and forgets the one before:
    /// the first 16 bytes of SHA-256 over the seed's digest and a count of
    /// challenges. LockedOut (and no challenge) while locked out.
    SeiStatus drawChallenge(uint64_t nowNs, uint8_t (&challenge)[kSeiChallengeSize]);

    /// Whether a command that needs a MAC may be tried at all: NoKey, then
    /// LockedOut, else Ok. Changes nothing.
    SeiStatus admit(uint64_t nowNs) const;

    /// Checks @p mac over the @p length bytes of @p request (the request
    /// without its MAC): admit()'s refusals first, then NoChallenge,
    /// StaleChallenge or BadMac, else Ok. Any attempt past admit() uses the
    /// challenge up; a wrong MAC counts towards the lockout, a right one
    /// clears the count.
    SeiStatus verify(const uint8_t* request, size_t length, const uint8_t (&mac)[kSeiMacSize], uint64_t nowNs);

private:
    uint8_t key_[kSeiKeySize] = {};
    bool hasKey_ = false;
    uint16_t nodeId_;
    uint32_t serial_;
    uint16_t lockoutSeconds_;
    /// SHA-256 of the caller's seed.
    static constexpr size_t kSeedDigestSize = 32;
    uint8_t seed_[kSeedDigestSize] = {};
    uint32_t challenges_ = 0;

    uint8_t challenge_[kSeiChallengeSize] = {};
    bool challengeOutstanding_ = false;
    uint64_t challengeDrawnNs_ = 0;

    unsigned badMacs_ = 0;
    bool locked_ = false;
    uint64_t lockedUntilNs_ = 0;
};

} // namespace sei
