#include <boot/BootInfo.hpp>

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

} // namespace boot
