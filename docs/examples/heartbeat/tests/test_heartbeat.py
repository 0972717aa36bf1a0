"""The heartbeat application on the emulated dual-Pentium board: one image, both nodes.

Every test boots the board with exact emulated time (-icount): node 2's
console is the emulator's console, node 3's the board's "node3" serial port,
reached through a socket (dcoslab/node_console.py). What node 3 printed
before the test connected is gone, so its side is read with commands. Every
assertion message carries both consoles' transcripts.
"""

import re
import time

import pytest

from dcoslab.node_console import NodeConsole

WATCHER = re.compile(r"heartbeat: node 2 watches semaphore (0x[0-9a-f]{8}): (\d+) beats, (\d+) missed")
BEATER = re.compile(r"heartbeat: node 3 beats semaphore (0x[0-9a-f]{8}): (\d+) sent, (\d+) failed, (\d+) lookups")


@pytest.fixture
def nodes(boot, dcos_board, dcos_image):
    """The board booted with the application, at both nodes' prompts: (node 2's console, node 3's)."""
    if dcos_board.name != "p5smp":
        pytest.fail(f"heartbeat runs on the dual-Pentium board, not {dcos_board.name}: "
                    "build and test it with BOARD=p5smp")
    node2 = boot(dcos_board, dcos_image, icount=True, serial_sockets=("node3",))
    node2.expect(r"node 3 started on the processor with APIC id 1")
    node2.expect(r"dcos> ")
    node3 = NodeConsole(node2, "node3")
    try:
        node3.prompt()
        yield node2, node3
    finally:
        node3.close()


def transcripts(node2, node3):
    return (f"\n----- node 2 console -----\n{node2.transcript}"
            f"\n----- node 3 console -----\n{node3.transcript}")


def heartbeat(console, pattern, node2, node3):
    """Runs `heartbeat` on one node and returns its numbers, the semaphore's id first."""
    output = console.command("heartbeat")
    match = pattern.search(output)
    assert match, f"unexpected `heartbeat` output {output!r}" + transcripts(node2, node3)
    return match.group(1), [int(number) for number in match.groups()[1:]]


def test_both_nodes_run_the_application_each_its_part(nodes):
    node2, node3 = nodes
    context = transcripts(node2, node3)
    assert "application 'heartbeat' started: 1 task" in node2.transcript, context
    assert re.search(r"heartbeat: node 2 watches its semaphore 'heartbeat' \(0x0002[0-9a-f]{4}\)",
                     node2.transcript), context
    # Node 3 runs the same application, loaded from node 2's image.
    version = node3.command("version")
    assert "board p5smp" in version and "loaded by node 2" in version, version + context
    for console in (node2, node3):
        listing = console.command("app")
        assert "application 'heartbeat': running" in listing, listing + transcripts(node2, node3)
        assert re.search(r"task +heart +0x[0-9a-f]{8}", listing), listing + transcripts(node2, node3)
    assert "usage: heartbeat" in node3.command("heartbeat now")


def test_node_3_beats_node_2s_semaphore_over_shared_memory(nodes):
    node2, node3 = nodes
    deadline = time.monotonic() + 120
    while True:
        semaphore, (beats, missed) = heartbeat(node2, WATCHER, node2, node3)
        if beats >= 30:
            break
        assert time.monotonic() < deadline, f"only {beats} beats in 120 s" + transcripts(node2, node3)
        time.sleep(0.2)
    assert "heartbeat: node 2 heard the first beat" in node2.transcript, transcripts(node2, node3)
    assert semaphore.startswith("0x0002"), semaphore
    # Every beat node 3 sent arrived, on time: node 2 never waited 300 ms in vain.
    assert missed == 0, transcripts(node2, node3)
    found, (sent, failed, lookups) = heartbeat(node3, BEATER, node2, node3)
    assert found == semaphore, transcripts(node2, node3)
    assert failed == 0 and lookups >= 1, transcripts(node2, node3)
    assert sent >= beats, transcripts(node2, node3)
