"""dcos-flash through a gs_usb adapter by libusb, unplugged in the middle of a transfer, then resumed (issue 18).

The emulated 486 board boots from its card (the production image in slot A)
and runs as CAN node 3 on the lab bus. The lab VM has no slcan and no
kernel gs_usb driver: its only way to the bus is the emulated candleLight
of tests_renode/labvm/gsusb_gadget.py (docs/protocols/lab-usb-devices.md),
whose CAN side (the VM's second serial port, Lawicel) the slcan bridge
(dcoslab/slcan_bridge.py) joins to the hub, as a real adapter's cable joins
it to the plant's bus. dcos-flash in the VM reaches the node through
`-i gsusb:<serial>` (host_tools/can, docs/protocols/gs_usb.md):

1. it reads the node's state;
2. it starts putting a signed image into the inactive slot, and the adapter
   is unplugged (the gadget unbound from its UDC) after a few hundred
   frames: the tool stops with a clear error and a non-zero status, and the
   node keeps what it acknowledged;
3. the adapter is plugged back, and `dcos-flash --resume` completes the
   transfer from where it stopped; the card then holds the image, pending.

Emulated time is paced at a twentieth of wall time, as in
test_flash_labvm.py, so that the slow VM answers within the node's ISO-TP
time-outs.
"""

import json
import os
import re
import tempfile

import pytest

from dcoslab.cards import card_state
from dcoslab.slcan_bridge import SlcanBridge
from dcoslab.vmworld import BridgedWorld, attach_reports, hold_world, vm_status
from labvm import LabVM
from labvm.gsusb_gadget import LAB_VM_LOAD, VM_SHELL
from test_flash_labvm import BOOT_TIMEOUT, NODE, STEP, WORK_ROOT, boot_node_on_card, carried

pytestmark = pytest.mark.xdist_group("test_flash_gsusb_labvm")

SERIAL = "LAB-GSUSB-FLASH"
GADGET = os.path.join(os.path.dirname(os.path.abspath(__file__)), "labvm", "gsusb_gadget.py")
# Frames the tool puts on the bus before the adapter is pulled: well into the image's 2,300 or so.
UNPLUG_AFTER_FRAMES = 400


def vm_script():
    files = "/run/labvm/files"
    common = f"-i gsusb:{SERIAL} -n {NODE} --json --timeout-ms 15000"
    return f"""
. /run/labvm/lib.sh
cd /tmp
{VM_SHELL}
trap 'echo "----- gadget log -----"; cat /tmp/gadget.log' EXIT
cp {files}/dcos-flash ./dcos-flash && chmod 755 ./dcos-flash
/usr/bin/python3 -u {files}/gsusb_gadget.py --serial {SERIAL} >/tmp/gadget.log 2>&1 &
wait_for 90 "the adapter" bound
wait_for 30 "the adapter enumerated" test -e /sys/bus/usb/devices/1-1/serial

out=$(./dcos-flash {common} info 2>&1); echo "@@INFO $out status=$?@@"

# The transfer, and the adapter pulled out of the laptop in its middle.
./dcos-flash {common} -k {files}/key.pem --no-restart {files}/tiny.dcos >/tmp/cut.out 2>/tmp/cut.err &
flash=$!
wait_for 300 "{UNPLUG_AFTER_FRAMES} frames of the transfer" at_least to_bus $(( $(status to_bus) + {UNPLUG_AFTER_FRAMES} ))
gsusb unplug
wait $flash
cut=$?
echo "@@CUT $(cat /tmp/cut.out /tmp/cut.err | tr '\\n' ' ') status=$cut@@"

# Plugged back in: the tool resumes where the node stopped taking blocks.
gsusb replug
wait_for 60 "the adapter back" bound
wait_for 30 "the adapter enumerated again" test -e /sys/bus/usb/devices/1-1/serial
out=$(./dcos-flash {common} info 2>&1); echo "@@HELD $out status=$?@@"
out=$(./dcos-flash {common} -k {files}/key.pem --no-restart --resume {files}/tiny.dcos 2>&1)
echo "@@RESUMED $out status=$?@@"
echo quit >$C
"""


@pytest.fixture(scope="module")
def world():
    os.makedirs(WORK_ROOT, exist_ok=True)
    work = tempfile.TemporaryDirectory(dir=WORK_ROOT)

    def build(world):
        files = boot_node_on_card(world, work.name)
        files["gsusb_gadget.py"] = carried(GADGET)
        socket_path = os.path.join(work.name, "bus.sock")
        # No gs_usb module: the adapter is the tool's alone, through libusb.
        world.vm = LabVM(vm_script(), files=files, load=[m for m in LAB_VM_LOAD if m != "gs_usb"],
                         boot_timeout=BOOT_TIMEOUT, timeout=1800,
                         qemu_args=["-chardev", f"socket,id=bus,path={socket_path},server=on,wait=off",
                                    "-serial", "chardev:bus"])
        world.vm.start()
        world.bridge = SlcanBridge(socket_path, world.lab.socket_path, "can0").start()

    with work:
        yield from hold_world(BridgedWorld(), build)


@pytest.fixture(autouse=True)
def _reports(request):
    attach_reports(request)


def test_dcos_flash_reads_the_node_through_the_adapter(world):
    output, status = vm_status(world, "INFO", STEP * 2)
    assert status == 0, output
    info = json.loads(output)
    assert (info["node"], info["mode"], info["slot_a"], info["slot_b"]) == (NODE, "application", "1.0.0", "empty"), info


def test_an_adapter_unplugged_mid_transfer_ends_the_tool_with_a_clear_error(world):
    output, status = vm_status(world, "CUT", STEP * 2)
    assert status != 0, output
    assert "unplugged" in output and "run again to resume" in output, output


def test_the_node_kept_what_it_acknowledged_and_resume_completes_the_transfer(world):
    output, status = vm_status(world, "HELD", STEP)
    assert status == 0, output
    held = json.loads(output)
    assert held["transfer_slot"] == "B" and held["transfer_offset"] > 0, held
    output, status = vm_status(world, "RESUMED", STEP * 2)
    assert status == 0, output
    done = json.loads(output)
    assert done["slot"] == "B" and done["version"] == "2.0.0" and done["bytes"] == 16386, done
    assert done["resumed_from"] == held["transfer_offset"], (done, held)
    state = card_state(world.card)
    assert state["boot_state"]["trial"] == "pending" and state["boot_state"]["trial_slot"] == "B", state
    assert state["slots"]["B"]["valid"] is True and state["slots"]["B"]["version"] == "2.0.0", state
    # Every frame the tool sent crossed the bridge: nothing the adapter took was lost on the way.
    assert world.bridge.error is None, world.bridge.error
    assert re.search(r"flash: service running", world.board.command("flash", timeout=STEP))
