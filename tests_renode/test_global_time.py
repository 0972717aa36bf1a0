"""The global time base (dissertation 5.6, 4.2.4; docs/protocols/time.md) on three emulated 486 boards.

Node 1 is the time master with an exact crystal; nodes 2 and 3 follow it
with crystals modelled 335.3 ppm and 251.5 ppm fast (the board's
crystal_ppm= option at a 100 Hz tick, one count of the 8254 in 11,932
being 83.8 ppm). QEMU 7.2's 8254 loses a tick now and then for some
divisors (docs/protocols/time.md, "Measured"); these two lose none in the
test's time, so a step the servo would rightly take for a lost tick does
not blur the bound measured here. The master syncs once a second. The lab bus injects a
time probe every few seconds at moments unrelated to the syncs; every node
notes its time of day at the probe frame's end, the same moment on all
of them, so the spread of one probe's notes is how far apart the clocks
really are. The nodes' own measurement (net time's largest-offset-ns and
drift-ppb) is checked against the same crystals.

Times are emulated (-icount, the hub's timing model); the wall-clock
time-outs only bound a hung board.
"""

import re

import pytest

from dcoslab.canbus import Frame
from dcoslab.remote import attach_node

BIT_RATE = 20_000
STEP = 120
SECOND = 1_000_000_000
# What each node's crystal is modelled as, and what the board makes of it.
CRYSTALS = {1: 0, 2: 335, 3: 250}
FAST_PPM = {1: 0.0, 2: 335.3, 3: 251.5}
INTERVAL_MS = 1000
# The stated bound for these crystals: the fastest follower's drift over
# one interval (335.3 us), plus the timestamps' error, which the test
# allows 24.7 us (docs/protocols/time.md, "The bound").
BOUND_NS = 360_000
# The probe's CAN identifier: priority 0, TimeSync (0x01), to the broadcast
# address, from CAN node 100, the lab's injector.
PROBE_ID = 0x0001FF00 | 100


@pytest.fixture
def trio(canlab):
    wiring = {f"board{n}": {"bus0": "can0", "append": f"node={n} tick_hz=100 crystal_ppm={CRYSTALS[n]}"}
              for n in (1, 2, 3)}
    lab = canlab({"can0": BIT_RATE}, wiring)
    boards = {n: lab.board(f"board{n}") for n in (1, 2, 3)}
    for n, board in boards.items():
        attach_node(board, n, [m for m in boards if m != n], BIT_RATE)
    return lab, boards


def time_status(board):
    """net time: the counters, the offsets and the probes noted, by sequence number."""
    output = board.command("net time")
    values = {name: int(value) for name, value in re.findall(r"^  ([a-z-]+) (-?\d+)\r?$", output, re.M)}
    probes = {int(seq): int(time) for seq, time in
              re.findall(r"^  probe (\d+) interface \d+ source \d+ time (\d+)\r?$", output, re.M)}
    return output, values, probes


class Prober:
    """Probes from the lab bus at emulated times of the test's choosing, and the nodes' notes of them."""

    def __init__(self, lab, boards):
        self.lab, self.boards = lab, boards
        self.sequence = 0
        self.spreads = []  # (sequence, {node: time of day}) for every probe every node noted

    def probe(self, at_ns):
        sequence = self.sequence % 64
        self.sequence += 1
        self.lab.hub.inject("can0", "prober", Frame.data_frame(PROBE_ID, bytes([0x80 | sequence]), extended=True),
                            at_ns=at_ns)
        return sequence

    def run(self, seconds, nodes, every_ns=3_700_000_000):
        """Emulated time on for `seconds`, a probe every `every_ns`; the notes of each, read back in batches."""
        hub = self.lab.hub
        end = hub.now_ns + seconds * SECOND
        while hub.now_ns < end:
            batch = []
            for _ in range(6):  # Fewer than the eight a node keeps.
                at = hub.now_ns + every_ns if not batch else batch[-1][1] + every_ns
                if at > end:
                    break
                batch.append((self.probe(at), at))
            if not batch:
                hub.wait_until(end, STEP)
                break
            hub.wait_until(batch[-1][1] + 50_000_000, STEP)
            notes = {n: time_status(self.boards[n])[2] for n in nodes}
            for sequence, _ in batch:
                missing = [n for n in nodes if sequence not in notes[n]]
                assert not missing, f"probe {sequence} not noted by node(s) {missing}"
                self.spreads.append((sequence, {n: notes[n][sequence] for n in nodes}))
        return [max(times.values()) - min(times.values()) for _, times in self.spreads]


def test_followers_stay_within_the_bound_of_the_master_for_ten_minutes(trio):
    lab, boards = trio
    # Node 3 starts years off: its first sync steps it.
    assert "error" not in boards[3].command("date 2031-05-05 10:00:00")
    assert "error" not in boards[1].command(f"net time master 0 {INTERVAL_MS}")
    lab.hub.wait_until(lab.hub.now_ns + 4 * SECOND, STEP)
    for n in (2, 3):
        output, values, _ = time_status(boards[n])
        assert "following node 1, rank 0, every 1000 ms, interface 0, in step" in output, output
    prober = Prober(lab, boards)
    spreads = prober.run(600, nodes=(1, 2, 3))
    assert len(spreads) >= 150
    assert max(spreads) <= BOUND_NS, sorted(spreads)[-10:]
    assert max(spreads) >= 100_000, "the drift the bound is about is really there"
    _, master, _ = time_status(boards[1])
    # Read at any moment: a Sync's FollowUp may still be on its way (it goes
    # once the Sync's own echo came back), so one may be missing.
    assert master["syncs-sent"] >= 600, master
    assert master["syncs-sent"] - 1 <= master["follow-ups-sent"] <= master["syncs-sent"], master
    for n in (2, 3):
        _, values, _ = time_status(boards[n])
        # The node's own measurement: its largest correction, and its rate against the master's.
        assert values["largest-offset-ns"] <= BOUND_NS, values
        assert abs(values["drift-ppb"] - FAST_PPM[n] * 1000) < 5_000, values
        assert values["corrections"] >= 595 and values["unpaired"] == 0 and values["malformed"] == 0, values
        # A correction held for straying from the drift's prediction is a
        # bad timestamp: rare, and never applied (the spreads above show it).
        assert values["held"] <= 3, values

    # A follower turned off drifts out of the bound within a minute.
    assert "error" not in boards[2].command("net time off")
    spreads = Prober(lab, boards).run(40, nodes=(1, 2))
    assert max(spreads) > 2 * BOUND_NS, spreads


def test_the_backup_master_takes_over_when_the_master_leaves_the_bus(trio):
    lab, boards = trio
    assert "error" not in boards[1].command(f"net time master 0 {INTERVAL_MS}")
    assert "error" not in boards[3].command(f"net time master 1 {INTERVAL_MS}")
    lab.hub.wait_until(lab.hub.now_ns + 4 * SECOND, STEP)
    output, values, _ = time_status(boards[3])
    assert "time: master, rank 1, every 1000 ms, quiet" in output, output
    assert "following node 1" in output, output
    prober = Prober(lab, boards)
    assert max(prober.run(20, nodes=(1, 2, 3))) <= BOUND_NS
    # The master leaves the bus; within three of its intervals the backup sends.
    for line in ("can detach can0", "can down can0"):
        assert "error" not in boards[1].command(line)
    lab.hub.wait_until(lab.hub.now_ns + 5 * SECOND, STEP)
    output, values, _ = time_status(boards[3])
    assert "time: master, rank 1, every 1000 ms, sending" in output, output
    output, _, _ = time_status(boards[2])
    assert "following node 3, rank 1" in output, output
    # Node 2 now follows node 3, which runs 251.5 ppm fast: node 2 is 83.8 ppm fast of it.
    spreads = prober.run(60, nodes=(2, 3))
    assert max(spreads) <= BOUND_NS, spreads
    _, values, _ = time_status(boards[2])
    assert abs(values["drift-ppb"] - (FAST_PPM[2] - FAST_PPM[3]) * 1000) < 5_000, values
