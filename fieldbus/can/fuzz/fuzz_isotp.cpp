// Fuzz target: the ISO-TP receiver and sender fed arbitrary frames, flow
// control, confirmations and jumps of time.
//
// Three state machines run side by side:
//   R  a receiver fed raw frames from the input (any PCI, length, identifier),
//      shadowed by the harness: every consecutive frame it takes must be the
//      one due, and a message it completes the bytes of the frames it took;
//   A  a sender whose flow control and confirmations come from the input;
//   B  a receiver joined to A by an in-order queue, whose flow control goes
//      back to A through another queue the input empties at will.
// The input is a configuration header, then operations of one byte each
// (choosing what happens and how much time passes first) with their operands.
// The checks: no access outside any buffer (the buffers are exactly as large
// as configured, so AddressSanitizer sees one byte too far); every frame A
// emits carries the next bytes of its message with the next sequence number;
// every message B completes equals the one A sent; every flow control
// carries the configured parameters; an idle machine has no deadline.
#include "FuzzCheck.hpp"

#include <can/IsoTpReceiver.hpp>
#include <can/IsoTpSender.hpp>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

namespace {

using namespace can;

// Time units an operation can advance the clock by: microseconds to seconds,
// so both separation times and 1 s time-outs are reached.
constexpr uint64_t kTimeUnitsNs[4] = {1000, 1000000, 50000000, 1000000000};

struct Queued {
    CanFrame frame;
    size_t message; // index into Harness::messages of the transfer it belongs to
};

struct Harness {
    IsoTpConfig aConfig;
    IsoTpConfig bConfig;
    uint8_t stMin = 0;
    uint16_t rCapacity = 0;
    std::unique_ptr<uint8_t[]> rBuffer;
    std::unique_ptr<uint8_t[]> bBuffer;
    IsoTpReceiver r;
    IsoTpReceiver b;
    IsoTpSender a;

    std::vector<std::vector<uint8_t>> messages; // every message A accepted, in order
    bool sending = false;                       // A has a transfer that has not ended
    size_t offset = 0;                          // bytes of the current message A emitted
    uint8_t sequence = 0;                       // the sequence number A's next CF must carry
    // What R should hold: the bytes of the first frame it took and of every
    // consecutive frame it took since, and the sequence number due next.
    std::vector<uint8_t> shadow;
    size_t shadowExpected = 0;
    uint8_t shadowSequence = 0;

    std::deque<Queued> aToB;
    std::deque<CanFrame> bToA;
    uint64_t now = 0;
};

CanFrame fuzzedFrame(fuzz::InputReader& input, const IsoTpConfig& receiving)
{
    const uint8_t shape = input.byte();
    const uint8_t length = shape % 9;
    uint32_t id = receiving.rxId;
    IdFormat format = receiving.format;
    switch ((shape >> 4) & 3) {
    case 2: id = receiving.txId; break;
    case 3:
        id = static_cast<uint32_t>(input.bytes(2)) & CanFrame::kMaxStandardId;
        format = IdFormat::Standard;
        break;
    default: break;
    }
    uint8_t bytes[8] = {};
    for (uint8_t i = 0; i < length; ++i) {
        bytes[i] = input.byte();
    }
    const bool remote = (shape & 0xC0) == 0xC0;
    const LinkResult<CanFrame> frame =
        remote ? CanFrame::makeRemote(id, format, length) : CanFrame::makeData(id, format, bytes, length);
    FUZZ_CHECK(frame.ok());
    return frame.value();
}

void checkFlowControl(const CanFrame& frame, const IsoTpConfig& config, uint8_t stMin)
{
    FUZZ_CHECK(frame.id() == config.txId && frame.format() == config.format && !frame.isRemote());
    FUZZ_CHECK(frame.length() == (config.padding.enabled ? 8 : 3));
    FUZZ_CHECK(frame.byte(0) == 0x30 || frame.byte(0) == 0x32);
    FUZZ_CHECK(frame.byte(1) == config.blockSize);
    FUZZ_CHECK(frame.byte(2) == stMin);
}

void checkIdle(const IsoTpReceiver& receiver)
{
    FUZZ_CHECK(!receiver.idle() || receiver.nextDeadlineNs() == IsoTpReceiver::kNoDeadline);
}

void receiverStep(const IsoTpStep& step, const IsoTpReceiver& receiver, const IsoTpConfig& config, uint8_t stMin,
                  uint16_t capacity)
{
    if (step.transmit) {
        checkFlowControl(step.frame, config, stMin);
    }
    if (step.completed) {
        FUZZ_CHECK(step.length >= 1 && step.length <= capacity);
        FUZZ_CHECK(receiver.idle());
    }
    FUZZ_CHECK(!(step.completed && step.rejected != LinkError::Ok));
    checkIdle(receiver);
}

// Checks one frame A emitted against the message it is sending.
void checkEmitted(Harness& h, const CanFrame& frame)
{
    const std::vector<uint8_t>& message = h.messages.back();
    FUZZ_CHECK(frame.id() == h.aConfig.txId && frame.format() == h.aConfig.format && !frame.isRemote());
    const uint8_t pci = frame.byte(0);
    size_t count = 0;
    size_t first = 1;
    switch (pci >> 4) {
    case 0: // single frame: the whole message
        FUZZ_CHECK(h.offset == 0);
        FUZZ_CHECK((pci & 0x0F) == message.size());
        count = message.size();
        break;
    case 1: // first frame: the length and the first six bytes
        FUZZ_CHECK(h.offset == 0);
        FUZZ_CHECK(static_cast<size_t>(((pci & 0x0F) << 8) | frame.byte(1)) == message.size());
        FUZZ_CHECK(frame.length() == 8);
        first = 2;
        count = 6;
        h.sequence = 1;
        break;
    case 2: // consecutive frame: the next bytes, the next sequence number
        FUZZ_CHECK(h.offset >= 6);
        FUZZ_CHECK((pci & 0x0F) == h.sequence);
        h.sequence = (h.sequence + 1) % 16;
        count = message.size() - h.offset < 7 ? message.size() - h.offset : 7;
        FUZZ_CHECK(count > 0);
        break;
    default:
        FUZZ_CHECK(false);
    }
    FUZZ_CHECK(frame.length() == (h.aConfig.padding.enabled ? 8 : first + count));
    for (size_t i = 0; i < count; ++i) {
        FUZZ_CHECK(frame.byte(first + i) == message[h.offset + i]);
    }
    for (size_t i = first + count; i < frame.length(); ++i) {
        FUZZ_CHECK(frame.byte(i) == h.aConfig.padding.value);
    }
    h.offset += count;
}

void senderStep(Harness& h, const IsoTpStep& step)
{
    if (step.aborted != LinkError::Ok) {
        FUZZ_CHECK(h.sending);
        h.sending = false;
    }
    if (step.transmit) {
        FUZZ_CHECK(h.sending);
        checkEmitted(h, step.frame);
        h.aToB.push_back({step.frame, h.messages.size() - 1});
    }
    if (step.completed) {
        FUZZ_CHECK(h.sending);
        FUZZ_CHECK(h.offset == h.messages.back().size() && step.length == h.offset);
        h.sending = false;
    }
    FUZZ_CHECK(h.a.idle() == !h.sending);
    FUZZ_CHECK(!h.a.idle() || h.a.nextDeadlineNs() == IsoTpSender::kNoDeadline);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    fuzz::InputReader input(data, size);
    Harness h;

    // The configuration header.
    const uint8_t blockSize = input.byte();
    const uint8_t stMinCode = input.byte();
    const uint8_t flags = input.byte();
    h.rCapacity = static_cast<uint16_t>(input.bytes(2) % IsoTpPci::kMaxMessageLength + 1);
    const uint8_t maxWaits = input.byte();
    const uint8_t timeouts = input.byte();

    IsoTpConfig& c = h.aConfig;
    if ((flags & 4) != 0) {
        c.format = IdFormat::Standard;
        c.txId = 0x7E0;
        c.rxId = 0x7E8;
    } else {
        c.txId = 0x18DAF110;
        c.rxId = 0x18DA10F1;
    }
    c.padding.enabled = (flags & 1) != 0;
    c.padding.value = static_cast<uint8_t>(flags | 0x0F);
    c.requirePaddedFrames = (flags & 2) != 0 && c.padding.enabled;
    c.maxWaitFrames = maxWaits;
    c.timeoutAsNs = (1 + (timeouts & 3)) * 250000000ull;
    c.timeoutBsNs = (1 + ((timeouts >> 2) & 3)) * 250000000ull;
    c.timeoutCrNs = (1 + ((timeouts >> 4) & 3)) * 250000000ull;
    c.blockSize = blockSize;
    c.separationTimeNs = IsoTpPci::separationTimeNs(stMinCode);
    FUZZ_CHECK(c.validate() == LinkError::Ok);
    h.bConfig = c;
    h.bConfig.txId = c.rxId;
    h.bConfig.rxId = c.txId;
    h.stMin = IsoTpPci::encodeSeparationTime(c.separationTimeNs).value();

    h.rBuffer.reset(new uint8_t[h.rCapacity]);
    h.bBuffer.reset(new uint8_t[IsoTpPci::kMaxMessageLength]);
    h.r = IsoTpReceiver::create(c, h.rBuffer.get(), h.rCapacity).value();
    h.b = IsoTpReceiver::create(h.bConfig, h.bBuffer.get(), IsoTpPci::kMaxMessageLength).value();
    h.a = IsoTpSender::create(c).value();

    while (!input.empty()) {
        const uint8_t operation = input.byte();
        h.now += input.byte() * kTimeUnitsNs[(operation >> 3) & 3];
        switch (operation & 7) {
        case 0: {
            const CanFrame frame = fuzzedFrame(input, c);
            const IsoTpStep step = h.r.onFrame(frame, h.now);
            receiverStep(step, h.r, c, h.stMin, h.rCapacity);
            const bool ours = frame.id() == c.rxId && frame.format() == c.format && !frame.isRemote()
                              && frame.length() > 0;
            const uint8_t type = frame.byte(0) >> 4;
            if (step.completed && ours && type == 0) {
                for (uint16_t i = 0; i < step.length; ++i) {
                    FUZZ_CHECK(h.rBuffer[i] == frame.byte(1 + i));
                }
            }
            if (ours && type == 1 && step.transmit && step.frame.byte(0) == 0x30) {
                // A first frame taken: the shadow restarts from it.
                h.shadow.assign(frame.data() + 2, frame.data() + 8);
                h.shadowExpected = static_cast<size_t>(((frame.byte(0) & 0x0F) << 8) | frame.byte(1));
                h.shadowSequence = 1;
            }
            if (ours && type == 2 && step.rejected == LinkError::Ok) {
                if (step.aborted == LinkError::WrongSequenceNumber) {
                    FUZZ_CHECK((frame.byte(0) & 0x0F) != h.shadowSequence);
                } else {
                    // Taken: it must be the one due, carrying the next bytes.
                    FUZZ_CHECK(step.aborted == LinkError::Ok);
                    FUZZ_CHECK((frame.byte(0) & 0x0F) == h.shadowSequence);
                    h.shadowSequence = (h.shadowSequence + 1) % 16;
                    const size_t count = h.shadowExpected - h.shadow.size() < 7 ? h.shadowExpected - h.shadow.size() : 7;
                    h.shadow.insert(h.shadow.end(), frame.data() + 1, frame.data() + 1 + count);
                    FUZZ_CHECK(step.completed == (h.shadow.size() == h.shadowExpected));
                    if (step.completed) {
                        FUZZ_CHECK(step.length == h.shadowExpected);
                        for (size_t i = 0; i < h.shadow.size(); ++i) {
                            FUZZ_CHECK(h.rBuffer[i] == h.shadow[i]);
                        }
                    }
                }
            }
            break;
        }
        case 1:
            receiverStep(h.r.poll(h.now), h.r, c, h.stMin, h.rCapacity);
            break;
        case 2: {
            const size_t length = input.bytes(2) % 4200;
            const uint8_t seed = input.byte();
            std::vector<uint8_t> message(length);
            for (size_t i = 0; i < length; ++i) {
                message[i] = static_cast<uint8_t>(seed + i * 31 + (i >> 8));
            }
            // A keeps pointing into the message it sends, so a new one is
            // stored only once A has taken it, never while a transfer runs.
            h.messages.push_back(std::move(message));
            const std::vector<uint8_t>& stored = h.messages.back();
            const bool wasIdle = !h.sending;
            const IsoTpStep step = h.a.start(stored.empty() ? nullptr : stored.data(), stored.size(), h.now);
            if (step.aborted != LinkError::Ok) {
                FUZZ_CHECK(h.sending);
                h.sending = false;
            }
            const bool acceptable = length >= 1 && length <= IsoTpPci::kMaxMessageLength;
            FUZZ_CHECK(step.transmit == (acceptable && !h.sending));
            if (!step.transmit) {
                FUZZ_CHECK(step.rejected != LinkError::Ok);
                FUZZ_CHECK(wasIdle || step.rejected == LinkError::Busy || !acceptable || step.aborted != LinkError::Ok);
                h.messages.pop_back();
                break;
            }
            h.sending = true;
            h.offset = 0;
            IsoTpStep emitted = step;
            emitted.aborted = LinkError::Ok;
            senderStep(h, emitted);
            break;
        }
        case 3:
            if (!h.messages.empty()) {
                senderStep(h, h.a.onTransmitConfirmed(h.now));
            } else {
                FUZZ_CHECK(h.a.onTransmitConfirmed(h.now).rejected == LinkError::NotExpected);
            }
            break;
        case 4: {
            const CanFrame frame = fuzzedFrame(input, c);
            if (!h.messages.empty()) {
                senderStep(h, h.a.onFrame(frame, h.now));
            } else {
                FUZZ_CHECK(!h.a.onFrame(frame, h.now).transmit);
            }
            break;
        }
        case 5:
            if (!h.messages.empty()) {
                senderStep(h, h.a.poll(h.now));
            }
            break;
        case 6:
            if (!h.aToB.empty()) {
                const Queued queued = h.aToB.front();
                h.aToB.pop_front();
                const IsoTpStep step = h.b.onFrame(queued.frame, h.now);
                receiverStep(step, h.b, h.bConfig, h.stMin, IsoTpPci::kMaxMessageLength);
                if (step.transmit) {
                    h.bToA.push_back(step.frame);
                }
                if (step.completed) {
                    const std::vector<uint8_t>& sent = h.messages[queued.message];
                    FUZZ_CHECK(step.length == sent.size());
                    for (size_t i = 0; i < sent.size(); ++i) {
                        FUZZ_CHECK(h.bBuffer[i] == sent[i]);
                    }
                }
            }
            break;
        case 7:
            if (!h.bToA.empty()) {
                const CanFrame frame = h.bToA.front();
                h.bToA.pop_front();
                if (!h.messages.empty()) {
                    senderStep(h, h.a.onFrame(frame, h.now));
                }
            }
            break;
        }
    }
    return 0;
}
