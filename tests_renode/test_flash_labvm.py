"""Flashing over real SocketCAN (docs/protocols/flash.md, "On CAN"):
dcos-flash in the lab VM on the Linux kernel's can0 (slcan, bridged to the
lab hub), once with its own ISO-TP on a raw CAN socket and once through
the kernel's own can-isotp socket (--kernel-isotp), which segments,
reassembles and paces the flow control for it: an implementation we did
not write on the tool's side of every transfer.

The emulated 486 board boots from its card (the production image in slot
A) and runs as CAN node 3; the VM's tool asks it for its state, then puts
a small signed image (16 KiB of payload, made here with the development
key) into its inactive slot while it runs, without restarting it. Emulated
time is paced at a twentieth of wall time, so that the VM, slow under an
emulated CPU, answers within the node's ISO-TP time-outs (1 s emulated,
20 s of wall time).
"""

import json
import os
import tempfile

import pytest

from dcoslab.board import REPOSITORY, load_board
from dcoslab.canlab import CanLab
from dcoslab.cards import BIN, DEVELOPMENT_KEY, card_state, new_card, signed, signed_loop
from dcoslab.remote import attach_node
from dcoslab.vmworld import BridgedWorld, attach_reports, hold_world, start_bridged_vm, vm_status

pytestmark = pytest.mark.xdist_group("test_flash_labvm")

BITRATE = 500_000
PACE = 0.05
NODE = 3
BOOT_TIMEOUT = 400
STEP = 600
# Under the tree's build folder, not /tmp: the VM sees the host's files there.
WORK_ROOT = os.path.join(REPOSITORY, "build", "labvm-flash")


def tiny_image(work):
    """A signed image of 16 KiB of payload: a loop and a page of data, linked at 1 MiB, never started."""
    return signed_loop(work, "tiny", "2.0.0", data_bytes=16384)


def vm_script():
    """The VM's commands. The tool, the image and the key come in as files
    (/run/labvm/files): the host's /tmp, where a CI clone may live, is not
    visible there."""
    files = "/run/labvm/files"
    common = f"-i can0 -n {NODE} --json --timeout-ms 15000"
    return f"""
. /run/labvm/lib.sh
cp {files}/dcos-flash /tmp/dcos-flash && chmod 755 /tmp/dcos-flash
out=$(/tmp/dcos-flash {common} info 2>&1); echo "@@INFO $out status=$?@@"
out=$(/tmp/dcos-flash {common} --kernel-isotp info 2>&1); echo "@@KINFO $out status=$?@@"
out=$(/tmp/dcos-flash {common} --kernel-isotp -k {files}/key.pem --no-restart {files}/tiny.dcos 2>&1)
echo "@@FLASH $out status=$?@@"
"""


def carried(path):
    with open(path, "rb") as handle:
        return handle.read()


def boot_node_on_card(world, work):
    """The world's board: the 486 booting from a card with 1.0.0 confirmed in slot A, node NODE on the paced lab
    bus can0 (world.card, world.lab, world.board). Returns the files the VM's tool needs: dcos-flash, the signed
    2.0.0 image (tiny.dcos) and the development key."""
    image = tiny_image(work)
    world.card = new_card(work, ("A", signed(work, "1.0.0"), False))
    world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BITRATE},
                       {"board1": {"bus0": "can0", "card": world.card}}, pace=PACE, timeout=BOOT_TIMEOUT)
    world.board = world.lab.board("board1")
    attach_node(world.board, NODE, [], BITRATE, timeout=STEP)
    return {"dcos-flash": carried(os.path.join(BIN, "dcos-flash")), "tiny.dcos": carried(image),
            "key.pem": carried(DEVELOPMENT_KEY)}


@pytest.fixture(scope="module")
def world():
    os.makedirs(WORK_ROOT, exist_ok=True)
    work = tempfile.TemporaryDirectory(dir=WORK_ROOT)

    def build(world):
        files = boot_node_on_card(world, work.name)
        start_bridged_vm(world, vm_script(), BITRATE, files, BOOT_TIMEOUT, 1200)

    with work:
        yield from hold_world(BridgedWorld(), build)


@pytest.fixture(autouse=True)
def _reports(request):
    attach_reports(request)


def marked(world, tag):
    return vm_status(world, tag, STEP)


def test_dcos_flash_in_the_lab_vm_reads_the_node_over_socketcan_with_both_iso_tp_implementations(world):
    own, status = marked(world, "INFO")
    assert status == 0, own
    kernel, status = marked(world, "KINFO")
    assert status == 0, kernel
    expected = {"node": NODE, "mode": "application", "protocol": 1, "confirmed": "A", "trial": "none",
                "trial_slot": "none", "slot_a": "1.0.0", "slot_b": "empty", "transfer_slot": "none",
                "transfer_offset": 0}
    assert json.loads(own) == expected and json.loads(kernel) == expected, (own, kernel)


def test_the_kernels_iso_tp_flashes_the_running_node(world):
    output, status = marked(world, "FLASH")
    assert status == 0, output
    done = json.loads(output)
    assert done["slot"] == "B" and done["version"] == "2.0.0" and done["bytes"] == 16386, done
    assert done["restarted"] is False, done
    # The node ran on: its console answers, and its card holds the image pending.
    assert "flash: service running" in world.board.command("flash", timeout=STEP)
    state = card_state(world.card)
    assert state["boot_state"]["trial"] == "pending" and state["boot_state"]["trial_slot"] == "B", state
    assert state["slots"]["B"]["valid"] is True and state["slots"]["B"]["version"] == "2.0.0", state
