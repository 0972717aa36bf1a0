"""The system engineering interface agent's management commands over CAN
(docs/protocols/config.md, "Objects and tasks", "Switching the bus's bit
rate"; docs/guide/configure.md): dcos-config on the lab's CAN bus against
running nodes booted from their cards, with an application whose image
declares a task for dcos-config to start more of
(tests_renode/config/manage_app). Each command is done and checked on the
node's console and through the protocol's own queries, and refused the way
the page says: unknown objects, a full table, a wrong type, an entry point
the image lacks, a kind the bus cannot create, a wrong key. A saved
configuration restores what was deleted and leaves the rest. Every frame
of the exchanges is decoded by the observer written from the page alone
(dcoslab/configwire.py).
"""
import re

import pytest

from dcoslab.cards import card_state, config_key, dcos_config, new_card, signed, signed_application
from dcoslab.configwire import read_wire

BITRATE = 1_000_000
# Bounds on a hung board or tool, not speeds.
TIMEOUT = 900
# The application is built once for the module's tests, so they share a worker.
pytestmark = pytest.mark.xdist_group("test_config_manage")


@pytest.fixture(scope="module")
def manage_image(tmp_path_factory):
    return signed_application(tmp_path_factory.mktemp("apps"), "tests_renode/config/manage_app")


def config(lab, *arguments, code=0):
    return dcos_config(lab, *arguments, code=code, timeout=TIMEOUT)


def node_card(tmp_path, name, image, serial, key, node, options=()):
    directory = tmp_path / name
    directory.mkdir()
    extra = ["--serial", str(serial), "--bitrate", str(BITRATE), "--config-key", key, *options]
    return new_card(directory, ("A", image, False), append=f"node={node}", options=tuple(extra))


def test_objects_and_tasks_are_listed_created_stopped_killed_deleted_saved_and_restored(canlab, tmp_path,
                                                                                     manage_image):
    key = config_key(tmp_path, "node")
    wrong = config_key(tmp_path, "wrong")
    card = node_card(tmp_path, "n", manage_image, 7007, key, 3)
    lab = canlab({"can0": BITRATE}, {"board1": {"bus0": "can0", "card": card}})
    board = lab.board("board1")
    lab.hub.wait_on_bus(["board1.0"], TIMEOUT)
    assert "application 'manage' started" in board.emulator.transcript, board.emulator.transcript
    node = ("-n", "3")

    # The application's objects, as every listing shows them.
    listed, _ = config(lab, "objects", *node)
    names = {(o["type"], o["name"]) for o in listed}
    assert {("task", "worker"), ("semaphore", "applock"), ("publisher", "level")} <= names, listed
    assert all(re.fullmatch(r"0x[0-9a-f]{8}", o["id"]) for o in listed), listed
    worker = next(o for o in listed if o["name"] == "worker")
    shown, _ = config(lab, "show", *node, worker["id"])
    assert (shown["type"], shown["name"], shown["base_priority"]) == ("task", "worker", 12), shown
    assert shown["stack_used"] > 0 and shown["stack_size"] >= shown["stack_used"], shown
    found, _ = config(lab, "find", *node, "semaphore", "applock")
    applock, _ = config(lab, "show", *node, "semaphore:applock")
    assert applock["id"] == found["id"] and applock["count"] == 1 and applock["settings"] == 0, applock
    stats, _ = config(lab, "stats", *node)
    assert stats["tables"]["task"]["used"] >= 3 and stats["task_switches"] > 0, stats
    assert stats["uptime_ns"] > 0 and stats["stack_free"] > 0, stats

    # A task of the image's entry point: started with its argument, stopped,
    # started again, killed.
    created, _ = config(lab, "task-create", *node, "-K", key, "worker", "w2", "--prio", "14", "--arg", "7")
    board.emulator.expect(r"worker 7: started", timeout=TIMEOUT)
    w2, _ = config(lab, "show", *node, created["id"])
    assert (w2["name"], w2["base_priority"], w2["state"] in ("ready", "blocked", "executing")) == ("w2", 14, True), w2
    config(lab, "task-stop", *node, "-K", key, "w2")
    assert config(lab, "show", *node, "task:w2")[0]["state"] == "suspended"
    config(lab, "task-start", *node, "-K", key, "w2")
    board.emulator.expect(r"worker 7: 50", timeout=TIMEOUT)
    config(lab, "task-kill", *node, "-K", key, "w2")
    _, errors = config(lab, "find", *node, "task", "w2", code=1)
    assert "kernel refused it: not found" in errors, errors
    _, errors = config(lab, "task-start", *node, "-K", key, created["id"], code=1)
    assert "kernel refused it: stale id" in errors, errors

    # The kernel's refusals, each said in its words.
    _, errors = config(lab, "task-create", *node, "-K", key, "nosuch", "x", code=1)
    assert "kernel refused it: not found" in errors, errors
    _, errors = config(lab, "task-stop", *node, "-K", key, found["id"], code=1)
    assert "kernel refused it: wrong object type" in errors, errors
    _, errors = config(lab, "create", *node, "-K", key, "pool", "p", code=1)
    assert "kernel refused it: not supported" in errors, errors
    _, errors = config(lab, "create", *node, "-K", key, "semaphore", "applock", code=1)
    assert "kernel refused it: already exists" in errors, errors
    _, errors = config(lab, "show", *node, "0x0003a7ff", code=1)
    assert "kernel refused it: invalid id" in errors or "stale id" in errors, errors
    _, errors = config(lab, "create", *node, "-K", wrong, "semaphore", "x", code=1)
    assert "refused the key" in errors, errors
    _, errors = config(lab, "create", *node, "semaphore", "x", code=2)
    assert "-K" in errors, errors

    # Objects made over the bus belong to the system and keep their settings.
    lock, _ = config(lab, "create", *node, "-K", key, "semaphore", "lock", "--counting", "--initial", "3",
                     "--visibility", "regional")
    shown, _ = config(lab, "show", *node, lock["id"])
    assert (shown["count"], shown["settings"], shown["visibility"], shown["owner"]) == (3, 1, "regional", "system")
    config(lab, "create", *node, "-K", key, "port", "inbox", "--fifo")
    saved = tmp_path / "node.toml"
    config(lab, "save", *node, str(saved))
    text = saved.read_text()
    assert "[node]\nserial = 7007" in text, text
    assert re.search(r"name = ['\"]lock['\"]", text) and re.search(r"name = ['\"]applock['\"]", text), text
    # The card names no node id (its command line's node=3 does), so neither does the file.
    assert re.search(r"^id = 0 ", text, re.M) and f"bit_rate = {BITRATE}" in text, text

    # Delete two, restore: they come back as they were, the rest is left alone.
    config(lab, "delete", *node, "-K", key, "semaphore:lock")
    config(lab, "delete", *node, "-K", key, "port:inbox")
    _, errors = config(lab, "show", *node, lock["id"], code=1)
    assert "stale id" in errors, errors
    # A task to start with the restore, and a table made too small for a
    # list of ports, so that it fills and AddObjects makes room.
    extra = "".join(f'\n[[port]]\nname = "p{i}"\n' for i in range(40))
    saved.write_text(text + '\n[[task]]\nname = "w3"\nentry = "worker"\npriority = 15\nargument = 9\n' + extra)
    _, errors = config(lab, "restore", *node, "-K", key, str(saved), code=1)
    assert "kernel refused it: object table full" in errors, errors
    board.emulator.expect(r"worker 9: started", timeout=TIMEOUT)
    restored, _ = config(lab, "show", *node, "semaphore:lock")
    assert (restored["count"], restored["settings"], restored["visibility"]) == (3, 1, "regional"), restored
    assert config(lab, "show", *node, "port:inbox")[0]["order_fifo"] == 1
    config(lab, "add-objects", *node, "-K", key, "port", "32")
    again, _ = config(lab, "restore", *node, "-K", key, str(saved))
    assert "semaphore lock" in again["present"] and "task w3" in again["present"], again
    assert "semaphore applock" in again["present"], again
    assert {item["object"] for item in again["created"]} <= {f"port p{i}" for i in range(40)}, again
    assert again["created"], again
    ports = [o for o in config(lab, "objects", *node, "port")[0] if re.fullmatch(r"p\d+", o["name"])]
    assert len(ports) == 40, ports

    # Every frame decodes by the page, and each change followed a challenge.
    wire = read_wire(lab.hub.frames())
    requests = [m for m in wire if m["direction"] == "request"]
    replies = [m for m in wire if m["direction"] == "reply"]
    assert {m["command"] for m in requests} >= {"ListObjects", "FindObject", "ObjectInfo", "NodeStatistics",
                                                "CreateTask", "StopTask", "StartTask", "KillTask", "CreateObject",
                                                "DeleteObject", "AddObjects", "SetConfiguration"}, requests
    assert {m["kernel_status"] for m in replies if m["status"] == "KernelRefused"} >= {3, 4, 13, 14, 18}, replies
    for index, message in enumerate(requests):
        if message["command"] in ("CreateTask", "StopTask", "StartTask", "KillTask", "CreateObject", "DeleteObject",
                                  "AddObjects", "SetConfiguration"):
            assert requests[index - 1]["command"] == "Challenge", requests[index - 1:index + 1]
    lab.close()
    assert card_state(card)["configuration"]["node"] == 0   # Restored as saved: none set.


def test_a_bit_rate_switch_takes_the_whole_bus_at_once(canlab, tmp_path):
    keys = {node: config_key(tmp_path, f"k{node}") for node in (1, 2)}
    image = signed(tmp_path, "1.0.0")
    cards = {node: node_card(tmp_path, f"n{node}", image, 8000 + node, keys[node], node) for node in (1, 2)}
    lab = canlab({"can0": BITRATE}, {f"board{node}": {"bus0": "can0", "card": cards[node]} for node in (1, 2)})
    lab.hub.wait_on_bus(["board1.0", "board2.0"], TIMEOUT)
    # A switch to the rate the nodes already run at changes nothing: no chip
    # is reset, and both still answer.
    config(lab, "switch-bitrate", "--delay-ms", "0")
    lab.hub.wait_until(lab.hub.now_ns + 50_000_000, TIMEOUT)
    for node in (1, 2):
        assert "switching to" not in lab.board(f"board{node}").emulator.transcript
        assert config(lab, "info", "-n", str(node))[0]["node"] == node
    for node in (1, 2):
        written, _ = config(lab, "set-bitrate", "-n", str(node), "-K", keys[node], "500000")
        assert written["bit_rate"] == 500000, written
    # Nothing changes on the bus until the switch.
    assert config(lab, "info", "-n", "2")[0]["configured_bit_rate"] == 500000
    config(lab, "switch-bitrate", "--delay-ms", "200")
    for node in (1, 2):
        lab.board(f"board{node}").emulator.expect(r"can0: switching to 500000 bit/s, as a configuration host asked",
                                                  timeout=TIMEOUT)
    # The hub logs each port's timing as it takes effect: both at 2,000 ns a
    # bit, at one moment, 200 ms after the announcement left.
    announced = [r for r in lab.hub.frames() if r.outcome == "ok" and r.frame.extended
                 and (r.frame.id >> 16) & 0xFF == 0x40 and list(r.frame.data[:2]) == [0x03, 0x23]]
    assert len(announced) == 2 and announced[0].frame.data[2:4] == b"\x00\x00", announced
    announced = announced[1:]
    # A wait's condition runs under the hub's lock, so the log is read after it.
    start = announced[0].end
    lab.hub.wait_until(start + 400_000_000, TIMEOUT)
    moments = {}
    for match in re.finditer(r"^# \d+ (board\d)\.0 \S+ from (\d+) ns: 2000 ns/bit", lab.hub.log_text(), re.M):
        if int(match.group(2)) > start:   # (a chip passes through other rates as it starts)
            moments.setdefault(match.group(1), int(match.group(2)))
    assert set(moments) == {"board1", "board2"}, lab.hub.log_text()[-3000:]
    assert all(start + 200_000_000 <= t <= start + 205_000_000 for t in moments.values()), (start, moments)
    assert abs(moments["board1"] - moments["board2"]) <= 2_000_000, moments
    # Off the 1 Mbit/s bus now: nobody answers there, as a real bus whose
    # adapter did not switch would find.
    config(lab, "--retries", "0", "--timeout-ms", "500", "info", "-n", "1", code=4)
    lab.close()
    for node in (1, 2):
        assert card_state(cards[node])["configuration"]["bitrate"] == 500000
