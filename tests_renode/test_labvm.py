"""The lab VM (tests_renode/labvm, docs/guide/lab-vm.md): Debian's Linux under QEMU with real
SocketCAN, running the host's can-utils and python3-can against the kernel's own CAN stack.

Boots are the slow part (about 4 s each, more on a busy machine), so the vcan
checks share one VM and the slcan checks another; each check still has its
own output and status, and its own test. Every failure message carries the
VM's console transcript.
"""

import os
import sys

import pytest

# The module's tests share a module-scoped lab VM: xdist (--dist loadgroup in
# pytest.ini) keeps them on one worker, so that each VM fixture boots once.
pytestmark = pytest.mark.xdist_group("test_labvm")

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.labvm import lab_vm  # noqa: E402,F401 (the fixture)
from labvm import (CanFrame, KvaserPciSetup, LabVM, LabVMError, SlcanError, SlcanSetup,  # noqa: E402
                   Sja1000Setup, check_command, parse_checks, run)

# Bounds for a hung VM, not speed targets.
BOOT_TIMEOUT = 240
CHECK_TIMEOUT = 60

PRELUDE = ". /run/labvm/lib.sh\n"

# cansend -> candump on vcan0, a standard and an extended frame.
CANDUMP_ROUND_TRIP = PRELUDE + r"""
timeout 30 candump -L -n 2 vcan0 >/tmp/round-trip.log &
dump=$!
labvm_wait_receiver vcan0 raw
cansend vcan0 123#11223344
cansend vcan0 1ABCDEF0#0102
wait $dump
cut -d' ' -f2- /tmp/round-trip.log
"""

# python-can sends a frame candump sees, then receives one cansend sends.
PYTHON_CAN_SCRIPT = r"""
import subprocess
import can

bus = can.Bus(interface="socketcan", channel="vcan0")
try:
    bus.send(can.Message(arbitration_id=0x456, data=bytes.fromhex("deadbeef"), is_extended_id=False))
    subprocess.run(["cansend", "vcan0", "18FF1234#CAFE"], check=True)
    message = bus.recv(timeout=20)
    if message is None:
        print("python-can received nothing")
    else:
        print(f"python-can received {message.arbitration_id:X} extended={message.is_extended_id} "
              f"data={message.data.hex()}")
finally:
    bus.shutdown()
"""

PYTHON_CAN = PRELUDE + r"""
timeout 30 candump -L -n 1 vcan0 >/tmp/python-can.log &
dump=$!
labvm_wait_receiver vcan0 raw
/usr/bin/python3 /run/labvm/files/python_can_check.py
wait $dump
echo "candump: $(cut -d' ' -f2- /tmp/python-can.log)"
"""

# ISO-TP with the kernel's can-isotp: 100 bytes 00..63 from 7E0 to 7E8's
# partner; candump records the frames on the bus.
ISOTP_MESSAGE = " ".join(f"{byte:02X}" for byte in range(100))
ISOTP = PRELUDE + r"""
timeout 30 candump -L vcan0 >/tmp/isotp-bus.log &
dump=$!
labvm_wait_receiver vcan0 raw
timeout 30 isotprecv -s 7E8 -d 7E0 vcan0 >/tmp/isotp-received &
receiver=$!
labvm_wait_receiver vcan0 isotp 7e0
echo "__MESSAGE__" | timeout 30 isotpsend -s 7E0 -d 7E8 vcan0
wait $receiver
echo "received: $(cat /tmp/isotp-received)"
sleep 0.2
kill $dump
echo "bus:"
cut -d' ' -f2- /tmp/isotp-bus.log
""".replace("__MESSAGE__", ISOTP_MESSAGE)

# The kernel loads a module on demand through the initramfs's modprobe:
# can-j1939 is in the image but not loaded at boot.
MODULE_AUTOLOAD = r"""
if grep -q '^can_j1939 ' /proc/modules; then echo "can_j1939 was loaded already"; exit 1; fi
/usr/bin/python3 -S -c 'import socket; socket.socket(socket.AF_CAN, socket.SOCK_DGRAM, 7).close()'
grep -o '^can_j1939 ' /proc/modules
"""

VCAN_CHECKS = {
    "candump_round_trip": CANDUMP_ROUND_TRIP,
    "python_can": PYTHON_CAN,
    "isotp": ISOTP,
    "module_autoload": MODULE_AUTOLOAD,
}


def _explain(what, transcript, output=None):
    text = what
    if output is not None:
        text += f"\n----- output of the check -----\n{output}"
    return text + f"\n----- lab VM console transcript -----\n{transcript}\n----- end of transcript -----"


class Outcome:
    """What a shared VM gave: its Result, or the error that stopped it."""

    def __init__(self):
        self.result = None
        self.error = None
        self.checks = {}
        self.vm = None

    def transcript(self):
        if self.result is not None:
            return self.result.transcript
        return self.vm.transcript if self.vm is not None else "(no VM)"

    def check(self, name):
        """The named check's CheckResult; fails the test if the VM or the check did not run."""
        if self.error is not None and name not in self.checks:
            pytest.fail(f"the shared lab VM failed before check {name!r} ran:\n{self.error}", pytrace=False)
        check = self.checks[name]
        if check.status is None:
            pytest.fail(_explain(f"check {name!r} did not finish", self.transcript(), self.result.output),
                        pytrace=False)
        return check


@pytest.fixture(scope="module")
def vcan_vm():
    """One VM with vcan0 running every check in VCAN_CHECKS."""
    outcome = Outcome()
    command, files = check_command(VCAN_CHECKS, timeout_each=CHECK_TIMEOUT)
    files["python_can_check.py"] = PYTHON_CAN_SCRIPT
    try:
        outcome.result = run(command, vcan=["vcan0"], files=files, boot_timeout=BOOT_TIMEOUT,
                             timeout=CHECK_TIMEOUT * len(VCAN_CHECKS) + 30)
        outcome.checks = parse_checks(outcome.result, VCAN_CHECKS)
    except LabVMError as error:
        outcome.error = error
    return outcome


def _expect_check(outcome, name, status=0):
    check = outcome.check(name)
    assert check.status == status, _explain(f"check {name!r} ended with status {check.status}",
                                            outcome.transcript(), check.output)
    return check


def test_cansend_frames_reach_candump(vcan_vm):
    check = _expect_check(vcan_vm, "candump_round_trip")
    assert check.output.splitlines() == ["vcan0 123#11223344", "vcan0 1ABCDEF0#0102"], \
        _explain("candump did not log exactly the two frames cansend sent", vcan_vm.transcript(), check.output)


def test_python_can_sends_a_frame_candump_sees(vcan_vm):
    check = _expect_check(vcan_vm, "python_can")
    assert "candump: vcan0 456#DEADBEEF" in check.output.splitlines(), \
        _explain("candump did not see python-can's frame 456#DEADBEEF", vcan_vm.transcript(), check.output)


def test_python_can_receives_a_frame_cansend_sends(vcan_vm):
    check = _expect_check(vcan_vm, "python_can")
    assert "python-can received 18FF1234 extended=True data=cafe" in check.output.splitlines(), \
        _explain("python-can did not receive cansend's frame 18FF1234#CAFE", vcan_vm.transcript(), check.output)


def test_isotp_transfers_100_bytes_through_the_kernel(vcan_vm):
    check = _expect_check(vcan_vm, "isotp")
    lines = check.output.splitlines()
    received = [line for line in lines if line.startswith("received:")]
    assert received and received[0].split()[1:] == ISOTP_MESSAGE.split(), \
        _explain("isotprecv did not print the 100 bytes isotpsend sent", vcan_vm.transcript(), check.output)
    bus = lines[lines.index("bus:") + 1:]
    data_frames = [line for line in bus if line.startswith("vcan0 7E0#")]
    flow_control = [line for line in bus if line.startswith("vcan0 7E8#")]
    # 100 bytes: a first frame with 6 bytes and 14 consecutive frames of 7 or fewer.
    assert len(data_frames) == 15 and data_frames[0].startswith("vcan0 7E0#1064000102030405"), \
        _explain("the transfer was not one first frame and 14 consecutive frames on 7E0", vcan_vm.transcript(),
                 check.output)
    assert data_frames[1].startswith("vcan0 7E0#21060708090A0B0C") and flow_control, \
        _explain("no flow control on 7E8, or the consecutive frames are wrong", vcan_vm.transcript(), check.output)


def test_kernel_loads_can_modules_on_demand(vcan_vm):
    check = _expect_check(vcan_vm, "module_autoload")
    assert check.output.split()[-1:] == ["can_j1939"], \
        _explain("opening a J1939 socket did not load can_j1939", vcan_vm.transcript(), check.output)


# -- slcan: the host joins the VM's SocketCAN through the second serial port ---

SLCAN_BITRATE = 250000  # Lawicel S5; not the default, so the parameter is seen to work
SLCAN_SCRIPT = PRELUDE + r"""
timeout 60 candump -L -n 2 can0 >/tmp/from-host.log &
dump=$!
labvm_wait_receiver can0 raw
echo "@@READY-FOR-HOST-FRAMES@@"
wait $dump
echo "candump:"
cut -d' ' -f2- /tmp/from-host.log
echo "@@SENDING-TO-HOST@@"
cansend can0 123#11223344
cansend can0 1ABCDEF0#0102
cansend can0 7FF#R
# slcan counts a frame when its last byte is handed to the serial port.
deadline=$(( $(labvm_uptime) + 10 ))
while read -r sent </sys/class/net/can0/statistics/tx_packets && [ "$sent" -lt 3 ]; do
    [ "$(labvm_uptime)" -lt "$deadline" ] || { echo "slcan sent $sent frames, not 3, in 10 s" >&2; exit 1; }
    sleep 0.05
done
sleep 0.5
"""


@pytest.fixture(scope="module")
def slcan_vm():
    """One VM with can0 on slcan; the host writes two frames in and receives three."""
    outcome = Outcome()
    vm = LabVM(SLCAN_SCRIPT, slcan=SlcanSetup("can0", SLCAN_BITRATE), boot_timeout=BOOT_TIMEOUT,
               timeout=CHECK_TIMEOUT * 2)
    outcome.vm = vm
    try:
        vm.start()
        outcome.port = vm.slcan
        vm.expect("@@READY-FOR-HOST-FRAMES@@", timeout=BOOT_TIMEOUT)
        vm.slcan.send_line("t123411223344")
        vm.slcan.send(CanFrame(0x1ABCDEF0, b"\x01\x02", extended=True))  # T1ABCDEF020102
        outcome.result = vm.wait()
        outcome.lines = list(vm.slcan.lines)
    except (LabVMError, SlcanError) as error:
        outcome.error = error
        outcome.lines = list(vm.slcan.lines) if vm.slcan is not None else []
    finally:
        vm.close()
    return outcome


def _slcan_section(outcome, start, end=None):
    if outcome.result is None:
        pytest.fail(f"the slcan lab VM did not finish:\n{outcome.error}", pytrace=False)
    text = outcome.result.output
    if start not in text:
        pytest.fail(_explain(f"the VM's command did not reach {start!r}", outcome.transcript(), text), pytrace=False)
    section = text.split(start, 1)[1]
    return section.split(end, 1)[0] if end else section


def test_slcand_opens_the_channel_at_the_requested_bit_rate(slcan_vm):
    # slcand -c -s5 -o: close, bit rate 250 kbit/s, open, before any frame.
    assert slcan_vm.lines[:3] == ["C", "S5", "O"], _explain(
        f"the host received {slcan_vm.lines[:5]} first, not C, S5, O", slcan_vm.transcript())


def test_lawicel_frames_from_the_host_reach_candump(slcan_vm):
    section = _slcan_section(slcan_vm, "candump:\n", "@@SENDING-TO-HOST@@")
    assert section.splitlines() == ["can0 123#11223344", "can0 1ABCDEF0#0102"], _explain(
        "candump in the VM did not log the host's two Lawicel frames", slcan_vm.transcript(), section)


def test_cansend_frames_reach_the_host_as_lawicel_lines(slcan_vm):
    _slcan_section(slcan_vm, "@@SENDING-TO-HOST@@")
    frames = [line for line in slcan_vm.lines if line[:1] in "tTrR"]
    assert frames == ["t123411223344", "T1ABCDEF020102", "r7FF0"], _explain(
        f"the host received the frame lines {frames}", slcan_vm.transcript(), slcan_vm.result.output)
    assert [CanFrame.from_lawicel(line) for line in frames] == [
        CanFrame(0x123, bytes.fromhex("11223344")), CanFrame(0x1ABCDEF0, b"\x01\x02", extended=True),
        CanFrame(0x7FF, remote=True)]
    assert slcan_vm.result.status == 0, _explain(f"the command ended with status {slcan_vm.result.status}",
                                                  slcan_vm.transcript(), slcan_vm.result.output)


# -- the VM's own contract: output, status, time-out, setup failure -----------

def test_output_and_exit_status_come_back_exactly(lab_vm):  # noqa: F811 (the fixture)
    vm = lab_vm("printf 'first\\n'; printf 'no newline at the end' >&2; exit 7", boot_timeout=BOOT_TIMEOUT,
                timeout=CHECK_TIMEOUT)
    result = vm.wait()
    assert (result.status, result.output, result.timed_out) == (7, "first\nno newline at the end", False), \
        _explain(f"status {result.status}, output {result.output!r}", result.transcript)


def test_a_command_is_killed_at_its_timeout():
    result = run("echo started; sleep 600", boot_timeout=BOOT_TIMEOUT, timeout=3)
    assert result.timed_out and result.status == 137 and result.output.startswith("started\n"), \
        _explain(f"status {result.status}, timed_out {result.timed_out}", result.transcript, result.output)
    with pytest.raises(LabVMError, match="killed at its time-out"):
        result.check()


def test_a_failing_setup_is_reported_with_the_transcript():
    with pytest.raises(LabVMError) as caught:
        run("echo never", vcan=["vcan0"], setup=["ip link add dev vcan0 type vcan"], boot_timeout=BOOT_TIMEOUT,
            timeout=CHECK_TIMEOUT)
    message = str(caught.value)
    assert "setup in the VM failed" in message and "File exists" in message \
        and "----- console transcript -----" in message, message


# -- host side only ---------------------------------------------------------------

@pytest.mark.parametrize("frame, line", [
    (CanFrame(0x123, bytes.fromhex("11223344")), "t123411223344\r"),
    (CanFrame(0x1ABCDEF0, b"\x01\x02", extended=True), "T1ABCDEF020102\r"),
    (CanFrame(0x7FF, remote=True, dlc=3), "r7FF3\r"),
    (CanFrame(0x5, b"", extended=True), "T000000050\r"),
])
def test_lawicel_encoding(frame, line):
    assert frame.lawicel() == line
    assert CanFrame.from_lawicel(line) == frame


@pytest.mark.parametrize("line", ["t12341122", "x1230", "t12", "T1ABCDEF02GG00", "r1231AA"])
def test_malformed_lawicel_lines_are_refused(line):
    with pytest.raises(SlcanError):
        CanFrame.from_lawicel(line)


def test_the_sja1000_card_setup_gives_the_device_the_driver_and_the_interfaces():
    card = Sja1000Setup("/tmp/lab/hub.sock", bus0="can0", name="linux", bitrate=250000)
    assert card.device_argument() == ("isa-sja1000,iobase=0x280,irq0=5,irq1=7,hub=/tmp/lab/hub.sock,hub-name=linux,"
                                      "hub-realtime=on,hub-timeout=60,bus0=can0")
    assert card.load_line() == "sja1000_isa port=0x280 irq=5"
    assert card.setup_lines() == ["ip link set can0 type can bitrate 250000", "ip link set can0 up"]
    # Both channels: the driver's arrays get one entry per chip, and Linux names them can0, can1 in that order.
    both = Sja1000Setup("/tmp/lab/hub.sock", bus0="can0", bus1="can1", bitrate=None)
    assert both.load_line() == "sja1000_isa port=0x280,0x2a0 irq=5,7"
    assert both.setup_lines() == [] and both.interface(1) == "can1"
    # Channel 1 alone is can0 in the VM.
    second = Sja1000Setup("/tmp/lab/hub.sock", bus0=None, bus1="can1")
    assert second.load_line() == "sja1000_isa port=0x2a0 irq=7" and second.interface(1) == "can0"
    assert second.device_argument().endswith(",bus1=can1")
    for bad in ({"bus0": None}, {"name": "lin.ux"}, {"bus0": "can 0"}):
        with pytest.raises(ValueError):
            Sja1000Setup("/tmp/lab/hub.sock", **bad)
    with pytest.raises(ValueError, match="comma"):
        Sja1000Setup("/tmp/lab,x/hub.sock")
    with pytest.raises(ValueError, match="both be can0"):
        LabVM("true", slcan=SlcanSetup(), sja1000=card)


def test_the_kvaser_pci_card_setup_gives_the_device_the_driver_and_the_interfaces():
    card = KvaserPciSetup("/tmp/lab/hub.sock", buses=("can0",), name="linux", bitrate=250000)
    assert card.device_argument() == ("lab-kvaser-pci,channels=1,hub=/tmp/lab/hub.sock,hub-name=linux,"
                                      "hub-realtime=on,hub-timeout=60,bus0=can0")
    assert card.load_line() == "kvaser_pci"
    assert card.setup_lines() == ["ip link set can0 type can bitrate 250000", "ip link set can0 up"]
    # Linux names every chip the card carries, wired or not: chip 2 of four is can2, and only wired chips come up.
    four = KvaserPciSetup("/tmp/lab/hub.sock", buses=(None, "can0", "can1", None), bitrate=125000)
    assert four.device_argument().startswith("lab-kvaser-pci,channels=4,")
    assert four.device_argument().endswith(",bus1=can0,bus2=can1")
    assert four.interface(2) == "can2" and [name for _, _, name in four.channels] == ["can1", "can2"]
    assert four.setup_lines() == ["ip link set can1 type can bitrate 125000", "ip link set can1 up",
                                  "ip link set can2 type can bitrate 125000", "ip link set can2 up"]
    assert KvaserPciSetup("/tmp/lab/hub.sock", bitrate=None).setup_lines() == []
    for bad in ({"buses": ()}, {"buses": ("can0",) * 5}, {"buses": (None, None)}, {"name": "lin.ux"},
                {"buses": ("can 0",)}):
        with pytest.raises(ValueError):
            KvaserPciSetup("/tmp/lab/hub.sock", **bad)
    with pytest.raises(ValueError):
        card.interface(1)
    with pytest.raises(ValueError, match="comma"):
        KvaserPciSetup("/tmp/lab,x/hub.sock")
    with pytest.raises(ValueError, match="both be can0"):
        LabVM("true", slcan=SlcanSetup(), sja1000=card)
