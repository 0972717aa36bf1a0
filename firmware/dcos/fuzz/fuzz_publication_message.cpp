// Fuzz target: the receiving side of publications over the network
// (docs/protocols/publications.md), which takes every publication frame a
// node hears on any bus.
//
// The input is a stream of frames, each a byte holding the bus (bit 7), a
// time step (bits 6-4) and the length (bits 3-0), then the frame's bytes.
// Each decoded part goes to that bus's reassembly, and each complete page
// through the duplicate filter, as the kernel does. Checks: a refused frame
// is refused for a reason the specification gives; a complete page is
// exactly the bytes of the last first, second and third parts that bus
// delivered, with the first part's sequence number, so no page is made of
// two publications; the filter never takes one sequence number twice in a
// row, and takes a number that is not newer only after a silence.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <dcos/internal/PublicationMessage.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>

using namespace dcos::internal;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    PublicationAssembler assemblers[2];
    // What each bus delivered last of each part, to check a complete page against.
    struct Seen {
        PublicationPart parts[3];
    } seen[2]{};
    PublicationFilter filter;
    bool taken = false;
    uint16_t lastTaken = 0;
    uint64_t lastTakenNs = 0;
    uint64_t now = 0;
    size_t at = 0;
    while (at < size) {
        const uint8_t control = data[at++];
        const int bus = control >> 7;
        now += static_cast<uint64_t>((control >> 4) & 0x7) * 300000000u; // 0 to 2.1 s per frame.
        const size_t length = control & 0x0F;
        if (length > size - at) {
            break;
        }
        const uint8_t* frame = data + at;
        at += length;
        // A relay header (a relayed publication's, "Across a gateway") is
        // never a publication's frame, and encodes back to itself.
        uint16_t relayNode = 0;
        uint8_t crossed = 0;
        if (decodeRelayHeader(frame, length, relayNode, &crossed)) {
            FUZZ_CHECK(crossed < kRelayCrossings);
            uint8_t again[kRelayHeaderBytes];
            encodeRelayHeader(relayNode, again, crossed);
            FUZZ_CHECK(length == kRelayHeaderBytes && std::memcmp(again, frame, length) == 0);
            PublicationPart notAPart;
            FUZZ_CHECK(decodePublicationPart(frame, length, notAPart) != PublicationMessageError::None);
            continue;
        }
        PublicationPart part;
        const PublicationMessageError error = decodePublicationPart(frame, length, part);
        if (error != PublicationMessageError::None) {
            FUZZ_CHECK(error == PublicationMessageError::WrongLength || error == PublicationMessageError::WrongTag);
            continue;
        }
        FUZZ_CHECK(length == (part.kind == PublicationPartKind::Withdrawal ? kWithdrawalBytes : kPublicationFrameBytes));
        FUZZ_CHECK(part.index <= 0x0FFF);
        if (part.kind == PublicationPartKind::Withdrawal) {
            continue;
        }
        seen[bus].parts[static_cast<int>(part.kind)] = part;
        if (assemblers[bus].take(part) != PublicationAssembler::Outcome::Complete) {
            continue;
        }
        const Seen& last = seen[bus];
        FUZZ_CHECK(assemblers[bus].sequence() == last.parts[0].sequence);
        FUZZ_CHECK((last.parts[1].tag == (last.parts[0].sequence & 3)) && last.parts[2].tag == last.parts[1].tag);
        const dcos::DsmPage& page = assemblers[bus].page();
        FUZZ_CHECK(std::memcmp(page.bytes, last.parts[0].bytes, 4) == 0);
        FUZZ_CHECK(std::memcmp(page.bytes + 4, last.parts[1].bytes, 6) == 0);
        FUZZ_CHECK(std::memcmp(page.bytes + 10, last.parts[2].bytes, 6) == 0);
        const uint16_t sequence = assemblers[bus].sequence();
        if (filter.take(sequence, now)) {
            if (taken) {
                const auto ahead = static_cast<uint16_t>(sequence - lastTaken);
                FUZZ_CHECK(ahead != 0);
                FUZZ_CHECK(ahead < 0x8000 || now - lastTakenNs >= PublicationFilter::kRestartSilenceNs);
            }
            taken = true;
            lastTaken = sequence;
            lastTakenNs = now;
        }
    }
    return 0;
}
