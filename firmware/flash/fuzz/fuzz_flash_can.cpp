// Fuzz target: the node's side of the flash protocol on CAN (CanFlashServer,
// docs/protocols/flash.md "On CAN"), which takes every frame a host, or
// anything else on the bus, sends to a running node or one in recovery.
//
// The input is a script of bus events, each starting with one byte:
//   0..3   a frame: then one byte that picks its identifier (the node's
//          own flash connection at priority 31 or 3, another node, another
//          message type, a standard frame), one byte of length (taken
//          modulo 9) and that many data bytes
//   4      the node's last transmitted frame is confirmed
//   5      time passes: one byte, in units of 10 ms
//   other  a poll at the present time
// Checks: every frame the server asks to send is a well-formed extended
// Flashing frame from the node to the host it serves; nothing is written
// to the card (no Authenticate succeeds without the seed key's private
// half); the next deadline never lies in the past after a poll.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"
#include "FuzzSeedKey.hpp"

#include <flash/CanFlashServer.hpp>
#include <flash/FlashSession.hpp>

#include <boot/CardLayout.hpp>
#include <can/MessageIdentifier.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace {

constexpr uint8_t kNode = 9;

class BlankCard final : public flash::FlashStore {
public:
    bool read(uint32_t lba, uint32_t count, void* buffer) override
    {
        FUZZ_CHECK(uint64_t{lba} + count <= boot::card::kMinimumCardSectors);
        std::memset(buffer, 0, size_t{count} * 512);
        return true;
    }
    bool write(uint32_t, uint32_t, const void*) override
    {
        ++writes;
        return true;
    }
    unsigned writes = 0;
};

uint32_t identifierFor(uint8_t pick)
{
    using can::MessageIdentifier;
    using can::MessageType;
    switch (pick % 6) {
    case 0: return MessageIdentifier::make(31, MessageType::Flashing, kNode, 254).value().encode();
    case 1: return MessageIdentifier::make(3, MessageType::Flashing, kNode, pick >> 3).value().encode();
    case 2: return MessageIdentifier::make(31, MessageType::Flashing, kNode + 1, 254).value().encode();
    case 3: return MessageIdentifier::make(31, MessageType::RemoteRequest, kNode, 254).value().encode();
    case 4: return MessageIdentifier::make(31, MessageType::Flashing, MessageIdentifier::kBroadcast, 254).value().encode();
    default: return pick;
    }
}

void checkOutput(const flash::CanFlashServer& server, const flash::CanFlashServer::Output& output)
{
    if (!output.transmit) {
        return;
    }
    FUZZ_CHECK(output.frame.format() == can::IdFormat::Extended);
    const can::LinkResult<can::MessageIdentifier> id = can::MessageIdentifier::fromFrame(output.frame);
    FUZZ_CHECK(id.ok());
    FUZZ_CHECK(id.value().type() == can::MessageType::Flashing);
    FUZZ_CHECK(id.value().source() == kNode);
    FUZZ_CHECK(id.value().destination() == server.peer());
    FUZZ_CHECK(output.frame.length() >= 1 && output.frame.length() <= 8);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    static const image::TrustedKey key = image::TrustedKey::fromPoint(flash_fuzz::kSeedKey);
    BlankCard store;
    flash::SessionIdentity identity;
    identity.node = kNode;
    identity.mode = flash::NodeMode::Application;
    flash::FlashSession session(store, &key, 1, identity, reinterpret_cast<const uint8_t*>("fuzz"), 4);
    flash::CanFlashServer server(session, kNode);
    uint64_t now = 0;
    size_t i = 0;
    while (i < size) {
        const uint8_t kind = data[i++];
        if (kind <= 3) {
            if (i + 2 > size) {
                break;
            }
            const uint8_t pick = data[i++];
            uint8_t length = static_cast<uint8_t>(data[i++] % 9);
            if (length > size - i) {
                length = static_cast<uint8_t>(size - i);
            }
            const uint32_t id = identifierFor(pick);
            const can::IdFormat format = pick % 6 == 5 ? can::IdFormat::Standard : can::IdFormat::Extended;
            const can::LinkResult<can::CanFrame> frame =
                can::CanFrame::makeData(id & can::CanFrame::maxId(format), format, data + i, length);
            i += length;
            if (frame.ok()) {
                checkOutput(server, server.onFrame(frame.value(), now));
            }
        } else if (kind == 4) {
            checkOutput(server, server.onTransmitConfirmed(now));
        } else if (kind == 5) {
            if (i < size) {
                now += uint64_t{data[i++]} * 10000000;
            }
        } else {
            checkOutput(server, server.poll(now));
            FUZZ_CHECK(server.nextDeadlineNs() > now);
        }
        FUZZ_CHECK(store.writes == 0);
    }
    return 0;
}
