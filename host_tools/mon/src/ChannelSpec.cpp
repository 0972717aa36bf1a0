#include <hostmon/ChannelSpec.hpp>

#include <fmt/core.h>

#include <cctype>

namespace hostmon {

namespace {

struct FormatName {
    const char* name;
    sei::SeiSampleFormat format;
};

constexpr FormatName kFormats[] = {
    {"u8", sei::SeiSampleFormat::U8},   {"i8", sei::SeiSampleFormat::I8},   {"u16", sei::SeiSampleFormat::U16},
    {"i16", sei::SeiSampleFormat::I16}, {"u32", sei::SeiSampleFormat::U32}, {"i32", sei::SeiSampleFormat::I32},
};

bool hasSpace(const std::string& text)
{
    for (const char c : text) {
        if (std::isspace(static_cast<unsigned char>(c)) != 0 || std::iscntrl(static_cast<unsigned char>(c)) != 0) {
            return true;
        }
    }
    return false;
}

} // namespace

const char* sampleFormatName(sei::SeiSampleFormat format)
{
    for (const FormatName& entry : kFormats) {
        if (entry.format == format) {
            return entry.name;
        }
    }
    return "?";
}

std::optional<ChannelSpec> parseChannelSpec(const std::string& text, std::string& why)
{
    ChannelSpec spec;
    // The label first: it is everything after the first '=', so it may hold
    // '@' and ':' of its own.
    std::string field = text;
    const size_t equals = text.find('=');
    if (equals != std::string::npos) {
        spec.label = text.substr(equals + 1);
        field = text.substr(0, equals);
        if (spec.label.empty()) {
            why = fmt::format("'{}': the label after '=' is empty", text);
            return std::nullopt;
        }
    } else {
        spec.label = field;
    }
    if (hasSpace(spec.label)) {
        why = fmt::format("'{}': a label is one word, without white space (the output splits on it)", text);
        return std::nullopt;
    }
    const size_t colon = field.find(':');
    if (colon != std::string::npos) {
        const std::string name = field.substr(colon + 1);
        bool known = false;
        for (const FormatName& entry : kFormats) {
            if (name == entry.name) {
                spec.format = entry.format;
                known = true;
            }
        }
        if (!known) {
            why = fmt::format("'{}': the format is one of u8, i8, u16, i16, u32, i32, not '{}'", text, name);
            return std::nullopt;
        }
        field = field.substr(0, colon);
    }
    const size_t at = field.find('@');
    if (at != std::string::npos) {
        const std::string offset = field.substr(at + 1);
        if (offset.empty() || offset.size() > 2 ||
            offset.find_first_not_of("0123456789") != std::string::npos) {
            why = fmt::format("'{}': the offset after '@' is a byte of the 16-byte page, 0 to 15", text);
            return std::nullopt;
        }
        const unsigned value = static_cast<unsigned>(std::stoul(offset));
        if (value >= sei::kSeiPageSize) {
            why = fmt::format("'{}': the offset after '@' is a byte of the 16-byte page, 0 to 15", text);
            return std::nullopt;
        }
        spec.offset = static_cast<uint8_t>(value);
        field = field.substr(0, at);
    }
    if (static_cast<size_t>(spec.offset) + sei::seiSampleSize(spec.format) > sei::kSeiPageSize) {
        why = fmt::format("'{}': a {} at offset {} runs past the 16-byte page", text, sampleFormatName(spec.format),
                          spec.offset);
        return std::nullopt;
    }
    if (field.size() >= 2 && field[0] == '0' && (field[1] == 'x' || field[1] == 'X')) {
        const std::string digits = field.substr(2);
        if (digits.empty() || digits.size() > 8 ||
            digits.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos) {
            why = fmt::format("'{}': a publisher's id is 0x and up to 8 hex digits", text);
            return std::nullopt;
        }
        spec.publisherId = static_cast<uint32_t>(std::stoul(digits, nullptr, 16));
        if (spec.publisherId == 0) {
            why = fmt::format("'{}': 0x0 is the null id, no publisher", text);
            return std::nullopt;
        }
        return spec;
    }
    if (field.empty() || field.size() > sei::kSeiMaxName || hasSpace(field)) {
        why = fmt::format("'{}': a publisher's name is 1 to {} characters without white space, or its id as 0x...",
                          text, sei::kSeiMaxName);
        return std::nullopt;
    }
    spec.publisherName = field;
    return spec;
}

} // namespace hostmon
