// What the flash protocol's host tests share: a card in memory that can
// lose its power at any write, signing keys made for the test run, signed
// images, and a host side that drives a FlashSession message by message.
#pragma once

#include <flash/FlashMessage.hpp>
#include <flash/FlashSession.hpp>

#include "../../boot/unit_tests/MemoryCard.hpp"

#include <boot/BootState.hpp>
#include <boot/CardLayout.hpp>
#include <boot/Crc32.hpp>
#include <hostimage/ImageSigner.hpp>
#include <hostimage/SigningKey.hpp>
#include <image/ImageVerifier.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace flash_test {

using flash::FlashMessage;
using flash::FlashStatus;
using flash::MessageType;
namespace card = boot::card;

inline std::vector<uint8_t> encoded(const FlashMessage& message)
{
    std::vector<uint8_t> bytes(flash::kMaxMessage);
    const size_t length = message.encode(bytes.data(), bytes.size());
    EXPECT_NE(length, 0u);
    bytes.resize(length);
    return bytes;
}

using boot_test::MemoryCard;

inline const hostimage::SigningKey& signingKey(int which)
{
    static std::vector<hostimage::SigningKey> keys = [] {
        std::vector<hostimage::SigningKey> made;
        for (int i = 0; i < 2; ++i) {
            std::string error;
            made.push_back(*hostimage::SigningKey::generate(error));
        }
        return made;
    }();
    return keys[static_cast<size_t>(which)];
}

inline image::TrustedKey trusted(const hostimage::SigningKey& key)
{
    uint8_t point[65];
    std::copy(key.publicPoint().begin(), key.publicPoint().end(), point);
    return image::TrustedKey::fromPoint(point);
}

inline std::vector<uint8_t> imageOf(size_t size, const image::ImageVersion& version, int key = 0)
{
    std::vector<uint8_t> payload(size);
    for (size_t i = 0; i < size; ++i) {
        payload[i] = static_cast<uint8_t>(i * 31 + 7);
    }
    std::string error;
    return *hostimage::ImageSigner::sign(hostimage::ElfPayload(payload, 0x100000, static_cast<uint32_t>(size), 0x100000),
                                         image::BoardType::Isa486, version, signingKey(key), error);
}


// The host's side of a session, message by message: on a session in this
// process, or through @p carry, which takes a request's bytes to the node
// and brings back the reply's (CanFlashServerTest carries them over ISO-TP).
class FlashHost {
public:
    using Carrier = std::function<std::vector<uint8_t>(const std::vector<uint8_t>&)>;

    FlashHost(flash::FlashSession& session, uint16_t node) : session_(&session), node_(node) {}
    FlashHost(Carrier carry, uint16_t node) : carry_(std::move(carry)), node_(node) {}

    FlashMessage ask(const FlashMessage& request)
    {
        const std::vector<uint8_t> bytes = encoded(request);
        std::vector<uint8_t> reply(flash::kMaxMessage);
        if (session_ != nullptr) {
            reply.resize(session_->handle(bytes.data(), bytes.size(), reply.data(), reply.size()));
        } else {
            reply = carry_(bytes);
        }
        FlashMessage decoded;
        EXPECT_TRUE(FlashMessage::decode(reply.data(), reply.size(), decoded));
        EXPECT_EQ(decoded.tag, request.tag);
        return decoded;
    }

    FlashMessage hello()
    {
        FlashMessage m;
        m.type = MessageType::Hello;
        m.tag = ++tag_;
        return ask(m);
    }

    /// Hello (unless @p freshHello is false: the last challenge again) and
    /// the challenge signed with key @p key.
    FlashStatus authenticate(int key = 0, bool freshHello = true)
    {
        const FlashMessage challenge = freshHello ? hello() : lastHello;
        lastHello = challenge;
        uint8_t digest[32];
        flash::authenticationDigest(node_, challenge.challenge, digest);
        FlashMessage m;
        m.type = MessageType::Authenticate;
        m.tag = ++tag_;
        const image::TrustedKey id = trusted(signingKey(key));
        std::copy(std::begin(id.id), std::end(id.id), m.keyId);
        std::string error;
        EXPECT_TRUE(signingKey(key).sign(digest, m.signature, error));
        return ask(m).status;
    }

    FlashMessage begin(const std::vector<uint8_t>& image)
    {
        FlashMessage m;
        m.type = MessageType::Begin;
        m.tag = ++tag_;
        std::copy_n(image.begin(), 256, m.header);
        return ask(m);
    }

    FlashMessage block(const std::vector<uint8_t>& image, uint32_t offset, uint32_t sequence, size_t length,
                       bool damage = false)
    {
        std::vector<uint8_t> bytes(image.begin() + 256 + offset, image.begin() + 256 + offset + length);
        FlashMessage m;
        m.type = MessageType::Data;
        m.tag = ++tag_;
        m.offset = offset;
        m.sequence = sequence;
        m.length = static_cast<uint16_t>(length);
        m.crc = boot::crc32(bytes.data(), bytes.size());
        if (damage) {
            bytes[0] ^= 1;
        }
        m.bytes = bytes.data();
        return ask(m);
    }

    /// Every block from @p from on; the last reply (its status is the first
    /// that was not Ok, if any).
    FlashMessage sendAll(const std::vector<uint8_t>& image, uint32_t from = 0)
    {
        FlashMessage reply;
        const uint32_t size = static_cast<uint32_t>(image.size() - 256);
        for (uint32_t offset = from; offset < size; offset += flash::kMaxBlock) {
            reply = block(image, offset, offset / flash::kMaxBlock, std::min<size_t>(flash::kMaxBlock, size - offset));
            if (reply.status != FlashStatus::Ok) {
                return reply;
            }
        }
        return reply;
    }

    FlashMessage simple(MessageType type)
    {
        FlashMessage m;
        m.type = type;
        m.tag = ++tag_;
        return ask(m);
    }

    FlashMessage lastHello;

private:
    flash::FlashSession* session_ = nullptr;
    Carrier carry_;
    uint16_t node_;
    uint8_t tag_ = 0;
};

} // namespace flash_test
