// The slcan (Lawicel CAN232/CANUSB) ASCII line protocol: parser and formatter.
//
// This is the protocol of CANable and USBtin adapters and of Linux's slcan
// line discipline (slcand, `ip link set slcan0 type can bitrate ...`), which
// sends `C\rS6\r`, optionally `F\r`, then `O\r`, and exchanges frames as
//
//     t iii l dd..  [tttt] CR     standard data frame: 3 hex id, DLC 0..8, 2 hex per byte
//     T iiiiiiii l dd.. [tttt] CR extended data frame: 8 hex id (at most 1FFFFFFF)
//     r iii l [tttt] CR           standard remote frame, no data
//     R iiiiiiii l [tttt] CR      extended remote frame
//
// where tttt is the adapter's optional millisecond timestamp (after `Z1`).
// The subset implemented is the one those three speak: frames, `S0`-`S8`,
// `O`, `C`, `F`, `V`, `N`, `Z0`/`Z1` and the replies CR (OK), BELL (error),
// `z`/`Z` (frame queued), `Fxx`, `Vhhss`, `Nxxxx`. Both directions decode,
// so the codec serves a host tool talking to an adapter and a node acting as
// one.
//
// The parser takes one byte at a time, as a UART interrupt delivers them,
// into a bounded line buffer. A line ends at CR. A BELL at the start of a
// line is the error reply; in the middle of one it cuts the line short, as
// Linux's slcan driver takes it, and the line is refused. A line feed at the
// start of a line is skipped, so a terminal's CR LF works. Every refused
// line is counted by reason in the statistics, and the next line is parsed
// afresh: a line longer than any the protocol defines is dropped up to its
// CR, never split. Hexadecimal digits are accepted in either case and
// written in upper case, as Linux writes them.
#pragma once

#include <can/LinkResult.hpp>
#include <can/SlcanMessage.hpp>

#include <stddef.h>
#include <stdint.h>

namespace can {

class SlcanCodec {
public:
    /// The longest line the protocol defines: an extended data frame with 8
    /// bytes and a timestamp, `T` + 8 + 1 + 16 + 4 characters before the CR.
    static constexpr size_t kMaxLineLength = 30;

    static constexpr char kCarriageReturn = '\r';
    static constexpr char kLineFeed = '\n';
    static constexpr char kBell = '\a';

    /// Number of `Sn` bit rates.
    static constexpr uint8_t kBitrateCount = 9;

    // Status flags of the `F` reply (Lawicel CAN232 manual, command F).
    static constexpr uint8_t kStatusReceiveQueueFull = 1u << 0;  ///< The receive FIFO is full.
    static constexpr uint8_t kStatusTransmitQueueFull = 1u << 1; ///< The transmit FIFO is full.
    static constexpr uint8_t kStatusErrorWarning = 1u << 2;      ///< Error warning (EI).
    static constexpr uint8_t kStatusDataOverrun = 1u << 3;       ///< Data overrun (DOI).
    static constexpr uint8_t kStatusErrorPassive = 1u << 5;      ///< Error passive (EPI); bit 4 is unused.
    static constexpr uint8_t kStatusArbitrationLost = 1u << 6;   ///< Arbitration lost (ALI).
    static constexpr uint8_t kStatusBusError = 1u << 7;          ///< Bus error (BEI).

    /// What a byte fed to the parser completed.
    enum class Outcome : uint8_t {
        Pending,  ///< The line goes on.
        Message,  ///< A line was decoded into message().
        Rejected, ///< A line was refused; lastError() says why.
    };

    /// Lines decoded and refused since the codec was made, by reason.
    struct Statistics {
        uint32_t messages = 0;          ///< Lines decoded.
        uint32_t rejected = 0;          ///< Lines refused, every reason together.
        uint32_t invalidHexDigit = 0;   ///< A character where a hex digit belongs.
        uint32_t lineTooLong = 0;       ///< More than kMaxLineLength characters.
        uint32_t invalidLineLength = 0; ///< A length that does not fit the command.
        uint32_t invalidIdentifier = 0; ///< A standard identifier above 7FF or extended above 1FFFFFFF.
        uint32_t invalidDataLength = 0; ///< A data length code other than 0..8.
        uint32_t unknownCommand = 0;    ///< A command letter outside the subset.
        uint32_t invalidArgument = 0;   ///< S9, Z2, a serial number with other than letters and digits.
        uint32_t lineInterrupted = 0;   ///< A BELL in the middle of a line.
    };

    /// Takes the next received byte.
    Outcome feed(uint8_t byte);

    /// The last message decoded; valid after feed() returned Message, until the next one.
    const SlcanMessage& message() const { return message_; }

    /// Why the last refused line was refused.
    LinkError lastError() const { return lastError_; }

    const Statistics& statistics() const { return statistics_; }

    /// Drops a partial line, e.g. after the serial line was reopened.
    void reset();

    /// Decodes one complete line, without its CR; what feed() does at a CR.
    static LinkResult<SlcanMessage> parseLine(const char* line, size_t length);

    /// Writes @p message as a line, with its CR (or the lone BELL of Error),
    /// into @p output; returns the number of characters, or BufferTooSmall,
    /// or InvalidArgument for a field outside the protocol (a bit rate index
    /// above 8, a timestamp above 59999, a serial number with other than
    /// letters and digits). No NUL is appended.
    static LinkResult<size_t> format(const SlcanMessage& message, char* output, size_t capacity);

    /// The bit rate of `S<index>` in bit/s: 10k, 20k, 50k, 100k, 125k, 250k,
    /// 500k, 800k, 1M; 0 for an index above 8.
    static uint32_t bitrate(uint8_t index);

    /// The `S` index of @p bitsPerSecond, or InvalidArgument for a rate the command lacks.
    static LinkResult<uint8_t> bitrateIndex(uint32_t bitsPerSecond);

private:
    Outcome reject(LinkError error);

    char line_[kMaxLineLength] = {};
    uint8_t length_ = 0;
    bool overlong_ = false;
    SlcanMessage message_;
    LinkError lastError_ = LinkError::Ok;
    Statistics statistics_;
};

} // namespace can
