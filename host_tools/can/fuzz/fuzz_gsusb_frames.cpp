// Fuzz target: what a gs_usb adapter sends the host (host_tools/can/src/
// GsUsbProtocol.cpp): every bulk IN transfer, read as an interface of one
// and of two channels, with and without hardware timestamps; and the same
// bytes as the answers to DEVICE_CONFIG and BT_CONST, the latter then used
// to compute a bit timing. The input is the transfer itself, so the seeds
// are transfers as an adapter sends them.
//
// The checks: a transfer is accepted only whole (20 bytes, 24 with
// timestamps); an accepted host frame encodes back to the very bytes it was
// read from; an accepted transfer is an echo or brings at least one frame or
// event, every frame valid and going back to the device as the same frame;
// the structures' decoders give back their input; and a chosen bit timing
// keeps to the adapter's limits and to the rate within 0.1 %.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostcan/GsUsbProtocol.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

using namespace hostcan::gsusb;

namespace {

// Clocks above this would make the bit timing search of one input take
// milliseconds; no CAN controller runs faster than a few tens of MHz.
constexpr uint32_t kFuzzMaxClock = 200'000'000;

void checkTransfer(const uint8_t* data, size_t size, bool timestamps, unsigned channels)
{
    const Result<HostFrame> frame = decodeHostFrame(data, size, timestamps);
    const Result<InTransfer> in = decodeInTransfer(data, size, timestamps, channels);
    FUZZ_CHECK(!in.ok() || frame.ok());
    if (!frame.ok()) {
        FUZZ_CHECK(!frame.reason().empty() && !in.reason().empty());
        return;
    }
    const size_t whole = timestamps ? kHostFrameTimestampedSize : kHostFrameSize;
    FUZZ_CHECK(size >= whole);
    const std::vector<uint8_t> again = encodeHostFrame(frame.value());
    FUZZ_CHECK(again.size() == whole && std::equal(again.begin(), again.end(), data));
    if (!in.ok()) {
        FUZZ_CHECK(!in.reason().empty());
        return;
    }
    FUZZ_CHECK(in.value().channel < channels);
    FUZZ_CHECK(in.value().isEcho || !in.value().received.empty());
    FUZZ_CHECK(!in.value().isEcho || in.value().echoId != kEchoIdReceived);
    for (const hostcan::Received& r : in.value().received) {
        FUZZ_CHECK(r.kind != hostcan::Received::Kind::Timeout);
        if (r.kind != hostcan::Received::Kind::Frame) {
            continue;
        }
        FUZZ_CHECK(r.frame.length() <= 8 && r.frame.id() <= can::CanFrame::maxId(r.frame.format()));
        const HostFrame out = hostFrameFor(r.frame, 0, in.value().channel);
        const Result<can::CanFrame> back = canFrameOf(out);
        FUZZ_CHECK(back.ok() && back.value() == r.frame);
    }
}

void checkStructures(const uint8_t* data, size_t size)
{
    const Result<DeviceConfig> config = decodeDeviceConfig(data, size);
    FUZZ_CHECK(config.ok() == (size >= DeviceConfig::kSize));
    if (config.ok()) {
        const std::vector<uint8_t> again = encodeDeviceConfig(config.value());
        FUZZ_CHECK(std::equal(again.begin() + 3, again.end(), data + 3)); // The reserved bytes are not kept.
        FUZZ_CHECK(config.value().channels() >= 1 && config.value().channels() <= 256);
    }
    const Result<BitTiming> timing = decodeBitTiming(data, size);
    if (timing.ok()) {
        const std::vector<uint8_t> again = encodeBitTiming(timing.value());
        FUZZ_CHECK(std::equal(again.begin(), again.end(), data));
    }
    const Result<DeviceMode> mode = decodeDeviceMode(data, size);
    if (mode.ok()) {
        const std::vector<uint8_t> again = encodeDeviceMode(mode.value());
        FUZZ_CHECK(std::equal(again.begin(), again.end(), data));
    }
    const Result<BitTimingConst> limits = decodeBitTimingConst(data, size);
    if (!limits.ok() || limits.value().clockHz > kFuzzMaxClock) {
        return;
    }
    const BitTimingConst& c = limits.value();
    FUZZ_CHECK(c.clockHz > 0 && c.brpIncrement > 0 && c.tseg1Min <= c.tseg1Max && c.brpMin <= c.brpMax);
    // The rate from the bytes after the structure, within what computeBitTiming takes and a little outside.
    uint32_t rate = 500'000;
    if (size >= BitTimingConst::kSize + 3) {
        const uint8_t* r = data + BitTimingConst::kSize;
        rate = (uint32_t{r[0]} | uint32_t{r[1]} << 8 | uint32_t{r[2]} << 16) % (kMaxBitRate + 2);
    }
    const Result<BitTimingChoice> choice = computeBitTiming(rate, c);
    if (!choice.ok()) {
        FUZZ_CHECK(!choice.reason().empty());
        return;
    }
    const BitTiming& t = choice.value().timing;
    const uint64_t tseg1 = uint64_t{t.propSeg} + t.phaseSeg1;
    FUZZ_CHECK(rate >= kMinBitRate && rate <= kMaxBitRate);
    FUZZ_CHECK(tseg1 >= std::max<uint32_t>(c.tseg1Min, 1) && tseg1 <= c.tseg1Max);
    FUZZ_CHECK(t.phaseSeg2 >= std::max<uint32_t>(c.tseg2Min, 1) && t.phaseSeg2 <= c.tseg2Max);
    FUZZ_CHECK(t.brp >= c.brpMin && t.brp <= c.brpMax && (t.brp - std::max<uint32_t>(c.brpMin, 1)) % c.brpIncrement == 0);
    FUZZ_CHECK(t.sjw >= 1 && t.sjw <= t.phaseSeg2 && t.sjw <= std::max<uint32_t>(t.phaseSeg1, 1));
    const uint64_t quanta = 1 + tseg1 + t.phaseSeg2;
    FUZZ_CHECK(choice.value().quanta == quanta);
    const uint64_t made = uint64_t{t.brp} * quanta * rate;
    const uint64_t error = made > c.clockHz ? made - c.clockHz : c.clockHz - made;
    FUZZ_CHECK(error * 1'000'000 < (uint64_t{kMaxBitRateErrorPpm} + 1) * made); // The search rounds its ppm down.
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    for (bool timestamps : {false, true}) {
        for (unsigned channels : {1u, 2u}) {
            checkTransfer(data, size, timestamps, channels);
        }
    }
    checkStructures(data, size);
    return 0;
}
