"""dcos-can through a gs_usb adapter by libusb, without the kernel's driver, in the lab VM.

The adapter is the emulated candleLight of tests_renode/labvm/gsusb_gadget.py
(docs/protocols/lab-usb-devices.md), a real USB device on the VM's dummy_hcd.
Linux's gs_usb binds it first (test_gsusb_labvm.py proves the frames it
carries that way); this module unbinds the driver and runs the host tool's
own gs_usb transport (host_tools/can, docs/protocols/gs_usb.md) on it through
libusb, as an engineer does on a laptop without the module: `dcos-can list`
finds it, `-i gsusb:<serial>` dumps the bus's frames and sends frames onto
it, and what a broken or unplugged adapter does ends in a clear error and a
non-zero exit, never in a wrong frame.

The adapter's CAN side is the VM's second serial port, whose host end this
test holds as a SlcanPort. One VM boot serves the module; every wait has a
time-out; a failing test prints the VM's console transcript.
"""

import json
import os
import re
import shutil
import sys
import tempfile

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.board import REPOSITORY  # noqa: E402
from labvm import CanFrame, LabVM, LabVMError, SlcanError, SlcanPort  # noqa: E402
from labvm.gsusb_gadget import LAB_VM_LOAD, VM_SHELL  # noqa: E402

pytestmark = pytest.mark.xdist_group("test_gsusb_libusb_labvm")

GADGET = os.path.join(os.path.dirname(os.path.abspath(__file__)), "labvm", "gsusb_gadget.py")
DCOS_CAN = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-can")
SERIAL = "LAB-GSUSB-0002"
BOOT_TIMEOUT = 240
STEP = 120  # any one wait for the VM; bounds a hang, does not measure speed
COMMAND_TIMEOUT = 420

RX_FRAMES = [
    CanFrame(0x123, b"\x11\x22\x33\x44"),
    CanFrame(0x1ABCDEF0, b"\x01\x02", extended=True),
    CanFrame(0x7FF, remote=True, dlc=2),
    CanFrame(0x000, b""),
    CanFrame(0x456, bytes(range(8))),
    # A DCOS remote request (docs/protocols/can.md), so the dump decodes one over USB too.
    CanFrame(0x0311FF01, b"\x03\x10\x20\x01\x00\x00\x00\x00", extended=True),
]
# (id, extended, remote, dlc, data) as dcos-can --json gives them.
RX_EXPECTED = [(0x123, False, False, 4, "11223344"), (0x1ABCDEF0, True, False, 2, "0102"), (0x7FF, False, True, 2, ""),
               (0x000, False, False, 0, ""), (0x456, False, False, 8, "0001020304050607"),
               (0x0311FF01, True, False, 8, "0310200100000000")]
TX_SENDS = ["321#DEADBEEF", "12345678#01", "7FF#R", "1FFFFFFF#R", "000#", "555#0102030405060708"]
TX_EXPECTED = ["t3214DEADBEEF", "T12345678101", "r7FF0", "R1FFFFFFF0", "t0000", "t55580102030405060708"]

VM_SCRIPT = (r"""
. /run/labvm/lib.sh
cd /tmp
""" + VM_SHELL + r"""
# report NAME STATUS: the exit status, stdout and stderr of a dcos-can run kept in /tmp/NAME.*
report() {
    echo "@@EXIT $1=$2@@"
    echo "@@OUT-BEGIN $1@@"; cat /tmp/$1.out; echo "@@OUT-END $1@@"
    echo "@@ERR-BEGIN $1@@"; cat /tmp/$1.err; echo "@@ERR-END $1@@"
}
# fault NAME COMMAND...: a dump that the adapter's injected fault must end.
fault() {
    _name=$1; shift
    timeout 60 ./dcos-can -i gsusb:__SERIAL__ dump -n 5 -t 30000 >/tmp/$_name.out 2>/tmp/$_name.err &
    _dump=$!
    wait_for 60 "the channel started for $_name" started
    for _command in "$@"; do gsusb $_command; done
    wait $_dump
    report $_name $?
    wait_for 30 "the channel stopped after $_name" stopped
}
trap 'echo "----- gadget log -----"; cat /tmp/gadget.log' EXIT
cp /run/labvm/files/dcos-can ./dcos-can
chmod 755 ./dcos-can

/usr/bin/python3 -u /run/labvm/files/gsusb_gadget.py --serial __SERIAL__ >/tmp/gadget.log 2>&1 &
gadget=$!
wait_for 90 "can0 from gs_usb" has_can0
wait_for 30 "gadget status" test -s $S
# The kernel's driver let go: from here on the adapter is a plain USB device.
echo 1-1:1.0 >/sys/bus/usb/drivers/gs_usb/unbind
wait_for 30 "can0 gone after unbinding gs_usb" no_can0

./dcos-can --json list >/tmp/list.out 2>/tmp/list.err
report list $?

# -- the bus's frames through libusb --
timeout 90 ./dcos-can -i gsusb:__SERIAL__ --json dump -n __RX_COUNT__ -t 60000 --decode >/tmp/rx.out 2>/tmp/rx.err &
dump=$!
wait_for 60 "the channel started by dcos-can" started
echo "@@READY rx@@"
wait $dump
report rx $?
wait_for 30 "the channel stopped when dcos-can ended" stopped
echo "@@BITRATE $(status bitrate) host_format=$(status host_format)@@"

# -- frames onto the bus through libusb --
echoes=$(status echoes)
timeout 60 ./dcos-can -i gsusb:__SERIAL__ send --timeout-ms 30000 __TX_SENDS__ >/tmp/tx.out 2>/tmp/tx.err
report tx $?
wait_for 30 "echo of every frame" at_least echoes $((echoes + __TX_COUNT__))
echo "@@SENT tx@@"

# -- an adapter that sends nonsense: the dump ends with the reason, nothing is taken for a frame --
fault short "short-in 8" "error state warning 100 5"
fault dlc "bad-frame dlc 15"
fault channel "bad-frame channel 2"

# -- the adapter unplugged in the middle of a dump, then plugged back --
fault unplug unplug
./dcos-can -i gsusb:__SERIAL__ dump -n 1 -t 2000 >/tmp/absent.out 2>/tmp/absent.err
report absent $?
gsusb replug
wait_for 60 "the adapter back" bound
# Linux's gs_usb binds it again on replug; take it back.
wait_for 60 "can0 from gs_usb after replug" has_can0
echo 1-1:1.0 >/sys/bus/usb/drivers/gs_usb/unbind
wait_for 30 "can0 gone after unbinding gs_usb again" no_can0
timeout 60 ./dcos-can -i gsusb dump -n 1 -t 30000 >/tmp/replug.out 2>/tmp/replug.err &
dump=$!
wait_for 60 "the channel started after replug" started
echo "@@READY replug@@"
wait $dump
report replug $?

echo quit >$C
wait $gadget
echo "@@STATUS-BEGIN@@"; cat $S; echo "@@STATUS-END@@"
""").replace("__SERIAL__", SERIAL).replace("__RX_COUNT__", str(len(RX_FRAMES))).replace(
    "__TX_SENDS__", " ".join(TX_SENDS)).replace("__TX_COUNT__", str(len(TX_SENDS)))


class Session:
    """The one VM run: its output and transcript, and what the adapter's bus side received."""

    def __init__(self, output, transcript, tx_frames):
        self.output = output
        self.transcript = transcript
        self.tx_frames = tx_frames

    def marker(self, name):
        return [match.group(1) or "" for match in re.finditer(r"@@" + re.escape(name) + r"(?: (.*?))?@@", self.output)]

    def section(self, name, tag):
        begin, end = f"@@{name}-BEGIN {tag}@@\n", f"@@{name}-END {tag}@@"
        start = self.output.find(begin)
        stop = self.output.find(end, start)
        assert start >= 0 and stop >= 0, self.explain(f"no section {name} {tag}")
        return self.output[start + len(begin):stop]

    def run(self, name):
        """(exit status, stdout, stderr) of the dcos-can run called name."""
        statuses = dict(item.split("=", 1) for item in self.marker("EXIT"))
        assert name in statuses, self.explain(f"no run {name}")
        return int(statuses[name]), self.section("OUT", name), self.section("ERR", name)

    def explain(self, what):
        return f"{what}\n----- lab VM console -----\n{self.transcript}"


@pytest.fixture(scope="module")
def session():
    if not os.path.exists(DCOS_CAN):
        pytest.fail(f"{DCOS_CAN} is not built: run `make host-tools` (make test builds it)", pytrace=False)
    with open(GADGET, encoding="utf-8") as handle:
        gadget = handle.read()
    with open(DCOS_CAN, "rb") as handle:
        tool = handle.read()
    directory = tempfile.mkdtemp(prefix="gsusb-libusb-")
    socket_path = os.path.join(directory, "bus.sock")
    vm = LabVM(VM_SCRIPT, files={"gsusb_gadget.py": gadget, "dcos-can": tool}, load=LAB_VM_LOAD,
               timeout=COMMAND_TIMEOUT, boot_timeout=BOOT_TIMEOUT,
               qemu_args=["-chardev", f"socket,id=bus,path={socket_path},server=on,wait=off",
                          "-serial", "chardev:bus"])
    port = None
    try:
        vm.start()
        port = SlcanPort(socket_path, connect_timeout=30)
        vm.expect(r"@@READY rx@@", timeout=BOOT_TIMEOUT + STEP)
        for frame in RX_FRAMES:
            port.send(frame)
        vm.expect(r"@@SENT tx@@", timeout=STEP)
        tx_frames = [port.receive_frame(timeout=STEP) for _ in TX_SENDS]
        vm.expect(r"@@READY replug@@", timeout=STEP * 3)
        port.send(CanFrame(0x321, b"\xAB\xCD"))
        result = vm.wait()
    except (LabVMError, SlcanError) as error:
        pytest.fail(f"the lab VM session failed: {error}\n----- lab VM console -----\n{vm.transcript}",
                    pytrace=False)
    finally:
        if port is not None:
            port.close()
        vm.close()
        shutil.rmtree(directory, ignore_errors=True)
    found = Session(result.output, result.transcript, tx_frames)
    if result.status != 0:
        pytest.fail(found.explain(f"the VM script ended with status {result.status}"), pytrace=False)
    return found


def test_dcos_can_list_finds_the_adapter_by_its_serial(session):
    status, out, err = session.run("list")
    assert status == 0, session.explain(err)
    listing = json.loads(out)
    # The kernel's driver is unbound, so no SocketCAN interface; the adapter, opened to ask its channels.
    assert listing["socketcan"] == [] and "usb_error" not in listing, session.explain(out)
    [adapter] = listing["gsusb"]
    assert adapter == {"bus": adapter["bus"], "address": adapter["address"], "vid": "1d50", "pid": "606f",
                       "serial": SERIAL, "product": "candleLight USB to CAN adapter", "channels": 1,
                       "interface": f"gsusb:{SERIAL}"}, session.explain(adapter)


def test_the_bus_frames_arrive_through_libusb_and_decode(session):
    status, out, err = session.run("rx")
    assert status == 0, session.explain(err)
    frames = [json.loads(line) for line in out.strip().splitlines()]
    assert [(f["id"], f["extended"], f["remote"], f["dlc"], f["data"]) for f in frames] == RX_EXPECTED, \
        session.explain(out)
    assert {f["interface"] for f in frames} == {f"gsusb:{SERIAL}"}, session.explain(out)
    assert frames[-1]["dcos"]["type"] == "remote request", session.explain(frames[-1])
    assert (frames[-1]["dcos"]["source"], frames[-1]["dcos"]["destination"]) == (1, 255), session.explain(frames[-1])
    # The tool set the bit rate it was given (the default, 500 kbit/s) and the host byte order word; on close it
    # reset the channel (the script waited for that).
    assert session.marker("BITRATE") == ["500000 host_format=0xbeef"], session.explain(session.marker("BITRATE"))


def test_frames_sent_through_libusb_reach_the_bus(session):
    status, _, err = session.run("tx")
    assert status == 0, session.explain(err)
    assert [frame.lawicel().rstrip("\r") for frame in session.tx_frames] == TX_EXPECTED, \
        session.explain(session.tx_frames)


@pytest.mark.parametrize("name, reason", [
    ("short", r"8 bytes"),
    ("dlc", r"(?i)dlc|length code|15"),
    ("channel", r"channel 2"),
])
def test_nonsense_from_the_adapter_ends_the_dump_with_its_reason(session, name, reason):
    status, out, err = session.run(name)
    assert status == 4, session.explain(f"{name}: exit {status}\n{out}\n{err}")
    assert out.strip() == "", session.explain(f"{name}: took something for a frame: {out}")
    assert re.search(reason, err) and f"gsusb:{SERIAL}" in err, session.explain(err)


def test_an_unplugged_adapter_ends_the_dump_with_a_clear_error_and_works_when_plugged_back(session):
    status, _, err = session.run("unplug")
    assert status == 4 and "unplugged" in err, session.explain(f"exit {status}: {err}")
    status, _, err = session.run("absent")
    assert status == 3 and SERIAL in err, session.explain(f"exit {status}: {err}")
    status, out, err = session.run("replug")
    assert status == 0 and out.split()[2:5] == ["321", "[2]", "AB"], session.explain(f"exit {status}: {out}{err}")
