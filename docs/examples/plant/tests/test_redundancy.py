"""The seed's Test Case 3 (9.4.3, Figs. 9.8 to 9.10) with plain tasks: two
publishers and two voting subscribers on four nodes, one node killed at
random in each of 20 trials, and control continues every time.

Nodes 1 and 2 each sample the plant and publish "pv"; nodes 3 and 4 each
run a voter that reads both, votes, computes the controller's output and
writes it to its own I/O board. The plant takes the higher of the two
voters' outputs (their outputs reach the actuator through diodes; the
plant simulator's "Several boards"), so either voter carries the loop
alone. Every publication goes on both CAN buses.

A trial boots the four nodes, lets the plant settle at its set point, and
stops one node's emulator (its CAN controller leaves both buses and its
outputs go dead) at a random moment. The node and the moment come from a
random generator seeded with the trial's number, so a failed trial is
repeated by its number alone. Control continues: from the kill on, the
plant never leaves the set point's band, the surviving voters go on
writing every period, and a voter whose followed sampler died follows the
other within the failover time.

Times are emulated (-icount); the hub keeps the boards in step.
"""

import math
import random

import pytest

from dcoslab.plantlab import PlantLab
from dcoslab.plantlab import statistics as statistics_of

SET_POINT_V = 2.0
BAND_V = 0.020
TRIALS = 20
SETTLED_S = 0.8           # the plant is within its band from here on, before any kill
KILL_BETWEEN_S = (0.9, 1.4)
AFTER_KILL_S = 0.8        # how long control must continue after the kill
PERIOD_S = 0.010
SAMPLERS = (1, 2)
VOTERS = (3, 4)


@pytest.fixture
def lab(boot, isa486, dcos_image, tmp_path):
    plant = PlantLab(boot, isa486, dcos_image, str(tmp_path), configuration="voting")
    yield plant
    plant.close()


def worst_deviation(trajectory, start_s, end_s=None):
    outputs = [y for t, _, y in trajectory if t >= start_s and (end_s is None or t < end_s)]
    assert outputs, f"no conversion from {start_s} s on"
    return max(abs(y - SET_POINT_V) for y in outputs)


def now_s(lab):
    return lab.lab.hub.now_ns / 1e9


def voters_of(lab, alive):
    return {node: statistics_of(lab.nodes[node])["voter"] for node in VOTERS if node in alive}


@pytest.mark.parametrize("trial", range(TRIALS))
def test_control_continues_when_a_node_dies(lab, trial):
    chooser = random.Random(trial)
    victim = chooser.choice(SAMPLERS + VOTERS)
    kill_s = round(chooser.uniform(*KILL_BETWEEN_S), 3)
    alive = [node for node in SAMPLERS + VOTERS if node != victim]
    where = f"trial {trial}: node {victim} killed at {kill_s} s"

    lab.start()
    lab.run_until(kill_s)
    # Emulated time runs on while the console answers, so the moments that
    # count are read from the hub, not taken from the schedule.
    before_s = now_s(lab)
    before = voters_of(lab, alive)
    lab.kill(lab.nodes[victim])
    lab.run_until(now_s(lab) + AFTER_KILL_S)
    end_s = now_s(lab)
    after = voters_of(lab, alive)
    samplers = {node: statistics_of(lab.nodes[node])["sampler"] for node in SAMPLERS if node in alive}
    trajectory = lab.trajectory()

    assert worst_deviation(trajectory, SETTLED_S, before_s) <= BAND_V, f"{where}: not settled before the kill"
    assert worst_deviation(trajectory, before_s) <= BAND_V, f"{where}: the plant left its band"
    periods = (end_s - before_s) / PERIOD_S
    for node, voter in after.items():
        # Every surviving voter kept writing: a cycle a period, less the
        # failover time when its followed sampler died.
        written = voter["cycles"] - before[node]["cycles"]
        assert written >= periods - 5, f"{where}: voter {node} wrote {written} outputs in {periods:.0f} periods: {voter}"
        assert voter["errors"] == 0 and voter["readback_errors"] == 0, f"{where}: voter {node}: {voter}"
        followed_died = victim == (1 if node == 3 else 2)
        assert voter["failovers"] == (1 if followed_died else 0), f"{where}: voter {node}: {voter}"
        if victim in SAMPLERS:
            # One sampler left: after the kill, no vote has two fresh values
            # once the dead sampler's last page is stale (it counts as fresh
            # for kFreshCycles = 2 more cycles, and one page may have been on
            # the bus), but for the cycles between the counters' reading and the kill.
            allowance = 1 + 2 + 1 + math.ceil(periods - AFTER_KILL_S / PERIOD_S)
            assert voter["agreed"] - before[node]["agreed"] <= allowance, f"{where}: voter {node}: {voter}"
        else:
            assert voter["agreed"] > before[node]["agreed"], f"{where}: voter {node}: {voter}"
    for node, sampler in samplers.items():
        assert sampler["errors"] == 0, f"{where}: sampler {node}: {sampler}"
