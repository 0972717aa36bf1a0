// The console command `shm`: the dual-Pentium board's shared-memory
// network's counts on this node (docs/protocols/shared-memory.md). Apart
// from SharedMemoryNetwork.cpp so that the minimal kernel configuration,
// which has no shell, links the board without it.
#include <bsp/P5smpBoard.hpp>
#include <bsp/SharedMemoryLink.hpp>

#include <bsp/Board.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

namespace {

shell::CommandResult shm(shell::Shell& shell, int argc, char**)
{
    if (argc != 1) {
        return shell::CommandResult::UsageError;
    }
    const bsp::SharedMemoryLink& link = bsp::boardSharedMemoryLink();
    if (!link.started()) {
        shell.print("shm: not started (%s)\r\n",
                    bsp::otherNodeRunning() ? "see the boot report" : "the board's other node does not run");
        return shell::CommandResult::Ok;
    }
    const bsp::SharedMemoryLinkStatistics s = link.statistics();
    shell.print("shm node %u to node %u: sent=%lu received=%lu ring_full=%lu not_signalled=%lu corrupted=%lu "
                "interrupts=%lu latency_last=%lu latency_min=%lu latency_max=%lu\r\n",
                unsigned(bsp::nodeId()), unsigned(bsp::otherNodeId()), static_cast<unsigned long>(s.sent),
                static_cast<unsigned long>(s.received), static_cast<unsigned long>(s.ringFull),
                static_cast<unsigned long>(s.notSignalled), static_cast<unsigned long>(s.corrupted),
                static_cast<unsigned long>(s.interrupts), static_cast<unsigned long>(s.latencyLast),
                static_cast<unsigned long>(s.latencyMin), static_cast<unsigned long>(s.latencyMax));
    return shell::CommandResult::Ok;
}

} // namespace

DCOS_SHELL_COMMAND_DETAILED(shmCommand, "shm", "show the shared-memory network's counts (dual-Pentium board)", "shm",
                            "  sent, received: messages through the rings; ring_full: sends refused, the other node\r\n"
                            "  took nothing for 64 messages; not_signalled: interrupts the local APIC did not deliver;\r\n"
                            "  corrupted: receives that found a ring's indices overwritten\r\n"
                            "  interrupts: the other node's interrupts taken; latency: from its stamp to this node's\r\n"
                            "  routine, in time-stamp counts (processor clocks; emulated ns under -icount)",
                            shm);

