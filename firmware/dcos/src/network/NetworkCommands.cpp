// The network interfaces manager's console command (seed 7.13): "net"
// lists its tables, resolves a node and, for the super user the console
// runs as, changes them. Output is one entry per line, so the lab's tests
// and a control engineer's scripts can read it.
#include <arch_x86/InstructionCounter.hpp>
#include <dcos/GlobalTime.hpp>
#include <dcos/NetworkInterfacesManager.hpp>
#include <dcos/internal/DsmManager.hpp>
#include <dcos/internal/IdText.hpp>
#include <dcos/internal/KernelConfig.hpp>
#include <dcos/internal/NetworkTables.hpp>
#include <dcos/internal/RemoteAgent.hpp>

#include <runtime/Text.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace dcos::internal {

namespace {

using runtime::textEquals;

// A copy of the tables to print from: static, since the tables are larger
// than a shell's stack should carry, and the console runs one command at a time.
constinit NetworkTables listed;

struct Text {
    char text[NetworkAddress::kTextSize];
};

Text textOf(NetworkAddress address)
{
    Text out;
    address.format(out.text);
    return out;
}

void list(shell::Shell& shell)
{
    copyNetworkTables(listed);
    shell.print("interfaces\r\n");
    listed.forEachInterface([&shell](uint8_t number, const NetworkInterface& interface) {
        shell.print("  %u  %-6s %u  %s/%u  physical %lu\r\n", unsigned(number), interfaceKindName(interface.kind),
                    unsigned(interface.channel), textOf(interface.address).text, unsigned(interface.prefixLength),
                    static_cast<unsigned long>(interface.physical));
    });
    shell.print("nodes\r\n");
    listed.forEachNodeAddress([&shell](const NetworkTables::NodeAddress& entry) {
        shell.print("  node %u  %s\r\n", unsigned(entry.node), textOf(entry.address).text);
    });
    shell.print("neighbours\r\n");
    listed.forEachNeighbour([&shell](const NetworkTables::Neighbour& entry) {
        shell.print("  %s  physical %lu\r\n", textOf(entry.address).text, static_cast<unsigned long>(entry.physical));
    });
    shell.print("routes\r\n");
    listed.forEachRoute([&shell](const NetworkTables::Route& entry) {
        shell.print("  %s/%u  via %s\r\n", textOf(entry.destination).text, unsigned(entry.prefixLength),
                    textOf(entry.gateway).text);
    });
}

// "a.b.c.d/len": the address and its prefix length.
bool parseSubnet(char* text, NetworkAddress& address, uint8_t& prefixLength)
{
    char* slash = text;
    while (*slash != '\0' && *slash != '/') {
        ++slash;
    }
    if (*slash != '/') {
        return false;
    }
    *slash = '\0';
    unsigned long length = 0;
    const bool ok = NetworkAddress::parse(text, address) && shell::Shell::parseUnsigned(slash + 1, length) && length <= 32;
    *slash = '/';
    prefixLength = static_cast<uint8_t>(length);
    return ok;
}

bool parseKind(const char* text, InterfaceKind& kind)
{
    constexpr InterfaceKind kinds[] = {InterfaceKind::Can, InterfaceKind::ModbusRtu, InterfaceKind::SharedMemory};
    for (InterfaceKind candidate : kinds) {
        if (textEquals(text, interfaceKindName(candidate))) {
            kind = candidate;
            return true;
        }
    }
    return false;
}

shell::CommandResult report(shell::Shell& shell, Status status)
{
    if (status != Status::Ok) {
        shell.print("net: %s\r\n", statusName(status));
        return shell::CommandResult::Failed;
    }
    return shell::CommandResult::Ok;
}

shell::CommandResult resolve(shell::Shell& shell, const char* nodeText)
{
    unsigned long node = 0;
    if (!shell::Shell::parseUnsigned(nodeText, node) || node > 0xFFFF) {
        return shell::CommandResult::UsageError;
    }
    const Result<NextHop> hop = NetworkInterfacesManager::Resolve(static_cast<uint16_t>(node));
    if (!hop.ok()) {
        return report(shell, hop.status());
    }
    shell.print("node %lu: %s via %s, interface %u, physical %lu\r\n", node, textOf(hop.value().destination).text,
                textOf(hop.value().via).text, unsigned(hop.value().interface),
                static_cast<unsigned long>(hop.value().physical));
    return shell::CommandResult::Ok;
}

struct Counter {
    const char* name;
    uint32_t value;
};

// Counters, one "  name value" line each, for the lab's tests and scripts.
template <size_t N>
void printCounters(shell::Shell& shell, const Counter (&counters)[N])
{
    for (const Counter& counter : counters) {
        shell.print("  %s %lu\r\n", counter.name, static_cast<unsigned long>(counter.value));
    }
}

// The remote agent's counters, one "name value" per line, then the
// transactions under way.
void listRemote(shell::Shell& shell)
{
    const RemoteStatistics s = remoteStatistics();
    shell.print("remote agent %s\r\n", remoteAgentStarted() ? "running" : "not started (no link attached)");
    const Counter counters[] = {
        {"requests", s.requests},         {"retransmissions", s.retransmissions},
        {"replies", s.replies},           {"pending-replies", s.pendingReplies},
        {"stray-replies", s.strayReplies}, {"unreachable", s.unreachable},
        {"no-call-slot", s.noCallSlot},   {"served", s.served},
        {"duplicates", s.duplicates},     {"refused-busy", s.refusedBusy},
        {"abandoned", s.abandoned},
        {"malformed", s.malformed},       {"send-failures", s.sendFailures},
        {"publications-sent", s.publicationsSent}, {"publication-parts", s.publicationParts},
        {"unknown-senders", s.unknownSenders}, {"names-not-found", s.namesNotFound},
        {"routed-requests", s.routedRequests}, {"forwarded", s.forwarded}, {"unrouted", s.unrouted},
        {"publications-relayed", s.publicationsRelayed},
        {"alarms-notified", s.alarmsNotified}, {"alarm-owners-lost", s.alarmOwnersLost},
        {"alarms-dropped", s.alarmsDropped},
        {"nodes-started", s.nodesStarted}, {"holds-freed", s.holdsFreed},
        {"timers-of-restarted", s.timersOfRestarted}, {"memory-lent", s.memoryLent},
        {"memory-returned", s.memoryReturned}, {"memory-reclaimed", s.memoryReclaimed}, {"no-flash-service", s.noFlashService},
    };
    printCounters(shell, counters);
    // The last transaction's instructions on each side, in an image with an
    // instruction counter (the remote bench's, docs/performance.md).
    if (arch_x86::instructionCount() == 0) {
        shell.print("  instructions not counted (no instruction counter in this image)\r\n");
    } else {
        const RemoteInstructions& i = s.instructions;
        const Counter instructions[] = {
            {"call-request-instructions", i.callRequest}, {"call-reply-instructions", i.callReply},
            {"serve-instructions", i.serve},              {"serve-parts-instructions", i.servePartsBefore},
        };
        printCounters(shell, instructions);
        shell.print("  call-span-instructions %llu\r\n", static_cast<unsigned long long>(i.callSpan));
    }
    for (size_t slot = 0; slot < kRemoteCalls; ++slot) {
        const RemoteCallInfo call = remoteCall(slot);
        if (call.inUse) {
            shell.print("  call %u  task %s  %s  transaction 0x%02x  interface %u  physical %lu\r\n",
                        unsigned(slot), IdText(call.caller).c_str(), remoteServiceName(call.service),
                        unsigned(call.transaction), unsigned(call.interface), static_cast<unsigned long>(call.peer));
        }
    }
}

// Publications over the network: the receiving side's counters, then the
// other nodes' publishers this node's tasks read.
void listPublications(shell::Shell& shell)
{
    const DsmNetworkStatistics s = DsmManager::networkStatistics();
    const Counter counters[] = {
        {"received", s.received},         {"duplicates", s.duplicates},
        {"torn", s.torn},                 {"unsubscribed", s.unsubscribed},
        {"withdrawals", s.withdrawals},   {"deferred", s.deferred},
        {"no-remote-publisher", s.noRemotePublisher},
    };
    printCounters(shell, counters);
    for (size_t slot = 0; slot < kRemotePublishers; ++slot) {
        const RemotePublisherInfo remote = DsmManager::remotePublisher(slot);
        if (remote.inUse) {
            shell.print("  publisher %s  subscriptions %u  data %lu%s\r\n", IdText(remote.publisher).c_str(),
                        unsigned(remote.subscriptions), static_cast<unsigned long>(remote.dataId),
                        remote.withdrawn ? "  withdrawn" : "");
        }
    }
}

// The global time base: the role, the master followed, the counters, the
// measured bound and the probes noted (docs/protocols/time.md).
void listTime(shell::Shell& shell)
{
    const GlobalTimeStatus s = globalTime.GetStatus();
    if (s.role == TimeRole::Master) {
        shell.print("time: master, rank %u, every %lu ms, %s\r\n", unsigned(s.rank),
                    static_cast<unsigned long>(s.intervalMs), s.sending ? "sending" : "quiet");
    } else {
        shell.print("time: %s\r\n", timeRoleName(s.role));
    }
    if (s.following && !s.sending) {
        shell.print("  following node %u, rank %u, every %lu ms, interface %u, %s\r\n", unsigned(s.masterNode),
                    unsigned(s.masterRank), static_cast<unsigned long>(s.masterIntervalMs),
                    unsigned(s.masterInterface), s.inStep ? "in step" : "not yet in step");
    } else if (!s.sending && s.role != TimeRole::Off) {
        shell.print("  no master heard\r\n");
    }
    const Counter counters[] = {
        {"syncs-sent", s.syncsSent},           {"follow-ups-sent", s.followUpsSent},
        {"syncs-received", s.syncsReceived},   {"follow-ups-received", s.followUpsReceived},
        {"corrections", s.corrections},        {"unpaired", s.unpaired},
        {"ignored", s.ignored},                {"held", s.held},
        {"malformed", s.malformed},            {"probes", s.probes},
    };
    printCounters(shell, counters);
    shell.print("  last-offset-ns %lld\r\n", static_cast<long long>(s.lastOffsetNs));
    shell.print("  largest-offset-ns %llu\r\n", static_cast<unsigned long long>(s.largestOffsetNs));
    shell.print("  drift-ppb %ld\r\n", static_cast<long>(s.driftPpb));
    TimeProbe probes[GlobalTime::kProbes];
    const size_t count = globalTime.GetProbes(probes, GlobalTime::kProbes);
    for (size_t i = 0; i < count; ++i) {
        shell.print("  probe %u interface %u source %lu time %llu\r\n", unsigned(probes[i].sequence),
                    unsigned(probes[i].interface), static_cast<unsigned long>(probes[i].source),
                    static_cast<unsigned long long>(probes[i].timeOfDayNs));
    }
}

shell::CommandResult timeBase(shell::Shell& shell, int argc, char** argv)
{
    if (argc == 2) {
        listTime(shell);
        return shell::CommandResult::Ok;
    }
    unsigned long number = 0;
    if (textEquals(argv[2], "master") && argc <= 5) {
        unsigned long rank = 0;
        unsigned long interval = kDefaultTimeSyncIntervalMs;
        if ((argc >= 4 && !shell::Shell::parseUnsigned(argv[3], rank)) ||
            (argc == 5 && !shell::Shell::parseUnsigned(argv[4], interval)) || rank > 0xFF || interval > 0xFFFFFFFFul) {
            return shell::CommandResult::UsageError;
        }
        return report(shell, globalTime.SetRole(TimeRole::Master, static_cast<uint8_t>(rank),
                                                static_cast<uint32_t>(interval)));
    }
    if (textEquals(argv[2], "follow") && argc == 3) {
        return report(shell, globalTime.SetRole(TimeRole::Follower));
    }
    if (textEquals(argv[2], "off") && argc == 3) {
        return report(shell, globalTime.SetRole(TimeRole::Off));
    }
    if (textEquals(argv[2], "probe") && argc == 4 && shell::Shell::parseUnsigned(argv[3], number) && number <= 63) {
        return report(shell, globalTime.SendProbe(static_cast<uint8_t>(number)));
    }
    return shell::CommandResult::UsageError;
}

shell::CommandResult net(shell::Shell& shell, int argc, char** argv)
{
    if (argc == 1) {
        list(shell);
        return shell::CommandResult::Ok;
    }
    if (argc == 2 && textEquals(argv[1], "remote")) {
        listRemote(shell);
        return shell::CommandResult::Ok;
    }
    if (argc == 2 && textEquals(argv[1], "publications")) {
        listPublications(shell);
        return shell::CommandResult::Ok;
    }
    if (argc >= 2 && textEquals(argv[1], "time")) {
        return timeBase(shell, argc, argv);
    }
    const bool remove = argc >= 3 && textEquals(argv[2], "remove");
    const char* const what = argv[1];
    NetworkAddress address;
    NetworkAddress other;
    uint8_t prefixLength = 0;
    unsigned long number = 0;
    unsigned long physical = 0;
    if (textEquals(what, "resolve") && argc == 3) {
        return resolve(shell, argv[2]);
    }
    if (textEquals(what, "interface")) {
        if (remove && argc == 4 && shell::Shell::parseUnsigned(argv[3], number) && number <= 0xFF) {
            return report(shell, NetworkInterfacesManager::RemoveInterface(static_cast<uint8_t>(number)));
        }
        InterfaceKind kind{};
        if (argc == 6 && parseKind(argv[2], kind) && shell::Shell::parseUnsigned(argv[3], number) && number <= 0xFF
            && parseSubnet(argv[4], address, prefixLength) && shell::Shell::parseUnsigned(argv[5], physical)) {
            const Result<uint8_t> added = NetworkInterfacesManager::AddInterface(
                kind, static_cast<uint8_t>(number), address, prefixLength, static_cast<uint32_t>(physical));
            if (added.ok()) {
                shell.print("interface %u\r\n", unsigned(added.value()));
            }
            return report(shell, added.status());
        }
        return shell::CommandResult::UsageError;
    }
    if ((textEquals(what, "map") || textEquals(what, "unmap")) && argc == 4
        && shell::Shell::parseUnsigned(argv[2], number) && number <= 0xFFFF && NetworkAddress::parse(argv[3], address)) {
        const uint16_t node = static_cast<uint16_t>(number);
        return report(shell, textEquals(what, "map") ? NetworkInterfacesManager::MapNode(node, address)
                                                     : NetworkInterfacesManager::UnmapNode(node, address));
    }
    if (textEquals(what, "neighbour")) {
        if (remove && argc == 4 && NetworkAddress::parse(argv[3], address)) {
            return report(shell, NetworkInterfacesManager::ClearPhysicalAddress(address));
        }
        if (argc == 4 && NetworkAddress::parse(argv[2], address) && shell::Shell::parseUnsigned(argv[3], physical)) {
            return report(shell, NetworkInterfacesManager::SetPhysicalAddress(address, static_cast<uint32_t>(physical)));
        }
        return shell::CommandResult::UsageError;
    }
    if (textEquals(what, "route")) {
        if (remove && argc == 4 && parseSubnet(argv[3], address, prefixLength)) {
            return report(shell, NetworkInterfacesManager::RemoveRoute(address, prefixLength));
        }
        if (argc == 4 && parseSubnet(argv[2], address, prefixLength) && NetworkAddress::parse(argv[3], other)) {
            return report(shell, NetworkInterfacesManager::AddRoute(address, prefixLength, other));
        }
        return shell::CommandResult::UsageError;
    }
    return shell::CommandResult::UsageError;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(
    netCommand, "net", "network interfaces manager: list, resolve or change the tables",
    "net [remote | publications | time | time master [RANK [INTERVAL_MS]] | time follow | time off | time probe SEQ"
    " | resolve NODE | interface can|modbus|shm CHANNEL A.B.C.D/LEN PHYSICAL | interface remove N"
    " | map|unmap NODE A.B.C.D | neighbour A.B.C.D PHYSICAL | neighbour remove A.B.C.D"
    " | route A.B.C.D/LEN GATEWAY | route remove A.B.C.D/LEN]",
    "  interfaces: number, kind, channel, own address/subnet prefix, own physical address\r\n"
    "  nodes: a logical node and one of its network addresses, tried in this order\r\n"
    "  neighbours: a network address on a local subnet and its physical address\r\n"
    "  routes: a destination subnet and the gateway it goes through\r\n"
    "  remote: the remote agent's counters and the remote transactions under way\r\n"
    "  publications: publications received from other nodes, and their publishers read here\r\n"
    "  time: the global time base: this node's role, the master it follows, the corrections,\r\n"
    "    the largest since in step (the measured bound) and the probes noted; master RANK (0-15,\r\n"
    "    0 preferred) INTERVAL_MS (100-25500, by 100) makes it a time master; probe SEQ (0-63)\r\n"
    "    sends a probe every node notes with its time of day\r\n"
    "  changing the tables needs a super user (the console is one)",
    net);

} // namespace dcos::internal
