// Each of the dual-Pentium board's interrupt lines belongs to one node
// (seed 5.3: devices are assigned to a node): the I/O APIC routes a line to
// its node's processor only, and a node cannot take another node's line.
// Node 3 owns IRQ 7 (its console, COM4) and the spare lines 12 and 13;
// node 2 every other one (COM1 on 4, the RS-485 ports on 3 and 9, the I/O
// board on 5, the PCI CAN card on 10). The emulator test types on both
// consoles first (tests_renode/test_board_p5smp.py), so that both consoles'
// lines have interrupted; then no interrupt of the other node's lines may
// have reached this one (its unexpected-interrupt counts), and installing a
// routine on one is refused.
#include "KernelTestSupport.hpp"
#include "TargetTest.hpp"

#include <bsp/Board.hpp>
#include <dcos/SystemAgent.hpp>

namespace target_test {

namespace {

using dcos::Status;

void noRoutine(void*) {}

bool nodeLines(shell::Shell& shell)
{
    static constexpr unsigned node3Lines[] = {7, 12, 13};
    static constexpr unsigned node2Lines[] = {3, 4, 5, 9, 10};
    const bool node3 = bsp::nodeId() == 3;
    if (!node3 && bsp::nodeId() != 2) {
        return check(shell, false, "this is node 2 or 3 of the dual-Pentium board");
    }
    const unsigned* const others = node3 ? node2Lines : node3Lines;
    const size_t count = node3 ? sizeof node2Lines / sizeof *node2Lines : sizeof node3Lines / sizeof *node3Lines;
    bool ok = true;
    for (size_t i = 0; i < count; ++i) {
        const unsigned line = others[i];
        shell.print("  line %u (the other node's): %lu unexpected here\r\n", line,
                    static_cast<unsigned long>(bsp::unexpectedInterruptCount(line)));
        ok = check(shell, bsp::unexpectedInterruptCount(line) == 0, "none of its interrupts reached this node") && ok;
        ok = checkStatus(shell, dcos::systemAgent.InstallISR(line, noRoutine, nullptr), Status::InvalidArgument,
                         "a routine on it is refused") && ok;
    }
    // A line of this node's own is taken, and given back.
    const unsigned own = bsp::spareInterruptLine(0);
    ok = checkStatus(shell, dcos::systemAgent.InstallISR(own, noRoutine, nullptr), Status::Ok,
                     "a routine on this node's spare line") && ok;
    ok = checkStatus(shell, dcos::systemAgent.RemoveISR(own), Status::Ok, "and removed") && ok;
    return ok;
}

DCOS_TARGET_TEST(nodeLinesTest, "nodelines", "the dual-Pentium board's lines reach only the node that owns them",
                 nodeLines);

} // namespace

} // namespace target_test
