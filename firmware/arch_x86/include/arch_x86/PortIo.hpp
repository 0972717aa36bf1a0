// Raw x86 port I/O.
//
// On the target these are single IN/OUT instructions. Host unit tests
// define DCOS_HOST_BUILD and link a recording mock instead
// (unit_tests/PortIoMock.hpp), so chip drivers can be tested for the exact
// register sequence they produce without hardware.
#pragma once

#include <stdint.h>

namespace arch_x86 {

#if defined(DCOS_HOST_BUILD)
uint8_t portRead8(uint16_t port);
uint16_t portRead16(uint16_t port);
void portWrite8(uint16_t port, uint8_t value);
void portWrite16(uint16_t port, uint16_t value);
uint32_t portRead32(uint16_t port);
void portWrite32(uint16_t port, uint32_t value);
#else
inline uint8_t portRead8(uint16_t port)
{
    uint8_t value;
    asm volatile("inb %1, %0" : "=a"(value) : "Nd"(port) : "memory");
    return value;
}

inline uint16_t portRead16(uint16_t port)
{
    uint16_t value;
    asm volatile("inw %1, %0" : "=a"(value) : "Nd"(port) : "memory");
    return value;
}

inline void portWrite8(uint16_t port, uint8_t value)
{
    asm volatile("outb %0, %1" : : "a"(value), "Nd"(port) : "memory");
}

inline void portWrite16(uint16_t port, uint16_t value)
{
    asm volatile("outw %0, %1" : : "a"(value), "Nd"(port) : "memory");
}

// The doubleword forms are what PCI configuration mechanism #1 needs (PCI
// Local Bus Specification 3.0, 3.2.2.3.2): its address and data ports take
// 32-bit accesses.
inline uint32_t portRead32(uint16_t port)
{
    uint32_t value;
    asm volatile("inl %1, %0" : "=a"(value) : "Nd"(port) : "memory");
    return value;
}

inline void portWrite32(uint16_t port, uint32_t value)
{
    asm volatile("outl %0, %1" : : "a"(value), "Nd"(port) : "memory");
}
#endif

} // namespace arch_x86
