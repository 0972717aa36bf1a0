#include <hostimage/ConfigurationKeyFile.hpp>

#include <hostimage/RandomGenerator.hpp>
#include <hostimage/ToolFiles.hpp>

#include <fmt/core.h>

namespace hostimage {

namespace {

int hexDigit(char character)
{
    if (character >= '0' && character <= '9') {
        return character - '0';
    }
    if (character >= 'a' && character <= 'f') {
        return character - 'a' + 10;
    }
    if (character >= 'A' && character <= 'F') {
        return character - 'A' + 10;
    }
    return -1;
}

bool isSpace(uint8_t character) { return character == ' ' || character == '\t' || character == '\r' || character == '\n'; }

} // namespace

std::optional<ConfigurationKey> readConfigurationKey(const std::string& path, std::string& error, bool& unreadable)
{
    unreadable = false;
    const std::optional<std::vector<uint8_t>> bytes = readWholeFile(path, error);
    if (!bytes) {
        unreadable = true;
        return std::nullopt;
    }
    size_t begin = 0;
    size_t end = bytes->size();
    while (begin < end && isSpace((*bytes)[begin])) {
        ++begin;
    }
    while (end > begin && isSpace((*bytes)[end - 1])) {
        --end;
    }
    ConfigurationKey key{};
    if (end - begin != key.size() * 2) {
        error = fmt::format("{} is not a configuration key: it must hold 64 hexadecimal digits "
                            "(dcos-config keygen makes one)",
                            path);
        return std::nullopt;
    }
    for (size_t i = 0; i < key.size(); ++i) {
        const int high = hexDigit(static_cast<char>((*bytes)[begin + 2 * i]));
        const int low = hexDigit(static_cast<char>((*bytes)[begin + 2 * i + 1]));
        if (high < 0 || low < 0) {
            error = fmt::format("{} is not a configuration key: character {} is not a hexadecimal digit", path,
                                begin + 2 * i + (high < 0 ? 1 : 2));
            return std::nullopt;
        }
        key[i] = static_cast<uint8_t>(high << 4 | low);
    }
    return key;
}

std::optional<ConfigurationKey> newConfigurationKey(std::string& error)
{
    RandomGenerator random("dcos-config-key");
    if (random.status() != 0) {
        error = describeMbedtlsError("cannot seed the random generator from the system's entropy", random.status());
        return std::nullopt;
    }
    ConfigurationKey key{};
    const int status = random.fill(key.data(), key.size());
    if (status != 0) {
        error = describeMbedtlsError("cannot draw a key", status);
        return std::nullopt;
    }
    return key;
}

bool writeConfigurationKey(const std::string& path, const ConfigurationKey& key, bool replace, std::string& error)
{
    const std::string text = hexText(key.data(), key.size()) + "\n";
    return writeWholeFile(path, text.data(), text.size(), true, replace, error);
}

} // namespace hostimage
