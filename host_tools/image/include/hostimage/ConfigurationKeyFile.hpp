// A node's configuration key on the host (docs/protocols/config.md,
// "Authentication"): 32 random bytes, one key per node, that dcos-card puts
// into the card's configuration at manufacture and dcos-config signs its
// commands with. The file holds the key as 64 hexadecimal digits and a
// newline, readable by its owner only, so that it can be checked by eye
// and kept beside the signing keys.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace hostimage {

using ConfigurationKey = std::array<uint8_t, 32>;

/// The key in the file at @p path; none, with the reason in @p error, when
/// the file cannot be read or is not 64 hexadecimal digits (a final newline
/// and surrounding white space allowed). @p unreadable tells the two apart.
std::optional<ConfigurationKey> readConfigurationKey(const std::string& path, std::string& error, bool& unreadable);

/// A new key from mbedTLS's CTR-DRBG seeded by the system's entropy source;
/// none, with the reason in @p error, when the generator cannot be seeded.
std::optional<ConfigurationKey> newConfigurationKey(std::string& error);

/// Writes @p key to a new file at @p path (mode 0600); an existing file is
/// replaced only if @p replace.
bool writeConfigurationKey(const std::string& path, const ConfigurationKey& key, bool replace, std::string& error);

} // namespace hostimage
