// Reading a TOML file a user wrote, as the host tools do it (dcos-modbus-sim's
// simulator configuration, dcos-config's saved node configuration): ASCII
// only, the parse error as a value with its line, unknown keys refused, and
// each value checked against its range with a message that names the key
// and the line. toml++ (Debian's) is built with exceptions; they end here.
#pragma once

#include <fmt/core.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace hosttoml {

/// Parses @p text (the file @p fileName's) into @p root; the error, with
/// file and line, when it is not ASCII or not TOML.
inline std::optional<std::string> parseAscii(std::string_view text, std::string_view fileName, toml::table& root)
{
    // toml++ 3.3 fails on some non-ASCII bytes in ways that are no parse
    // error (found by fuzz_modbus_sim_config), so the file is ASCII and a
    // byte outside it is refused with its line.
    unsigned line = 1;
    for (const char c : text) {
        if (static_cast<unsigned char>(c) >= 0x80) {
            return fmt::format("{}:{}: only ASCII characters are accepted (the TOML library fails on some others)",
                               fileName, line);
        }
        line += c == '\n' ? 1 : 0;
    }
    try {
        root = toml::parse(text, fileName);
    } catch (const toml::parse_error& error) {
        return fmt::format("{}:{}:{}: not TOML: {}", fileName, error.source().begin.line,
                           error.source().begin.column, error.description());
    }
    return std::nullopt;
}

// The first error stops the check: one clear message with a line number
// serves better than a cascade that follows from it.
class TomlChecker {
public:
    explicit TomlChecker(std::string_view fileName) : fileName_(fileName) {}

    bool failed() const { return !message_.empty(); }
    const std::string& message() const { return message_; }

    void fail(const toml::node& node, const std::string& text) { failAt(node.source().begin.line, text); }

    void failAt(int64_t line, const std::string& text)
    {
        if (message_.empty()) {
            message_ = fmt::format("{}:{}: {}", fileName_, line, text);
        }
    }

    // Rejects keys other than @p allowed, so a misspelt key is an error
    // rather than a setting that silently does nothing.
    void onlyKeys(const toml::table& table, std::initializer_list<std::string_view> allowed, const std::string& where)
    {
        for (auto&& [key, node] : table) {
            if (std::find(allowed.begin(), allowed.end(), key.str()) == allowed.end()) {
                std::string list;
                for (std::string_view a : allowed) {
                    list += (list.empty() ? "" : ", ") + std::string(a);
                }
                fail(node, fmt::format("{}: unknown key '{}' (known: {})", where, key.str(), list));
                return;
            }
        }
    }

    std::optional<int64_t> integer(const toml::table& table, std::string_view key, int64_t min, int64_t max,
                                   const std::string& where)
    {
        const toml::node* node = table.get(key);
        if (node == nullptr) {
            return std::nullopt;
        }
        const std::optional<int64_t> value = node->value_exact<int64_t>();
        if (!value || *value < min || *value > max) {
            fail(*node, fmt::format("{}: '{}' must be an integer from {} to {}", where, key, min, max));
            return std::nullopt;
        }
        return value;
    }

    std::optional<double> number(const toml::table& table, std::string_view key, double min, double max,
                                 const std::string& where)
    {
        const toml::node* node = table.get(key);
        if (node == nullptr) {
            return std::nullopt;
        }
        // An integer is a number too: "per_second = 500" must not be refused for lacking ".0".
        std::optional<double> value;
        if (node->is_integer()) {
            value = static_cast<double>(node->as_integer()->get());
        } else if (node->is_floating_point()) {
            value = node->as_floating_point()->get();
        }
        if (!value || !std::isfinite(*value) || *value < min || *value > max) {
            fail(*node, fmt::format("{}: '{}' must be a number from {} to {}", where, key, min, max));
            return std::nullopt;
        }
        return value;
    }

    std::optional<std::string> string(const toml::table& table, std::string_view key, size_t maxLength,
                                      const std::string& where)
    {
        const toml::node* node = table.get(key);
        if (node == nullptr) {
            return std::nullopt;
        }
        const std::optional<std::string> value = node->value_exact<std::string>();
        if (!value || value->size() > maxLength) {
            fail(*node, fmt::format("{}: '{}' must be a string of at most {} bytes", where, key, maxLength));
            return std::nullopt;
        }
        return value;
    }

    const toml::table* subtable(const toml::table& table, std::string_view key, const std::string& where)
    {
        const toml::node* node = table.get(key);
        if (node == nullptr) {
            return nullptr;
        }
        if (!node->is_table()) {
            fail(*node, fmt::format("{}: '{}' must be a table, e.g. {} = {{ ... }}", where, key, key));
            return nullptr;
        }
        return node->as_table();
    }

    // A missing key is reported only if nothing else was: a key that is
    // present but wrong has said so already.
    void require(const toml::node& at, bool present, std::string_view key, const std::string& where)
    {
        if (!present && !failed()) {
            fail(at, fmt::format("{}: '{}' is required", where, key));
        }
    }

    /// A true or false at @p key, or nothing when it is absent.
    std::optional<bool> boolean(const toml::table& table, std::string_view key, const std::string& where)
    {
        const toml::node* node = table.get(key);
        if (node == nullptr) {
            return std::nullopt;
        }
        const std::optional<bool> value = node->value_exact<bool>();
        if (!value) {
            fail(*node, fmt::format("{}: '{}' must be true or false", where, key));
        }
        return value;
    }

private:
    std::string fileName_;
    std::string message_;
};

} // namespace hosttoml
