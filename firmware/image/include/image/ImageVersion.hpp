// The version a controller image carries: major.minor.patch and a build
// number, compared in that order.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace image {

struct ImageVersion {
    uint8_t major = 0;
    uint8_t minor = 0;
    uint16_t patch = 0;
    uint32_t build = 0;

    /// Negative, zero or positive as this version is older than, the same
    /// as or newer than @p other.
    int compare(const ImageVersion& other) const;

    /// Parses "MAJOR.MINOR.PATCH" or "MAJOR.MINOR.PATCH+BUILD" (decimal,
    /// each part within its field); false for anything else.
    static bool parse(const char* text, ImageVersion& out);

    /// Writes the form parse() reads ("+BUILD" only when the build is not
    /// 0) into @p out of @p size bytes, always terminated; the length.
    size_t format(char* out, size_t size) const;
};

} // namespace image
