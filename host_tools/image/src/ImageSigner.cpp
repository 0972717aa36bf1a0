#include <hostimage/ImageSigner.hpp>

#include <image/Sha256.hpp>

namespace hostimage {

std::optional<std::vector<uint8_t>> ImageSigner::sign(const ElfPayload& payload, image::BoardType board,
                                                      const image::ImageVersion& version, const SigningKey& key,
                                                      std::string& error)
{
    image::ImageHeader header;
    header.board = board;
    header.version = version;
    header.payloadSize = static_cast<uint32_t>(payload.bytes().size());
    header.memorySize = payload.memorySize();
    header.loadAddress = payload.loadAddress();
    header.entry = payload.entry();
    image::Sha256::digest(payload.bytes().data(), payload.bytes().size(), header.payloadDigest);
    image::Sha256::digest(key.publicPoint().data(), key.publicPoint().size(), header.keyId);

    uint8_t bytes[image::ImageHeader::kSize];
    header.encode(bytes);
    uint8_t signedDigest[image::ImageHeader::kDigestSize];
    image::Sha256::digest(bytes, image::ImageHeader::kSignedSize, signedDigest);
    if (!key.sign(signedDigest, header.signature, error)) {
        return std::nullopt;
    }
    header.encode(bytes);
    // The header must decode as the controllers will read it; a payload the
    // format cannot describe (empty, entry outside) is refused here.
    const image::ImageResult<image::ImageHeader> check = image::ImageHeader::decode(bytes, sizeof bytes);
    if (!check.ok()) {
        error = image::imageErrorText(check.error());
        return std::nullopt;
    }
    std::vector<uint8_t> out(bytes, bytes + sizeof bytes);
    out.insert(out.end(), payload.bytes().begin(), payload.bytes().end());
    return out;
}

} // namespace hostimage
