// Fuzz target: the node's side of the flash protocol (docs/protocols/flash.md),
// which takes every byte a host sends to a node in recovery.
//
// The input is a byte stream on the serial line: it goes through the
// SerialFramer, and every frame it completes goes to a FlashSession on a
// card in memory, whose reply must decode. Checks: every reply decodes and
// echoes its request's type (or is an ErrorReply); a frame re-framed and
// re-received gives the same payload; nothing is written to the card before
// an Authenticate succeeds, which without the seed key's private half never
// happens; no write reaches the boot sector, the stage loader or the
// configuration.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"
#include "FuzzSeedKey.hpp"

#include <flash/FlashSession.hpp>
#include <flash/SerialFramer.hpp>

#include <boot/CardLayout.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace {

class SmallCard final : public flash::FlashStore {
public:
    bool read(uint32_t lba, uint32_t count, void* buffer) override
    {
        FUZZ_CHECK(uint64_t{lba} + count <= boot::card::kMinimumCardSectors);
        std::memset(buffer, 0, size_t{count} * 512);
        return true;
    }
    bool write(uint32_t lba, uint32_t count, const void*) override
    {
        FUZZ_CHECK(uint64_t{lba} + count <= boot::card::kMinimumCardSectors);
        FUZZ_CHECK(lba >= boot::card::kBootStateLba);
        ++writes;
        return true;
    }
    unsigned writes = 0;
};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    static const image::TrustedKey key = image::TrustedKey::fromPoint(flash_fuzz::kSeedKey);
    SmallCard store;
    flash::SessionIdentity identity;
    identity.node = 9;
    flash::FlashSession session(store, &key, 1, identity, reinterpret_cast<const uint8_t*>("fuzz"), 4);
    flash::SerialFramer receiver;
    flash::SerialFramer again;
    for (size_t i = 0; i < size; ++i) {
        if (!receiver.receive(data[i])) {
            continue;
        }
        const std::vector<uint8_t> payload(receiver.payload(), receiver.payload() + receiver.payloadLength());
        uint8_t framed[flash::kMaxMessage + flash::SerialFramer::kOverhead];
        const size_t framedLength = flash::SerialFramer::frame(payload.data(), payload.size(), framed, sizeof framed);
        FUZZ_CHECK(framedLength == payload.size() + flash::SerialFramer::kOverhead);
        bool completed = false;
        for (size_t j = 0; j < framedLength; ++j) {
            completed = again.receive(framed[j]);
        }
        FUZZ_CHECK(completed && again.payloadLength() == payload.size() &&
                   std::memcmp(again.payload(), payload.data(), payload.size()) == 0);

        uint8_t reply[flash::kMaxMessage];
        const size_t length = session.handle(payload.data(), payload.size(), reply, sizeof reply);
        FUZZ_CHECK(length > 0);
        flash::FlashMessage decoded;
        FUZZ_CHECK(flash::FlashMessage::decode(reply, length, decoded));
        const bool known = payload[0] >= 1 && payload[0] <= 6;
        FUZZ_CHECK(decoded.type == flash::MessageType::ErrorReply ||
                   (known && static_cast<uint8_t>(decoded.type) == (payload[0] | 0x80)));
        FUZZ_CHECK(store.writes == 0);
    }
    return 0;
}
