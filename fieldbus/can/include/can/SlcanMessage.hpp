// One line of the slcan (Lawicel CAN232/CANUSB) ASCII protocol, decoded.
//
// The same line protocol runs both ways between a host and an adapter
// (CANable, USBtin, Linux's slcan line discipline on the host side): the
// host sends commands and frames to transmit, the adapter answers with
// replies and the frames it received. A message is one of the kinds below;
// which fields mean something depends on the kind.
#pragma once

#include <can/CanFrame.hpp>

#include <stdint.h>

namespace can {

enum class SlcanMessageKind : uint8_t {
    Frame,            ///< `t`, `T`, `r`, `R`: a frame to send (host) or received (adapter), maybe timestamped.
    SetBitrate,       ///< `S0`..`S8`: the standard bit rate `bitrateIndex`.
    Open,             ///< `O`: join the bus.
    Close,            ///< `C`: leave the bus.
    ReadStatusFlags,  ///< `F`: ask for the status flags.
    StatusFlags,      ///< `Fxx`: the adapter's status flags, `statusFlags`.
    ReadVersion,      ///< `V`: ask for the versions.
    Version,          ///< `Vhhss`: hardware and software version, `hardwareVersion`, `softwareVersion`.
    ReadSerial,       ///< `N`: ask for the serial number.
    Serial,           ///< `Nxxxx`: the serial number, four characters in `serial`.
    SetTimestamps,    ///< `Z0`, `Z1`: append timestamps to received frames, `timestampsOn`.
    Ok,               ///< CR alone: the command was carried out (hosts also send it to flush a line).
    Error,            ///< BELL (0x07) alone: the command was refused.
    TransmitAck,      ///< `z` (standard) or `Z` (extended) alone: a frame was queued for the bus.
};

struct SlcanMessage {
    /// Lawicel's timestamp counts milliseconds and wraps after a minute: 0..0xEA5F.
    static constexpr uint16_t kMaxTimestampMs = 59999;
    /// Number of characters of a serial number.
    static constexpr uint8_t kSerialLength = 4;

    SlcanMessageKind kind = SlcanMessageKind::Ok;

    CanFrame frame;             ///< Frame.
    bool hasTimestamp = false;  ///< Frame: a timestamp followed the data.
    uint16_t timestampMs = 0;   ///< Frame: the adapter's millisecond timestamp.

    uint8_t bitrateIndex = 0;       ///< SetBitrate: 0..8 (SlcanCodec::bitrate()).
    uint8_t statusFlags = 0;        ///< StatusFlags: SlcanCodec::kStatus* bits.
    uint8_t hardwareVersion = 0;    ///< Version: two hex digits, e.g. 0x10 for 1.0.
    uint8_t softwareVersion = 0;    ///< Version: two hex digits, e.g. 0x13 for 1.3.
    char serial[kSerialLength] = {}; ///< Serial: letters and digits.
    bool timestampsOn = false;      ///< SetTimestamps.
    IdFormat ackFormat = IdFormat::Standard; ///< TransmitAck: `z` standard, `Z` extended.
};

} // namespace can
