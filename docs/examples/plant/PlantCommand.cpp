// The console command `plant`: start the loop's components on this node,
// all or some, and show what each has done.
//
//     plant io                 the I/O board, the sampler (publishes "pv") and nothing else yet
//     plant control [<pv>]     the controller, reading publisher <pv> (local or another node's;
//                              by default the one named "pv", found on this node or another)
//     plant actuate [<mv> [<backup>]]
//                              the actuator, reading publisher <mv> (by default the one named
//                              "mv"), and a second controller's <backup>; on the node with the I/O board
//     plant vote <pv> <other pv>
//                              the voter (Test Case 3): reads two samplers' publishers, votes,
//                              computes the output and writes AO1; on a node with the I/O board
//     plant all                all three on this node
//     plant setpoint <mV>      the controller's set point
//     plant                    the components' statistics, a line each
//
// Every line a start prints names the publisher it created, for the
// command that starts the next component, here or on another node.
#include "Plant.hpp"

#include <dcos/DsmAgent.hpp>
#include <runtime/Text.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace plant {

namespace {

using dcos::ObjectId;
using dcos::Result;
using dcos::Status;
using runtime::textEquals;
using shell::CommandResult;

CommandResult failed(shell::Shell& shell, const char* what, Status status)
{
    shell.print("plant: cannot start the %s: %s\r\n", what, dcos::statusName(status));
    return CommandResult::Failed;
}

bool parseId(const char* text, ObjectId& id)
{
    unsigned long raw = 0;
    if (!shell::Shell::parseUnsigned(text, raw) || raw == 0 || raw > 0xFFFFFFFFul) {
        return false;
    }
    id = ObjectId::fromRaw(static_cast<uint32_t>(raw));
    return true;
}

// The publisher the command names: the id given, or the publisher called
// @p name, on this node or, failing that, on another (distributed names).
bool inputOf(shell::Shell& shell, int argc, char** argv, const char* name, ObjectId& id)
{
    if (argc == 3) {
        if (!parseId(argv[2], id)) {
            shell.print("plant: '%s' is not a publisher id\r\n", argv[2]);
            return false;
        }
        return true;
    }
    const Result<ObjectId> found = dcos::dsmAgent.NameToObject(name);
    if (!found.ok()) {
        shell.print("plant: no publisher \"%s\" on this node or another: %s\r\n", name,
                    dcos::statusName(found.status()));
        return false;
    }
    id = found.value();
    return true;
}

CommandResult started(shell::Shell& shell, const char* what, const Result<ObjectId>& publisher)
{
    if (!publisher.ok()) {
        return failed(shell, what, publisher.status());
    }
    shell.print("plant: %s started, publisher 0x%08lx\r\n", what, static_cast<unsigned long>(publisher.value().raw()));
    return CommandResult::Ok;
}

void printStatistics(shell::Shell& shell)
{
    const SamplerStatistics s = samplerStatistics();
    const ControllerStatistics c = controllerStatistics();
    const ActuatorStatistics a = actuatorStatistics();
    shell.print("sampler: samples %lu, pv %ld uV, errors %lu\r\n", static_cast<unsigned long>(s.samples),
                static_cast<long>(s.lastMicrovolts), static_cast<unsigned long>(s.errors));
    shell.print("controller: cycles %lu, setpoint %ld uV, pv %ld uV, mv %ld uV, timeouts %lu, errors %lu\r\n",
                static_cast<unsigned long>(c.cycles), static_cast<long>(setPoint()), static_cast<long>(c.lastPv),
                static_cast<long>(c.lastMv), static_cast<unsigned long>(c.timeouts),
                static_cast<unsigned long>(c.errors));
    shell.print("actuator: writes %lu, mv %ld uV, delay %lu us, max %lu us, timeouts %lu, errors %lu, failovers %lu\r\n",
                static_cast<unsigned long>(a.writes), static_cast<long>(a.lastMv),
                static_cast<unsigned long>(a.lastDelayNs / 1000), static_cast<unsigned long>(a.maxDelayNs / 1000),
                static_cast<unsigned long>(a.timeouts), static_cast<unsigned long>(a.errors),
                static_cast<unsigned long>(a.failovers));
    const VoterStatistics v = voterStatistics();
    shell.print("voter: cycles %lu, pv %ld uV, mv %ld uV, agreed %lu, disagreed %lu, single %lu, failovers %lu, "
                "readback errors %lu, errors %lu\r\n",
                static_cast<unsigned long>(v.cycles), static_cast<long>(v.lastPv), static_cast<long>(v.lastMv),
                static_cast<unsigned long>(v.agreed), static_cast<unsigned long>(v.disagreed),
                static_cast<unsigned long>(v.single), static_cast<unsigned long>(v.failovers),
                static_cast<unsigned long>(v.readBackErrors), static_cast<unsigned long>(v.errors));
}

CommandResult plantCommand(shell::Shell& shell, int argc, char** argv)
{
    ObjectId id;
    if (argc == 1) {
        printStatistics(shell);
        return CommandResult::Ok;
    }
    const char* const verb = argv[1];
    if (textEquals(verb, "io") && argc == 2) {
        return started(shell, "sampler", startSampler());
    }
    if (textEquals(verb, "control") && argc <= 3) {
        if (!inputOf(shell, argc, argv, "pv", id)) {
            return CommandResult::Failed;
        }
        return started(shell, "controller", startController(id));
    }
    if (textEquals(verb, "actuate") && argc <= 4) {
        if (!inputOf(shell, argc < 4 ? argc : 3, argv, "mv", id)) {
            return CommandResult::Failed;
        }
        ObjectId backup;
        if (argc == 4 && !parseId(argv[3], backup)) {
            shell.print("plant: '%s' is not a publisher id\r\n", argv[3]);
            return CommandResult::Failed;
        }
        const Status status = startActuator(id, backup);
        if (status != Status::Ok) {
            return failed(shell, "actuator", status);
        }
        shell.print("plant: actuator started, reading 0x%08lx\r\n", static_cast<unsigned long>(id.raw()));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "vote") && argc == 4) {
        ObjectId other;
        for (int i = 2; i < 4; ++i) {
            if (!parseId(argv[i], i == 2 ? id : other)) {
                shell.print("plant: '%s' is not a publisher id\r\n", argv[i]);
                return CommandResult::Failed;
            }
        }
        const Status status = startVoter(id, other);
        if (status != Status::Ok) {
            return failed(shell, "voter", status);
        }
        shell.print("plant: voter started, reading 0x%08lx and 0x%08lx\r\n", static_cast<unsigned long>(id.raw()),
                    static_cast<unsigned long>(other.raw()));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "all") && argc == 2) {
        const Result<ObjectId> pv = startSampler();
        if (started(shell, "sampler", pv) != CommandResult::Ok) {
            return CommandResult::Failed;
        }
        const Result<ObjectId> mv = startController(pv.value());
        if (started(shell, "controller", mv) != CommandResult::Ok) {
            return CommandResult::Failed;
        }
        const Status status = startActuator(mv.value());
        if (status != Status::Ok) {
            return failed(shell, "actuator", status);
        }
        shell.print("plant: actuator started, reading 0x%08lx\r\n", static_cast<unsigned long>(mv.value().raw()));
        return CommandResult::Ok;
    }
    if (textEquals(verb, "setpoint") && argc == 3) {
        const bool negative = argv[2][0] == '-';
        unsigned long magnitude = 0;
        if (!shell::Shell::parseUnsigned(argv[2] + (negative ? 1 : 0), magnitude) || magnitude > 10000) {
            shell.print("plant: the set point is -10000 to 10000 mV\r\n");
            return CommandResult::UsageError;
        }
        const long millivolts = negative ? -static_cast<long>(magnitude) : static_cast<long>(magnitude);
        setSetPoint(static_cast<int32_t>(millivolts * 1000));
        shell.print("plant: set point %ld mV\r\n", millivolts);
        return CommandResult::Ok;
    }
    return CommandResult::UsageError;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(plantShellCommand, "plant", "the control loop's components: start them, show them",
                            "plant [io | control [<pv>] | actuate [<mv> [<backup mv>]] | vote <pv> <other pv> | all |\r\n"
                            "       setpoint <mV>]",
                            "  io: the I/O board and the sampler, which publishes AI0 as \"pv\" every 10 ms\r\n"
                            "  control: the controller, reading publisher <pv> (default: the one named pv,\r\n"
                            "    here or on another node), publishing \"mv\"\r\n"
                            "  actuate: the actuator, reading publisher <mv> (default: the one named mv),\r\n"
                            "    writing AO0 (needs the I/O board); with a backup mv, the other takes over\r\n"
                            "    when the one followed is silent for three periods\r\n"
                            "  vote: the voter, reading two samplers' publishers, voting on the process value\r\n"
                            "    and writing the output to AO1, read back on AI1 (needs the I/O board)\r\n"
                            "  all: the three on this node; setpoint: the controller's and the voter's, in mV\r\n"
                            "  with no argument: each component's statistics",
                            plantCommand);

} // namespace plant
