// Fuzz target: the RTU receive state machine fed characters, polls and
// restarts of silence at arbitrary times.
//
// The input is a baud-rate choice, then operations of two bytes: what to do
// and how much time passes first (in eighths of a character, or in whole
// t3.5 units, so that both gaps inside frames and frame ends are reached).
// The checks: a delivered frame is 4..256 bytes with a good CRC and equals
// the last bytes fed before the call that delivered it; every frame seen is
// counted exactly once in one category; a poll at the deadline always ends
// in Idle; an idle receiver has no deadline; a frame that took a character
// marked damaged is never delivered.
#include "../../can/fuzz/FuzzCheck.hpp"

#include <modbus/Crc16.hpp>
#include <modbus/RtuReceiver.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

using modbus::RtuReceiver;

constexpr uint32_t kBauds[4] = {1200, 9600, 19200, 115200};

void checkCounters(const RtuReceiver& receiver)
{
    const RtuReceiver::Counters& c = receiver.counters();
    FUZZ_CHECK(c.busMessages ==
               c.crcErrors + c.overruns + c.gapErrors + c.damagedFrames + c.shortFrames + c.framesDelivered);
    FUZZ_CHECK(c.framesLost <= c.framesDelivered);
    FUZZ_CHECK(receiver.state() != RtuReceiver::State::Idle || receiver.nextDeadlineNs() == RtuReceiver::kNoDeadline);
    FUZZ_CHECK(receiver.state() == RtuReceiver::State::Idle || receiver.nextDeadlineNs() != RtuReceiver::kNoDeadline);
}

// A frame delivered by the last call must be the last bytes fed before it.
void checkDelivery(const RtuReceiver& receiver, uint32_t deliveredBefore, const std::vector<uint8_t>& fed,
                   size_t fedBefore)
{
    if (receiver.counters().framesDelivered == deliveredBefore) {
        return;
    }
    FUZZ_CHECK(receiver.counters().framesDelivered == deliveredBefore + 1);
    FUZZ_CHECK(receiver.frameReady());
    const size_t length = receiver.frameLength();
    FUZZ_CHECK(length >= modbus::kMinRtuAduLength && length <= modbus::kMaxRtuAduLength);
    FUZZ_CHECK(modbus::Crc16::check(receiver.frame(), length));
    FUZZ_CHECK(fedBefore >= length);
    for (size_t i = 0; i < length; ++i) {
        FUZZ_CHECK(receiver.frame()[i] == fed[fedBefore - length + i]);
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz::InputReader input(data, size);
    const uint8_t configuration = input.byte();
    const auto timing = modbus::RtuTiming::make(kBauds[configuration & 3], (configuration & 4) != 0 ? 10 : 11);
    FUZZ_CHECK(timing.ok());
    RtuReceiver receiver(timing.value());
    std::vector<uint8_t> fed;
    uint64_t now = 0;
    // The frame under reception took a damaged character: it ends as frame
    // number `messages` + 1 and must not be delivered.
    struct {
        bool pending = false;
        uint32_t messages = 0;
        uint32_t delivered = 0;
    } damaged;

    while (!input.empty()) {
        const uint8_t operation = input.byte();
        const uint8_t amount = input.byte();
        // Time passes in eighths of a character, or in whole t3.5.
        now += (operation & 0x80) != 0 ? amount * timing.value().t35Ns : amount * timing.value().characterNs / 8;
        const uint32_t deliveredBefore = receiver.counters().framesDelivered;
        const size_t fedBefore = fed.size();
        switch (operation & 3) {
        case 0:
        case 1: {
            // A byte taken from the input; a run of them mostly, so frames
            // with a right CRC can be built by the fuzzer.
            const uint8_t byte = input.byte();
            fed.push_back(byte);
            receiver.onByte(byte, now);
            if ((operation & 0x40) != 0) {
                // The UART flagged it: its frame, if it is in one, must not
                // be delivered (checked at the frame's end below).
                receiver.markLastCharacterDamaged();
                if (receiver.state() == RtuReceiver::State::Reception && !damaged.pending) {
                    damaged = {true, receiver.counters().busMessages, receiver.counters().framesDelivered};
                }
            }
            break;
        }
        case 2: {
            const uint64_t deadline = receiver.nextDeadlineNs();
            receiver.poll(now);
            if (deadline != RtuReceiver::kNoDeadline && now >= deadline) {
                FUZZ_CHECK(receiver.state() == RtuReceiver::State::Idle);
            }
            break;
        }
        case 3:
            if ((operation & 4) != 0) {
                receiver.restartSilence(now);
                damaged.pending = false; // The frame is dropped uncounted.
                FUZZ_CHECK(receiver.state() == RtuReceiver::State::Initial);
            } else if (receiver.frameReady()) {
                receiver.takeFrame();
                FUZZ_CHECK(!receiver.frameReady());
            }
            break;
        }
        if (damaged.pending && receiver.counters().busMessages > damaged.messages) {
            // One call ends at most one frame, so this is the damaged one.
            FUZZ_CHECK(receiver.counters().busMessages == damaged.messages + 1);
            FUZZ_CHECK(receiver.counters().framesDelivered == damaged.delivered);
            damaged.pending = false;
        }
        checkDelivery(receiver, deliveredBefore, fed, fedBefore);
        checkCounters(receiver);
    }
    return 0;
}
