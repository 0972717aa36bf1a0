// dcos-modbus-sim's configuration: the register map of a simulated slave
// and how its values behave, read from a TOML file (toml++ parses it; the
// checks here make sense of what it holds). Every error names the file and
// the line of the value at fault (docs/guide/modbus-host.md has the format).
#pragma once

#include <hostmodbus/DeviceIdentification.hpp>
#include <hostmodbus/Result.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace hostmodbus {

/// The four data tables of [AP] 4.3, named as the configuration names them.
enum class Table : uint8_t { Coil, DiscreteInput, HoldingRegister, InputRegister };
constexpr int kTableCount = 4;

const char* tableName(Table table);
constexpr bool isRegisterTable(Table table) { return table == Table::HoldingRegister || table == Table::InputRegister; }

/// What a point does between requests.
struct Behaviour {
    enum class Kind {
        /// Keeps its value; a master may write coils and holding registers.
        None,
        /// A register that moves towards another register's value at a
        /// rate, or towards zero while an enable bit is off (a drive's speed).
        Ramp,
        /// A register that follows offset + amplitude * sin(2 pi t / period), plus noise.
        Sine,
        /// A register that holds a value, plus noise.
        Constant,
        /// A bit that is on while two registers are within a tolerance (a drive's "at speed").
        Compare,
    } kind = Kind::None;
    /// Indices into SimulatorConfig::points: the ramp's target, the compare's two registers.
    int source = -1;
    int other = -1;
    /// The ramp's enable bit, or -1 for none.
    int enable = -1;
    double perSecond = 0;
    double offset = 0;
    double amplitude = 0;
    double periodSeconds = 0;
    double noise = 0;
    double tolerance = 0;
};

/// One entry of the map: a named point, or a block of plain ones.
struct Point {
    Table table = Table::HoldingRegister;
    std::string name;
    uint16_t address = 0;
    /// More than one only for a block without behaviour.
    uint16_t count = 1;
    /// The initial value of every item (0 or 1 for bits).
    uint16_t value = 0;
    Behaviour behaviour;
    /// Where the entry is in the file, for messages.
    int line = 0;
};

struct SimulatorConfig {
    uint8_t slave = 1;
    /// The device identification objects (2B/0E), sorted by id.
    std::vector<DeviceIdObject> identification;
    std::vector<Point> points;

    /// The index of the point named @p name, or -1.
    int find(std::string_view name) const;
};

/// Parses and checks the configuration @p text, which came from @p fileName
/// (used in messages only). Nothing is thrown: toml++'s parse errors become
/// the result's error like the checks' own.
Result<SimulatorConfig> parseSimulatorConfig(std::string_view text, std::string_view fileName);

/// Reads the file, then parses it as above.
Result<SimulatorConfig> loadSimulatorConfig(const std::string& path);

} // namespace hostmodbus
