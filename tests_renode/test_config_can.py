"""Configuring controllers over CAN (docs/protocols/config.md,
docs/guide/configure.md): dcos-config on the lab's CAN bus against the
system engineering interface agent of running nodes, each booted from its
own card (dcos-card with a serial number, a configuration key and the bus's
bit rate, so that it is on the network from boot), on a 1 Mbit/s lab bus in
exact time.
"""
import re

from dcoslab.cards import new_card, signed, card_state, config_key, dcos_config
from dcoslab.configwire import read_wire

BITRATE = 1_000_000
# Generous: bounds on a hung board or tool, not speeds. The probe wait is
# wall time on the host, so it is long enough for a busy machine.
TIMEOUT = 900
PROBE_MS = "500"


def config(lab, *arguments, code=0):
    return dcos_config(lab, *arguments, code=code, probe_ms=PROBE_MS, timeout=TIMEOUT)


def node_card(tmp_path, name, serial, key=None, append="", options=()):
    directory = tmp_path / name
    directory.mkdir()
    extra = ["--serial", str(serial), "--bitrate", str(BITRATE), *options]
    if key is not None:
        extra += ["--config-key", key]
    return new_card(directory, ("A", signed(directory, "1.0.0"), False), append=append, options=tuple(extra))


def test_two_fresh_nodes_sharing_a_number_are_found_by_serial_and_one_is_renumbered(canlab, tmp_path):
    keys = {serial: config_key(tmp_path, f"node-{serial}") for serial in (1001, 2002)}
    cards = {serial: node_card(tmp_path, f"n{serial}", serial, keys[serial]) for serial in keys}
    lab = canlab({"can0": BITRATE}, {"board1": {"bus0": "can0", "card": cards[1001]},
                                     "board2": {"bus0": "can0", "card": cards[2002]}})
    lab.hub.wait_on_bus(["board1.0", "board2.0"], TIMEOUT)
    # Both run as node 1, CAN node 1: only their serial numbers tell them apart.
    found, _ = config(lab, "scan")
    assert [(n["serial"], n["node"], n["can_node"], n["board"], n["key"], n["queries"]) for n in found] == [
        (1001, 1, 1, "isa486", True, "open"), (2002, 1, 1, "isa486", True, "open")], found
    # The second becomes node 2, with its own key; the first's key is refused there.
    _, errors = config(lab, "set-node", "--serial", "2002", "-K", keys[1001], "2", code=1)
    assert "refused the key" in errors, errors
    written, _ = config(lab, "set-node", "--serial", "2002", "-K", keys[2002], "2")
    assert written["node_id"] == 2 and written["sequence"] == 2, written
    info, _ = config(lab, "info", "--serial", "2002")
    assert info["node"] == 1 and info["configured_node"] == 2, info   # At the next start.
    assert info["configuration"]["node"] == 2 and info["configuration"]["bit_rate"] == BITRATE, info
    restarted, _ = config(lab, "restart", "--serial", "2002", "-K", keys[2002])
    assert restarted["restarted"] is True, restarted
    board2 = lab.board("board2")
    board2.emulator.expect(r"sei: restarting, as a configuration host asked", timeout=TIMEOUT)
    board2.emulator.expect(r"command line: node=2 can0=1000000 boot\.slot=A", timeout=TIMEOUT)
    board2.emulator.expect(r"can0 carries interface 0: 130\.1\.0\.2/16, CAN node 2", timeout=TIMEOUT)
    lab.hub.wait_on_bus(["board2.0"], TIMEOUT)
    # Now each answers at its own number, and a scan says so.
    for node, serial in ((1, 1001), (2, 2002)):
        info, _ = config(lab, "info", "-n", str(node))
        assert (info["node"], info["serial"], info["can_node"]) == (node, serial, node), info
    found, _ = config(lab, "scan")
    assert [(n["serial"], n["node"]) for n in found] == [(1001, 1), (2002, 2)], found
    # Every frame on the bus, read by an observer written from the protocol's
    # page: each decodes, and the exchanges are what the tool says it did.
    wire = read_wire(lab.hub.frames())
    requests = [m for m in wire if m["direction"] == "request"]
    replies = [m for m in wire if m["direction"] == "reply"]
    assert {m["command"] for m in requests} >= {"ProbeSerial", "Select", "Deselect", "Identify", "Challenge",
                                                "SetNodeId", "Restart"}, requests
    assert [m["status"] for m in replies if m["command"] == "SetNodeId"] == ["BadMac", "Ok"], replies
    assert [m["node_id"] for m in requests if m["command"] == "SetNodeId"] == [2, 2], requests
    # Addressed by serial number: the selected node answered from the broadcast address.
    assert {m["source"] for m in replies if m["command"] in ("SetNodeId", "Restart", "Select")} == {255}, replies
    assert all(m["status"] == "Ok" for m in replies if m["command"] == "ProbeSerial")
    # Each signed request followed a challenge to the same address.
    for index, message in enumerate(requests):
        if message["command"] in ("SetNodeId", "Restart"):
            earlier = [m for m in requests[:index] if m["destination"] == message["destination"]]
            assert earlier and earlier[-1]["command"] == "Challenge", requests[:index + 1]
    lab.close()
    assert card_state(cards[2002])["configuration"]["node"] == 2
    assert card_state(cards[1001])["configuration"]["node"] == 0


def test_wrong_keys_lock_a_node_out_and_the_lockout_ends(canlab, tmp_path):
    key = config_key(tmp_path, "right")
    wrong = config_key(tmp_path, "wrong")
    card = node_card(tmp_path, "n", 3003, key, append="node=3", options=("--lockout", "3"))
    lab = canlab({"can0": BITRATE}, {"board1": {"bus0": "can0", "card": card}})
    lab.hub.wait_on_bus(["board1.0"], TIMEOUT)
    board = lab.board("board1")
    for _ in range(3):
        _, errors = config(lab, "set-bitrate", "-n", "3", "-K", wrong, "500000", code=1)
        assert "refused the key" in errors, errors
    # Locked out: even the right key is refused now, and the node says why.
    _, errors = config(lab, "set-bitrate", "-n", "3", "-K", key, "500000", code=1)
    assert "locked out" in errors, errors
    status = board.command("sei")
    assert "sei: serial 3003, configuration key set, queries open" in status, status
    assert re.search(r"sei: locked out for \d s after 3 wrong keys", status), status
    assert "  bad-macs 0" in status, status   # The count starts again after a lockout.
    info, _ = config(lab, "info", "-n", "3")  # Queries stay open.
    assert info["locked_out"] is True and info["configuration"]["bit_rate"] == BITRATE, info
    # Three seconds of the node's time later the lockout has ended.
    lab.hub.wait_until(lab.hub.now_ns + 3_500_000_000, TIMEOUT)
    written, _ = config(lab, "set-bitrate", "-n", "3", "-K", key, "500000")
    assert written["bit_rate"] == 500000, written
    statuses = [(m["command"], m["status"]) for m in read_wire(lab.hub.frames()) if m["direction"] == "reply"
                and m["command"] in ("Challenge", "SetBitRate")]
    assert statuses[-2:] == [("Challenge", "Ok"), ("SetBitRate", "Ok")], statuses
    assert ("SetBitRate", "BadMac") in statuses and ("Challenge", "LockedOut") in statuses, statuses
    # A rate the chip cannot make is refused after the key is checked, and nothing is written.
    _, errors = config(lab, "set-bitrate", "-n", "3", "-K", key, "12345", code=1)
    assert "12345" in errors or "cannot" in errors, errors
    lab.close()
    assert card_state(card)["configuration"]["bitrate"] == 500000


def test_a_node_without_a_key_changes_nothing_and_closed_queries_need_the_key(canlab, tmp_path):
    key = config_key(tmp_path, "k")
    open_card = node_card(tmp_path, "a", 4004, None, append="node=4")
    closed_card = node_card(tmp_path, "b", 5005, key, append="node=5", options=("--closed-queries",))
    lab = canlab({"can0": BITRATE}, {"board4": {"bus0": "can0", "card": open_card},
                                     "board5": {"bus0": "can0", "card": closed_card}})
    lab.hub.wait_on_bus(["board4.0", "board5.0"], TIMEOUT)
    _, errors = config(lab, "set-node", "-n", "4", "-K", key, "9", code=1)
    assert "holds no configuration key" in errors, errors
    _, errors = config(lab, "info", "-n", "5", code=2)
    assert "-K" in errors, errors
    info, _ = config(lab, "info", "-n", "5", "-K", key)
    assert info["queries"] == "closed" and info["configuration"]["node"] == 0, info
    # Nobody at a number: silence, exit 4.
    _, errors = config(lab, "--retries", "1", "--timeout-ms", "500", "info", "-n", "77", code=4)
    # A node id set over the bus wins over the "node=" the card was made with.
    config(lab, "set-node", "-n", "5", "-K", key, "6")
    config(lab, "restart", "-n", "5", "-K", key)
    board5 = lab.board("board5")
    board5.emulator.expect(r"command line: node=6 can0=1000000 node=5 boot\.slot=A", timeout=TIMEOUT)
    board5.emulator.expect(r"can0 carries interface 0: 130\.1\.0\.6/16, CAN node 6", timeout=TIMEOUT)
    lab.close()
    assert card_state(open_card)["configuration"]["node"] == 0
