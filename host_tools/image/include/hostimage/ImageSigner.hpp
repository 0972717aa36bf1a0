// Makes a signed controller image (docs/boot.md, "Controller images") from
// a payload: the header filled in, the payload's digest, the key's id, and
// the signature over the header.
#pragma once

#include <hostimage/ElfPayload.hpp>
#include <hostimage/SigningKey.hpp>

#include <image/ImageHeader.hpp>

#include <optional>
#include <string>
#include <vector>

namespace hostimage {

class ImageSigner {
public:
    /// The image's bytes: the 256-byte header, then the payload.
    static std::optional<std::vector<uint8_t>> sign(const ElfPayload& payload, image::BoardType board,
                                                    const image::ImageVersion& version, const SigningKey& key,
                                                    std::string& error);
};

} // namespace hostimage
