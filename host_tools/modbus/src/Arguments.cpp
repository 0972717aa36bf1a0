#include <hostmodbus/Arguments.hpp>

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cctype>

namespace hostmodbus {

namespace {

// The text shown back to the user in a message: unprintable bytes would
// garble the terminal, and a pasted megabyte would drown the message.
std::string shown(std::string_view text)
{
    std::string out;
    for (char c : text.substr(0, 40)) {
        const auto u = static_cast<unsigned char>(c);
        out += std::isprint(u) ? std::string(1, c) : fmt::format("\\x{:02x}", u);
    }
    return text.size() > 40 ? out + "..." : out;
}

std::string lower(std::string_view text)
{
    std::string out(text);
    std::transform(out.begin(), out.end(), out.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return out;
}

// Splits "a,b,c" into its items; an empty item is kept, so "1,,2" is refused
// by the item's parser rather than read as "1,2".
std::vector<std::string_view> split(std::string_view text, char separator)
{
    std::vector<std::string_view> items;
    size_t start = 0;
    while (true) {
        const size_t end = text.find(separator, start);
        items.push_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
        if (end == std::string_view::npos) {
            return items;
        }
        start = end + 1;
    }
}

} // namespace

Result<uint32_t> parseUnsigned(std::string_view text, uint32_t max, std::string_view what)
{
    unsigned base = 10;
    std::string_view digits = text;
    if (digits.size() > 2 && digits[0] == '0' && (digits[1] == 'x' || digits[1] == 'X')) {
        base = 16;
        digits.remove_prefix(2);
    }
    // Ten digits are more than any value here needs; the limit keeps the
    // accumulator from overflowing before the range check.
    if (digits.empty() || digits.size() > 10) {
        return Result<uint32_t>::failure(
            fmt::format("'{}' is not a {}: write a number from 0 to {} (or 0x{:X})", shown(text), what, max, max));
    }
    uint64_t value = 0;
    for (char c : digits) {
        const auto u = static_cast<unsigned char>(c);
        unsigned digit = 0;
        if (std::isdigit(u)) {
            digit = static_cast<unsigned>(c - '0');
        } else if (base == 16 && std::isxdigit(u)) {
            digit = static_cast<unsigned>(std::tolower(u) - 'a' + 10);
        } else {
            return Result<uint32_t>::failure(
                fmt::format("'{}' is not a {}: write a number from 0 to {} (or 0x{:X})", shown(text), what, max, max));
        }
        value = value * base + digit;
    }
    if (value > max) {
        return Result<uint32_t>::failure(fmt::format("{} {} is out of range: at most {}", what, shown(text), max));
    }
    return Result<uint32_t>::success(static_cast<uint32_t>(value));
}

Result<uint16_t> parseAddress(std::string_view text)
{
    const Result<uint32_t> r = parseUnsigned(text, 0xFFFF, "data address");
    return r.ok() ? Result<uint16_t>::success(static_cast<uint16_t>(r.value())) : Result<uint16_t>::failure(r.error());
}

Result<uint16_t> parseRegisterValue(std::string_view text)
{
    if (!text.empty() && text[0] == '-') {
        const Result<uint32_t> magnitude = parseUnsigned(text.substr(1), 0x8000, "negative register value");
        if (!magnitude.ok() || magnitude.value() == 0) {
            return Result<uint16_t>::failure(fmt::format(
                "'{}' is not a register value: write 0 to 65535, 0x0000 to 0xFFFF, or -32768 to -1", shown(text)));
        }
        return Result<uint16_t>::success(static_cast<uint16_t>(0x10000u - magnitude.value()));
    }
    const Result<uint32_t> r = parseUnsigned(text, 0xFFFF, "register value");
    if (!r.ok()) {
        return Result<uint16_t>::failure(fmt::format(
            "'{}' is not a register value: write 0 to 65535, 0x0000 to 0xFFFF, or -32768 to -1", shown(text)));
    }
    return Result<uint16_t>::success(static_cast<uint16_t>(r.value()));
}

Result<bool> parseBit(std::string_view text)
{
    const std::string word = lower(text);
    if (word == "1" || word == "on" || word == "true") {
        return Result<bool>::success(true);
    }
    if (word == "0" || word == "off" || word == "false") {
        return Result<bool>::success(false);
    }
    return Result<bool>::failure(fmt::format("'{}' is not a coil value: write 1, 0, on, off, true or false", shown(text)));
}

Result<uint8_t> parseSlaveAddress(std::string_view text)
{
    const Result<uint32_t> r = parseUnsigned(text, 247, "slave address");
    if (!r.ok() || r.value() == 0) {
        return Result<uint8_t>::failure(fmt::format("'{}' is not a slave address: write 1 to 247", shown(text)));
    }
    return Result<uint8_t>::success(static_cast<uint8_t>(r.value()));
}

Result<Range> checkRange(uint32_t address, uint32_t count, unsigned maxCount)
{
    if (count == 0 || count > maxCount) {
        return Result<Range>::failure(fmt::format("a count of {} is out of range: 1 to {}", count, maxCount));
    }
    if (address + count > 0x10000) {
        return Result<Range>::failure(
            fmt::format("{} items from address {} run past the last address, 65535", count, address));
    }
    return Result<Range>::success(Range{static_cast<uint16_t>(address), static_cast<uint16_t>(count)});
}

Result<RegisterList> parseRegisterList(std::string_view text, unsigned maxCount)
{
    const size_t equals = text.find('=');
    if (equals == std::string_view::npos) {
        return Result<RegisterList>::failure(
            fmt::format("'{}' is not a register list: write address=value,value,..., e.g. 100=1,0x20,-3", shown(text)));
    }
    const Result<uint16_t> address = parseAddress(text.substr(0, equals));
    if (!address.ok()) {
        return Result<RegisterList>::failure(address.error());
    }
    RegisterList list;
    list.address = address.value();
    for (std::string_view item : split(text.substr(equals + 1), ',')) {
        // The count is checked as the list grows, so a huge list is refused
        // without being parsed whole.
        if (list.values.size() >= maxCount) {
            return Result<RegisterList>::failure(fmt::format("more than {} registers in one write", maxCount));
        }
        const Result<uint16_t> value = parseRegisterValue(item);
        if (!value.ok()) {
            return Result<RegisterList>::failure(value.error());
        }
        list.values.push_back(value.value());
    }
    const Result<Range> range = checkRange(list.address, static_cast<uint32_t>(list.values.size()), maxCount);
    if (!range.ok()) {
        return Result<RegisterList>::failure(range.error());
    }
    return Result<RegisterList>::success(std::move(list));
}

Result<BitList> parseBitList(std::string_view text, unsigned maxCount)
{
    const size_t equals = text.find('=');
    if (equals == std::string_view::npos) {
        return Result<BitList>::failure(
            fmt::format("'{}' is not a coil list: write address=bit,bit,..., e.g. 16=1,0,1", shown(text)));
    }
    const Result<uint16_t> address = parseAddress(text.substr(0, equals));
    if (!address.ok()) {
        return Result<BitList>::failure(address.error());
    }
    BitList list;
    list.address = address.value();
    for (std::string_view item : split(text.substr(equals + 1), ',')) {
        if (list.values.size() >= maxCount) {
            return Result<BitList>::failure(fmt::format("more than {} coils in one write", maxCount));
        }
        const Result<bool> value = parseBit(item);
        if (!value.ok()) {
            return Result<BitList>::failure(value.error());
        }
        list.values.push_back(value.value());
    }
    const Result<Range> range = checkRange(list.address, static_cast<uint32_t>(list.values.size()), maxCount);
    if (!range.ok()) {
        return Result<BitList>::failure(range.error());
    }
    return Result<BitList>::success(std::move(list));
}

Result<Range> parseRange(std::string_view text, unsigned maxCount)
{
    const size_t colon = text.find(':');
    if (colon == std::string_view::npos) {
        return Result<Range>::failure(fmt::format("'{}' is not a range: write address:count, e.g. 100:4", shown(text)));
    }
    const Result<uint16_t> address = parseAddress(text.substr(0, colon));
    if (!address.ok()) {
        return Result<Range>::failure(address.error());
    }
    const Result<uint32_t> count = parseUnsigned(text.substr(colon + 1), maxCount, "count");
    if (!count.ok()) {
        return Result<Range>::failure(count.error());
    }
    return checkRange(address.value(), count.value(), maxCount);
}

Result<char> parseParity(std::string_view text)
{
    const std::string word = lower(text);
    if (word == "n" || word == "none") {
        return Result<char>::success('N');
    }
    if (word == "e" || word == "even") {
        return Result<char>::success('E');
    }
    if (word == "o" || word == "odd") {
        return Result<char>::success('O');
    }
    return Result<char>::failure(fmt::format("'{}' is not a parity: write N, E or O (none, even, odd)", shown(text)));
}

Result<int> checkBaudRate(long baud)
{
    static constexpr std::array<long, 13> kRates{300,   600,   1200,   2400,   4800,   9600,  19200,
                                                 38400, 57600, 115200, 230400, 460800, 921600};
    if (std::find(kRates.begin(), kRates.end(), baud) == kRates.end()) {
        return Result<int>::failure(fmt::format(
            "{} baud is not a rate the serial driver can set: use one of 300, 600, 1200, 2400, 4800, 9600, 19200, "
            "38400, 57600, 115200, 230400, 460800, 921600",
            baud));
    }
    return Result<int>::success(static_cast<int>(baud));
}

} // namespace hostmodbus
