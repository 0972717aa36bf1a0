"""The controller's CAN driver against the Linux kernel's own CAN stack (issue 11).

One production-image board on the lab's CAN bus can0 (500 kbit/s, the hub in
lock-step, paced to wall time) and the lab VM (Debian's Linux under QEMU)
with can0 on slcan, joined by the slcan bridge (dcoslab/slcan_bridge.py): the
bridge is the VM's Lawicel adapter and a host participant of the hub. The
controller then talks to can-utils, python-can and the kernel's can-isotp
through a real SocketCAN interface.

The VM boots once for the module and runs one script (VM_SCRIPT) in phases.
The two worlds synchronise through the console and the bus, never by sleeps:

- the VM tells the test it is ready by printing `@@READY <phase>@@` once
  its receivers listen (labvm_wait_receiver, or python-can's socket open);
- where the VM must act only after the controller is receiving, the test
  starts the command at the board's console and then has a hub node put a
  "go" frame (0x7F1..0x7F3) on the bus, which the VM waits for with candump.
  The go frames are ordinary bus traffic: the controller dumps them too, and
  they are in the bus log and the VM's trace like every other frame.

ISO-TP's 1 s time-outs are where the two clocks meet (emulated on the
controller, wall time in the VM): a transfer that fails only by a time-out is
repeated, at most three times, with a warning. The VM raises slcan's transmit
queue from 10 frames, which the kernel's ISO-TP sender overflows (a dropped
last consecutive frame); the last test checks the queue dropped nothing.

A failing test's report carries the board's console, the VM's console, the
bridge's log and the bus log.
"""

import json
import os
import re
import socket
import time
import warnings

import pytest

from dcoslab.board import REPOSITORY, load_board
from dcoslab.canbus import Client, Frame, Hub
from dcoslab.canlab import CanLab
from dcoslab import vmworld
from dcoslab.labvm import LabVM, SlcanSetup
from dcoslab.slcan_bridge import SlcanBridge, parse_lawicel, to_lawicel
from dcoslab.vmworld import BridgedWorld, attach_reports, hold_world

# The module's tests share a module-scoped lab VM: xdist (--dist loadgroup in
# pytest.ini) keeps them on one worker, in order: the VM runs one script in phases
# that the tests follow in order.
pytestmark = pytest.mark.xdist_group("test_can_linux_interop")

BITRATE = 500_000
PACE = 1.0  # emulated time runs no faster than wall time while the slow VM works
BOOT_TIMEOUT = 240  # the VM's boot; generous, it bounds a hang
STEP = 120  # any one wait for the other world; bounds a hang, does not measure speed
MESSAGE = bytes(range(100))
MESSAGE_HEX = MESSAGE.hex().upper()
# The session's last frame: the go frame that ends the last phase.
LAST_FRAME = "7F3#FF"

PYTHON_PEER = r"""
import sys, time
import can

GO, ANSWER = 0x7F2, 0x456
bus = can.Bus(channel="can0", interface="socketcan", can_filters=[
    {"can_id": GO, "can_mask": 0x7FF, "extended": False},
    {"can_id": ANSWER, "can_mask": 0x7FF, "extended": False}])
print("@@READY python@@", flush=True)

def wait_for(can_id, seconds=90):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        message = bus.recv(timeout=max(0.1, deadline - time.monotonic()))
        if message is not None and message.arbitration_id == can_id:
            return message
    print(f"@@PYTHON no frame {can_id:X} within {seconds} s@@", flush=True)
    sys.exit(1)

wait_for(GO)
bus.send(can.Message(arbitration_id=0x18DAF110, is_extended_id=True, data=bytes([0xCA, 0xFE, 0x00, 0x42])))
got = wait_for(ANSWER)
print(f"@@PYTHON GOT {got.arbitration_id:X} {'ext' if got.is_extended_id else 'std'} {bytes(got.data).hex().upper()}@@",
      flush=True)
bus.shutdown()
"""

VM_SCRIPT = r"""
. /run/labvm/lib.sh
cd /tmp
""" + vmworld.PHASE_SHELL + r"""
# slcan's queue is 10 frames; the kernel's ISO-TP sender puts consecutive frames in it faster than the
# serial line takes them, and a full queue drops the frame (seen: the last one of a transfer).
ip link set can0 txqueuelen 1000
# Every frame can0 sees, for the whole session (the test compares it with the bus log).
candump -L can0 >/tmp/trace.log &
trace=$!

# -- raw frames both ways --
raw_phase 123#11223344

# -- python-can as a peer --
timeout 150 /usr/bin/python3 /run/labvm/files/peer.py
echo "@@PYTHON status=$?@@"

# -- dcos-can (our host tool, on the kernel's SocketCAN) as a peer --
cp /run/labvm/files/dcos-can /tmp/dcos-can
chmod 755 /tmp/dcos-can
timeout 150 candump -n 1 can0,7F4:7FF >/dev/null &
go=$!
labvm_wait_receiver can0 raw 7f4 30
before=$(labvm_count_receivers can0 raw 0)
timeout 150 /tmp/dcos-can -i can0 --json dump -n 1 -t 120000 >/tmp/dcos-dump.json &
dump=$!
labvm_wait_receivers can0 raw 0 $((before + 1)) 30
echo "@@READY dcos-can@@"
wait $dump
echo "@@DCOSDUMP status=$? $(tr '\n' '\t' </tmp/dcos-dump.json)@@"
wait $go
/tmp/dcos-can -i can0 send 5A6#CA.FE.00.42
echo "@@DCOSSEND status=$?@@"

# -- ISO-TP: the controller sends, the kernel receives (again after a time-out, at most 3 times) --
attempt=1
while :; do
    timeout 150 isotprecv -s 7E8 -d 7E0 can0 >/tmp/isotp.txt &
    rx=$!
    labvm_wait_receiver can0 isotp 7e0 30
    echo "@@READY isotp-to-linux $attempt@@"
    wait $rx
    status=$?
    got=$(cat /tmp/isotp.txt)
    echo "@@ISOTPRECV $attempt status=$status $got@@"
    [ "$status" = 0 ] && [ "$(echo $got)" = "__MESSAGE__" ] && break
    [ $attempt -ge 3 ] && break
    attempt=$((attempt + 1))
done

# -- ISO-TP: the kernel sends, the controller receives; each go frame 7F3#<n> asks for one
#    transfer, 7F3#FF ends the phase --
while :; do
    timeout 150 candump -L -n 1 can0,7F3:7FF >/tmp/go.log &
    go=$!
    labvm_wait_receiver can0 raw 7f3 30
    echo "@@READY isotp-from-linux@@"
    wait $go
    grep -q "#0[1-9]" /tmp/go.log || break
    echo "__MESSAGE__" | timeout 60 isotpsend -s 7E0 -d 7E8 can0
    echo "@@ISOTPSEND status=$?@@"
done

# -- the session's trace --
end_trace __LAST_FRAME__
echo "@@QDISC $(tc -s qdisc show dev can0 | tr '\n' ' ')@@"
""".replace("__MESSAGE__", " ".join(f"{byte:02X}" for byte in MESSAGE)).replace("__LAST_FRAME__", LAST_FRAME)


def _dcos_can_binary():
    """The host tool, carried into the VM as a file (the host's /tmp, where a CI clone may live, is not visible)."""
    path = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-can")
    if not os.path.exists(path):
        pytest.fail(f"{path} is not built; run make", pytrace=False)
    with open(path, "rb") as handle:
        return handle.read()


@pytest.fixture(scope="module")
def world():
    def build(world):
        # canlab({"can0": 500_000}, {"board1": {"bus0": "can0"}}, pace=1.0, kind="production"), for the module.
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BITRATE}, {"board1": {"bus0": "can0"}},
                           pace=PACE, kind="production")
        world.board = world.lab.board("board1")
        world.mark("board booted")
        world.vm = LabVM(VM_SCRIPT, slcan=SlcanSetup("can0", BITRATE), connect_slcan=False,
                         files={"peer.py": PYTHON_PEER, "dcos-can": _dcos_can_binary()},
                         boot_timeout=BOOT_TIMEOUT, timeout=600)
        world.vm.start()
        # At once: slcand's C, S6, O come once, when the VM's setup runs.
        world.bridge = SlcanBridge(world.vm.slcan_socket_path, world.lab.socket_path, "can0").start()
        output = world.board.command(f"can up can0 {BITRATE}")
        assert re.search(rf"can0 up at 0x280 irq 10: {BITRATE} bit/s", output), output
        world.bridge.wait_for(lambda b: b.is_open, BOOT_TIMEOUT, "slcand to open the channel")
        world.mark("VM's slcan open")

    yield from hold_world(BridgedWorld(), build)


@pytest.fixture(autouse=True)
def _reports(request):
    """Puts the board's and the VM's consoles, the bridge's log and the bus log into a failing test's report."""
    attach_reports(request)


def bus_frames(world):
    return vmworld.bus_frames(world.lab)


def go(world, can_id, phase):
    vmworld.go(world.lab, can_id, phase)


def vm_section(world, name):
    return vmworld.vm_frames(world.vm, name, STEP)


# -- the bridge alone (no VM, no board) ------------------------------------------


def test_lawicel_lines_map_to_hub_frames_and_back():
    for line, frame in (("t123411223344", Frame.data_frame(0x123, b"\x11\x22\x33\x44")),
                        ("T1ABCDEF020102", Frame.data_frame(0x1ABCDEF0, b"\x01\x02", extended=True)),
                        ("r7FF0", Frame(0x7FF, False, True, 0)), ("R1ABCDEF03", Frame(0x1ABCDEF0, True, True, 3)),
                        ("t0000", Frame(0, False, False, 0))):
        assert parse_lawicel(line) == frame
        assert to_lawicel(frame) == line + "\r"
    assert parse_lawicel("t7ff8a1b2c3d4e5f6a7b8") == Frame.data_frame(0x7FF, bytes.fromhex("a1b2c3d4e5f6a7b8"))
    for bad in ("t12", "t8001", "tGGG0", "t12391122334455667788", "t1232112", "r1231AA", "T200000000", "x",
                "T1FFFFFFF9"):
        with pytest.raises(ValueError):
            parse_lawicel(bad)


def test_the_bridge_drops_bad_lines_and_refuses_another_bit_rate(tmp_path):
    hub = Hub(str(tmp_path / "hub.sock"), {"can0": BITRATE}).start()
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(str(tmp_path / "vm.sock"))
    server.listen(1)
    peer = bridge = None
    try:
        peer = Client(hub.socket_path, "peer")
        peer.attach(0, "can0")
        bridge = SlcanBridge(str(tmp_path / "vm.sock"), hub.socket_path, "can0", timeout=10).start()
        vm, _ = server.accept()
        vm.settimeout(10)
        # Another bit rate: refused, and the channel stays closed.
        vm.sendall(b"C\rS4\rO\rt1230\r")
        bridge.wait_for(lambda b: b.counts["dropped_closed"] == 1, 10, "the frame on a closed channel dropped")
        assert bridge.commands == ["C", "S4", "O"] and not bridge.is_open
        # The right one, then garbage between two good frames.
        vm.sendall(b"S6\rO\rt1AB1FF\rt12\rhello\r\xff\xfe\rT1FFFFFFF9\rT1ABCDEF020102\r")
        events = peer.events(lambda lines: sum(line.startswith("RX ") for line in lines) >= 2, timeout=10)
        received = [" ".join(line.split()[4:8]) for line in events if line.startswith("RX ")]
        assert received == ["1ab SD 1 ff", "1abcdef0 XD 2 0102"], events
        bridge.wait_for(lambda b: b.counts["sent"] == 2, 10, "the two frames sent")
        assert bridge.counts["malformed"] == 4 and bridge.error is None, bridge.log_text()
        # From the bus to the VM, in upper case.
        peer.transmit(0, Frame.data_frame(0x456, b"\xde\xad"))
        answers = b""
        deadline = time.monotonic() + 10
        while b"t4562DEAD\r" not in answers and time.monotonic() < deadline:
            answers += vm.recv(4096)
        # C, S4 (refused), O (refused), S6, O, hello (refused); no answers to frames.
        assert answers == b"\r\a\a\r\r\at4562DEAD\r", answers
    finally:
        if bridge is not None:
            bridge.stop()
            assert bridge.error is None, bridge.error
        if peer is not None:
            peer.close()
        hub.stop()
        server.close()


# -- the controller and Linux ----------------------------------------------------------------


def test_slcand_opens_the_bridge_at_the_bus_bit_rate(world):
    assert world.bridge.commands[:3] == ["C", "S6", "O"], world.bridge.log_text()
    assert world.bridge.is_open and world.bridge.counts["refused"] == 0


def test_frames_pass_both_ways_between_the_controller_and_candump_cansend(world):
    world.vm.expect(r"@@READY raw@@", timeout=BOOT_TIMEOUT)
    world.mark("raw: VM ready")
    board = world.board
    output = board.command("can send can0 1ABCDEF0#0102")
    assert "can0  1ABCDEF0   [2]  01 02  sent" in output, output
    board.emulator.send("can dump can0 2 60000\r")
    board.emulator.expect(r"can dump can0 2 60000\r\n")
    go(world, 0x7F1, 1)
    board.emulator.expect(r"can0  7F1        \[1\]  01\r\n", timeout=STEP)
    board.emulator.expect(r"can0  123        \[4\]  11 22 33 44\r\n", timeout=STEP)
    board.emulator.expect(r"dcos> ", timeout=STEP)
    trace = vm_section(world, "RAW")
    world.mark("raw: done")
    assert trace == ["1ABCDEF0#0102", "7F1#01", "123#11223344"], trace
    # candump's trace in the VM is the hub's bus log, frame for frame.
    assert trace == bus_frames(world), world.lab.hub.log_text()
    senders = [record.sender for record in world.lab.hub.frames()]
    assert senders == ["board1.0", "hub.lab", "linux.0"], world.lab.hub.log_text()


def test_python_can_in_the_vm_is_a_peer_of_the_controller(world):
    world.vm.expect(r"@@READY python@@", timeout=STEP)
    world.mark("python: VM ready")
    board = world.board
    board.emulator.send("can dump can0 2 60000\r")
    board.emulator.expect(r"can dump can0 2 60000\r\n")
    go(world, 0x7F2, 2)
    board.emulator.expect(r"can0  7F2        \[1\]  02\r\n", timeout=STEP)
    board.emulator.expect(r"can0  18DAF110   \[4\]  CA FE 00 42\r\n", timeout=STEP)
    board.emulator.expect(r"dcos> ", timeout=STEP)
    output = board.command("can send can0 456#DEADBEEF")
    assert "can0  456        [4]  DE AD BE EF  sent" in output, output
    got = world.vm.expect(r"@@PYTHON (GOT [^@]*|[^@]*)@@", timeout=STEP).group(1).decode()
    world.mark("python: done")
    assert got == "GOT 456 std DEADBEEF", got
    world.vm.expect(r"@@PYTHON status=0@@", timeout=STEP)


def test_dcos_can_on_the_kernels_socketcan_is_a_peer_of_the_controller(world):
    """Our host tool over real SocketCAN (the kernel's can-raw on slcan) and the controller, both ways."""
    world.vm.expect(r"@@READY dcos-can@@", timeout=STEP)
    world.mark("dcos-can: VM ready")
    board = world.board
    output = board.command("can send can0 01F0A5A5#0102030405")
    assert "can0  01F0A5A5   [5]  01 02 03 04 05  sent" in output, output
    dumped = world.vm.expect(r"@@DCOSDUMP status=(\d+) (.*?)@@", timeout=STEP)
    assert dumped.group(1) == b"0", dumped.group(0)
    lines = [json.loads(line) for line in dumped.group(2).decode().split("\t") if line.startswith("{")]
    assert [(line.get("id"), line.get("extended"), line.get("data")) for line in lines if "event" not in line] == [
        (0x01F0A5A5, True, "0102030405")], dumped.group(0)
    board.emulator.send("can dump can0 2 60000\r")
    board.emulator.expect(r"can dump can0 2 60000\r\n")
    go(world, 0x7F4, 4)
    board.emulator.expect(r"can0  7F4        \[1\]  04\r\n", timeout=STEP)
    board.emulator.expect(r"can0  5A6        \[4\]  CA FE 00 42\r\n", timeout=STEP)
    board.emulator.expect(r"dcos> ", timeout=STEP)
    world.vm.expect(r"@@DCOSSEND status=0@@", timeout=STEP)
    world.mark("dcos-can: done")


# ISO 15765-2's time-outs (1 s between frames, in both worlds) are the one place where the two clocks meet:
# the controller's run in emulated time (paced to wall time), the kernel's in wall time. A transfer that
# fails only by such a time-out, when the busy host stalls one side, is repeated (at most ATTEMPTS in all)
# and the repetition is reported; any other failure fails at once.
ATTEMPTS = 3
TIMEOUT_ERRORS = ("N_Cr time-out", "N_Bs time-out", "N_As time-out", "no ISO-TP message began")


def test_the_kernels_isotp_receiver_takes_a_message_from_the_controller(world):
    for attempt in range(1, ATTEMPTS + 1):
        world.vm.expect(rf"@@READY isotp-to-linux {attempt}@@", timeout=STEP)
        world.mark(f"isotp to linux: VM ready ({attempt})")
        output = world.board.command(f"can isotp-send can0 7E0 7E8 {MESSAGE_HEX}", timeout=STEP)
        match = world.vm.expect(rf"@@ISOTPRECV {attempt} status=(\d+) ([0-9A-Fa-f ]*?)\s*@@", timeout=STEP)
        received = bytes.fromhex(match.group(2).decode())
        if "can0  isotp 100 bytes sent" in output and match.group(1) == b"0" and received == MESSAGE:
            break
        timed_out = any(error in output for error in TIMEOUT_ERRORS) or received == b""
        assert timed_out and attempt < ATTEMPTS, f"attempt {attempt}: {output!r}, the VM: {match.group(0)!r}"
        warnings.warn(f"ISO-TP to Linux: attempt {attempt} timed out ({output.strip()!r}, the VM got "
                      f"{len(received)} bytes); repeated")
    world.mark("isotp to linux: done")


def test_the_controller_takes_a_message_from_the_kernels_isotp_sender(world):
    board = world.board
    try:
        for attempt in range(1, ATTEMPTS + 1):
            world.vm.expect(r"@@READY isotp-from-linux@@", timeout=STEP)
            world.mark(f"isotp from linux: VM ready ({attempt})")
            board.emulator.send("can isotp-recv can0 7E8 7E0 60000\r")
            board.emulator.expect(r"can isotp-recv can0 7E8 7E0 60000\r\n")
            go(world, 0x7F3, attempt)
            match = board.emulator.expect(r"(can0  isotp (\d+) bytes: ([0-9A-F ]+)|error: [^\r]*)\r\n", timeout=STEP)
            board.emulator.expect(r"dcos> ", timeout=STEP)
            sent = world.vm.expect(r"@@ISOTPSEND status=(\d+)@@", timeout=STEP)
            if match.group(2) is not None:
                assert int(match.group(2)) == 100 and bytes.fromhex(match.group(3).decode()) == MESSAGE, \
                    match.group(0)
                assert sent.group(1) == b"0", sent.group(0)
                break
            error = match.group(1).decode()
            assert any(e in error for e in TIMEOUT_ERRORS) and attempt < ATTEMPTS, f"attempt {attempt}: {error}"
            warnings.warn(f"ISO-TP from Linux: attempt {attempt} timed out ({error!r}, isotpsend "
                          f"{sent.group(0).decode()}); repeated")
    finally:
        # Ends the VM's phase, whatever happened here.
        world.vm.expect(r"@@READY isotp-from-linux@@", timeout=STEP)
        go(world, 0x7F3, 0xFF)
    world.mark("isotp from linux: done")


def test_the_vms_whole_trace_is_the_bus_log(world):
    trace = vm_section(world, "TRACE")
    bridge_error = world.bridge.error  # before the VM powers off and closes its end
    result = world.vm.wait()
    world.mark("VM finished")
    print(f"timings (s from the module's start): {world.timings}")
    assert result.status == 0, result.output
    qdisc = re.search(r"@@QDISC (.*?)@@", result.output)
    assert qdisc and "(dropped 0," in qdisc.group(1), f"the VM's can0 queue dropped frames: {qdisc}"
    assert trace == bus_frames(world), f"VM trace:\n{trace}\nbus log:\n{world.lab.hub.log_text()}"
    assert all(record.outcome == "ok" for record in world.lab.hub.frames()), world.lab.hub.log_text()
    assert world.bridge.counts["malformed"] == 0 and world.bridge.counts["failed"] == 0, dict(world.bridge.counts)
    assert bridge_error is None, bridge_error
