"""Board definitions: one JSON file per emulated board under tests_renode/boards/
(share/dcos/boards/ in an installed DCOS).

The harness and `make run` both build their emulator command line from these
files, so a board's machine, CPU, memory, devices and serial wiring are stated
in exactly one place.
"""

import json
import os
from dataclasses import dataclass, field

from .built_emulator import resolve_emulator
from .layout import BOARDS_DIRECTORY, ROOT

# The directory board image paths are relative to: the repository, or the
# prefix of an installed DCOS (see layout.py).
REPOSITORY = ROOT

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
    # Processors (-smp), one per socket: the dual-Pentium board has two, each its own node.
    smp: int = 1
    devices: list = field(default_factory=list)
    serial_ports: list = field(default_factory=list)
    images: dict = field(default_factory=dict)
    benchmark_cpu: str = ""
    # Memory for the bench image only, whose kernel tables are built for 4096
    # objects of every type (mk/bench.mk); 0: memory_mib. Production and test
    # images always run with memory_mib, the board's real memory.
    benchmark_memory_mib: int = 0
    # Emulator arguments every run of the board takes, e.g. ["-nic", "none"]:
    # the isapc machine otherwise adds an NE2000 at 0x300, the I/O board's port.
    emulator_args: list = field(default_factory=list)
    # Serial ports that can be wired to a lab line instead (dcoslab/rs485.py):
    # port name -> {"driver": ..., "properties": {...}}, the device that then
    # takes the port's place (the isa486's RS-485 port: isa-rs485-uart).
    line_ports: dict = field(default_factory=dict)
    # The board's CAN card, the device whose channels a lab bus wires
    # (dcoslab/canlab.py): the isa486's ISA card, the p5smp's PCI card.
    can_card: str = "isa-sja1000"

    def image(self, kind="production"):
        """Absolute path of the board's firmware image of the given kind."""
        return os.path.join(REPOSITORY, self.images[kind])

    def benchmark_memory(self):
        """Memory in MiB to boot the bench image with."""
        return self.benchmark_memory_mib or self.memory_mib

    def device_drivers(self):
        """The drivers of the board's devices, in order."""
        return [device["driver"] for device in self.devices]

    def emulator_command(self, image, serial_backends, append="", icount=False, cpu=None, memory_mib=None,
                         accel=None, device_properties=None, without_devices=(), extra_args=(), line_ports=None,
                         card=False, card_drive=None):
        """The emulator argv for image, with one chardev argument per serial port.

        serial_backends maps names in serial_ports to a QEMU -serial value
        (for example "mon:stdio" or "chardev:console"); a port it does not
        name is "null": the UART is on the board, its line goes nowhere (the
        isa486's RS-485 port, COM2, unless a test joins it to a host
        program). The order of serial_ports is the order of the -serial
        arguments: COM1, COM2, ... on a PC; a port a device entry names as
        its "serial_port" (a UART at an address and line of the board
        file's choosing) is that device's chardev instead. cpu replaces the
        board's CPU model (the bench image runs on benchmark_cpu), memory_mib
        the board's memory (the bench image runs with benchmark_memory()).
        accel names a QEMU accelerator, e.g. "kvm" (default: QEMU's, TCG);
        with "kvm" and no cpu the emulator's default CPU model is used.

        Per run, without changing the board file: device_properties maps a
        device's driver to properties added to or replacing the board's (e.g.
        {"isa-mfio": {"no-irq": "on"}}); without_devices names drivers to
        leave out (a board that is absent); extra_args go to the emulator as
        they are (e.g. the -chardev a device property refers to).

        card=True boots image as the board's CompactFlash card (docs/boot.md):
        a raw disk on the primary IDE channel that the BIOS boots, with the
        board's IB700 watchdog fitted; the kernel's command line is the
        card's own (append must be empty). The emulator then restarts the
        board on a reset (a watchdog's, say) as a real board does, where a
        -kernel boot stops (-no-reboot). card_drive replaces the card's
        -drive value (a block filter over the same file, dcoslab/powercut.py).

        line_ports maps serial ports named in the board's line_ports to the
        properties that join them to a lab line (hub, hub-name, line): such a
        port is left out of the machine's own UARTs ("-serial none" keeps the
        other ports' numbers) and its line device takes its place, at the
        same I/O ports and interrupt.
        """
        line_ports = line_ports or {}
        for port in line_ports:
            if port not in self.line_ports:
                raise ValueError(f"board {self.name} has no serial port '{port}' that can join a line; "
                                 f"those that can: {', '.join(self.line_ports) or 'none'}")
        drivers = self.device_drivers()
        for driver in list(device_properties or {}) + list(without_devices):
            if driver not in drivers:
                raise ValueError(f"board {self.name} has no device '{driver}'; its devices are: {', '.join(drivers)}")
        command = [resolve_emulator(self.emulator)]
        for path in self.bios_paths:
            command += ["-L", path]
        command += ["-M", self.machine]
        if accel:
            command += ["-accel", accel]
        if cpu or not accel:
            command += ["-cpu", cpu or self.cpu]
        command += ["-m", str(memory_mib or self.memory_mib)]
        if self.smp > 1:
            # One processor per socket, as on the board: a single package
            # of several cores would set CPUID's HT flag, and the BIOS then
            # lists only the first processor of each package in its MP table.
            command += ["-smp", f"{self.smp},sockets={self.smp},cores=1,threads=1"]
        if card:
            if append:
                raise ValueError("a card carries its own command line (dcos-card create --append), not -append")
            # cache=unsafe: the card's FLUSH CACHE is not an fsync of the
            # host's file. Under -icount a board polls on in emulated time
            # while the host syncs, and a busy host's fsync can outlast the
            # driver's bounded wait (drivers/ata); what reaches the file is
            # the same, and power cuts are the filter's (dcoslab/powercut.py).
            command += ["-drive", card_drive or f"file={image},if=ide,format=raw,index=0,cache=unsafe", "-boot", "c",
                        "-device", "ib700", "-watchdog-action", "reset"]
        else:
            command += ["-kernel", image, "-no-reboot"]
        command += [
            "-display", "none",
            "-monitor", "none",
        ]
        command += list(self.emulator_args)
        if append:
            command += ["-append", append]
        if icount:
            # rdtsc and all timers follow retired instructions: exact and repeatable.
            command += ["-icount", "shift=0,align=off,sleep=off", "-rtc", "clock=vm"]
        for device in self.devices:
            if device["driver"] in without_devices:
                continue
            merged = dict(device.get("properties", {}))
            merged.update((device_properties or {}).get(device["driver"], {}))
            port = device.get("serial_port")
            if port:
                # A UART the board file places itself (its own address and
                # line, where -serial would take the PC's defaults) joins its
                # serial port through a chardev of the port's name.
                backend = serial_backends.get(port, "null")
                if backend.startswith("chardev:"):
                    merged["chardev"] = backend[len("chardev:"):]
                elif backend in ("null", "pty"):
                    command += ["-chardev", f"{backend},id={port}"]
                    merged["chardev"] = port
                else:
                    raise ValueError(f"serial port '{port}' of board {self.name} is a device's: "
                                     f"it takes null, pty or chardev:ID, not {backend!r}")
            properties = "".join(f",{key}={value}" for key, value in merged.items())
            command += ["-device", device["driver"] + properties]
        for port, properties in line_ports.items():
            device = self.line_ports[port]
            merged = dict(device.get("properties", {}))
            merged.update(properties)
            command += ["-device", device["driver"] + "".join(f",{key}={value}" for key, value in merged.items())]
        command += list(extra_args)
        device_ports = {device.get("serial_port") for device in self.devices}
        for port in self.serial_ports:
            if port in device_ports:
                continue
            if port in line_ports:
                if port in serial_backends:
                    raise ValueError(f"serial port '{port}' cannot be both on a line and on {serial_backends[port]}")
                command += ["-serial", "none"]
            else:
                command += ["-serial", serial_backends.get(port, "null")]
        return command


def load_board(name):
    """Reads <boards directory>/<name>.json."""
    path = os.path.join(BOARDS_DIRECTORY, f"{name}.json")
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
    except FileNotFoundError:
        known = sorted(entry[:-5] for entry in os.listdir(BOARDS_DIRECTORY) if entry.endswith(".json"))
        raise SystemExit(f"unknown board '{name}'; the boards are: {', '.join(known)}") from None
    return Board(**data)
