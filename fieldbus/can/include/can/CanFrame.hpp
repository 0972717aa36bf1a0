// One classic CAN frame (ISO 11898-1): identifier, remote flag, up to 8 bytes.
//
// A CanFrame is valid by construction: the factories refuse an identifier
// that does not fit its format and a data length code above 8, with the
// reason, so every layer above (the DCOS identifier, ISO-TP, slcan, a chip
// driver) can take a frame without checking it again. Bytes past the data
// length are kept zero, and a remote frame carries no data, so two frames
// compare equal exactly when they put the same bits on the bus.
//
// Classic CAN lets a data length code of 9..15 stand for 8 bytes; DCOS never
// sends one and refuses to receive one, as Linux's SocketCAN and the slcan
// protocol do, so that the length of a frame is always its code.
#pragma once

#include <can/LinkResult.hpp>

#include <stddef.h>
#include <stdint.h>

namespace can {

/// The identifier format of a frame.
enum class IdFormat : uint8_t {
    Standard = 0, ///< 11-bit base format (CAN 2.0A).
    Extended = 1, ///< 29-bit extended format (CAN 2.0B); DCOS's own frames use it.
};

class CanFrame {
public:
    /// Largest identifier of the 11-bit base format.
    static constexpr uint32_t kMaxStandardId = 0x7FF;
    /// Largest identifier of the 29-bit extended format.
    static constexpr uint32_t kMaxExtendedId = 0x1FFFFFFF;
    /// Largest data length of a classic CAN frame, in bytes.
    static constexpr uint8_t kMaxDataLength = 8;

    /// A standard data frame with identifier 0 and no data.
    constexpr CanFrame() = default;

    /// Whether a frame with these fields would be valid; the reason if not.
    static constexpr LinkError check(uint32_t id, IdFormat format, uint8_t length)
    {
        if (id > maxId(format)) {
            return LinkError::InvalidIdentifier;
        }
        if (length > kMaxDataLength) {
            return LinkError::InvalidDataLength;
        }
        return LinkError::Ok;
    }

    /// A data frame carrying @p length bytes from @p bytes (which may be
    /// null when @p length is 0).
    static LinkResult<CanFrame> makeData(uint32_t id, IdFormat format, const uint8_t* bytes, uint8_t length);

    /// A remote frame asking for @p length bytes; it carries no data.
    static LinkResult<CanFrame> makeRemote(uint32_t id, IdFormat format, uint8_t length);

    /// The largest identifier of @p format.
    static constexpr uint32_t maxId(IdFormat format)
    {
        return format == IdFormat::Extended ? kMaxExtendedId : kMaxStandardId;
    }

    constexpr uint32_t id() const { return id_; }
    constexpr IdFormat format() const { return format_; }
    constexpr bool isExtended() const { return format_ == IdFormat::Extended; }
    constexpr bool isRemote() const { return remote_; }
    /// The data length code: the number of data bytes, or of bytes asked for by a remote frame.
    constexpr uint8_t length() const { return length_; }
    /// The data bytes; length() of them are meaningful for a data frame, none for a remote frame.
    constexpr const uint8_t* data() const { return data_; }
    /// Data byte @p index; 0 past the data.
    constexpr uint8_t byte(size_t index) const { return index < kMaxDataLength ? data_[index] : 0; }

    friend bool operator==(const CanFrame& a, const CanFrame& b);

private:
    uint32_t id_ = 0;
    IdFormat format_ = IdFormat::Standard;
    bool remote_ = false;
    uint8_t length_ = 0;
    uint8_t data_[kMaxDataLength] = {};
};

} // namespace can
