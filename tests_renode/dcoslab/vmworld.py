"""A module-scoped lab of one or more boards on a hub and the lab VM, for tests that run one VM script in phases.

The lab VM boots in tens of seconds, so a module boots it once, with its
boards and hub, and its tests take the script's phases in turn
(test_can_linux_interop.py, test_can_sja1000_linux.py). World holds the
pieces, closes them whatever happened, and hands the lab plugin what a
failing test's report shows: every console, the VM's, and the bus log.
The helpers below are the phases' common words: the frames as candump -L
writes them, the hub's "go" frames, and the VM's marked output sections;
PHASE_SHELL holds the VM's side of the phases the scripts share.
"""

import os
import time

from .canbus import Frame
from .emulator import Emulator


# Shell functions of the VM scripts that run in phases against a board on the lab bus can0; a script puts
# them after `. /run/labvm/lib.sh`, whose functions they call.
PHASE_SHELL = r"""
# raw_phase FRAME...: frames both ways. candump takes the board's frame (sent before the phase's go frame),
# the go frame 7F1 and then each FRAME, which cansend puts on can0 once the go frame came; @@READY raw@@
# once the receivers listen, and the frames as the section RAW.
raw_phase() {
    timeout 150 candump -L -n $(($# + 2)) can0 >/tmp/raw.log &
    _raw=$!
    timeout 150 candump -n 1 can0,7F1:7FF >/dev/null &
    _go=$!
    labvm_wait_receiver can0 raw 7f1 30
    labvm_wait_receiver can0 raw 0 30
    echo "@@READY raw@@"
    wait $_go
    for _frame in "$@"; do
        cansend can0 "$_frame"
    done
    wait $_raw
    echo "@@RAW"; cut -d' ' -f2- /tmp/raw.log; echo "@@END RAW@@"
}
# end_trace LAST_FRAME: stops the session's trace (candump -L can0 >/tmp/trace.log, its pid in $trace) once
# LAST_FRAME is in (candump writes each frame as it comes) and prints it as the section TRACE.
end_trace() {
    _deadline=$(( $(labvm_uptime) + 30 ))
    while ! grep -q " can0 $1\$" /tmp/trace.log; do
        [ "$(labvm_uptime)" -lt "$_deadline" ] || { echo "no $1 in the trace in 30 s" >&2; break; }
        sleep 0.05
    done
    kill -INT $trace
    wait $trace
    echo "@@TRACE"; cut -d' ' -f2- /tmp/trace.log; echo "@@END TRACE@@"
}
"""


class Report:
    """Something with a name and a transcript, for the lab plugin's failure report."""

    def __init__(self, name, text, argv=()):
        self.name = name
        self._text = text
        self.argv = list(argv)

    @property
    def transcript(self):
        return self._text()


class World:
    """The boards, the hub and the VM of a module; subclasses add what they join them with."""

    def __init__(self):
        self.lab = None
        self.board = None
        self.vm = None
        self.started = time.monotonic()
        self.timings = {}
        self._emulators = []

    def boot(self, board, kind, icount=False, name=None, device_properties=None, extra_args=(), append="",
             cpu=None, card=None):
        """The lab plugin's boot fixture, for a module-scoped CanLab; the emulators close with the world.

        kind is an image kind of the board or the path of an image file; cpu
        replaces the board's CPU model (the remote bench's counting image
        runs on the board's benchmark_cpu); card, a CompactFlash card image the
        board boots from instead (docs/boot.md)."""
        image = card or (kind if os.path.sep in kind else board.image(kind))
        emulator = Emulator(board, image, append=append, icount=icount, cpu=cpu,
                            device_properties=device_properties, extra_args=extra_args, name=name,
                            card=card is not None)
        self._emulators.append(emulator)
        return emulator.start()

    def reports(self):
        reports = []
        if self.board is not None:
            reports.append(self.board.emulator)
        if self.vm is not None:
            reports.append(Report("lab VM", lambda: self.vm.transcript, self.vm.argv))
        return reports

    def mark(self, name):
        """Notes when a phase got somewhere, in seconds from the module's start (printed by the last test)."""
        self.timings[name] = round(time.monotonic() - self.started, 1)

    def close(self):
        if self.vm is not None:
            self.vm.close()
        for emulator in self._emulators:
            emulator.close()
        if self.lab is not None:
            self.lab.close()


class BridgedWorld(World):
    """The boards, the hub and the lab VM, joined by the slcan bridge (dcoslab/slcan_bridge.py)."""

    def __init__(self):
        super().__init__()
        self.bridge = None

    def reports(self):
        reports = super().reports()
        if self.bridge is not None:
            reports.append(Report("slcan bridge", lambda: f"counts {dict(self.bridge.counts)}, error "
                                  f"{self.bridge.error}\n{self.bridge.log_text()}"))
        return reports

    def close(self):
        if self.bridge is not None:
            self.bridge.stop()
        super().close()


def start_bridged_vm(world, script, bitrate, files, boot_timeout, timeout):
    """Starts the lab VM with `script` and `files` (carried in as bytes:
    the VM does not see the host's /tmp) and the slcan bridge between its
    can0 and the world's lab bus; returns once slcand has opened the channel."""
    from dcoslab.labvm import LabVM, SlcanSetup
    from dcoslab.slcan_bridge import SlcanBridge

    world.vm = LabVM(script, slcan=SlcanSetup("can0", bitrate), connect_slcan=False, files=files,
                     boot_timeout=boot_timeout, timeout=timeout)
    world.vm.start()
    world.bridge = SlcanBridge(world.vm.slcan_socket_path, world.lab.socket_path, "can0").start()
    world.bridge.wait_for(lambda b: b.is_open, boot_timeout, "slcand to open the channel")


def vm_status(world, tag, timeout):
    """What the VM printed as `@@<tag> <output> status=<code>@@`: (output, code)."""
    match = world.vm.expect(rf"@@{tag} (.*?) status=(\d+)@@", timeout=timeout)
    return match.group(1).decode(), int(match.group(2))


def hold_world(world, build):
    """A module fixture's body: build(world) boots its pieces; the world is
    yielded to the module's tests and closed afterwards, or at once if
    building it failed. Use as `yield from hold_world(World(), build)`."""
    try:
        build(world)
    except BaseException:
        world.close()
        raise
    try:
        yield world
    finally:
        world.close()


def attach_reports(request, name="world"):
    """For an autouse fixture: puts the world's consoles and bus log into a failing test's report."""
    request.node.dcos_emulators = []
    request.node.dcos_canlabs = []
    if name in request.fixturenames:
        shared = request.getfixturevalue(name)
        request.node.dcos_emulators.extend(shared.reports())  # read when the report is made
        request.node.dcos_canlabs.append(shared.lab)


def candump_form(frame):
    """A frame as `candump -L` writes it after the interface: 123#11223344, 1ABCDEF0#0102, 7FF#R."""
    identifier = f"{frame.id:08X}" if frame.extended else f"{frame.id:03X}"
    return f"{identifier}#R" if frame.remote else f"{identifier}#{frame.data.hex().upper()}"


def bus_frames(lab, bus="can0"):
    """The frames that went through on the bus, in order, as candump -L writes them."""
    return [candump_form(record.frame) for record in lab.hub.frames() if record.outcome == "ok" and record.bus == bus]


def go(lab, can_id, phase, bus="can0"):
    """A hub node puts the go frame for a phase on the bus."""
    lab.hub.inject(bus, "lab", Frame.data_frame(can_id, bytes([phase])))


def vm_section(vm, name, timeout):
    """The text the VM printed between `@@<name>` and `@@END <name>@@`."""
    match = vm.expect(rf"@@{name}\r?\n([\s\S]*?)@@END {name}@@", timeout=timeout)
    return match.group(1).decode("latin-1").replace("\r", "")


def vm_frames(vm, name, timeout):
    """A section of candump -L lines, without their timestamps: 123#11223344 ..."""
    return [line.split(" ", 1)[-1].strip() for line in vm_section(vm, name, timeout).splitlines() if line.strip()]
