"""Recovery through the reset and strap lines, end to end (docs/guide/flashing.md, "Recovery through the reset and strap lines").

The emulated 486 board boots from its card, whose confirmed image (slot A)
hangs at boot: a loop, which no watchdog ends, since a confirmed image runs
without one. Its service header (the lab-gpio-header model) is wired to the
emulated MCP2221A in the lab VM (tests_renode/labvm/mcp2221_bridge.py), whose
GPIO lines reach it as the header's line protocol through the VM's third
serial port and a relay in this test, which logs every line. dcos-flash
--recover, run in the VM, drives the MCP2221A through hidapi (hid-generic's
hidraw node): the strap low, a pulse on reset; the board restarts into the
stage loader, which sees the strap and stays in recovery; the tool finds it
there over the VM's can0 (slcan, bridged to the lab bus), releases the strap,
puts a new image into slot B, restarts the node into it as a trial and waits;
the engineer (this test) confirms the trial on the console, and the tool
reports the trial confirmed.

Emulated time is paced (PACE of wall time), so that the VM, slow under an
emulated CPU, answers within the stage loader's and the node's ISO-TP
time-outs.
"""

import json
import os
import socket
import tempfile
import threading
import time

import pytest

from dcoslab.board import REPOSITORY, load_board
from dcoslab.canlab import CanLab
from dcoslab.cards import BIN, DEVELOPMENT_KEY, card_state, new_card, signed, signed_loop
from dcoslab.vmworld import BridgedWorld, attach_reports, hold_world, vm_status

pytestmark = pytest.mark.xdist_group("test_flash_recover_labvm")

BITRATE = 1_000_000  # the card's recovery rate too: the image crosses the bus in half the time of 500 kbit/s
PACE = 0.25
NODE = 3
BOOT_TIMEOUT = 400
STEP = 1500
WORK_ROOT = os.path.join(REPOSITORY, "build", "labvm-recover")
BRIDGE = os.path.join(REPOSITORY, "tests_renode", "labvm", "mcp2221_bridge.py")


def hanging_image(work):
    """A signed image that loops at its first instruction: it never confirms, never answers."""
    return signed_loop(work, "hang", "1.0.0")


class Relay:
    """Joins the VM's serial port (the MCP2221A's lines) to the board's header, and logs both ways."""

    def __init__(self, vm_socket, board_socket, timeout=120):
        self.lines = []
        self._vm = self._connect(vm_socket, timeout)
        self._board = self._connect(board_socket, timeout)
        self._lock = threading.Lock()
        for source, sink, side in ((self._vm, self._board, "bridge"), (self._board, self._vm, "header")):
            threading.Thread(target=self._copy, args=(source, sink, side), daemon=True).start()

    @staticmethod
    def _connect(path, timeout):
        deadline = time.monotonic() + timeout
        while True:
            connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                connection.connect(path)
                return connection
            except OSError:
                connection.close()
                assert time.monotonic() < deadline, f"no socket {path}"
                time.sleep(0.05)

    def _copy(self, source, sink, side):
        pending = b""
        while True:
            try:
                data = source.recv(4096)
                if not data:
                    return
                sink.sendall(data)
            except OSError:
                return
            pending += data
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                with self._lock:
                    self.lines.append(f"{side}: {line.decode('ascii', 'replace')}")

    def log(self):
        with self._lock:
            return list(self.lines)

    def close(self):
        for connection in (self._vm, self._board):
            connection.close()


def vm_script():
    files = "/run/labvm/files"
    return f"""
. /run/labvm/lib.sh
cp {files}/dcos-flash /tmp/dcos-flash && chmod 755 /tmp/dcos-flash
/usr/bin/python3 -u {files}/mcp2221_bridge.py --tty /dev/ttyS2 --serial LAB-MCP-0001 >/tmp/bridge.log 2>&1 &
until [ -e /dev/hidraw0 ]; do sleep 0.2; done
echo "@@READY lines@@"
out=$(/tmp/dcos-flash -i can0 -n {NODE} --json --timeout-ms 20000 --recover --bridge LAB-MCP-0001 \\
      --recovery-timeout 600 --confirm-timeout 1200 -k {files}/key.pem {files}/new.dcos 2>&1)
echo "@@RECOVER $out status=$?@@"
echo "----- bridge log -----"; cat /tmp/bridge.log
"""


@pytest.fixture(scope="module")
def world():
    from dcoslab.labvm import LabVM, SlcanSetup
    from dcoslab.slcan_bridge import SlcanBridge
    from labvm.mcp2221_bridge import LAB_VM_LOAD

    os.makedirs(WORK_ROOT, exist_ok=True)
    work = tempfile.TemporaryDirectory(dir=WORK_ROOT)
    board_socket = os.path.join(work.name, "header.sock")

    def build(world):
        world.card = new_card(work.name, ("A", hanging_image(work.name), False),
                              options=("--bitrate", str(BITRATE)))
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BITRATE},
                           {"board1": {"bus0": "can0", "card": world.card, "expect": r"stage: starting slot A",
                                       "devices": {"lab-gpio-header": {"chardev": "hdr"}},
                                       "args": ["-chardev", f"socket,id=hdr,path={board_socket},server=on,wait=off"]}},
                           pace=PACE, timeout=BOOT_TIMEOUT)
        world.board = world.lab.board("board1")
        with open(BRIDGE, "rb") as handle:
            bridge = handle.read()
        files = {"dcos-flash": open(os.path.join(BIN, "dcos-flash"), "rb").read(),
                 "new.dcos": open(signed(work.name, "2.0.0"), "rb").read(),
                 "key.pem": open(DEVELOPMENT_KEY, "rb").read(), "mcp2221_bridge.py": bridge}
        vm_socket = os.path.join(work.name, "lines.sock")
        world.vm = LabVM(vm_script(), slcan=SlcanSetup("can0", BITRATE), connect_slcan=False, files=files,
                         load=LAB_VM_LOAD, boot_timeout=BOOT_TIMEOUT, timeout=STEP * 2,
                         qemu_args=["-chardev", f"socket,id=lines,path={vm_socket},server=on,wait=off",
                                    "-serial", "chardev:lines"])
        world.vm.start()
        world.relay = Relay(vm_socket, board_socket)
        world.bridge = SlcanBridge(world.vm.slcan_socket_path, world.lab.socket_path, "can0").start()
        world.bridge.wait_for(lambda b: b.is_open, BOOT_TIMEOUT, "slcand to open the channel")

    with work:
        shared = BridgedWorld()
        shared.relay = None
        try:
            yield from hold_world(shared, build)
        finally:
            if shared.relay is not None:
                shared.relay.close()


@pytest.fixture(autouse=True)
def _reports(request):
    attach_reports(request)


def test_a_node_whose_image_hangs_is_recovered_through_the_lines_then_flashed_and_confirmed(world):
    board = world.board.emulator
    world.vm.expect(r"@@READY lines@@", timeout=STEP)
    # The reset pulse restarts the board; the stage loader sees the strap and stays in recovery.
    board.expect(r"stage: the recovery strap is set", timeout=STEP)
    board.expect(r"stage: boot state \d+: confirmed slot A, trial none", timeout=STEP)
    board.expect(r"stage: recovery: the recovery strap is set", timeout=STEP)
    board.expect(rf"stage: recovery: waiting for an image on this serial line or on CAN as node {NODE} "
                 rf"at {BITRATE} bit/s", timeout=STEP)
    # The tool flashes slot B there and restarts the node into it, the strap released: a trial.
    board.expect(r"stage: slot B: isa486 2\.0\.0, signature and digest valid", timeout=STEP)
    board.expect(r"stage: starting slot B", timeout=STEP)
    board.expect(r"dcos> ", timeout=STEP)
    assert "confirmed:" in world.board.command("boot confirm", timeout=STEP)
    output, status = vm_status(world, "RECOVER", STEP)
    assert status == 0, output
    done = json.loads(output.strip().splitlines()[-1])
    assert done["recovered"] is True and done["slot"] == "B" and done["version"] == "2.0.0", done
    assert done["trial"] == "confirmed", done
    # The lines as the board's header saw them: strap low, reset pulsed, strap released.
    lines = [line for line in world.relay.log() if line.startswith("bridge: ")]
    assert lines[:2] == ["bridge: strap=1", "bridge: reset=1"], world.relay.log()
    assert lines[2:] == ["bridge: strap=0", "bridge: reset=0", "bridge: reset=1", "bridge: strap=1"], \
        world.relay.log()
    assert "header: restart" in world.relay.log()
    world.lab.close()
    state = card_state(world.card)["boot_state"]
    assert state["confirmed"] == "B" and state["trial"] == "none", state
