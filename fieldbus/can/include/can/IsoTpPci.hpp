// ISO 15765-2 protocol control information (N_PCI) for classic CAN, normal addressing.
//
// The first byte of every ISO-TP frame says what the frame is (ISO 15765-2,
// "N_PCItype" in "Protocol control information specification") and carries
// one 4-bit parameter; flow control frames carry two more bytes. This class
// holds the constants of that clause and the separation-time encoding, so the
// sender and the receiver cannot disagree on a number:
//
//     byte 0 bits 7..4   N_PCItype: 0 SF, 1 FF, 2 CF, 3 FC, 4..15 reserved
//     SF  byte 0 bits 3..0  SF_DL, 1..7 data bytes follow
//     FF  byte 0 bits 3..0 + byte 1   FF_DL (12 bits, 8..4095); 6 data bytes follow
//         (FF_DL = 0 is the escape of the 2016 edition: a 32-bit FF_DL follows)
//     CF  byte 0 bits 3..0  SequenceNumber (SN), 1..7 data bytes follow
//     FC  byte 0 bits 3..0  FlowStatus (FS); byte 1 BlockSize (BS); byte 2 STmin
//
// Only normal addressing is implemented: the whole CAN identifier is the
// address (DCOS puts source and destination node in it), so every frame
// keeps all 8 data bytes for N_PCI and data.
#pragma once

#include <can/CanFrame.hpp>
#include <can/LinkResult.hpp>

#include <stddef.h>
#include <stdint.h>

namespace can {

/// N_PCItype, ISO 15765-2 "N_PCItype" (values 4..15 are reserved).
enum class PciType : uint8_t {
    SingleFrame = 0,       ///< SF: a whole message of 1..7 bytes.
    FirstFrame = 1,        ///< FF: the first 6 bytes of a segmented message and its length.
    ConsecutiveFrame = 2,  ///< CF: the next 7 bytes of a segmented message.
    FlowControl = 3,       ///< FC: the receiver paces the sender.
};

/// FlowStatus of a flow control frame, ISO 15765-2 "FlowStatus (FS) parameter definition".
enum class FlowStatus : uint8_t {
    ContinueToSend = 0,  ///< CTS: send the next block of consecutive frames.
    Wait = 1,            ///< WT: wait for another flow control frame.
    Overflow = 2,        ///< OVFLW: the message does not fit the receiver's buffer; abort.
};

/// How frames shorter than 8 bytes are sent.
///
/// ISO 15765-2 allows both: "CAN frame data optimization" (the DLC is just
/// what the N_PCI and data need) or padding every frame to 8 bytes. Linux's
/// can-isotp optimizes unless CAN_ISOTP_TX_PADDING is set, and so do
/// isotpsend and isotprecv without -p; DCOS defaults to the same.
struct IsoTpPadding {
    /// Pad with 0xCC, Linux's CAN_ISOTP_DEFAULT_PAD_CONTENT: 11001100 has no
    /// run of equal bits long enough to need a stuff bit.
    static constexpr uint8_t kDefaultValue = 0xCC;

    bool enabled = false;          ///< Send every frame with 8 data bytes.
    uint8_t value = kDefaultValue; ///< The byte filling the unused ones.
};

class IsoTpPci {
public:
    /// Shift of N_PCItype within byte 0.
    static constexpr unsigned kTypeShift = 4;
    /// Mask of the 4-bit parameter in byte 0 (SF_DL, FF_DL high bits, SN, FS).
    static constexpr uint8_t kLowNibble = 0x0F;

    /// Largest SF_DL with a classic CAN frame and normal addressing
    /// ("SF_DL error handling": a larger one is ignored).
    static constexpr uint8_t kMaxSingleFrameData = 7;
    /// Bytes of N_PCI in a first frame with a 12-bit FF_DL.
    static constexpr uint8_t kFirstFramePciLength = 2;
    /// Bytes of N_PCI in a first frame with the 32-bit FF_DL escape.
    static constexpr uint8_t kEscapedFirstFramePciLength = 6;
    /// Data bytes in a first frame with a 12-bit FF_DL.
    static constexpr uint8_t kFirstFrameData = CanFrame::kMaxDataLength - kFirstFramePciLength;
    /// Data bytes in a full consecutive frame.
    static constexpr uint8_t kConsecutiveFrameData = CanFrame::kMaxDataLength - 1;
    /// Length of a flow control frame without padding: FS, BS, STmin.
    static constexpr uint8_t kFlowControlLength = 3;
    /// Smallest FF_DL with normal addressing ("FF_DL error handling": smaller is ignored,
    /// since such a message fits a single frame).
    static constexpr uint16_t kMinSegmentedLength = kMaxSingleFrameData + 1;
    /// Largest FF_DL without the escape: the 12-bit field. DCOS messages never exceed it.
    static constexpr uint16_t kMaxMessageLength = 0xFFF;
    /// SequenceNumber modulus: SN counts 1, 2, .. 15, 0, 1, .. (ISO 15765-2 9.6.4.3).
    static constexpr uint8_t kSequenceModulus = 16;

    /// STmin 0x00..0x7F: milliseconds ("SeparationTime (STmin) parameter definition").
    static constexpr uint8_t kStMinMaxMilliseconds = 0x7F;
    /// STmin 0xF1..0xF9: 100..900 microseconds in steps of 100.
    static constexpr uint8_t kStMinFirstMicroseconds = 0xF1;
    static constexpr uint8_t kStMinLastMicroseconds = 0xF9;
    static constexpr uint32_t kStMinMicrosecondStepNs = 100000;
    static constexpr uint32_t kNanosecondsPerMillisecond = 1000000;
    /// The longest separation time, 127 ms: what a sender uses for a reserved
    /// STmin value (ISO 15765-2:2016 9.6.5.5).
    static constexpr uint32_t kMaxSeparationTimeNs = kStMinMaxMilliseconds * kNanosecondsPerMillisecond;

    /// The separation time an STmin byte asks for, in nanoseconds; a reserved
    /// value (0x80..0xF0, 0xFA..0xFF) counts as 127 ms.
    static constexpr uint32_t separationTimeNs(uint8_t stMin)
    {
        if (stMin <= kStMinMaxMilliseconds) {
            return stMin * kNanosecondsPerMillisecond;
        }
        if (stMin >= kStMinFirstMicroseconds && stMin <= kStMinLastMicroseconds) {
            return (stMin - (kStMinFirstMicroseconds - 1)) * kStMinMicrosecondStepNs;
        }
        return kMaxSeparationTimeNs;
    }

    /// The STmin byte for a separation time of at least @p nanoseconds,
    /// rounded up to the next value STmin can express so that a sender never
    /// goes faster than asked; InvalidConfiguration above 127 ms.
    static constexpr LinkResult<uint8_t> encodeSeparationTime(uint32_t nanoseconds)
    {
        if (nanoseconds == 0) {
            return static_cast<uint8_t>(0);
        }
        // Checked first, so that the rounding below cannot overflow.
        if (nanoseconds > kMaxSeparationTimeNs) {
            return LinkError::InvalidConfiguration;
        }
        const uint32_t steps = (nanoseconds + kStMinMicrosecondStepNs - 1) / kStMinMicrosecondStepNs;
        if (steps <= kStMinLastMicroseconds - (kStMinFirstMicroseconds - 1)) {
            return static_cast<uint8_t>(kStMinFirstMicroseconds - 1 + steps);
        }
        return static_cast<uint8_t>((nanoseconds + kNanosecondsPerMillisecond - 1) / kNanosecondsPerMillisecond);
    }

    /// The N_PCItype of a received frame; ShortFrame for a frame with no
    /// data, ReservedPciType for the values 4..15.
    static LinkResult<PciType> typeOf(const CanFrame& frame);

    /// A data frame on @p id with @p length bytes from @p bytes, padded as
    /// @p padding says. @p id must fit @p format and @p length be 1..8.
    static CanFrame makeFrame(uint32_t id, IdFormat format, const uint8_t* bytes, uint8_t length,
                              const IsoTpPadding& padding);

    /// A flow control frame on @p id.
    static CanFrame makeFlowControl(uint32_t id, IdFormat format, FlowStatus status, uint8_t blockSize,
                                    uint8_t stMin, const IsoTpPadding& padding);

    /// The first N_PCI byte of type @p type with parameter @p parameter.
    static constexpr uint8_t pciByte(PciType type, uint8_t parameter)
    {
        return static_cast<uint8_t>((static_cast<uint8_t>(type) << kTypeShift) | (parameter & kLowNibble));
    }
};

static_assert(IsoTpPci::separationTimeNs(0xF1) == 100000 && IsoTpPci::separationTimeNs(0xF9) == 900000,
              "0xF1..0xF9 are 100..900 microseconds");
static_assert(IsoTpPci::separationTimeNs(0x7F) == 127000000 && IsoTpPci::separationTimeNs(0x80) == 127000000,
              "0x7F is 127 ms, and a reserved value is taken as 127 ms");
static_assert(IsoTpPci::encodeSeparationTime(100000).value() == 0xF1
                  && IsoTpPci::encodeSeparationTime(100001).value() == 0xF2
                  && IsoTpPci::encodeSeparationTime(900001).value() == 0x01,
              "encoding rounds up to the next expressible separation time");

} // namespace can
