#include <hostconfig/ConfigurationFile.hpp>

#include <hosttoml/TomlChecker.hpp>

#include <can/MessageIdentifier.hpp>
#include <sei/SeiMessage.hpp>

#include <fmt/core.h>
#include <toml++/toml.h>

#include <set>
#include <sstream>
#include <utility>

namespace hostconfig {

namespace {

using hosttoml::TomlChecker;

std::string quoted(const std::string& text)
{
    // toml++ writes a string with every escape TOML needs.
    std::ostringstream out;
    out << toml::value<std::string>(text);
    return out.str();
}

std::optional<uint8_t> visibilityOf(TomlChecker& check, const toml::table& table, const std::string& where)
{
    const std::optional<std::string> word = check.string(table, "visibility", 8, where);
    if (!word) {
        return uint8_t{0};
    }
    if (const std::optional<uint8_t> visibility = visibilityFromName(*word)) {
        return visibility;
    }
    check.fail(*table.get("visibility"), fmt::format("{}: 'visibility' must be \"local\", \"regional\" or \"global\"",
                                                     where));
    return std::nullopt;
}

// The array of tables [[key]], each checked by @p read; nothing when absent.
template <typename Read>
void eachEntry(TomlChecker& check, const toml::table& root, const char* key, Read read)
{
    const toml::node* node = root.get(key);
    if (node == nullptr) {
        return;
    }
    if (!node->is_array_of_tables()) {
        check.fail(*node, fmt::format("'{}' must be an array of tables: write [[{}]] before each entry", key, key));
        return;
    }
    size_t index = 0;
    for (const toml::node& entry : *node->as_array()) {
        if (check.failed()) {
            return;
        }
        read(*entry.as_table(), fmt::format("{} {}", key, ++index));
    }
}

} // namespace

std::string writeSavedNode(const SavedNode& node, const std::string& header)
{
    std::string out;
    std::istringstream lines(header);
    for (std::string line; std::getline(lines, line);) {
        out += "# " + line + "\n";
    }
    const NodeConfiguration& c = node.configuration;
    out += "\n[node]\n";
    if (node.serial != 0) {
        out += fmt::format("serial = {}            # the node it was saved from; restore does not change it\n",
                           node.serial);
    }
    out += fmt::format("id = {}{}\n", c.nodeId,
                       c.nodeId == 0 ? "                 # 0: none set; the command line's node= or the default, 1"
                                     : "");
    out += fmt::format("bit_rate = {}\n", c.bitRate);
    out += fmt::format("queries = \"{}\"\n", c.queriesClosed() ? "closed" : "open");
    out += fmt::format("lockout_seconds = {}    # 0: 60 s\n", c.lockoutSeconds);
    out += fmt::format("command_line = {}\n", quoted(c.commandLine));
    for (const ObjectSpec& object : node.objects) {
        switch (object.kind) {
        case ObjectType::Semaphore:
            out += "\n[[semaphore]]\n";
            out += fmt::format("name = {}\n", quoted(object.name));
            out += fmt::format("initial_count = {}\n", object.initialCount);
            out += fmt::format("counting = {}\n", object.counting);
            out += fmt::format("inheritance = {}\n", object.inheritance);
            out += fmt::format("fifo = {}\n", object.fifo);
            break;
        case ObjectType::MessagePort:
            out += "\n[[port]]\n";
            out += fmt::format("name = {}\n", quoted(object.name));
            out += fmt::format("fifo = {}\n", object.fifo);
            break;
        case ObjectType::DsmPublisher:
            out += "\n[[publisher]]\n";
            out += fmt::format("name = {}\n", quoted(object.name));
            break;
        default: continue;
        }
        const char* visibility = visibilityName(object.visibility);
        out += fmt::format("visibility = \"{}\"\n", visibility != nullptr ? visibility : visibilityName(0));
    }
    for (const TaskSpec& task : node.tasks) {
        out += "\n[[task]]\n";
        out += fmt::format("name = {}\n", quoted(task.name));
        out += fmt::format("entry = {}\n", quoted(task.entry));
        out += fmt::format("priority = {}\n", task.priority);
        out += fmt::format("stack_size = {}\n", task.stackSize);
        out += fmt::format("argument = {}\n", task.argument);
    }
    return out;
}

std::optional<std::string> readSavedNode(const std::string& text, const std::string& fileName, SavedNode& out)
{
    toml::table root;
    if (const std::optional<std::string> error = hosttoml::parseAscii(text, fileName, root)) {
        return error;
    }
    TomlChecker check(fileName);
    SavedNode node;
    check.onlyKeys(root, {"node", "semaphore", "port", "publisher", "task"}, "the file");
    const toml::table* table = check.subtable(root, "node", "the file");
    if (table == nullptr && !check.failed()) {
        check.failAt(1, "a [node] table with id and bit_rate is required");
    }
    if (table != nullptr && !check.failed()) {
        const std::string where = "[node]";
        check.onlyKeys(*table, {"serial", "id", "bit_rate", "queries", "lockout_seconds", "command_line"}, where);
        const std::optional<int64_t> serial = check.integer(*table, "serial", 0, 0xFFFFFFFFll, where);
        const std::optional<int64_t> id =
            check.integer(*table, "id", 0, can::MessageIdentifier::kMaxNodeNumber, where);
        const std::optional<int64_t> rate = check.integer(*table, "bit_rate", 1, 0xFFFFFFFFll, where);
        const std::optional<std::string> queries = check.string(*table, "queries", 8, where);
        const std::optional<int64_t> lockout = check.integer(*table, "lockout_seconds", 0, 0xFFFF, where);
        const std::optional<std::string> commandLine = check.string(*table, "command_line", sei::kSeiMaxText, where);
        check.require(*table, id.has_value(), "id", where);
        check.require(*table, rate.has_value(), "bit_rate", where);
        if (queries && *queries != "open" && *queries != "closed") {
            check.fail(*table->get("queries"), "[node]: 'queries' must be \"open\" or \"closed\"");
        }
        node.serial = static_cast<uint32_t>(serial.value_or(0));
        node.configuration.nodeId = static_cast<uint16_t>(id.value_or(0));
        node.configuration.bitRate = static_cast<uint32_t>(rate.value_or(0));
        node.configuration.flags = queries == "closed" ? sei::kSeiConfigurationQueriesClosed : 0;
        node.configuration.lockoutSeconds = static_cast<uint16_t>(lockout.value_or(0));
        node.configuration.commandLine = commandLine.value_or("");
    }
    std::set<std::pair<ObjectType, std::string>> names;
    const auto named = [&](const toml::table& entry, const std::string& where, ObjectType kind) {
        const std::optional<std::string> name = check.string(entry, "name", sei::kSeiMaxName, where);
        check.require(entry, name.has_value() && !name->empty(), "name", where);
        if (name && !name->empty() && !names.insert({kind, *name}).second) {
            check.fail(entry, fmt::format("{}: a second {} named '{}'", where, kindName(static_cast<uint8_t>(kind)),
                                          *name));
        }
        return name.value_or("");
    };
    eachEntry(check, root, "semaphore", [&](const toml::table& entry, const std::string& where) {
        check.onlyKeys(entry, {"name", "initial_count", "counting", "inheritance", "fifo", "visibility"}, where);
        ObjectSpec spec;
        spec.kind = ObjectType::Semaphore;
        spec.name = named(entry, where, spec.kind);
        spec.initialCount = static_cast<uint32_t>(check.integer(entry, "initial_count", 0, 0xFFFFFFFFll, where).value_or(1));
        spec.counting = check.boolean(entry, "counting", where).value_or(false);
        spec.inheritance = check.boolean(entry, "inheritance", where).value_or(false);
        spec.fifo = check.boolean(entry, "fifo", where).value_or(false);
        spec.visibility = visibilityOf(check, entry, where).value_or(0);
        node.objects.push_back(spec);
    });
    eachEntry(check, root, "port", [&](const toml::table& entry, const std::string& where) {
        check.onlyKeys(entry, {"name", "fifo", "visibility"}, where);
        ObjectSpec spec;
        spec.kind = ObjectType::MessagePort;
        spec.name = named(entry, where, spec.kind);
        spec.fifo = check.boolean(entry, "fifo", where).value_or(false);
        spec.visibility = visibilityOf(check, entry, where).value_or(0);
        node.objects.push_back(spec);
    });
    eachEntry(check, root, "publisher", [&](const toml::table& entry, const std::string& where) {
        check.onlyKeys(entry, {"name", "visibility"}, where);
        ObjectSpec spec;
        spec.kind = ObjectType::DsmPublisher;
        spec.name = named(entry, where, spec.kind);
        spec.visibility = visibilityOf(check, entry, where).value_or(0);
        node.objects.push_back(spec);
    });
    eachEntry(check, root, "task", [&](const toml::table& entry, const std::string& where) {
        check.onlyKeys(entry, {"name", "entry", "priority", "stack_size", "argument"}, where);
        TaskSpec spec;
        spec.name = named(entry, where, ObjectType::Task);
        const std::optional<std::string> entryPoint = check.string(entry, "entry", sei::kSeiMaxName, where);
        check.require(entry, entryPoint.has_value() && !entryPoint->empty(), "entry", where);
        spec.entry = entryPoint.value_or("");
        spec.priority = static_cast<uint8_t>(check.integer(entry, "priority", 0, 31, where).value_or(16));
        spec.stackSize = static_cast<uint32_t>(check.integer(entry, "stack_size", 2048, 0x100000, where).value_or(4096));
        spec.argument = static_cast<uint32_t>(check.integer(entry, "argument", 0, 0xFFFFFFFFll, where).value_or(0));
        node.tasks.push_back(spec);
    });
    if (check.failed()) {
        return check.message();
    }
    out = node;
    return std::nullopt;
}

} // namespace hostconfig
