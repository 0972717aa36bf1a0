"""Flashing a controller over CAN (docs/protocols/flash.md "On CAN",
docs/guide/flashing.md): dcos-flash on the lab's CAN bus against the
running node's flash service, which takes the image into the card's
inactive slot while the node runs, and against the stage loader's recovery,
which a flash tool can ask the node to stay in.

Each board boots from its own card (dcos-card, the development key) with
the production image in slot A, on a 1 Mbit/s lab bus in exact time. The
images flashed are the production firmware, signed as newer versions.
"""
import json
import os
import subprocess

from dcoslab.cards import BIN, DEVELOPMENT_KEY, card_state, new_card, signed, tool
from dcoslab.remote import attach_node

BITRATE = 1_000_000
NODE = 3
# Generous: bounds on a hung board or tool, not speeds.
TIMEOUT = 900


def lab_with_card(canlab, card, expect=r"dcos> "):
    lab = canlab({"can0": BITRATE}, {"board1": {"bus0": "can0", "card": card, "expect": expect}})
    return lab, lab.board("board1")


def flash_tool(lab, *arguments):
    """dcos-flash on the lab bus, started; the caller waits for it."""
    return subprocess.Popen([os.path.join(BIN, "dcos-flash"), "-i", f"lab:{lab.socket_path}:can0", "-n", str(NODE),
                             "--json", *arguments], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def finished(process, code=0):
    output, errors = process.communicate(timeout=TIMEOUT)
    assert process.returncode == code, (process.returncode, output, errors)
    return output, errors


def test_a_running_node_takes_an_image_over_can_and_the_tool_waits_for_its_confirmation(canlab, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False))
    lab, board = lab_with_card(canlab, card)
    attach_node(board, NODE, [], BITRATE)
    status = board.command("flash")
    assert "flash: service running, 1 trusted key" in status, status

    info = flash_tool(lab, "info")
    output, _ = finished(info)
    assert json.loads(output) == {"node": NODE, "mode": "application", "protocol": 1, "confirmed": "A",
                                  "trial": "none", "trial_slot": "none", "slot_a": "1.0.0", "slot_b": "empty",
                                  "transfer_slot": "none", "transfer_offset": 0}, output

    image = signed(tmp_path, "1.1.0")
    flashing = flash_tool(lab, "-k", DEVELOPMENT_KEY, "--confirm-timeout", str(TIMEOUT), image)
    # The node runs on while it takes the image: its console answers, and
    # then it restarts into the new image, as a trial.
    board.emulator.expect(r"flash: restarting into the new image, as host 254 asked", timeout=TIMEOUT)
    board.emulator.expect(r"stage: slot B: isa486 1\.1\.0, signature and digest valid", timeout=TIMEOUT)
    board.emulator.expect(r"stage: starting slot B", timeout=TIMEOUT)
    board.emulator.expect(r"dcos> ", timeout=TIMEOUT)
    # The new image brings its CAN interface up, and the tool, asking all
    # along, sees a trial not yet confirmed; then the engineer confirms.
    attach_node(board, NODE, [], BITRATE)
    assert "confirmed:" in board.command("boot confirm")
    output, _ = finished(flashing)
    done = json.loads(output)
    assert done["slot"] == "B" and done["version"] == "1.1.0" and done["restarted"] is True, done
    assert done["trial"] == "confirmed", done
    assert done["bytes"] == os.path.getsize(image) - 256, done
    lab.close()
    state = card_state(card)["boot_state"]
    assert state["confirmed"] == "B" and state["trial"] == "none", state


def test_a_node_told_to_stay_in_recovery_takes_an_image_there_over_can(canlab, tmp_path):
    # The card's configuration names the bus's bit rate: the stage loader has
    # no other way to know it, and the kernel brings can0 up on the network
    # at it as it starts, with no console command.
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False), options=("--bitrate", str(BITRATE)))
    lab, board = lab_with_card(canlab, card)
    boot_lines = board.emulator.transcript
    assert f"command line: can0={BITRATE} node={NODE} boot.slot=A" in boot_lines, boot_lines
    assert f"can0 carries interface 0: 130.1.0.{NODE}/16, CAN node {NODE}" in boot_lines, boot_lines
    lab.hub.wait_on_bus(["board1.0"], TIMEOUT)

    stranger = tmp_path / "stranger.pem"
    tool("dcos-image", "keygen", "-o", str(stranger))
    _, errors = finished(flash_tool(lab, "-k", str(stranger), "restart", "--recovery"), code=1)
    assert "authentication failed" in errors, errors

    finished(flash_tool(lab, "-k", DEVELOPMENT_KEY, "restart", "--recovery"))
    board.emulator.expect(r"flash: restarting into the stage loader's recovery", timeout=TIMEOUT)
    board.emulator.expect(r"stage: recovery: a flash tool asked the node to stay in recovery", timeout=TIMEOUT)
    board.emulator.expect(rf"stage: recovery: waiting for an image on this serial line or on CAN as node {NODE} "
                          rf"at {BITRATE} bit/s", timeout=TIMEOUT)
    # The chip takes part once it has seen the bus idle for 11 bits.
    lab.hub.wait_on_bus(["board1.0"], TIMEOUT)
    output, _ = finished(flash_tool(lab, "info"))
    info = json.loads(output)
    assert info["mode"] == "recovery" and info["confirmed"] == "A", info

    image = signed(tmp_path, "1.2.0")
    output, _ = finished(flash_tool(lab, "-k", DEVELOPMENT_KEY, "--no-wait", image))
    done = json.loads(output)
    assert done["slot"] == "B" and done["restarted"] is True and "trial" not in done, done
    # The mark held once: the stage loader now boots the new image as a trial.
    board.emulator.expect(r"stage: a new image on trial", timeout=TIMEOUT)
    board.emulator.expect(r"command line: .*boot\.slot=B boot\.version=1\.2\.0 boot\.trial=1", timeout=TIMEOUT)
    board.emulator.expect(r"dcos> ", timeout=TIMEOUT)
    # A second image while that trial runs unconfirmed would need its slot:
    # refused, nothing written. The trial image is on the bus by itself too.
    lab.hub.wait_on_bus(["board1.0"], TIMEOUT)
    _, errors = finished(flash_tool(lab, "-k", DEVELOPMENT_KEY, signed(tmp_path, "1.3.0")), code=1)
    assert "runs a trial image from the slot the new image needs" in errors, errors
    assert "confirmed:" in board.command("boot confirm")
    lab.close()
    state = card_state(card)
    assert state["boot_state"]["confirmed"] == "B" and state["slots"]["B"]["version"] == "1.2.0", state


def test_a_node_nobody_has_and_a_wrong_interface_are_named(canlab, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False))
    lab, board = lab_with_card(canlab, card)
    # Alone on the bus, nothing acknowledges the tool's frames.
    alone = subprocess.run([os.path.join(BIN, "dcos-flash"), "-i", f"lab:{lab.socket_path}:can0", "-n", "9", "info"],
                           capture_output=True, text=True, timeout=TIMEOUT)
    assert alone.returncode == 4 and "is another node there to acknowledge it?" in alone.stderr, alone.stderr
    # With the board on the bus, node 9 is simply not there.
    attach_node(board, NODE, [], BITRATE)
    silent = subprocess.run([os.path.join(BIN, "dcos-flash"), "-i", f"lab:{lab.socket_path}:can0", "-n", "9",
                             "--retries", "1", "--timeout-ms", "300", "info"], capture_output=True, text=True,
                            timeout=TIMEOUT)
    assert silent.returncode == 4 and "no answer from the node after 2 attempts" in silent.stderr, silent.stderr
    missing = subprocess.run([os.path.join(BIN, "dcos-flash"), "-i", "lab:/nonexistent/hub.sock:can0", "-n", "3",
                              "info"], capture_output=True, text=True, timeout=TIMEOUT)
    assert missing.returncode == 3 and "no lab bus hub" in missing.stderr, missing.stderr
    unnumbered = subprocess.run([os.path.join(BIN, "dcos-flash"), "-i", "can0", "info"], capture_output=True,
                                text=True, timeout=TIMEOUT)
    assert unnumbered.returncode == 2 and "-n names the node's CAN node number" in unnumbered.stderr


def test_nodes_on_one_bus_are_addressed_each_by_its_own_number(canlab, tmp_path):
    cards = {}
    for node in (3, 4):
        directory = tmp_path / f"node{node}"
        directory.mkdir()
        cards[node] = new_card(directory, ("A", signed(directory, f"1.0.{node}"), False), append=f"node={node}")
    lab = canlab({"can0": BITRATE}, {"board3": {"bus0": "can0", "card": cards[3]},
                                     "board4": {"bus0": "can0", "card": cards[4]}})
    attach_node(lab.board("board3"), 3, [4], BITRATE)
    attach_node(lab.board("board4"), 4, [3], BITRATE)
    for node in (3, 4):
        asked = subprocess.run([os.path.join(BIN, "dcos-flash"), "-i", f"lab:{lab.socket_path}:can0", "-n", str(node),
                                "--json", "info"], capture_output=True, text=True, timeout=TIMEOUT)
        assert asked.returncode == 0, asked.stderr
        info = json.loads(asked.stdout)
        assert info["node"] == node and info["slot_a"] == f"1.0.{node}", info
    # Only the node addressed answered each time.
    for board in ("board3", "board4"):
        counters = lab.board(board).command("flash")
        assert "  requests 1\r" in counters, counters
