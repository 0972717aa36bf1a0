#include <hostimage/ToolFiles.hpp>

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

namespace hostimage {

namespace {

constexpr std::streamoff kLargestFile = 64 << 20;

} // namespace

std::optional<std::vector<uint8_t>> readWholeFile(const std::string& path, std::string& error)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error = fmt::format("cannot read {}: {}", path, std::strerror(errno));
        return std::nullopt;
    }
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0 || size > kLargestFile) {
        error = fmt::format("{} is not a regular file of at most 64 MiB", path);
        return std::nullopt;
    }
    in.seekg(0);
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) {
        error = fmt::format("cannot read {}", path);
        return std::nullopt;
    }
    return bytes;
}

bool writeWholeFile(const std::string& path, const void* data, size_t size, bool secret, bool replace,
                    std::string& error)
{
    if (!replace && access(path.c_str(), F_OK) == 0) {
        error = fmt::format("{} exists already (--force replaces it)", path);
        return false;
    }
    const std::string temporary = path + ".tmp";
    const mode_t mode = secret ? 0600 : 0644;
    const int descriptor = open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC, mode);
    if (descriptor < 0) {
        error = fmt::format("cannot write {}: {}", temporary, std::strerror(errno));
        return false;
    }
    bool written = fchmod(descriptor, mode) == 0;
    const auto* bytes = static_cast<const uint8_t*>(data);
    for (size_t done = 0; written && done < size;) {
        const ssize_t count = write(descriptor, bytes + done, size - done);
        if (count <= 0) {
            written = false;
            break;
        }
        done += static_cast<size_t>(count);
    }
    written = fsync(descriptor) == 0 && written;
    written = close(descriptor) == 0 && written;
    if (!written || rename(temporary.c_str(), path.c_str()) != 0) {
        error = fmt::format("cannot write {}: {}", path, std::strerror(errno));
        unlink(temporary.c_str());
        return false;
    }
    return true;
}

std::string hexText(const uint8_t* data, size_t size)
{
    std::string text;
    for (size_t i = 0; i < size; ++i) {
        text += fmt::format("{:02x}", data[i]);
    }
    return text;
}

std::string versionText(const image::ImageVersion& version)
{
    char text[32];
    version.format(text, sizeof text);
    return text;
}

image::TrustedKey trustedKeyOf(const SigningKey::PublicPoint& point)
{
    uint8_t bytes[image::EcdsaP256::kPublicKeySize];
    std::copy(point.begin(), point.end(), bytes);
    return image::TrustedKey::fromPoint(bytes);
}

std::optional<SigningKey::PublicPoint> readPublicKey(const std::string& path, std::string& error, bool& unreadable)
{
    unreadable = false;
    const std::optional<std::vector<uint8_t>> bytes = readWholeFile(path, error);
    if (!bytes) {
        unreadable = true;
        return std::nullopt;
    }
    const std::optional<SigningKey::PublicPoint> point =
        SigningKey::publicPointFromPem(std::string(bytes->begin(), bytes->end()), error);
    if (!point) {
        error = fmt::format("{}: {}", path, error);
    }
    return point;
}

} // namespace hostimage
