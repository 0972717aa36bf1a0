"""Configuring over real SocketCAN (docs/protocols/config.md, "On CAN"):
dcos-config in the lab VM on the Linux kernel's can0 (slcan, bridged to the
lab hub), with its own ISO-TP and through the kernel's can-isotp socket,
while python-can on the same can0 records every frame as an observer we
did not write the stack of; the host decodes what it recorded with the
observer written from the protocol's page (dcoslab/configwire.py).

The emulated 486 board boots from its card (serial number 0xFFFFFFFE, a
configuration key, the bus's bit rate, node 3), so it is on the bus from
boot with no console command. Emulated time is paced at a twentieth of
wall time, as in test_flash_labvm.py, so that the VM answers within the
node's ISO-TP time-outs.
"""

import json
import os
import tempfile
import types

import pytest

from dcoslab.board import REPOSITORY, load_board
from dcoslab.canlab import CanLab
from dcoslab.cards import BIN, card_state, new_card, signed, tool
from dcoslab.configwire import read_wire
from dcoslab.vmworld import BridgedWorld, attach_reports, hold_world, start_bridged_vm, vm_status

pytestmark = pytest.mark.xdist_group("test_config_labvm")

BITRATE = 500_000
PACE = 0.05
NODE = 3
# All ones but the last bit: the scan's search takes 34 or 35 probes.
SERIAL = 0xFFFFFFFE
BOOT_TIMEOUT = 400
STEP = 900
WORK_ROOT = os.path.join(REPOSITORY, "build", "labvm-config")

RECORDER = r"""
import can, os, sys, time
bus = can.interface.Bus(channel="can0", interface="socketcan")
with open("/tmp/frames.txt", "w") as out:
    print("recording", flush=True)
    while not os.path.exists("/tmp/stop"):
        message = bus.recv(0.2)
        if message is not None and not message.is_error_frame:
            out.write(f"{message.arbitration_id:08x} {int(message.is_extended_id)} {message.data.hex()}\n")
            out.flush()
bus.shutdown()
"""


def vm_script():
    files = "/run/labvm/files"
    common = "-i can0 --json --timeout-ms 15000 --probe-ms 2000"
    return f"""
. /run/labvm/lib.sh
cp {files}/dcos-config /tmp/dcos-config && chmod 755 /tmp/dcos-config
python3 {files}/recorder.py > /tmp/recorder.log 2>&1 &
for i in $(seq 100); do grep -q recording /tmp/recorder.log && break; sleep 0.2; done
out=$(/tmp/dcos-config {common} scan 2>&1); echo "@@SCAN $out status=$?@@"
out=$(/tmp/dcos-config {common} info -n {NODE} 2>&1); echo "@@INFO $out status=$?@@"
out=$(/tmp/dcos-config {common} --kernel-isotp -K {files}/node.key set-node -n {NODE} 7 2>&1)
echo "@@SET $out status=$?@@"
out=$(/tmp/dcos-config {common} --kernel-isotp -K {files}/other.key set-node -n {NODE} 8 2>&1)
echo "@@WRONG $out status=$?@@"
out=$(/tmp/dcos-config {common} objects -n {NODE} 2>&1); echo "@@OBJECTS $out status=$?@@"
out=$(/tmp/dcos-config {common} --kernel-isotp -K {files}/node.key create -n {NODE} semaphore vmlock --initial 0 2>&1)
echo "@@CREATE $out status=$?@@"
out=$(/tmp/dcos-config {common} --kernel-isotp show -n {NODE} semaphore:vmlock 2>&1); echo "@@SHOW $out status=$?@@"
out=$(/tmp/dcos-config {common} -K {files}/node.key delete -n {NODE} semaphore:vmlock 2>&1)
echo "@@DELETE $out status=$?@@"
out=$(/tmp/dcos-config {common} find -n {NODE} semaphore vmlock 2>&1); echo "@@GONE $out status=$?@@"
touch /tmp/stop; wait
echo "@@FRAMES $(tr '\\n' ';' < /tmp/frames.txt)@@"
"""


@pytest.fixture(scope="module")
def world():
    os.makedirs(WORK_ROOT, exist_ok=True)
    work = tempfile.TemporaryDirectory(dir=WORK_ROOT)

    def build(world):
        keys = {}
        for name in ("node", "other"):
            keys[name] = os.path.join(work.name, f"{name}.key")
            tool("dcos-config", "keygen", "-o", keys[name])
        card = new_card(work.name, ("A", signed(work.name, "1.0.0"), False), append=f"node={NODE}",
                        options=("--serial", str(SERIAL), "--config-key", keys["node"], "--bitrate", str(BITRATE)))
        world.card = card
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BITRATE},
                           {"board1": {"bus0": "can0", "card": card}}, pace=PACE, timeout=BOOT_TIMEOUT)
        world.board = world.lab.board("board1")
        files = {"recorder.py": RECORDER.encode()}
        for name, path in (("dcos-config", os.path.join(BIN, "dcos-config")), ("node.key", keys["node"]),
                           ("other.key", keys["other"])):
            with open(path, "rb") as handle:
                files[name] = handle.read()
        start_bridged_vm(world, vm_script(), BITRATE, files, BOOT_TIMEOUT, 3000)

    with work:
        yield from hold_world(BridgedWorld(), build)


@pytest.fixture(autouse=True)
def _reports(request):
    attach_reports(request)


def marked(world, tag):
    return vm_status(world, tag, STEP)


def test_dcos_config_in_the_lab_vm_scans_reads_and_renumbers_the_node_over_socketcan(world):
    scanned, status = marked(world, "SCAN")
    assert status == 0, scanned
    [found] = json.loads(scanned)
    assert (found["serial"], found["node"], found["can_node"], found["key"]) == (SERIAL, NODE, NODE, True), found
    info, status = marked(world, "INFO")
    assert status == 0, info
    assert json.loads(info)["configuration"]["bit_rate"] == BITRATE, info
    # Signed through the kernel's ISO-TP: taken; under another node's key: refused.
    written, status = marked(world, "SET")
    assert status == 0 and json.loads(written)["node_id"] == 7, written
    wrong, status = marked(world, "WRONG")
    assert status == 1 and "refused the key" in wrong, wrong
    # The node's objects, a semaphore made, shown and deleted over SocketCAN.
    objects, status = marked(world, "OBJECTS")
    assert status == 0, objects
    assert {"idle", "flash", "card"} <= {o["name"] for o in json.loads(objects)}, objects
    created, status = marked(world, "CREATE")
    assert status == 0, created
    shown, status = marked(world, "SHOW")
    assert status == 0, shown
    shown = json.loads(shown)
    assert (shown["id"], shown["type"], shown["count"], shown["owner"]) == (
        json.loads(created)["id"], "semaphore", 0, "system"), shown
    deleted, status = marked(world, "DELETE")
    assert status == 0, deleted
    gone, status = marked(world, "GONE")
    assert status == 1 and "kernel refused it: not found" in gone, gone


def test_python_can_saw_every_exchange_and_each_decodes_by_the_protocols_page(world):
    match = world.vm.expect(rb"@@FRAMES (.*?)@@", timeout=STEP)
    records = []
    for line in match.group(1).decode().split(";"):
        if not line.strip():
            continue
        identifier, extended, data = line.split(" ")
        frame = types.SimpleNamespace(id=int(identifier, 16), extended=extended == "1", data=bytes.fromhex(data))
        records.append(types.SimpleNamespace(outcome="ok", frame=frame))
    wire = read_wire(records)
    requests = [m for m in wire if m["direction"] == "request"]
    replies = [m for m in wire if m["direction"] == "reply"]
    assert sum(m["command"] == "ProbeSerial" for m in requests) >= 33, requests
    assert [m["serial"] for m in requests if m["command"] == "Select"] == [SERIAL], requests
    assert [(m["command"], m["status"]) for m in replies if m["command"] in ("SetNodeId",)] == [
        ("SetNodeId", "Ok"), ("SetNodeId", "BadMac")], replies
    # The object commands, each reply as the page lays it out.
    assert [m["command"] for m in requests if m["command"] in ("CreateObject", "DeleteObject")] == [
        "CreateObject", "DeleteObject"], requests
    listed = [m for m in replies if m["command"] == "ListObjects" and m["status"] == "Ok"]
    assert listed and any(name == "flash" for m in listed for _, _, name in m["entries"]), listed
    assert [(m["command"], m["status"], m.get("kernel_status")) for m in replies if m["command"] == "FindObject"][-1] \
        == ("FindObject", "KernelRefused", 13), replies
    identified = [m for m in replies if m["command"] == "Identify" and m["status"] == "Ok"]
    assert identified and all(m["serial"] == SERIAL and m["node"] == NODE for m in identified), identified
    # The node wrote its card: the next start is node 7's.
    assert card_state(world.card)["configuration"]["node"] == 7
