// dcos-config's object and task commands (hostconfig::NodeObjects,
// NodeChanges) against nodes in memory that run the protocol's own server:
// a listing put together from its pages, names found, figures named by
// type, the changes authenticated, a create never asked twice, and the
// kernel's refusals carried to the tool in the kernel's words. The
// TOML file of a saved node (hostconfig::ConfigurationFile) is written and
// read back, and every file it must refuse is refused with its line.
#include <hostconfig/ConfigurationFile.hpp>
#include <hostconfig/NodeObjects.hpp>
#include <hostconfig/NodeSession.hpp>

#include "ConfigTestNodes.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace {

using config_test::keyOf;
using dcos::ObjectType;
using config_test::MemoryBus;
using config_test::MemoryNode;
using hostconfig::ConfigClient;
using hostconfig::ConfigError;
using hostconfig::NodeIdentity;
using sei::SeiCommand;
using sei::SeiStatus;

constexpr hostconfig::ClientOptions kOptions{std::chrono::milliseconds(100), 3};

struct Fixture {
    Fixture() : node(4711, 3, keyOf(1)), bus({&node}, 3), client(bus, kOptions)
    {
        EXPECT_FALSE(client.identify(identity));
    }

    MemoryNode node;
    MemoryBus bus;
    ConfigClient client;
    NodeIdentity identity;
    hostconfig::ConfigurationKey key = keyOf(1);
};

TEST(NodeObjectsTest, AListingIsPutTogetherFromItsPages)
{
    Fixture f;
    hostconfig::NodeChanges changes(f.client, f.identity, f.key);
    for (int i = 0; i < 8; ++i) {
        hostconfig::ObjectSpec spec;
        spec.name = "s" + std::to_string(i);
        uint32_t id = 0;
        ASSERT_FALSE(changes.createObject(spec, id));
    }
    ASSERT_FALSE(changes.addObjects(ObjectType::Semaphore, 16));
    for (int i = 8; i < 19; ++i) {
        hostconfig::ObjectSpec spec;
        spec.name = "s" + std::to_string(i);
        uint32_t id = 0;
        ASSERT_FALSE(changes.createObject(spec, id));
    }
    hostconfig::NodeObjects objects(f.client, f.identity, nullptr);
    std::vector<hostconfig::ObjectEntry> entries;
    ASSERT_FALSE(objects.list(ObjectType::Semaphore, entries));
    ASSERT_EQ(entries.size(), 19u);
    EXPECT_EQ(entries.front().name, "s0");
    EXPECT_EQ(entries.back().name, "s18");
    EXPECT_EQ(f.bus.sent(SeiCommand::ListObjects), 3u) << "8 + 8 + 3";
}

TEST(NodeObjectsTest, FindInfoAndTheKernelsRefusals)
{
    Fixture f;
    hostconfig::NodeChanges changes(f.client, f.identity, f.key);
    hostconfig::TaskSpec task;
    task.entry = "sampler";
    task.name = "s2";
    task.priority = 9;
    uint32_t id = 0;
    ASSERT_FALSE(changes.createTask(task, id));
    hostconfig::NodeObjects objects(f.client, f.identity, nullptr);
    uint32_t found = 0;
    ASSERT_FALSE(objects.find(ObjectType::Task, "s2", found));
    EXPECT_EQ(found, id);
    hostconfig::ObjectDetails details;
    ASSERT_FALSE(objects.info(id, details));
    EXPECT_EQ(details.name, "s2");
    EXPECT_EQ(details.figure("base_priority"), 9u);
    EXPECT_EQ(details.figure("stack_size"), 4096u);
    EXPECT_EQ(details.figures.front().first, "base_priority");

    const ConfigError missing = objects.find(ObjectType::Task, "nosuch", found);
    EXPECT_EQ(missing.kind, ConfigError::Kind::Refused);
    EXPECT_EQ(missing.status, SeiStatus::KernelRefused);
    EXPECT_EQ(hostconfig::describe(missing, "node 3"), "node 3's kernel refused it: not found");
    EXPECT_EQ(hostconfig::exitCodeOf(missing), hostconfig::kExitRefused);
    task.entry = "nosuch";
    EXPECT_EQ(hostconfig::describe(changes.createTask(task, id), "node 3"), "node 3's kernel refused it: not found");
    hostconfig::ObjectSpec pool;
    pool.kind = ObjectType::BufferPool;
    pool.name = "p";
    EXPECT_EQ(hostconfig::describe(changes.createObject(pool, id), "node 3"),
              "node 3's kernel refused it: not supported");
    EXPECT_EQ(hostconfig::describe(changes.onObject(SeiCommand::StopTask, found + 0x1000), "node 3"),
              "node 3's kernel refused it: wrong object type");
}

TEST(NodeObjectsTest, ACreateWhoseReplyIsLostIsNotAskedAgainButAStopIs)
{
    Fixture f;
    hostconfig::NodeChanges changes(f.client, f.identity, f.key);
    f.bus.dropCommand = SeiCommand::CreateObject;
    f.bus.dropReplies = 1;
    hostconfig::ObjectSpec spec;
    spec.name = "once";
    uint32_t id = 0;
    EXPECT_EQ(changes.createObject(spec, id).kind, ConfigError::Kind::Silent);
    EXPECT_EQ(f.bus.sent(SeiCommand::CreateObject), 1u);
    EXPECT_EQ(f.node.backend.countOf(10), 1u) << "the node did make it";
}

TEST(NodeObjectsTest, WordsForKindsStatesAndIds)
{
    EXPECT_EQ(hostconfig::kindName(10), "semaphore");
    EXPECT_EQ(hostconfig::kindName(2), "type-2");
    EXPECT_EQ(hostconfig::kindFromName("port"), ObjectType::MessagePort);
    EXPECT_FALSE(hostconfig::kindFromName("process"));
    EXPECT_EQ(hostconfig::taskStateName(5), "suspended");
    EXPECT_EQ(hostconfig::kernelStatusText(4), "object table full");
    EXPECT_EQ(hostconfig::kernelStatusText(200), "kernel status 200");
    EXPECT_EQ(hostconfig::idText(0x3a001), "0x0003a001");
    EXPECT_EQ(hostconfig::parseId("0x0003A001"), 0x3a001u);
    EXPECT_EQ(hostconfig::parseId("42"), 42u);
    for (const char* bad : {"", "0x", "-1", "+1", "12abc", "0x100000000", "lock"}) {
        EXPECT_FALSE(hostconfig::parseId(bad)) << bad;
    }
}

hostconfig::SavedNode sample()
{
    hostconfig::SavedNode node;
    node.serial = 1001;
    node.configuration.nodeId = 5;
    node.configuration.bitRate = 500000;
    node.configuration.flags = sei::kSeiConfigurationQueriesClosed;
    node.configuration.lockoutSeconds = 90;
    node.configuration.commandLine = "tick_hz=2000 name=\"x'y\"";
    hostconfig::ObjectSpec semaphore;
    semaphore.name = "lock";
    semaphore.initialCount = 3;
    semaphore.counting = true;
    semaphore.visibility = 1;
    hostconfig::ObjectSpec port;
    port.kind = ObjectType::MessagePort;
    port.name = "inbox";
    port.fifo = true;
    hostconfig::ObjectSpec publisher;
    publisher.kind = ObjectType::DsmPublisher;
    publisher.name = "level";
    publisher.visibility = 2;
    node.objects = {semaphore, port, publisher};
    hostconfig::TaskSpec task;
    task.name = "w2";
    task.entry = "worker";
    task.priority = 14;
    task.stackSize = 8192;
    task.argument = 7;
    node.tasks = {task};
    return node;
}

TEST(ConfigurationFileTest, AWrittenFileReadsBackTheSame)
{
    const hostconfig::SavedNode node = sample();
    const std::string text = hostconfig::writeSavedNode(node, "saved for a test\nsecond line");
    EXPECT_EQ(text.rfind("# saved for a test\n# second line\n", 0), 0u) << text;
    hostconfig::SavedNode back;
    const std::optional<std::string> error = hostconfig::readSavedNode(text, "node.toml", back);
    ASSERT_FALSE(error) << *error;
    EXPECT_EQ(back.serial, 1001u);
    EXPECT_EQ(back.configuration.nodeId, 5);
    EXPECT_EQ(back.configuration.bitRate, 500000u);
    EXPECT_TRUE(back.configuration.queriesClosed());
    EXPECT_EQ(back.configuration.lockoutSeconds, 90);
    EXPECT_EQ(back.configuration.commandLine, node.configuration.commandLine);
    ASSERT_EQ(back.objects.size(), 3u);
    EXPECT_EQ(back.objects[0].kind, ObjectType::Semaphore);
    EXPECT_EQ(back.objects[0].initialCount, 3u);
    EXPECT_TRUE(back.objects[0].counting);
    EXPECT_EQ(back.objects[0].visibility, 1);
    EXPECT_EQ(back.objects[1].kind, ObjectType::MessagePort);
    EXPECT_TRUE(back.objects[1].fifo);
    EXPECT_EQ(back.objects[2].visibility, 2);
    ASSERT_EQ(back.tasks.size(), 1u);
    EXPECT_EQ(back.tasks[0].entry, "worker");
    EXPECT_EQ(back.tasks[0].priority, 14);
    EXPECT_EQ(back.tasks[0].stackSize, 8192u);
    EXPECT_EQ(back.tasks[0].argument, 7u);
}

TEST(ConfigurationFileTest, FilesThatCannotBeRestoredAreRefusedWithTheirLine)
{
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"", "a [node] table"},
        {"[node]\nid = 3\n", "'bit_rate' is required"},
        {"[node]\nid = 300\nbit_rate = 250000\n", "node.toml:2: [node]: 'id' must be an integer from 0 to 254"},
        {"[node]\nid = 3\nbit_rate = 250000\nspeed = 1\n", "node.toml:4: [node]: unknown key 'speed'"},
        {"[node]\nid = 3\nbit_rate = 250000\nqueries = \"maybe\"\n", "'queries' must be \"open\" or \"closed\""},
        {"[node]\nid = 3\nbit_rate = 250000\n[[port]]\nname = \"abcdefghijklmnop\"\n",
         "'name' must be a string of at most 15 bytes"},
        {"[node]\nid = 3\nbit_rate = 250000\n[[port]]\nname = \"a\"\n[[port]]\nname = \"a\"\n", "a second port named 'a'"},
        {"[node]\nid = 3\nbit_rate = 250000\n[[task]]\nname = \"t\"\n", "'entry' is required"},
        {"[node]\nid = 3\nbit_rate = 250000\n[[task]]\nname = \"t\"\nentry = \"w\"\npriority = 32\n",
         "'priority' must be an integer from 0 to 31"},
        {"[node]\nid = 3\nbit_rate = 250000\n[[semaphore]]\nname = \"s\"\nvisibility = \"world\"\n",
         "'visibility' must be"},
        {"port = 1\n[node]\nid = 3\nbit_rate = 250000\n", "'port' must be an array of tables"},
        {"[node\n", "node.toml:1:"},
        {"[node]\nid = 3\nbit_rate = 250000\ncommand_line = \"\xc3\xa9\"\n", "only ASCII characters"},
    };
    for (const auto& [text, expected] : cases) {
        hostconfig::SavedNode out;
        const std::optional<std::string> error = hostconfig::readSavedNode(text, "node.toml", out);
        ASSERT_TRUE(error) << text;
        EXPECT_NE(error->find(expected), std::string::npos) << *error << "\n" << text;
    }
}

} // namespace
