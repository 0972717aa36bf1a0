#include <hostmodbus/SimulatorConfig.hpp>

#include <hosttoml/TomlChecker.hpp>

#include <fmt/core.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

namespace hostmodbus {

namespace {

constexpr size_t kMaxNameLength = 32;
// Device identification strings are kept short enough that the basic and
// regular objects all fit one response, and so no single object can exceed
// the 256-byte ADU on its own (which a stream could never deliver).
constexpr size_t kMaxIdentificationLength = 64;
// Plain blocks are capped at what one read can fetch, times a few: large
// enough for any demo, small enough that a typo cannot ask for gigabytes.
constexpr int64_t kMaxBlockCount = 2000;
// Rates, periods and amplitudes beyond this are typing errors, not drives.
constexpr double kMaxMagnitude = 1e9;

const char* const kTableKeys[kTableCount] = {"coil", "discrete_input", "holding_register", "input_register"};

using Checker = hosttoml::TomlChecker;

bool validName(const std::string& name)
{
    if (name.empty() || name.size() > kMaxNameLength || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) {
        return false;
    }
    return std::all_of(name.begin(), name.end(),
                       [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

void readDevice(Checker& check, const toml::table& device, SimulatorConfig& config)
{
    const std::string where = "[device]";
    check.onlyKeys(device,
                   {"slave", "vendor_name", "product_code", "revision", "vendor_url", "product_name", "model_name",
                    "user_application_name"},
                   where);
    if (const auto slave = check.integer(device, "slave", 1, 247, where)) {
        config.slave = static_cast<uint8_t>(*slave);
    }
    // The keys in object id order ([AP] Table 6.21), the basic three required.
    const std::pair<const char*, bool> objects[] = {{"vendor_name", true},  {"product_code", true},
                                                    {"revision", true},     {"vendor_url", false},
                                                    {"product_name", false}, {"model_name", false},
                                                    {"user_application_name", false}};
    for (uint8_t id = 0; id < std::size(objects); ++id) {
        const auto value = check.string(device, objects[id].first, kMaxIdentificationLength, where);
        if (value) {
            config.identification.push_back({id, *value});
        } else if (objects[id].second && device.get(objects[id].first) == nullptr) {
            check.fail(device, fmt::format("{}: '{}' is required (a basic device identification object)", where,
                                           objects[id].first));
        }
    }
}

// A point named by a behaviour: it must exist and be in one of the tables
// the behaviour can use.
int reference(Checker& check, const SimulatorConfig& config, const toml::table& table, std::string_view key,
              bool wantRegister, const std::string& where, bool required)
{
    const toml::node* node = table.get(key);
    if (node == nullptr) {
        if (required) {
            check.fail(table, fmt::format("{}: '{}' is required", where, key));
        }
        return -1;
    }
    const std::optional<std::string> name = node->value_exact<std::string>();
    if (!name) {
        check.fail(*node, fmt::format("{}: '{}' must be the name of a point, in quotes", where, key));
        return -1;
    }
    const int index = config.find(*name);
    if (index < 0) {
        check.fail(*node, fmt::format("{}: '{}' names '{}', which no entry is called", where, key, *name));
        return -1;
    }
    const Point& point = config.points[static_cast<size_t>(index)];
    if (isRegisterTable(point.table) != wantRegister) {
        check.fail(*node, fmt::format("{}: '{}' names '{}', a {}, where a {} is needed", where, key, *name,
                                      tableName(point.table), wantRegister ? "register" : "coil or discrete input"));
        return -1;
    }
    return index;
}

// The behaviour of @p point from its entry, once every name is known.
void readBehaviour(Checker& check, SimulatorConfig& config, size_t index, const toml::table& entry)
{
    Point& point = config.points[index];
    const std::string where = fmt::format("{} '{}'", tableName(point.table), point.name);
    const char* const kinds[] = {"ramp", "sine", "constant", "compare"};
    const char* chosen = nullptr;
    for (const char* kind : kinds) {
        if (entry.get(kind) != nullptr) {
            if (chosen != nullptr) {
                check.fail(*entry.get(kind),
                           fmt::format("{}: '{}' and '{}' together: a point has one behaviour", where, chosen, kind));
                return;
            }
            chosen = kind;
        }
    }
    if (chosen == nullptr) {
        return;
    }
    const toml::table* table = check.subtable(entry, chosen, where);
    if (table == nullptr) {
        return;
    }
    const std::string inner = fmt::format("{} {}", where, chosen);
    const bool wantsRegister = std::string_view(chosen) != "compare";
    if (isRegisterTable(point.table) != wantsRegister) {
        check.fail(*table, fmt::format("{}: a {} cannot {}", where, tableName(point.table),
                                       wantsRegister ? fmt::format("have a {} (registers only)", chosen)
                                                     : std::string("compare (coils and discrete inputs only)")));
        return;
    }
    if (point.count != 1) {
        check.fail(*table, fmt::format("{}: a block of {} cannot have a behaviour; give it count = 1", where, point.count));
        return;
    }
    Behaviour& b = point.behaviour;
    const std::string_view kind = chosen;
    if (kind == "ramp") {
        check.onlyKeys(*table, {"follows", "per_second", "enable"}, inner);
        b.kind = Behaviour::Kind::Ramp;
        b.source = reference(check, config, *table, "follows", true, inner, true);
        b.enable = reference(check, config, *table, "enable", false, inner, false);
        const auto rate = check.number(*table, "per_second", 1e-6, kMaxMagnitude, inner);
        check.require(*table, rate.has_value(), "per_second", inner);
        b.perSecond = rate.value_or(0);
        if (b.source == static_cast<int>(index)) {
            check.fail(*table, fmt::format("{}: a register cannot ramp towards itself", inner));
        }
    } else if (kind == "sine") {
        check.onlyKeys(*table, {"offset", "amplitude", "period_s", "noise"}, inner);
        b.kind = Behaviour::Kind::Sine;
        b.offset = check.number(*table, "offset", -kMaxMagnitude, kMaxMagnitude, inner).value_or(0);
        b.amplitude = check.number(*table, "amplitude", 0, kMaxMagnitude, inner).value_or(0);
        const auto period = check.number(*table, "period_s", 1e-3, kMaxMagnitude, inner);
        check.require(*table, period.has_value(), "period_s", inner);
        b.periodSeconds = period.value_or(1);
        b.noise = check.number(*table, "noise", 0, kMaxMagnitude, inner).value_or(0);
    } else if (kind == "constant") {
        check.onlyKeys(*table, {"value", "noise"}, inner);
        b.kind = Behaviour::Kind::Constant;
        const auto value = check.number(*table, "value", -kMaxMagnitude, kMaxMagnitude, inner);
        check.require(*table, value.has_value(), "value", inner);
        b.offset = value.value_or(0);
        b.noise = check.number(*table, "noise", 0, kMaxMagnitude, inner).value_or(0);
    } else {
        check.onlyKeys(*table, {"a", "b", "tolerance"}, inner);
        b.kind = Behaviour::Kind::Compare;
        b.source = reference(check, config, *table, "a", true, inner, true);
        b.other = reference(check, config, *table, "b", true, inner, true);
        b.tolerance = check.number(*table, "tolerance", 0, 65535, inner).value_or(0);
    }
}

void readPoint(Checker& check, Table table, const toml::table& entry, SimulatorConfig& config)
{
    Point point;
    point.table = table;
    point.line = static_cast<int>(entry.source().begin.line);
    const std::string where = fmt::format("[[{}]]", kTableKeys[static_cast<int>(table)]);
    check.onlyKeys(entry, {"name", "address", "count", "value", "ramp", "sine", "constant", "compare"}, where);
    const auto name = check.string(entry, "name", kMaxNameLength, where);
    const auto address = check.integer(entry, "address", 0, 0xFFFF, where);
    const auto count = check.integer(entry, "count", 1, kMaxBlockCount, where);
    if (check.failed()) {
        return;
    }
    if (!address) {
        check.fail(entry, fmt::format("{}: 'address' is required", where));
        return;
    }
    point.address = static_cast<uint16_t>(*address);
    point.count = static_cast<uint16_t>(count.value_or(1));
    if (*address + point.count > 0x10000) {
        check.fail(entry, fmt::format("{}: {} items from address {} run past 65535", where, point.count, *address));
        return;
    }
    if (name) {
        if (!validName(*name)) {
            check.fail(*entry.get("name"),
                       fmt::format("{}: '{}' is not a name: letters, digits and _, not starting with a digit", where,
                                   *name));
            return;
        }
        if (config.find(*name) >= 0) {
            check.fail(*entry.get("name"), fmt::format("{}: the name '{}' is taken by the entry on line {}", where,
                                                       *name, config.points[static_cast<size_t>(config.find(*name))].line));
            return;
        }
        point.name = *name;
    } else {
        point.name = fmt::format("{}_{}", kTableKeys[static_cast<int>(table)], point.address);
    }
    if (const toml::node* value = entry.get("value")) {
        if (isRegisterTable(table)) {
            const std::optional<int64_t> v = value->value_exact<int64_t>();
            if (!v || *v < -32768 || *v > 65535) {
                check.fail(*value, fmt::format("{}: 'value' must be an integer from -32768 to 65535", where));
                return;
            }
            point.value = static_cast<uint16_t>(*v & 0xFFFF);
        } else {
            const std::optional<bool> v = value->value_exact<bool>();
            if (!v) {
                check.fail(*value, fmt::format("{}: 'value' must be true or false", where));
                return;
            }
            point.value = *v ? 1 : 0;
        }
    }
    // Two entries on one address would leave the value to whichever came last.
    for (const Point& other : config.points) {
        if (other.table == table && point.address < other.address + other.count &&
            other.address < point.address + point.count) {
            check.fail(entry, fmt::format("{}: addresses {}..{} overlap '{}' on line {}", where, point.address,
                                          point.address + point.count - 1, other.name, other.line));
            return;
        }
    }
    config.points.push_back(std::move(point));
}

} // namespace

const char* tableName(Table table)
{
    switch (table) {
    case Table::Coil: return "coil";
    case Table::DiscreteInput: return "discrete input";
    case Table::HoldingRegister: return "holding register";
    case Table::InputRegister: return "input register";
    }
    return "?";
}

int SimulatorConfig::find(std::string_view name) const
{
    for (size_t i = 0; i < points.size(); ++i) {
        if (points[i].name == name) {
            return static_cast<int>(i);
        }
    }
    return -1;
}

Result<SimulatorConfig> parseSimulatorConfig(std::string_view text, std::string_view fileName)
{
    using R = Result<SimulatorConfig>;
    // toml++ 3.3 (Debian's) reaches __builtin_unreachable() when it tests
    // some non-ASCII characters for white space (U+00A1 to U+0499 among
    // them, is_non_ascii_horizontal_whitespace): undefined behaviour on a
    // hostile or merely accented file, found by fuzz_modbus_sim_config. The
    // file is therefore ASCII, and a byte outside it is refused with its line.
    toml::table root;
    if (const std::optional<std::string> error = hosttoml::parseAscii(text, fileName, root)) {
        return R::failure(*error);
    }
    Checker check(fileName);
    SimulatorConfig config;
    check.onlyKeys(root, {"device", "coil", "discrete_input", "holding_register", "input_register"}, "the file");
    const toml::table* device = check.subtable(root, "device", "the file");
    if (device == nullptr && !check.failed()) {
        check.failAt(1, "a [device] table with vendor_name, product_code and revision is required");
    }
    if (device != nullptr) {
        readDevice(check, *device, config);
    }
    // Entries first, behaviours second, so a behaviour may name an entry
    // that comes later in the file.
    std::vector<const toml::table*> entries;
    for (int t = 0; t < kTableCount && !check.failed(); ++t) {
        const toml::node* node = root.get(kTableKeys[t]);
        if (node == nullptr) {
            continue;
        }
        if (!node->is_array_of_tables()) {
            check.fail(*node, fmt::format("'{}' must be an array of tables: write [[{}]] before each entry",
                                          kTableKeys[t], kTableKeys[t]));
            break;
        }
        for (const toml::node& element : *node->as_array()) {
            readPoint(check, static_cast<Table>(t), *element.as_table(), config);
            if (check.failed()) {
                break;
            }
            entries.push_back(element.as_table());
        }
    }
    for (size_t i = 0; i < entries.size() && !check.failed(); ++i) {
        readBehaviour(check, config, i, *entries[i]);
    }
    if (!check.failed() && config.points.empty()) {
        check.failAt(1, "no entries: declare at least one [[coil]], [[discrete_input]], [[holding_register]] or "
                        "[[input_register]]");
    }
    if (check.failed()) {
        return R::failure(check.message());
    }
    return R::success(std::move(config));
}

Result<SimulatorConfig> loadSimulatorConfig(const std::string& path)
{
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        return Result<SimulatorConfig>::failure(fmt::format("{}: cannot be read", path));
    }
    std::ostringstream text;
    text << file.rdbuf();
    if (file.bad()) {
        return Result<SimulatorConfig>::failure(fmt::format("{}: reading failed", path));
    }
    return parseSimulatorConfig(text.str(), path);
}

} // namespace hostmodbus
