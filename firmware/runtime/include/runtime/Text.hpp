// Comparing and measuring NUL-terminated text, for names and console words.
//
// The firmware has no C library, and the compiler may not turn a loop into
// a call to strcmp or strlen (-fno-tree-loop-distribute-patterns), so these
// are written out once here. They are constexpr, so configuration rules
// checked by the compiler use the same code as the running node.
#pragma once

#include <stddef.h>

namespace runtime {

/// The number of characters before the terminating NUL.
constexpr size_t textLength(const char* text)
{
    size_t length = 0;
    while (text[length] != '\0') {
        ++length;
    }
    return length;
}

/// Whether two NUL-terminated texts are the same, character for character.
constexpr bool textEquals(const char* a, const char* b)
{
    size_t i = 0;
    for (; a[i] != '\0' && a[i] == b[i]; ++i) {
    }
    return a[i] == b[i];
}

} // namespace runtime
