"""Message ports and distributed shared memory on the emulated 486 board (seed 7.9, 7.10).

Each case boots the test image under -icount, so the time-outs and the
interleavings the on-target tests check are exact and repeatable. The tests
live in tests_renode/target/PortDsmTest.cpp and print what they measured.
"""

import re

import pytest

from dcoslab.target import run_target_test

PORT_DSM_TARGET_TESTS = [
    "portprims",        # every port primitive with its errors: ids, ownership, ISRs, full table
    "portbufs",         # no buffer left: Send refuses and nothing is lost; AddMsgBufs; Delete returns buffers
    "portorder",        # FIFO, priority and LIFO order from a mixed sequence
    "porttimeout",      # Receive time-out and poll; a waiting receiver woken by Delete
    "portwake",         # a blocked receiver woken by Send from a task and from an ISR
    "dsmprims",         # every DSM primitive with its errors: ids, ownership, ISRs, full tables
    "dsmread",          # Read at once when newer, poll, time-out, woken by Write and by Delete
    "dsmrace",          # readers racing a writer and an ISR see no torn page, identifiers increase
    "portdsmrecovery",  # a dead task's ports (queued buffers come back), publishers, subscriptions
]


@pytest.mark.parametrize("name", PORT_DSM_TARGET_TESTS)
def test_port_dsm(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)


def test_ports_command_shows_queues_and_free_buffers(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(r"dcos> ")
    output = emulator.command("ports")
    assert "id          name             order     queued  levels    receiver  owner" in output
    match = re.search(r"(\d+) of (\d+) port slots used; message buffers: (\d+) free of (\d+) active, (\d+) reserved",
                      output)
    assert match, output
    used, active, free, buffers, reserved = (int(group) for group in match.groups())
    assert used == 0 and active > 0
    assert free == buffers and 0 < buffers <= reserved
    assert "ports" in emulator.command("help")
