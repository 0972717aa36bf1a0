"""The seed's Test Case 2 (9.4.2, Fig. 9.7) with plain tasks: one copy of the loop, on one, two and three nodes.

Instance 1: the sampler, the controller and the actuator on node 1.
Instance 2: the sampler and the actuator on node 1, with the I/O board
wired to the plant simulator; the controller on node 2, reading "pv" and
writing "mv" across two CAN buses (docs/protocols/publications.md). The
same image and the same commands but for where each component starts; the
plant must be held at the set point within 20 mV in both, and end within
5 mV of it: the same control result.

Instance 3: the sampler on node 1, the controller on node 2, the actuator
on node 3; nodes 1 and 3 each have an I/O board wired to the plant.

Times are emulated (-icount); the hub keeps the boards in step.
"""

import pytest

from dcoslab.plantlab import PlantLab
from dcoslab.plantlab import statistics as statistics_of

SET_POINT_V = 2.0
BAND_V = 0.020
# Where every configuration must end: the same control result, within 5 mV.
END_V = 0.005
RUN_S = 3.0


@pytest.fixture
def plant(boot, isa486, dcos_image, tmp_path):
    labs = []

    def start(configuration):
        lab = PlantLab(boot, isa486, dcos_image, str(tmp_path), configuration=configuration)
        labs.append(lab)
        return lab

    yield start
    for lab in labs:
        lab.close()


def settled(trajectory, start_s):
    """The plant output's worst deviation from the set point from start_s on."""
    outputs = [y for t, _, y in trajectory if t >= start_s]
    assert outputs, "no conversion after the settling time"
    return max(abs(y - SET_POINT_V) for y in outputs)


def run(plant, configuration):
    lab = plant(configuration)
    pv, mv = lab.start()
    lab.run_until(RUN_S)
    counts = lab.statistics()
    trajectory = lab.trajectory()
    lab.close()
    return pv, mv, counts, trajectory


def test_one_node_holds_the_plant_at_its_set_point(plant):
    pv, mv, counts, trajectory = run(plant, "one")
    assert pv.startswith("0x00018") and mv.startswith("0x00018")
    assert settled(trajectory, RUN_S - 1.0) <= BAND_V
    assert abs(trajectory[-1][2] - SET_POINT_V) <= END_V
    assert counts["sampler"]["errors"] == counts["controller"]["errors"] == counts["actuator"]["errors"] == 0
    # Every sample went through the controller to the DAC.
    assert counts["sampler"]["samples"] >= 250
    assert counts["actuator"]["writes"] >= counts["sampler"]["samples"] - 1


def test_two_nodes_hold_it_the_same_with_the_controller_across_the_bus(plant):
    pv, mv, counts, trajectory = run(plant, "two")
    # The controller on node 2 reads node 1's "pv" and node 1's actuator node 2's "mv".
    assert pv.startswith("0x00018") and mv.startswith("0x00028")
    assert settled(trajectory, RUN_S - 1.0) <= BAND_V
    assert abs(trajectory[-1][2] - SET_POINT_V) <= END_V, "the same control result as on one node"
    assert counts["controller"]["timeouts"] == 0 and counts["controller"]["errors"] == 0
    assert counts["actuator"]["writes"] >= counts["sampler"]["samples"] - 2
    # Sample to DAC across the bus and back: two publications of three
    # frames at 500 kbit/s (about 0.8 ms each), well inside one period.
    assert 1_000 <= counts["actuator"]["max"] < 5_000, counts["actuator"]


def test_a_redundant_controller_takes_over_when_its_twin_dies(plant):
    """Seed 9.4.3 (Test Case 3): active backup redundancy. Controllers on
    nodes 2 and 3 both publish "mv"; node 1's actuator follows node 2's.
    Node 2 dies half way: node 3's output takes over within three periods,
    and the plant stays at its set point."""
    lab = plant("redundant")
    lab.start()
    lab.run_until(RUN_S / 2)
    before = lab.statistics()["actuator"]
    assert before["failovers"] == 0 and before["writes"] > 100
    lab.kill(lab.control)
    lab.run_until(RUN_S)
    actuator = statistics_of(lab.io)["actuator"]
    samples = statistics_of(lab.io)["sampler"]["samples"]
    trajectory = lab.trajectory()
    lab.close()
    assert actuator["failovers"] == 1, actuator
    # At most the failover time without a new output: three periods.
    assert actuator["writes"] >= samples - 4, (actuator, samples)
    assert actuator["errors"] == 0
    assert settled(trajectory, RUN_S - 1.0) <= BAND_V


def test_three_nodes_hold_it_the_same_with_each_component_on_its_own_node(plant):
    """The seed's instance 3: the sampler on node 1, the controller on node 2,
    the actuator on node 3, with the I/O boards of nodes 1 and 3 both wired
    to the plant (the simulator's --boards)."""
    pv, mv, counts, trajectory = run(plant, "three")
    assert pv.startswith("0x00018") and mv.startswith("0x00028")
    assert settled(trajectory, RUN_S - 1.0) <= BAND_V
    assert abs(trajectory[-1][2] - SET_POINT_V) <= END_V, "the same control result as on one node"
    assert counts["controller"]["timeouts"] == 0 and counts["controller"]["errors"] == 0
    assert counts["actuator"]["errors"] == 0
    assert counts["actuator"]["writes"] >= counts["sampler"]["samples"] - 2
    # Two publications across the bus, as on two nodes; the lab starts the
    # boards' clocks together, so the sampler's uptime holds on node 3.
    assert 1_000 <= counts["actuator"]["max"] < 5_000, counts["actuator"]
