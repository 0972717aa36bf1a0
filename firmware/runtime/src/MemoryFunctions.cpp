// The C memory primitives the compiler may call on its own.
//
// GCC emits calls to memcpy, memmove, memset and memcmp for structure copies
// and large initialisations even in freestanding code, so the firmware must
// define them. They are written with string instructions, which every x86
// from the 8086 on executes, and so that the optimiser cannot turn the loop
// back into a call to the function being defined.
#include <stddef.h>
#include <stdint.h>

extern "C" {

void* memcpy(void* destination, const void* source, size_t count)
{
    void* d = destination;
    asm volatile("cld; rep movsb" : "+D"(d), "+S"(source), "+c"(count) : : "memory", "cc");
    return destination;
}

void* memmove(void* destination, const void* source, size_t count)
{
    auto* d = static_cast<unsigned char*>(destination);
    auto* s = static_cast<const unsigned char*>(source);
    if (d <= s || d >= s + count) {
        return memcpy(destination, source, count);
    }
    // Overlapping with the destination above the source: copy backwards.
    d += count - 1;
    s += count - 1;
    asm volatile("std; rep movsb; cld" : "+D"(d), "+S"(s), "+c"(count) : : "memory", "cc");
    return destination;
}

void* memset(void* destination, int value, size_t count)
{
    void* d = destination;
    asm volatile("cld; rep stosb" : "+D"(d), "+c"(count) : "a"(value) : "memory", "cc");
    return destination;
}

int memcmp(const void* left, const void* right, size_t count)
{
    auto* l = static_cast<const unsigned char*>(left);
    auto* r = static_cast<const unsigned char*>(right);
    for (size_t i = 0; i < count; ++i) {
        if (l[i] != r[i]) {
            return l[i] < r[i] ? -1 : 1;
        }
    }
    return 0;
}

size_t strlen(const char* text)
{
    size_t length = 0;
    while (text[length] != '\0') {
        ++length;
    }
    return length;
}

} // extern "C"
