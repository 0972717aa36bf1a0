// The text form of a CAN frame that can-utils made the common language of
// CAN tools: cansend's `<id>#<data>` to write one, candump's columns to show
// one. The controller's `can` console command and the host tools take and
// print frames this way, so an engineer can paste a line from candump into
// either, and a script can parse what both print.
//
//     123#DEADBEEF      standard frame 0x123, 4 bytes (3 hex digits: standard)
//     1ABCDEF0#01.02    extended frame (8 hex digits), dots between bytes allowed
//     123#              no data
//     123#R   123#R4    remote frame, with its data length code 0..8
//
// Pure code without hardware: built for the host tests, the fuzzers and the
// firmware alike.
#pragma once

#include <can/CanFrame.hpp>
#include <can/LinkResult.hpp>

#include <stddef.h>

namespace can {

class FrameText {
public:
    /// The longest line format() writes: "1ABCDEF0   [8]  " and 8 bytes as " xx".
    static constexpr size_t kMaxFormattedLength = 8 + 3 + 3 + 1 + 8 * 3;

    /// Parses cansend's form. InvalidHexDigit for a character that should
    /// be a hexadecimal digit (or the '#' missing), InvalidIdentifier for an
    /// identifier that is not 3 or 8 digits or does not fit its format,
    /// InvalidDataLength for more than 8 bytes or an odd digit, and
    /// LineTooLong for text past what any frame needs.
    static LinkResult<CanFrame> parse(const char* text);

    /// Writes candump's form without the interface column: the identifier
    /// (3 digits standard, 8 extended), "[n]" and the bytes, or "remote
    /// request" for a remote frame, upper-case hexadecimal, NUL-terminated.
    /// Returns the length written, 0 when @p capacity cannot hold it.
    static size_t format(const CanFrame& frame, char* buffer, size_t capacity);
};

} // namespace can
