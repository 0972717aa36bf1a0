// The text form of network addresses, for the console and the tools (seed 7.13).
#include <dcos/NetworkAddress.hpp>

namespace dcos {

void NetworkAddress::format(char (&text)[kTextSize]) const
{
    size_t at = 0;
    for (int shift = 24; shift >= 0; shift -= 8) {
        const unsigned octet = (raw_ >> shift) & 0xFF;
        // Digits of the octet, most significant first, without leading zeros.
        if (octet >= 100) {
            text[at++] = static_cast<char>('0' + octet / 100);
        }
        if (octet >= 10) {
            text[at++] = static_cast<char>('0' + octet / 10 % 10);
        }
        text[at++] = static_cast<char>('0' + octet % 10);
        if (shift != 0) {
            text[at++] = '.';
        }
    }
    text[at] = '\0';
}

bool NetworkAddress::parse(const char* text, NetworkAddress& address)
{
    if (text == nullptr) {
        return false;
    }
    uint32_t raw = 0;
    for (int part = 0; part < 4; ++part) {
        unsigned octet = 0;
        int digits = 0;
        for (; *text >= '0' && *text <= '9'; ++text) {
            // A leading zero would read as octal in other tools: refused.
            if (++digits > 3 || (digits == 2 && octet == 0)) {
                return false;
            }
            octet = octet * 10 + static_cast<unsigned>(*text - '0');
        }
        if (digits == 0 || octet > 255) {
            return false;
        }
        raw = (raw << 8) | octet;
        if (part < 3 && *text++ != '.') {
            return false;
        }
    }
    if (*text != '\0') {
        return false;
    }
    address = NetworkAddress(raw);
    return true;
}

} // namespace dcos
