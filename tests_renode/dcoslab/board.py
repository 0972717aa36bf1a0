"""Board definitions: one JSON file per emulated board under tests_renode/boards/.

The harness and `make run` both build their emulator command line from these
files, so a board's machine, CPU, memory, devices and serial wiring are stated
in exactly one place.
"""

import json
import os
from dataclasses import dataclass, field

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BOARDS_DIRECTORY = os.path.join(REPOSITORY, "tests_renode", "boards")

# isa-debug-exit turns a guest write of v into the exit status (v << 1) | 1.
# These are the values the test image writes (tests_renode/target/EmulatorExit.hpp).
EXIT_PASS = (0x10 << 1) | 1
EXIT_FAIL = (0x11 << 1) | 1
EXIT_PANIC = (0x7F << 1) | 1


@dataclass
class Board:
    name: str
    description: str
    emulator: str
    bios_paths: list
    machine: str
    cpu: str
    memory_mib: int
    devices: list = field(default_factory=list)
    serial_ports: list = field(default_factory=list)
    images: dict = field(default_factory=dict)
    benchmark_cpu: str = ""

    def image(self, kind="production"):
        """Absolute path of the board's firmware image of the given kind."""
        return os.path.join(REPOSITORY, self.images[kind])

    def emulator_command(self, image, serial_backends, append="", icount=False, cpu=None):
        """The emulator argv for image, with one chardev argument per serial port.

        serial_backends maps each name in serial_ports to a QEMU -serial value
        (for example "mon:stdio" or "chardev:console"). cpu replaces the
        board's CPU model (the bench image runs on benchmark_cpu).
        """
        command = [self.emulator]
        for path in self.bios_paths:
            command += ["-L", path]
        command += [
            "-M", self.machine,
            "-cpu", cpu or self.cpu,
            "-m", str(self.memory_mib),
            "-kernel", image,
            "-display", "none",
            "-no-reboot",
            "-monitor", "none",
        ]
        if append:
            command += ["-append", append]
        if icount:
            # rdtsc and all timers follow retired instructions: exact and repeatable.
            command += ["-icount", "shift=0,align=off,sleep=off", "-rtc", "clock=vm"]
        for device in self.devices:
            properties = "".join(f",{key}={value}" for key, value in device.get("properties", {}).items())
            command += ["-device", device["driver"] + properties]
        for port in self.serial_ports:
            command += ["-serial", serial_backends[port]]
        return command


def load_board(name):
    """Reads tests_renode/boards/<name>.json."""
    path = os.path.join(BOARDS_DIRECTORY, f"{name}.json")
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
    except FileNotFoundError:
        known = sorted(entry[:-5] for entry in os.listdir(BOARDS_DIRECTORY) if entry.endswith(".json"))
        raise SystemExit(f"unknown board '{name}'; the boards are: {', '.join(known)}") from None
    return Board(**data)
