// The simulated slave's data and behaviours: libmodbus's modbus_mapping_t,
// sized to the configuration's map, and the ramps, sines and comparisons
// that change it as time passes. dcos-modbus-sim answers requests from the
// mapping with modbus_reply() and calls advance() between them.
#pragma once

#include <hostmodbus/Result.hpp>
#include <hostmodbus/SimulatorConfig.hpp>

#include <modbus.h>

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace hostmodbus {

class Simulator {
public:
    /// The simulator for @p config, its points at their initial values and
    /// its behaviours evaluated once; @p seed makes the noise repeatable.
    static Result<std::unique_ptr<Simulator>> create(const SimulatorConfig& config, uint32_t seed);

    ~Simulator();
    Simulator(const Simulator&) = delete;
    Simulator& operator=(const Simulator&) = delete;

    modbus_mapping_t* mapping() { return mapping_; }
    const SimulatorConfig& config() const { return config_; }

    /// Moves the behaviours on by @p seconds of wall-clock time.
    void advance(double seconds);

    /// Whether every address of @p count from @p address is declared in
    /// @p table: the mapping spans the lowest to the highest address, and a
    /// request into a gap between entries is refused as [AP] 7 (exception 02)
    /// says an address the slave does not have must be.
    bool declared(Table table, uint32_t address, uint32_t count) const;

    /// The current value of the point @p index (its first item for a block).
    uint16_t value(size_t index) const;

private:
    explicit Simulator(const SimulatorConfig& config, uint32_t seed);

    uint16_t* registerAt(Table table, uint16_t address) const;
    uint8_t* bitAt(Table table, uint16_t address) const;
    void write(size_t index, uint16_t value);
    double noise(double amplitude);

    SimulatorConfig config_;
    modbus_mapping_t* mapping_ = nullptr;
    std::mt19937 random_;
    double elapsed_ = 0;
    /// A ramp's exact position, so that rates below one unit per step
    /// still move the register.
    std::vector<double> rampPosition_;
};

} // namespace hostmodbus
