// Why a controller image was refused, and a value-or-reason result.
//
// Every check of a controller image (docs/boot.md, "Controller images")
// ends in one of these. The reasons are fine-grained on purpose: an
// engineer whose image is refused must learn from the tool whether it is
// damaged, meant for another board, signed by another key or simply older
// than what the controller runs, because each has a different remedy.
#pragma once

#include <stdint.h>

namespace image {

enum class ImageError : uint8_t {
    Ok = 0,
    Truncated,         ///< Shorter than its header, or than the header says.
    TrailingData,      ///< Longer than the header says.
    BadMagic,          ///< Not a DCOS controller image at all.
    UnsupportedFormat, ///< A header format or size this verifier does not know.
    MalformedHeader,   ///< Reserved fields or flags not zero, a zero-sized payload.
    UnknownBoard,      ///< A board type no DCOS board has.
    WrongBoard,        ///< Built for another board than the one checking it.
    Oversized,         ///< Larger than the slot that is to hold it.
    BadAddresses,      ///< Entry outside the payload, or memory outside the board's window.
    UnknownKey,        ///< Signed by a key the controller does not trust.
    BadSignature,      ///< The signature does not verify: altered, or not signed.
    PayloadMismatch,   ///< The payload is not the one the signed header describes.
    Downgrade,         ///< Older than the installed image, and downgrades not allowed.
};

/// One line for an engineer: what is wrong with the image.
const char* imageErrorText(ImageError error);

/// A value, or the ImageError that explains why there is none.
template <typename T>
class ImageResult {
public:
    ImageResult(const T& value) : value_(value), error_(ImageError::Ok) {}
    ImageResult(ImageError error) : value_(), error_(error) {}

    bool ok() const { return error_ == ImageError::Ok; }
    ImageError error() const { return error_; }
    /// The value; only meaningful when ok() is true.
    const T& value() const { return value_; }

private:
    T value_;
    ImageError error_;
};

} // namespace image
