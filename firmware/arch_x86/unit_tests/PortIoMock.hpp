// A recording stand-in for x86 port I/O in host unit tests.
//
// Every access is logged in order, and reads return values a test queued
// per port (or a per-port default), so a test can check the exact register
// sequence a chip driver produces.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace port_io_mock {

struct Access {
    bool write;
    uint16_t port;
    uint16_t value;
    int width;

    bool operator==(const Access&) const = default;
};

/// Clears the log, the queued reads and the defaults.
void reset();

/// The accesses since the last reset() or takeLog().
std::vector<Access> takeLog();

/// Queues a value for the next read of port.
void queueRead(uint16_t port, uint16_t value);

/// The value a read of port returns when nothing is queued (initially 0xFF,
/// an empty ISA bus).
void setDefaultRead(uint16_t port, uint16_t value);

/// Writes a readable log line per access, for failure messages.
std::string describe(const std::vector<Access>& log);

inline Access write8(uint16_t port, uint8_t value) { return {true, port, value, 8}; }
inline Access read8(uint16_t port, uint8_t value) { return {false, port, value, 8}; }

} // namespace port_io_mock
