#include "PortIoMock.hpp"

#include <arch_x86/PortIo.hpp>

#include <cstdarg>
#include <cstdio>
#include <stdexcept>

namespace port_io_mock {

namespace {
std::vector<Access> log;
std::map<uint16_t, std::deque<uint32_t>> queued;
std::map<uint16_t, uint32_t> defaults;

struct Attached {
    uint16_t first;
    uint16_t size;
    Responder* responder;
};
std::vector<Attached> responders;

const Attached* responderFor(uint16_t port)
{
    for (const Attached& a : responders) {
        if (port >= a.first && port - a.first < a.size) {
            return &a;
        }
    }
    return nullptr;
}

uint32_t nextRead(uint16_t port, int width)
{
    auto& queue = queued[port];
    if (!queue.empty()) {
        const uint32_t value = queue.front();
        queue.pop_front();
        return value;
    }
    if (const Attached* a = responderFor(port)) {
        return a->responder->read(static_cast<uint16_t>(port - a->first), width);
    }
    const auto found = defaults.find(port);
    return found != defaults.end() ? found->second : 0xFF;
}

void written(uint16_t port, uint32_t value, int width)
{
    if (const Attached* a = responderFor(port)) {
        a->responder->write(static_cast<uint16_t>(port - a->first), value, width);
    }
}
} // namespace

void attach(uint16_t first, uint16_t size, Responder* responder) { responders.push_back({first, size, responder}); }

void reset()
{
    log.clear();
    queued.clear();
    defaults.clear();
    responders.clear();
}

std::vector<Access> takeLog()
{
    std::vector<Access> out;
    out.swap(log);
    return out;
}

void queueRead(uint16_t port, uint32_t value) { queued[port].push_back(value); }

void setDefaultRead(uint16_t port, uint32_t value) { defaults[port] = value; }

std::string describe(const std::vector<Access>& accesses)
{
    std::string text;
    char line[64];
    for (const Access& a : accesses) {
        std::snprintf(line, sizeof line, "%s%d 0x%03x %s 0x%02lx\n", a.write ? "out" : "in", a.width, a.port,
                      a.write ? "<-" : "->", static_cast<unsigned long>(a.value));
        text += line;
    }
    return text;
}

} // namespace port_io_mock

namespace arch_x86 {

uint8_t portRead8(uint16_t port)
{
    const uint8_t value = static_cast<uint8_t>(port_io_mock::nextRead(port, 8));
    port_io_mock::log.push_back({false, port, value, 8});
    return value;
}

uint16_t portRead16(uint16_t port)
{
    const uint16_t value = static_cast<uint16_t>(port_io_mock::nextRead(port, 16));
    port_io_mock::log.push_back({false, port, value, 16});
    return value;
}

uint32_t portRead32(uint16_t port)
{
    const uint32_t value = port_io_mock::nextRead(port, 32);
    port_io_mock::log.push_back({false, port, value, 32});
    return value;
}

void portWrite8(uint16_t port, uint8_t value)
{
    port_io_mock::log.push_back({true, port, value, 8});
    port_io_mock::written(port, value, 8);
}

void portWrite16(uint16_t port, uint16_t value)
{
    port_io_mock::log.push_back({true, port, value, 16});
    port_io_mock::written(port, value, 16);
}

void portWrite32(uint16_t port, uint32_t value)
{
    port_io_mock::log.push_back({true, port, value, 32});
    port_io_mock::written(port, value, 32);
}

} // namespace arch_x86

// On the host a panic becomes a C++ exception, so a test can show that a
// bug (such as an out-of-window register access) is caught.
extern "C" [[noreturn]] void dcosPanic(const char* format, ...)
{
    char message[256];
    va_list arguments;
    va_start(arguments, format);
    std::vsnprintf(message, sizeof message, format, arguments);
    va_end(arguments);
    throw std::runtime_error(message);
}
