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
    uint32_t value;
    int width;

    bool operator==(const Access&) const = default;
};

/// A register model standing in for one chip: reads of its ports come from
/// it and writes go to it (both are still logged), so a driver's longer
/// conversations with a chip can be tested against the chip's behaviour
/// instead of a script of values. Offsets are from the first port.
class Responder {
public:
    virtual uint32_t read(uint16_t offset, int width) = 0;
    virtual void write(uint16_t offset, uint32_t value, int width) = 0;

protected:
    ~Responder() = default;
};

/// Lets @p responder answer @p size ports from @p first until reset().
/// A value queued for one of its ports still comes first.
void attach(uint16_t first, uint16_t size, Responder* responder);

/// Clears the log, the queued reads, the defaults and the responders.
void reset();

/// The accesses since the last reset() or takeLog().
std::vector<Access> takeLog();

/// Queues a value for the next read of port.
void queueRead(uint16_t port, uint32_t value);

/// The value a read of port returns when nothing is queued (initially 0xFF,
/// an empty ISA bus).
void setDefaultRead(uint16_t port, uint32_t value);

/// Writes a readable log line per access, for failure messages.
std::string describe(const std::vector<Access>& log);

inline Access write8(uint16_t port, uint8_t value) { return {true, port, value, 8}; }
inline Access read8(uint16_t port, uint8_t value) { return {false, port, value, 8}; }

} // namespace port_io_mock
