#include <boot/BootInfo.hpp>

#include <stddef.h>

namespace boot {

bool findCommandLineOption(const char* commandLine, const char* key, char* value, uint32_t capacity)
{
    const char* p = commandLine;
    while (*p != '\0') {
        while (*p == ' ') {
            ++p;
        }
        const char* word = p;
        while (*p != '\0' && *p != ' ') {
            ++p;
        }
        // Compare the word's key part (before any '=') with key.
        const char* k = key;
        const char* w = word;
        while (*k != '\0' && w < p && *w == *k) {
            ++k;
            ++w;
        }
        if (*k == '\0' && (w == p || *w == '=')) {
            if (w < p) {
                ++w; // Skip '='.
            }
            uint32_t length = 0;
            while (w < p && length + 1 < capacity) {
                value[length++] = *w++;
            }
            if (capacity != 0) {
                value[length] = '\0';
            }
            return true;
        }
    }
    return false;
}

bool parseNodeId(const char* text, uint16_t& node)
{
    uint32_t value = 0;
    size_t digits = 0;
    for (; text[digits] != '\0'; ++digits) {
        if (text[digits] < '0' || text[digits] > '9' || digits == 5) {
            return false;
        }
        value = value * 10 + static_cast<uint32_t>(text[digits] - '0');
    }
    if (digits == 0 || value < 1 || value > 0xFFFE) {
        return false;
    }
    node = static_cast<uint16_t>(value);
    return true;
}

} // namespace boot
