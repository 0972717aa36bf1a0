// Fuzz target: a saved node configuration as dcos-config restore reads it
// (host_tools/config/src/ConfigurationFile.cpp, on toml++ compiled in,
// header-only, so it is instrumented too).
//
// The checks: a refusal names the file and a line ("fuzz.toml:<n>...",
// n >= 1); an accepted file holds only what restore can send (a node id a
// CAN node number can carry, a bit rate that is not 0, a command line and
// names that fit their fields, an entry point for every task, no two
// objects of a kind with one name), and writing it and reading it back
// gives the same configuration.
#include "../../../fieldbus/can/fuzz/FuzzCheck.hpp"

#include <hostconfig/ConfigurationFile.hpp>

#include <cctype>
#include <cstddef>
#include <cstdint>
#include <set>
#include <string>
#include <utility>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    const std::string text(reinterpret_cast<const char*>(data), size);
    hostconfig::SavedNode node;
    const std::optional<std::string> error = hostconfig::readSavedNode(text, "fuzz.toml", node);
    if (error) {
        FUZZ_CHECK(error->rfind("fuzz.toml:", 0) == 0);
        FUZZ_CHECK(error->size() > 10 && std::isdigit(static_cast<unsigned char>((*error)[10])) &&
                   (*error)[10] != '0');
        return 0;
    }
    FUZZ_CHECK(node.configuration.nodeId <= 254);
    FUZZ_CHECK(node.configuration.bitRate != 0);
    FUZZ_CHECK(node.configuration.commandLine.size() <= sei::kSeiMaxText);
    std::set<std::pair<int, std::string>> names;
    for (const hostconfig::ObjectSpec& object : node.objects) {
        FUZZ_CHECK(!object.name.empty() && object.name.size() <= sei::kSeiMaxName);
        FUZZ_CHECK(object.visibility <= 2);
        FUZZ_CHECK(names.insert({static_cast<int>(object.kind), object.name}).second);
    }
    for (const hostconfig::TaskSpec& task : node.tasks) {
        FUZZ_CHECK(!task.name.empty() && task.name.size() <= sei::kSeiMaxName);
        FUZZ_CHECK(!task.entry.empty() && task.entry.size() <= sei::kSeiMaxName);
        FUZZ_CHECK(task.priority <= 31);
    }
    hostconfig::SavedNode back;
    const std::optional<std::string> again =
        hostconfig::readSavedNode(hostconfig::writeSavedNode(node, "again"), "again.toml", back);
    FUZZ_CHECK(!again);
    FUZZ_CHECK(back.configuration.nodeId == node.configuration.nodeId);
    FUZZ_CHECK(back.configuration.bitRate == node.configuration.bitRate);
    FUZZ_CHECK(back.configuration.flags == node.configuration.flags);
    FUZZ_CHECK(back.configuration.commandLine == node.configuration.commandLine);
    FUZZ_CHECK(back.objects.size() == node.objects.size() && back.tasks.size() == node.tasks.size());
    return 0;
}
