// Fuzz target: dcos-modbus-sim's configuration file, parsed by toml++ (here
// compiled in, header-only, so it is instrumented too) and checked by
// host_tools/modbus/src/SimulatorConfig.cpp.
//
// The checks: a refusal names the file and a line ("fuzz.toml:<n>: ...",
// n >= 1); an accepted configuration has entries, none overlapping, each
// within the address space, every behaviour's references pointing at
// points of the right kind, and the basic identification objects; and the
// simulator built from it runs a few steps of its behaviours without a
// sanitizer report (the steps' lengths come from the input's last bytes).
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostmodbus/Simulator.hpp>
#include <hostmodbus/SimulatorConfig.hpp>

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <string_view>

using namespace hostmodbus;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    const Result<SimulatorConfig> r = parseSimulatorConfig(text, "fuzz.toml");
    if (!r.ok()) {
        const std::string& e = r.error();
        FUZZ_CHECK(e.rfind("fuzz.toml:", 0) == 0);
        FUZZ_CHECK(e.size() > 10 && std::isdigit(static_cast<unsigned char>(e[10])) && e[10] != '0');
        return 0;
    }
    const SimulatorConfig& config = r.value();
    FUZZ_CHECK(!config.points.empty());
    FUZZ_CHECK(config.slave >= 1 && config.slave <= 247);
    FUZZ_CHECK(config.identification.size() >= 3);
    for (uint8_t id = 0; id < 3; ++id) {
        FUZZ_CHECK(config.identification[id].id == id);
    }
    for (size_t i = 0; i < config.points.size(); ++i) {
        const Point& p = config.points[i];
        FUZZ_CHECK(p.count >= 1 && p.address + static_cast<uint32_t>(p.count) <= 0x10000);
        FUZZ_CHECK(isRegisterTable(p.table) || p.value <= 1);
        for (size_t j = 0; j < i; ++j) {
            const Point& q = config.points[j];
            FUZZ_CHECK(q.table != p.table || p.address >= q.address + q.count || q.address >= p.address + p.count);
            FUZZ_CHECK(q.name != p.name);
        }
        const Behaviour& b = p.behaviour;
        const auto points = static_cast<int>(config.points.size());
        if (b.kind != Behaviour::Kind::None) {
            FUZZ_CHECK(p.count == 1);
        }
        if (b.kind == Behaviour::Kind::Ramp) {
            FUZZ_CHECK(b.source >= 0 && b.source < points && b.source != static_cast<int>(i));
            FUZZ_CHECK(isRegisterTable(config.points[static_cast<size_t>(b.source)].table));
            FUZZ_CHECK(b.enable < points);
            FUZZ_CHECK(b.enable < 0 || !isRegisterTable(config.points[static_cast<size_t>(b.enable)].table));
            FUZZ_CHECK(b.perSecond > 0);
        }
        if (b.kind == Behaviour::Kind::Compare) {
            FUZZ_CHECK(!isRegisterTable(p.table));
            FUZZ_CHECK(b.source >= 0 && b.source < points && b.other >= 0 && b.other < points);
        }
        if (b.kind == Behaviour::Kind::Sine) {
            FUZZ_CHECK(b.periodSeconds > 0);
        }
    }
    Result<std::unique_ptr<Simulator>> simulator = Simulator::create(config, 1);
    FUZZ_CHECK(simulator.ok());
    for (size_t i = 0; i < 4; ++i) {
        const double seconds = size > i ? data[size - 1 - i] / 16.0 : 0.5;
        simulator.value()->advance(seconds);
    }
    for (size_t i = 0; i < config.points.size(); ++i) {
        (void)simulator.value()->value(i);
    }
    return 0;
}
