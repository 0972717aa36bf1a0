// What dcos-image and dcos-card share: whole-file reads with a size limit,
// whole-file writes that never leave half a file, and hexadecimal text.
#pragma once

#include <hostimage/SigningKey.hpp>

#include <image/ImageVerifier.hpp>
#include <image/ImageVersion.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hostimage {

/// A file's bytes; none, with the reason in @p error, for a file that
/// cannot be read or is larger than 64 MiB (no image or card is).
std::optional<std::vector<uint8_t>> readWholeFile(const std::string& path, std::string& error);

/// Writes a file whole, through a temporary name renamed over the target,
/// so that a failure leaves no half-written file. A @p secret file is
/// created readable by its owner only (mode 0600). An existing file is
/// replaced only if @p replace.
bool writeWholeFile(const std::string& path, const void* data, size_t size, bool secret, bool replace,
                    std::string& error);

/// Lower-case hexadecimal, two digits a byte.
std::string hexText(const uint8_t* data, size_t size);

/// "1.2.3" or "1.2.3+7".
std::string versionText(const image::ImageVersion& version);

/// The controllers' form of a public key.
image::TrustedKey trustedKeyOf(const SigningKey::PublicPoint& point);

/// A public key (or a private key's public half) read from a PEM file.
std::optional<SigningKey::PublicPoint> readPublicKey(const std::string& path, std::string& error, bool& unreadable);

} // namespace hostimage
