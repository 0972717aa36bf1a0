"""The distributed plant: the control loop of docs/examples/plant on one or two boards.

A PlantLab starts the host plant simulator (host_tools/plant_simulator, a
first-order-plus-dead-time process written to CSV) and boots the plant
application's image on the lab's CAN buses: node 1, whose I/O board is
wired to the simulator, and, for the two-node configuration, node 2. It
brings both channels of each board up as network interfaces (two buses,
dcoslab/remote.py's attach_redundant) and starts the loop's components
with the application's `plant` console command:

    configuration "one": node 1 runs the sampler, the controller and the actuator;
    configuration "two": node 1 the sampler and the actuator, node 2 the controller,
    each finding the publisher it reads by name on the other node;
    configuration "three": node 1 the sampler, node 2 the controller, node 3
    the actuator, nodes 1 and 3 both wired to the simulator (--boards 2);
    configuration "redundant": as "two", with a second controller on node 3;
    node 1's actuator follows node 2's "mv" and falls back on node 3's
    (active backup redundancy, the seed's Test Case 3, 9.4.3);
    configuration "voting": the seed's Test Case 3 on four nodes, every one
    with an I/O board wired to the simulator (--boards 4): nodes 1 and 2
    each run a sampler publishing "pv", nodes 3 and 4 each a voter reading
    both and writing AO1, which the plant takes through a diode (the higher
    of the two voters' outputs drives it; a dead node's output does not).

Every I/O board is wired with plant-on-write, so the simulator learns an
output when it is written (docs/iobus/mfio-register-map.md).

The seed's Test Case 2 (9.4.2, Fig. 9.7, instances 1 to 3); `make plant`
(tests_renode/plant.py) and docs/examples/plant/tests use it.
"""

import csv
import os
import re
import subprocess
import sys
import time

from .canlab import CanLab
from .layout import PLANT_SIMULATOR
from .remote import attach_redundant
# The plant: gain 1, time constant 200 ms, dead time 20 ms, as the single-board closed loop test's.
PLANT_OPTIONS = ["--gain", "1", "--tau", "0.2", "--dead-time", "0.02", "--input-channel", "0",
                 "--output-channel", "0"]
BIT_RATE = 500_000

# Test Case 3's plant input is AO1, read back on AI1 (loopback); AI0 measures the process.
VOTING_OPTIONS = ["--input-channel", "1", "--other-inputs", "loopback", "--boards", "4"]
CONFIGURATIONS = ("one", "two", "three", "redundant", "voting")
# The simulator's options beyond PLANT_OPTIONS, and the nodes wired to it, by configuration.
SIMULATOR_OPTIONS = {"three": ["--boards", "2"], "voting": VOTING_OPTIONS}
WIRED_NODES = {"three": (1, 3), "voting": (1, 2, 3, 4)}
COMPONENTS = ("sampler", "controller", "actuator", "voter")

_STARTED = re.compile(r"plant: \w+ started, publisher (0x[0-9a-f]{8})")


class PlantError(RuntimeError):
    pass


def start_plant_simulator(socket_path, csv_path, options=(), timeout=60):
    """The simulator listening on socket_path, writing its trajectory to csv_path; its process."""
    process = subprocess.Popen([sys.executable, PLANT_SIMULATOR, "--socket", socket_path, "--csv", csv_path,
                                "--accept-timeout", "300", *PLANT_OPTIONS, *options],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + timeout
    while not os.path.exists(socket_path):
        if process.poll() is not None or time.monotonic() > deadline:
            process.kill()
            raise PlantError(f"the plant simulator did not listen on {socket_path}: {process.stderr.read()}")
        time.sleep(0.05)
    return process


def read_trajectory(csv_path):
    """(seconds, AO0 in volts, plant output in volts) for each conversion in the simulator's CSV."""
    rows = []
    with open(csv_path, newline="", encoding="utf-8") as handle:
        for row in csv.DictReader(handle):
            rows.append((int(row["time_ns"]) / 1e9, float(row["dac0"]), float(row["process_output"])))
    return rows


def statistics(board, timeout=120):
    """The `plant` command's lines, a line a component, as {component: {field: number}}."""
    output = board.command("plant", timeout=timeout)
    result = {}
    for component, fields in re.findall(rf"^({'|'.join(COMPONENTS)}): (.*?)\r?$", output, re.M):
        result[component] = {name.strip().replace(" ", "_"): int(value)
                             for name, value in re.findall(r"([a-z ]+?) (-?\d+)(?: uV| us)?(?:,|$)", fields)}
    if len(result) != len(COMPONENTS):
        raise PlantError(f"unexpected `plant` output: {output!r}")
    return result


class PlantLab:
    def __init__(self, boot, board_definition, image, directory, configuration="two", bit_rate=BIT_RATE,
                 timeout=120, pace=None):
        if configuration not in CONFIGURATIONS:
            raise ValueError(f"configuration {configuration!r}: {', '.join(CONFIGURATIONS)}")
        self.configuration = configuration
        self.timeout = timeout
        self.csv_path = os.path.join(directory, "plant.csv")
        socket_path = os.path.join(directory, "plant.sock")
        self.simulator = start_plant_simulator(socket_path, self.csv_path, SIMULATOR_OPTIONS.get(configuration, ()))
        wired = {"devices": {"isa-mfio": {"wiring": "plant", "plant": "plant", "plant-on-write": "on"}},
                 "args": ["-chardev", f"socket,id=plant,path={socket_path}"]}
        others = {"one": [], "two": [2], "three": [2, 3], "redundant": [2, 3], "voting": [2, 3, 4]}[configuration]
        nodes = {}
        for node in [1, *others]:
            nodes[f"node{node}"] = {"bus0": "can0", "bus1": "can1", "append": f"node={node}",
                                    **(wired if node in WIRED_NODES.get(configuration, (1,)) else {})}
        try:
            self.lab = CanLab(boot, board_definition, {"can0": bit_rate, "can1": bit_rate}, nodes, pace=pace,
                              kind=image, timeout=timeout)
            self.io = self.lab.board("node1")
            self.control = self.lab.board("node2") if others else self.io
            self.backup = self.lab.board("node3") if configuration == "redundant" else None
            self.nodes = {node: self.lab.board(f"node{node}") for node in [1, *others]}
            self.actuator = self.nodes[3] if configuration == "three" else self.io
            everyone = [1, *others]
            for node in everyone if others else []:
                attach_redundant(self.lab.board(f"node{node}"), node, [peer for peer in everyone if peer != node],
                                 bit_rate, timeout)
        except BaseException:
            self.close()
            raise

    def start(self):
        """Starts the components where the configuration puts them; (pv, mv)
        publisher ids ("voting": the two samplers' pv)."""
        if self.configuration == "voting":
            # Two publishers are called "pv": each voter is given both ids, the
            # one it follows first (node 3 follows node 1's, node 4 node 2's).
            pv = [self._started(self.nodes[node], "plant io") for node in (1, 2)]
            for node, order in ((3, pv), (4, pv[::-1])):
                line = f"plant vote {order[0]} {order[1]}"
                output = self.nodes[node].command(line, timeout=self.timeout)
                if "voter started" not in output:
                    raise PlantError(f"{line}: {output!r}")
            return pv[0], pv[1]
        if self.configuration == "one":
            output = self.io.command("plant all", timeout=self.timeout)
            ids = _STARTED.findall(output)
            if len(ids) != 2 or "actuator started" not in output:
                raise PlantError(f"plant all: {output!r}")
            return ids[0], ids[1]
        # Each component finds its input by name: the controller node 1's
        # "pv", the actuator node 2's "mv" (distributed names).
        pv = self._started(self.io, "plant io")
        mv = self._started(self.control, "plant control")
        line = "plant actuate"
        if self.backup is not None:
            # Two publishers are called "mv": the actuator is given both ids.
            self.backup_mv = self._started(self.backup, "plant control")
            line = f"plant actuate {mv} {self.backup_mv}"
        output = self.actuator.command(line, timeout=self.timeout)
        if f"actuator started, reading {mv}" not in output:
            raise PlantError(f"{line}: {output!r}")
        return pv, mv

    def _started(self, board, line):
        output = board.command(line, timeout=self.timeout)
        match = _STARTED.search(output)
        if not match:
            raise PlantError(f"{line}: {output!r}")
        return match.group(1)

    def run_until(self, seconds):
        """Lets emulated time run until `seconds` after the boards' start.

        In steps of 100 ms of emulated time, each with the whole time-out: a
        busy host makes the boards slow, not stuck, and only a board that
        stops for the time-out fails the run."""
        target = int(seconds * 1e9)
        while self.lab.hub.now_ns < target:
            self.lab.hub.wait_until(min(target, self.lab.hub.now_ns + 100_000_000), self.timeout)

    def set_point(self, millivolts):
        output = self.control.command(f"plant setpoint {millivolts}", timeout=self.timeout)
        if "set point" not in output:
            raise PlantError(f"plant setpoint: {output!r}")

    def kill(self, board):
        """Stops a node's emulator: the node is dead, the others carry on."""
        board.emulator.close()

    def statistics(self):
        """Every component's statistics, from the nodes that run them."""
        io = statistics(self.io, self.timeout)
        control = statistics(self.control, self.timeout)
        actuator = statistics(self.actuator, self.timeout) if self.actuator is not self.io else io
        return {"sampler": io["sampler"], "controller": control["controller"], "actuator": actuator["actuator"]}

    def trajectory(self):
        return read_trajectory(self.csv_path)

    def close(self):
        lab = getattr(self, "lab", None)
        if lab is not None:
            lab.close()
        if self.simulator.poll() is None:
            self.simulator.terminate()
        try:
            self.simulator.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.simulator.kill()
