// The checks node 2 makes of node 3's kernel image before it writes a byte
// of it (SecondProcessor::load): a 32-bit little-endian i386 executable
// whose every loadable segment lies in [base, end) and within the file, and
// whose entry point is inside a segment's bytes (System V ABI, "Object
// Files", and its i386 supplement). Free of hardware, so that the host
// tests give it every kind of bad image.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace bsp {

class ElfImage {
public:
    /// An image has a handful of segments; more is not an image of ours.
    static constexpr uint16_t kMaximumSegments = 16;

    /// One loadable segment: @p fileBytes from @p fileOffset of the file to
    /// @p physical, and zeros up to @p memoryBytes.
    struct Segment {
        uint32_t fileOffset;
        uint32_t physical;
        uint32_t fileBytes;
        uint32_t memoryBytes;
    };

    /// Checks the image at [@p image, @p image + @p bytes); on success sets
    /// @p entry and returns true.
    static bool check(const uint8_t* image, size_t bytes, uint32_t base, uint32_t end, uint32_t& entry);

    /// Calls @p each(segment) for every loadable segment of an image
    /// check() accepted.
    template <typename Each>
    static void forEachLoadable(const uint8_t* image, Each each)
    {
        const uint16_t count = segmentCount(image);
        for (uint16_t i = 0; i < count; ++i) {
            Segment segment{};
            if (loadableAt(image, i, segment)) {
                each(segment);
            }
        }
    }

private:
    static uint16_t segmentCount(const uint8_t* image);
    static bool loadableAt(const uint8_t* image, uint16_t index, Segment& segment);
};

} // namespace bsp
