// The management commands of the configuration protocol (seed 7.14,
// docs/protocols/config.md, "Objects and tasks") through the node's server
// on a backend in memory: each command done, each refused the way the
// page says (no MAC, a wrong key, the kernel's refusals carried through:
// unknown object, full table, wrong type, not found, not supported), the
// queries open or closed by configuration, and the whole configuration
// written in one record.
#include <sei/SeiServer.hpp>

#include "SeiTestSupport.hpp"

#include <gtest/gtest.h>

namespace {

using namespace sei_test;

class SeiManagementTest : public ::testing::Test {
protected:
    explicit SeiManagementTest(bool queriesClosed = false)
        : node(keyOf(0x11), 0x12345678, 0, queriesClosed), host(carrier(), keyOf(0x11), 5, 0x12345678)
    {
    }

    SeiHost::Carrier carrier() { return serverCarrier(node.server, now); }

    SeiMessage createTask(const char* entry, const char* name, uint8_t priority = 9, uint32_t stack = 4096)
    {
        SeiMessage m = request(SeiCommand::CreateTask);
        m.text = entry;
        m.textLength = static_cast<uint8_t>(std::string(entry).size());
        m.name = name;
        m.nameLength = static_cast<uint8_t>(std::string(name).size());
        m.priority = priority;
        m.stackSize = stack;
        return m;
    }

    SeiMessage createObject(uint8_t type, const char* name, uint32_t p0 = 0, uint32_t p1 = 0)
    {
        SeiMessage m = request(SeiCommand::CreateObject);
        m.objectType = type;
        m.name = name;
        m.nameLength = static_cast<uint8_t>(std::string(name).size());
        m.parameters[0] = p0;
        m.parameters[1] = p1;
        return m;
    }

    static SeiMessage onObject(SeiCommand command, uint32_t id)
    {
        SeiMessage m = request(command);
        m.objectId = id;
        return m;
    }

    static SeiMessage list(uint8_t type, uint16_t first = 0)
    {
        SeiMessage m = request(SeiCommand::ListObjects);
        m.objectType = type;
        m.first = first;
        return m;
    }

    static SeiMessage find(uint8_t type, const char* name)
    {
        SeiMessage m = request(SeiCommand::FindObject);
        m.objectType = type;
        m.name = name;
        m.nameLength = static_cast<uint8_t>(std::string(name).size());
        return m;
    }

    /// A KernelRefused reply carrying @p kernel.
    static void expectKernel(const SeiMessage& reply, uint8_t kernel)
    {
        EXPECT_EQ(reply.status, SeiStatus::KernelRefused);
        EXPECT_EQ(reply.kernelStatus, kernel);
    }

    uint64_t now = 1000 * kSecond;
    Node node;
    SeiHost host;
};

using B = MemoryBackend;

TEST_F(SeiManagementTest, CreateStopStartAndKillATask)
{
    const SeiMessage created = host.authenticated(createTask("sampler", "s2"));
    ASSERT_EQ(created.status, SeiStatus::Ok);
    const uint32_t id = created.objectId;
    EXPECT_EQ(node.backend.objects.at(id).name, "s2");
    EXPECT_EQ(node.backend.objects.at(id).priority, 9);

    EXPECT_EQ(host.authenticated(onObject(SeiCommand::StopTask, id)).status, SeiStatus::Ok);
    EXPECT_EQ(node.backend.objects.at(id).state, 5) << "suspended";
    SeiMessage info = onObject(SeiCommand::ObjectInfo, id);
    const SeiMessage described = host.ask(info);
    EXPECT_EQ(described.status, SeiStatus::Ok);
    EXPECT_EQ(described.objectType, B::kTask);
    EXPECT_EQ(described.state, 5);
    EXPECT_EQ(std::string(described.name, described.nameLength), "s2");
    EXPECT_EQ(host.authenticated(onObject(SeiCommand::StartTask, id)).status, SeiStatus::Ok);
    EXPECT_EQ(node.backend.objects.at(id).state, 2) << "ready";
    EXPECT_EQ(host.authenticated(onObject(SeiCommand::KillTask, id)).status, SeiStatus::Ok);
    EXPECT_EQ(node.backend.objects.count(id), 0u);
    expectKernel(host.authenticated(onObject(SeiCommand::KillTask, id)), B::kInvalidId);
}

TEST_F(SeiManagementTest, TaskCommandsRefusedByTheKernel)
{
    expectKernel(host.authenticated(createTask("nosuch", "x")), B::kNotFound);
    expectKernel(host.authenticated(createTask("sampler", "x", 32)), B::kInvalidArgument);
    expectKernel(host.authenticated(createTask("sampler", "x", 9, 100)), B::kInvalidArgument);
    const uint32_t semaphore = host.authenticated(createObject(B::kSemaphore, "lock", 1)).objectId;
    expectKernel(host.authenticated(onObject(SeiCommand::StopTask, semaphore)), B::kWrongType);
    expectKernel(host.authenticated(onObject(SeiCommand::StartTask, semaphore)), B::kWrongType);
    expectKernel(host.authenticated(onObject(SeiCommand::KillTask, semaphore)), B::kWrongType);
    ASSERT_EQ(host.authenticated(createTask("sampler", "dup")).status, SeiStatus::Ok);
    expectKernel(host.authenticated(createTask("logger", "dup")), B::kAlreadyExists);
}

TEST_F(SeiManagementTest, AFullTableIsSaidAndAddObjectsMakesRoom)
{
    for (int i = 0; i < 8; ++i) {
        ASSERT_EQ(host.authenticated(createObject(B::kPort, "")).status, SeiStatus::Ok) << i;
    }
    expectKernel(host.authenticated(createObject(B::kPort, "")), B::kTableFull);
    SeiMessage add = request(SeiCommand::AddObjects);
    add.objectType = B::kPort;
    add.count = 8;
    EXPECT_EQ(host.authenticated(add).status, SeiStatus::Ok);
    EXPECT_EQ(host.authenticated(createObject(B::kPort, "")).status, SeiStatus::Ok);
    add.count = 100;
    expectKernel(host.authenticated(add), B::kInvalidArgument);
}

TEST_F(SeiManagementTest, CreateAndDeleteObjects)
{
    const SeiMessage semaphore = host.authenticated(createObject(B::kSemaphore, "lock", 1));
    ASSERT_EQ(semaphore.status, SeiStatus::Ok);
    const SeiMessage found = host.ask(find(B::kSemaphore, "lock"));
    EXPECT_EQ(found.status, SeiStatus::Ok);
    EXPECT_EQ(found.objectId, semaphore.objectId);
    expectKernel(host.ask(find(B::kPort, "lock")), B::kNotFound);
    expectKernel(host.authenticated(createObject(B::kPool, "p")), B::kNotSupported);
    expectKernel(host.authenticated(createObject(B::kTask, "t")), B::kInvalidArgument);
    EXPECT_EQ(host.authenticated(onObject(SeiCommand::DeleteObject, semaphore.objectId)).status, SeiStatus::Ok);
    expectKernel(host.ask(find(B::kSemaphore, "lock")), B::kNotFound);
    expectKernel(host.authenticated(onObject(SeiCommand::DeleteObject, semaphore.objectId)), B::kInvalidId);
    expectKernel(host.ask(onObject(SeiCommand::ObjectInfo, semaphore.objectId)), B::kInvalidId);
}

TEST_F(SeiManagementTest, ListObjectsPagesThroughATable)
{
    for (int i = 0; i < 8; ++i) {
        const std::string name = "s" + std::to_string(i);
        ASSERT_EQ(host.authenticated(createObject(B::kSemaphore, name.c_str(), 1)).status, SeiStatus::Ok);
    }
    SeiMessage add = request(SeiCommand::AddObjects);
    add.objectType = B::kSemaphore;
    add.count = 2;
    ASSERT_EQ(host.authenticated(add).status, SeiStatus::Ok);
    ASSERT_EQ(host.authenticated(createObject(B::kSemaphore, "s8", 1)).status, SeiStatus::Ok);
    std::vector<std::string> names;
    uint16_t first = 0;
    for (int page = 0; page < 4 && first != sei::kSeiListEnd; ++page) {
        const SeiMessage reply = host.ask(list(B::kSemaphore, first));
        ASSERT_EQ(reply.status, SeiStatus::Ok);
        for (size_t i = 0; i < reply.entryCount; ++i) {
            names.emplace_back(reply.entries[i].name, reply.entries[i].nameLength);
        }
        first = reply.next;
    }
    EXPECT_EQ(first, sei::kSeiListEnd);
    EXPECT_EQ(names, (std::vector<std::string>{"s0", "s1", "s2", "s3", "s4", "s5", "s6", "s7", "s8"}));
    expectKernel(host.ask(list(2)), B::kInvalidArgument); // Processes have no table.
}

TEST_F(SeiManagementTest, NodeStatisticsListsEveryTable)
{
    ASSERT_EQ(host.authenticated(createObject(B::kSemaphore, "a", 1)).status, SeiStatus::Ok);
    const SeiMessage reply = host.ask(request(SeiCommand::NodeStatistics));
    ASSERT_EQ(reply.status, SeiStatus::Ok);
    EXPECT_EQ(reply.uptimeNs, 123456789012ull);
    EXPECT_EQ(reply.tableCount, 8);
    bool semaphores = false;
    for (size_t i = 0; i < reply.tableCount; ++i) {
        if (reply.tables[i].type == B::kSemaphore) {
            semaphores = true;
            EXPECT_EQ(reply.tables[i].used, 1);
            EXPECT_EQ(reply.tables[i].capacity, 8);
        }
    }
    EXPECT_TRUE(semaphores);
}

TEST_F(SeiManagementTest, EveryChangeNeedsARightMacOnAFreshChallenge)
{
    const std::vector<SeiMessage> changes = {
        createTask("sampler", "t"),
        onObject(SeiCommand::StartTask, B::idOf(B::kTask, 1)),
        onObject(SeiCommand::StopTask, B::idOf(B::kTask, 1)),
        onObject(SeiCommand::KillTask, B::idOf(B::kTask, 1)),
        createObject(B::kSemaphore, "x", 1),
        onObject(SeiCommand::DeleteObject, B::idOf(B::kSemaphore, 1)),
        [] {
            SeiMessage m = request(SeiCommand::AddObjects);
            m.objectType = B::kTask;
            m.count = 1;
            return m;
        }(),
    };
    for (const SeiMessage& change : changes) {
        const uint8_t code = static_cast<uint8_t>(static_cast<uint8_t>(change.command) | sei::kSeiReplyBit);
        // Without any challenge, a MAC of zeros.
        SeiMessage unsigned_ = change;
        unsigned_.hasMac = true;
        EXPECT_EQ(host.raw(encoded(unsigned_)), (Bytes{code, static_cast<uint8_t>(SeiStatus::NoChallenge)}));
        // A wrong key, then (the challenge used up) the same bytes again.
        host.setKey(keyOf(0x40));
        EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
        const Bytes wrong = host.signedBytes(change);
        EXPECT_EQ(host.raw(wrong), (Bytes{code, static_cast<uint8_t>(SeiStatus::BadMac)}));
        EXPECT_EQ(host.raw(wrong), (Bytes{code, static_cast<uint8_t>(SeiStatus::NoChallenge)})) << "a replay";
        host.setKey(keyOf(0x11));
        // Two wrong keys in a row never lock: the right one resets the count.
        (void)host.authenticated(change);
        // A right MAC, then the same bytes replayed.
        EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
        const Bytes right = host.signedBytes(change);
        (void)host.raw(right);
        EXPECT_EQ(host.raw(right), (Bytes{code, static_cast<uint8_t>(SeiStatus::NoChallenge)})) << "a replay";
        // A challenge older than 30 s.
        EXPECT_EQ(host.challenge().status, SeiStatus::Ok);
        now += 31 * kSecond;
        EXPECT_EQ(host.askSigned(change).status, SeiStatus::StaleChallenge);
    }
    EXPECT_TRUE(node.backend.objects.size() <= 2u);
}

TEST_F(SeiManagementTest, SetConfigurationWritesTheWholeRecordOnce)
{
    SeiMessage m = request(SeiCommand::SetConfiguration);
    m.nodeId = 9;
    m.bitRate = 500000;
    m.flags = sei::kSeiConfigurationQueriesClosed;
    m.lockoutSeconds = 120;
    m.text = "tick_hz=2000";
    m.textLength = 12;
    const SeiMessage written = host.authenticated(m);
    ASSERT_EQ(written.status, SeiStatus::Ok);
    EXPECT_EQ(written.sequence, 8u);
    EXPECT_EQ(node.backend.writes, 1u);
    EXPECT_EQ(node.backend.configuration.nodeId, 9);
    EXPECT_EQ(node.backend.configuration.bitRate, 500000u);
    EXPECT_TRUE(node.backend.configuration.queriesClosed);
    EXPECT_EQ(node.backend.configuration.lockoutSeconds, 120);
    EXPECT_EQ(node.backend.commandLine, "tick_hz=2000");
    // The queries closed at once: a listing now needs the key.
    EXPECT_EQ(host.ask(list(B::kTask)).status, SeiStatus::NotPermitted);
    SeiMessage signedList = list(B::kTask);
    EXPECT_EQ(host.authenticated(signedList).status, SeiStatus::Ok);
}

TEST_F(SeiManagementTest, SetConfigurationRefusesWhatSetNodeIdAndSetBitRateRefuse)
{
    SeiMessage m = request(SeiCommand::SetConfiguration);
    m.nodeId = 9;
    m.bitRate = 500000;
    for (const uint16_t id : {255, 256, 0xFFFF}) {
        m.nodeId = id;
        EXPECT_EQ(host.authenticated(m).status, SeiStatus::InvalidArgument) << id;
    }
    m.nodeId = 9;
    for (const uint32_t rate : {0u, 333333u}) {
        m.bitRate = rate;
        EXPECT_EQ(host.authenticated(m).status, SeiStatus::InvalidArgument) << rate;
    }
    EXPECT_EQ(node.backend.writes, 0u);
    m.bitRate = 250000;
    m.nodeId = 0;
    EXPECT_EQ(host.authenticated(m).status, SeiStatus::Ok) << "0: no node id set, the command line's is used";
    EXPECT_EQ(node.backend.configuration.nodeId, 0);
    node.backend.failing = true;
    EXPECT_EQ(host.authenticated(m).status, SeiStatus::CardError);
}

TEST_F(SeiManagementTest, ActivateBitRateIsTakenByEveryNodeAndAnsweredByNone)
{
    SeiMessage m = request(SeiCommand::ActivateBitRate);
    m.delayMs = 250;
    EXPECT_FALSE(carrier()(encoded(m)).has_value());
    ASSERT_EQ(node.backend.activations.size(), 1u);
    EXPECT_EQ(node.backend.activations[0].first, 250);
    EXPECT_EQ(node.backend.activations[0].second, now);
}

TEST_F(SeiManagementTest, MonitorIsAQueryAndItsChannelsMustBePublishers)
{
    const uint32_t publisher = host.authenticated(createObject(B::kPublisher, "speed")).objectId;
    const uint32_t semaphore = host.authenticated(createObject(B::kSemaphore, "lock", 1)).objectId;
    SeiMessage m = request(SeiCommand::Monitor);
    m.leaseSeconds = 10;
    m.periodMs = 100;
    m.channelCount = 1;
    m.channels[0].publisher = publisher;
    EXPECT_EQ(host.ask(m).status, SeiStatus::Ok);
    ASSERT_EQ(node.backend.monitorRequests.size(), 1u);
    EXPECT_EQ(node.backend.monitorRequests[0].channels[0].publisher, publisher);
    m.channels[0].publisher = semaphore;
    expectKernel(host.ask(m), B::kWrongType);
    m.channels[0].publisher = B::idOf(B::kPublisher, 99);
    expectKernel(host.ask(m), B::kInvalidId);
    EXPECT_EQ(node.backend.monitorRequests.size(), 1u);
}

class SeiClosedManagementTest : public SeiManagementTest {
protected:
    SeiClosedManagementTest() : SeiManagementTest(true) {}
};

TEST_F(SeiClosedManagementTest, ClosedQueriesNeedTheKeyOpenOnesDoNot)
{
    for (const SeiMessage& query : {list(B::kTask), find(B::kTask, "x"), onObject(SeiCommand::ObjectInfo, 1),
                                    request(SeiCommand::NodeStatistics), request(SeiCommand::Monitor)}) {
        EXPECT_EQ(host.ask(query).status, SeiStatus::NotPermitted) << static_cast<int>(query.command);
        const SeiMessage signedReply = host.authenticated(query);
        EXPECT_NE(signedReply.status, SeiStatus::NotPermitted);
        EXPECT_NE(signedReply.status, SeiStatus::BadMac);
    }
    host.setKey(keyOf(0x12));
    EXPECT_EQ(host.authenticated(list(B::kTask)).status, SeiStatus::BadMac);
}

} // namespace
