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

#include <flash/FlashSession.hpp>
#include <flash/SerialFramer.hpp>

#include <boot/CardLayout.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace {

// The public key of the image fuzz target's seed (its private key was thrown away).
constexpr uint8_t kSeedKey[65] = {
    0x04, 0xb1, 0x5c, 0xea, 0xff, 0xe7, 0x0d, 0xe4, 0xeb, 0xec, 0x0e, 0x9d, 0x77, 0xde, 0x8e, 0xb3, 0x23,
    0xe6, 0xae, 0x57, 0x65, 0x3a, 0x0b, 0xc0, 0x6e, 0x9e, 0x82, 0x80, 0xce, 0x58, 0x56, 0x66, 0x64, 0xca,
    0x9a, 0xff, 0xbc, 0xca, 0x81, 0x5a, 0xab, 0x6d, 0x3d, 0x02, 0xad, 0x8d, 0x13, 0xf4, 0xcf, 0x5e, 0x5b,
    0x34, 0xf6, 0x87, 0xba, 0xa4, 0x4a, 0xdc, 0xbd, 0xe2, 0x68, 0x47, 0xaa, 0x78, 0x84};

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
    static const image::TrustedKey key = image::TrustedKey::fromPoint(kSeedKey);
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
