// How long a frame holds the bus: its bits with worst-case bit stuffing and
// the interframe space, the figure bus load and response-time analysis use
// (Davis, Burns, Bril and Lukkien, "Controller Area Network (CAN)
// schedulability analysis: refuted, revisited and revised", 2007, eq. 15):
//
//     bits = g + 8s + 13 + floor((g + 8s - 1) / 4)
//
// with s data bytes and g = 34 for a standard frame, 54 for an extended one
// (the bits exposed to stuffing besides the data). The 13 counts the CRC
// delimiter, ACK slot and delimiter, end of frame and the 3-bit intermission,
// which are never stuffed. A full 8-byte frame takes 135 bits standard and
// 160 bits extended: at 1 Mbit/s at most 7,407 standard or 6,250 extended frames a second.
//
// The lab's CAN bus hub (docs/protocols/labbus.md) times frames the same way.
#pragma once

#include <can/CanFrame.hpp>

#include <stdint.h>

namespace can {

/// Bits @p frame holds the bus for, worst-case stuffing and intermission included.
constexpr uint32_t frameBits(const CanFrame& frame)
{
    const uint32_t exposed = (frame.isExtended() ? 54u : 34u) + 8u * (frame.isRemote() ? 0u : frame.length());
    return exposed + 13u + (exposed - 1u) / 4u;
}

/// Nanoseconds @p frame holds a bus of @p bitRate bit/s (rounded up).
constexpr uint64_t frameNanoseconds(const CanFrame& frame, uint32_t bitRate)
{
    return bitRate == 0 ? 0 : (uint64_t{frameBits(frame)} * 1'000'000'000u + bitRate - 1) / bitRate;
}

} // namespace can
