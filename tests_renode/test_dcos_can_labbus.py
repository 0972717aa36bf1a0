"""dcos-can on the lab's CAN bus hub (docs/protocols/labbus.md, "Joining from a host tool").

The hub runs in this process with no board: its clock follows the wall
clock. A Python participant (dcoslab.canbus.Client) plays the other node;
dcos-can must see its frames with their emulated times, and its own frames
must reach it.
"""

import json
import os
import subprocess
import tempfile

import pytest

from dcoslab.board import REPOSITORY
from dcoslab.canbus import Client, Frame, Hub

DCOS_CAN = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-can")
TIMEOUT = 60


@pytest.fixture
def hub():
    directory = tempfile.mkdtemp(prefix="dcos-labbus-")
    path = os.path.join(directory, "hub.sock")
    running = Hub(path, {"can0": 500_000, "can1": 125_000}).start()
    yield running
    running.stop()
    os.rmdir(directory) if not os.listdir(directory) else None


def tool(hub, *arguments, bus="can0"):
    return subprocess.Popen([DCOS_CAN, "-i", f"lab:{hub.socket_path}:{bus}", *arguments], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def wait_for_participants(hub, count, bus="can0"):
    """Until count tools have joined and attached a port to bus: a frame sent before a tool's
    port is on the bus is not one the tool can see."""
    hub.wait_for(lambda: len(hub.participants) >= count and len(hub.buses[bus].ports) >= count, TIMEOUT,
                 f"{count} participants on {bus}")


def annotations(lines):
    """The annotation after "  ; " on each line of a `dcos-can dump --decode` text."""
    return [line.split("  ; ", 1)[1] for line in lines.splitlines()]


def decoded_dumps(hub, frames):
    """Another node sends frames; what `dcos-can dump --decode` prints of them, in JSON and in text."""
    count = str(len(frames))
    dump = tool(hub, "--json", "dump", "-n", count, "-t", "30000", "--decode")
    text = tool(hub, "dump", "-n", count, "-t", "30000", "--decode")
    wait_for_participants(hub, 2)
    other = Client(hub.socket_path, "other")
    try:
        other.attach(0, "can0")
        for frame in frames:
            other.transmit(0, frame)
        output, errors = dump.communicate(timeout=TIMEOUT)
        lines, text_errors = text.communicate(timeout=TIMEOUT)
    finally:
        other.close()
    assert dump.returncode == 0, errors
    assert text.returncode == 0, text_errors
    return output, lines


def test_dump_shows_another_nodes_frames_with_emulated_times(hub):
    dump = tool(hub, "--json", "dump", "-n", "2", "-t", "30000", "--decode")
    wait_for_participants(hub, 1)
    other = Client(hub.socket_path, "other")
    try:
        assert other.attach(0, "can0") == 2000
        other.transmit(0, Frame(0x0320FF05, extended=True, dlc=2, data=bytes([1, 2])))
        other.transmit(0, Frame(0x123, dlc=0))
        output, errors = dump.communicate(timeout=TIMEOUT)
    finally:
        other.close()
    assert dump.returncode == 0, errors
    frames = [json.loads(line) for line in output.splitlines()]
    assert [(f["id"], f["extended"], f["data"]) for f in frames] == [(0x0320FF05, True, "0102"), (0x123, False, "")]
    assert all(f["emulated_time"] for f in frames)
    # The second frame starts after the first (extended, 2 bytes: 93 bits with intermission, 2 us each).
    assert frames[1]["timestamp_ns"] - frames[0]["timestamp_ns"] >= 52 * 2000, frames
    assert frames[0]["dcos"] == {"priority": 3, "type": "DSM publication", "source": 5, "destination": 255,
                                 "publication": {"malformed": "wrong length"}}


def test_dump_puts_publications_back_together(hub):
    # docs/protocols/publications.md's worked example: publisher index 0xA53,
    # sequence 0x5677, page 10..1F; a part out of turn; a withdrawal.
    example = [bytes.fromhex("3A53567710111213"), bytes.fromhex("7A53141516171819"),
               bytes.fromhex("BA531A1B1C1D1E1F")]
    frames = [Frame(0x0A20FF02, extended=True, dlc=len(data), data=data)
              for data in example + [example[2], bytes.fromhex("CA53")]]
    output, lines = decoded_dumps(hub, frames)
    publications = [json.loads(line)["dcos"]["publication"] for line in output.splitlines()]
    assert publications == [
        {"index": 0xA53, "part": 0, "sequence": 0x5677},
        {"index": 0xA53, "part": 1},
        {"index": 0xA53, "part": 2, "page": "101112131415161718191A1B1C1D1E1F", "page_sequence": 0x5677},
        {"index": 0xA53, "part": 2, "out_of_turn": True},
        {"index": 0xA53, "withdrawn": True},
    ]
    assert annotations(lines) == [
        "prio 10 DSM publication 2->all: publisher 0xa53 part 1/3 seq 22135",
        "prio 10 DSM publication 2->all: publisher 0xa53 part 2/3",
        "prio 10 DSM publication 2->all: publisher 0xa53 part 3/3 page 101112131415161718191A1B1C1D1E1F (seq 22135)",
        "prio 10 DSM publication 2->all: publisher 0xa53 part 3/3 out of turn",
        "prio 10 DSM publication 2->all: publisher 0xa53 withdrawn",
    ], lines


def test_dump_decodes_remote_transactions(hub):
    # docs/protocols/remote-transactions.md: a request, its pending and final
    # replies, and a request no node should send.
    output, lines = decoded_dumps(hub, [
        Frame(0x14110201, extended=True, dlc=8, data=bytes([1, 0x13, 0xA0, 0x05, 0, 0, 0, 200])),
        Frame(0x14100102, extended=True, dlc=8, data=bytes([1, 0x13, 0, 1, 0, 0, 0, 0])),
        Frame(0x14100102, extended=True, dlc=8, data=bytes([1, 0x13, 7, 0, 0, 0, 0, 0])),
        Frame(0x14110201, extended=True, dlc=3, data=bytes([9, 0x13, 0]))])
    remote = [json.loads(line)["dcos"]["remote"] for line in output.splitlines()]
    assert remote == [
        {"service": "acquire", "transaction": 0x13, "object": 0xA005, "argument": 200},
        {"service": "acquire", "transaction": 0x13, "status": "ok", "pending": True, "value": 0},
        {"service": "acquire", "transaction": 0x13, "status": "timed out", "pending": False, "value": 0},
        {"malformed": "wrong length"},
    ]
    assert annotations(lines) == [
        "prio 20 remote request 1->2: acquire txn 0x13 object 0xa005 argument 200",
        "prio 20 remote reply 2->1: acquire txn 0x13 ok pending value 0",
        "prio 20 remote reply 2->1: acquire txn 0x13 timed out value 0",
        "prio 20 remote request 1->2: malformed: wrong length",
    ], lines


def test_frames_dcos_can_sends_reach_another_node(hub):
    other = Client(hub.socket_path, "other")
    try:
        other.attach(0, "can0")
        send = tool(hub, "send", "123#DEADBEEF", "1ABCDEF0#R4")
        _, errors = send.communicate(timeout=TIMEOUT)
        assert send.returncode == 0, errors
        lines = other.events(lambda got: sum(line.startswith("RX ") for line in got) >= 2, TIMEOUT)
    finally:
        other.close()
    received = [line.split()[4:8] for line in lines if line.startswith("RX ")]
    assert received == [["123", "SD", "4", "deadbeef"], ["1abcdef0", "XR", "4", "-"]], lines


def test_stats_take_the_bit_rate_from_the_hub(hub):
    stats = tool(hub, "--json", "stats", "-s", "3", bus="can1")
    wait_for_participants(hub, 1, bus="can1")
    other = Client(hub.socket_path, "other")
    try:
        other.attach(0, "can1")
        for index in range(4):
            other.transmit(0, Frame(0x100 + index, dlc=8, data=bytes(8)))
        output, errors = stats.communicate(timeout=TIMEOUT)
    finally:
        other.close()
    assert stats.returncode == 0, errors
    result = json.loads(output)
    assert result["bit_rate"] == 125_000 and result["frames"] == 4, result


def test_an_unknown_bus_and_a_missing_hub_are_named(hub):
    refused = tool(hub, "dump", "-n", "1", bus="can7")
    _, errors = refused.communicate(timeout=TIMEOUT)
    assert refused.returncode == 4 and "refused bus 'can7'" in errors, errors
    missing = subprocess.run([DCOS_CAN, "-i", "lab:/nonexistent/hub.sock:can0", "dump"], capture_output=True,
                             text=True, timeout=TIMEOUT)
    assert missing.returncode == 3 and "no lab bus hub at /nonexistent/hub.sock" in missing.stderr, missing.stderr
    malformed = subprocess.run([DCOS_CAN, "-i", "lab:can0", "dump"], capture_output=True, text=True, timeout=TIMEOUT)
    assert malformed.returncode == 2 and "lab:<hub socket>:<bus>" in malformed.stderr, malformed.stderr


def test_a_frame_nobody_acknowledges_is_reported_not_lost_silently(hub):
    alone = tool(hub, "send", "--timeout-ms", "500", "123#01")
    _, errors = alone.communicate(timeout=TIMEOUT)
    assert alone.returncode == 1, errors
    assert "not on the lab bus within 500 ms" in errors and "acknowledge" in errors, errors


def test_stats_count_bus_errors_and_frames_with_a_bad_length(hub):
    """Corrupted frames and a DLC of 12 show as bus errors in dcos-can stats; the good frames are all counted."""
    stats = tool(hub, "--json", "stats", "-s", "4")
    wait_for_participants(hub, 1)
    other = Client(hub.socket_path, "other")
    try:
        other.attach(0, "can0")
        hub.corrupt("other.0", 2)
        for index in range(3):
            other.transmit(0, Frame.data_frame(0x200 + index, bytes([index] * 8)))
        hub.inject("can0", "lab", Frame(0x300, dlc=12, data=bytes(range(8))))
        output, errors = stats.communicate(timeout=TIMEOUT)
    finally:
        other.close()
    assert stats.returncode == 0, errors
    result = json.loads(output)
    corrupted = [r for r in hub.frames() if r.outcome == "form-error"]
    assert len(corrupted) == 2, hub.log_text()
    # The three frames and the one of DLC 12 went through; the tool counts the three and drops the fourth.
    assert result["frames"] == 3, result
    assert result["events"] == {"bus-error": 3}, result
    assert result["state"] == "error-active", result


def test_dump_decodes_name_queries(hub):
    # docs/protocols/remote-transactions.md, "Names": node 1 asks every node
    # for the semaphore "pump"; node 2 answers with its id; a query part
    # for a type without names.
    output, lines = decoded_dumps(hub, [
        Frame(0x1812FF01, extended=True, dlc=8, data=bytes([0x0A, 0x10]) + b"pump\0\0"),
        Frame(0x1812FF01, extended=True, dlc=8, data=bytes([0x4A, 0x10, 0, 0, 0, 0, 0, 0])),
        Frame(0x1812FF01, extended=True, dlc=8, data=bytes([0x8A, 0x10, 0, 0, 0, 0, 0, 0])),
        Frame(0x18100102, extended=True, dlc=8, data=bytes([10, 0x10, 0, 0, 0x00, 0x02, 0xA0, 0x01])),
        Frame(0x1812FF01, extended=True, dlc=8, data=bytes([0x09, 0x11]) + b"abcdef")])
    decoded = [json.loads(line)["dcos"] for line in output.splitlines()]
    assert decoded[0]["name_query"] == {"type": "semaphore", "part": 0, "transaction": 0x10, "name_bytes": "pump"}
    assert decoded[3]["remote"] == {"service": "name", "transaction": 0x10, "status": "ok", "pending": False,
                                    "value": 0x0002A001}
    assert decoded[4]["name_query"] == {"malformed": "no such object type"}
    notes = annotations(lines)
    assert notes[:2] == ['prio 24 name query 1->all: semaphore part 1/3 txn 0x10 "pump"',
                               'prio 24 name query 1->all: semaphore part 2/3 txn 0x10 ""'], lines


def test_dump_decodes_a_port_send(hub):
    # docs/protocols/remote-transactions.md, "Port sends": node 1 sends node
    # 2's port 0x7123 sixteen bytes E0..EF at priority -3, transaction 0x5B.
    output, lines = decoded_dumps(hub, [
        Frame(0x14110201, extended=True, dlc=8, data=bytes([11, 0x5B, 0x71, 0x23, 0xFD, 0xE0, 0xE1, 0xE2])),
        Frame(0x14110201, extended=True, dlc=8, data=bytes([0x9B]) + bytes(range(0xE3, 0xEA))),
        Frame(0x14110201, extended=True, dlc=7, data=bytes([0xAB]) + bytes(range(0xEA, 0xF0))),
        Frame(0x14110201, extended=True, dlc=8, data=bytes([0xCB]) + bytes(7))])
    remote = [json.loads(line)["dcos"]["remote"] for line in output.splitlines()]
    assert remote == [
        {"service": "port-send", "transaction": 0x5B, "object": 0x7123, "argument": 0xFDE0E1E2},
        {"service": "port-send", "part": 1, "slot": 0xB},
        {"service": "port-send", "part": 2, "slot": 0xB},
        {"malformed": "unknown service"},
    ]
    notes = annotations(lines)
    assert notes[1:3] == ["prio 20 remote request 1->2: port-send part 2/3 slot 11",
                                "prio 20 remote request 1->2: port-send part 3/3 slot 11"], lines


def test_dump_decodes_a_routed_request(hub):
    # docs/protocols/remote-transactions.md, "Gateways": node 1 asks gateway
    # 2 to count node 3's semaphore 0xa001: a route header, then the request.
    output, lines = decoded_dumps(hub, [
        Frame(0x14130201, extended=True, dlc=4, data=bytes([0xC4, 0x21, 0x00, 0x03])),
        Frame(0x14130201, extended=True, dlc=8, data=bytes([3, 0x21, 0xA0, 0x01, 0, 0, 0, 0])),
        Frame(0x14130201, extended=True, dlc=4, data=bytes([0xC0, 0x21, 0x00, 0x03]))])
    remote = [json.loads(line)["dcos"]["remote"] for line in output.splitlines()]
    assert remote == [
        {"route_to": 3, "hops_left": 4, "transaction": 0x21},
        {"service": "count", "transaction": 0x21, "object": 0xA001, "argument": 0},
        {"malformed": "reserved bits set"},
    ]
    notes = annotations(lines)
    assert notes[0] == "prio 20 routed request 1->2: route to node 3 hops 4 txn 0x21", lines


def test_dump_decodes_the_global_time_base(hub):
    # docs/protocols/time.md: node 1's Sync (sequence 5, second 0x12_3456_789A,
    # rank 3, every 2.5 s), its FollowUp, a probe and a Sync with a bad rank.
    output, lines = decoded_dumps(hub, [
        Frame(0x0001FF01, extended=True, dlc=8, data=bytes([0x05, 0x12, 0x34, 0x56, 0x78, 0x9A, 0x03, 25])),
        Frame(0x0001FF01, extended=True, dlc=8, data=bytes([0x45, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77])),
        Frame(0x0001FF64, extended=True, dlc=1, data=bytes([0x89])),
        Frame(0x0001FF01, extended=True, dlc=8, data=bytes([0x06, 0, 0, 0, 0, 1, 0x10, 10]))])
    decoded = [json.loads(line)["dcos"]["time"] for line in output.splitlines()]
    assert decoded == [
        {"kind": "sync", "sequence": 5, "seconds": 0x123456789A, "rank": 3, "interval_ms": 2500},
        {"kind": "follow-up", "sequence": 5, "nanoseconds_low56": 0x11223344556677},
        {"kind": "probe", "sequence": 9},
        {"malformed": "bad rank"},
    ]
    assert annotations(lines) == [
        "prio 0 time sync 1->all: sync seq 5 second 78187493530 rank 3 every 2500 ms",
        "prio 0 time sync 1->all: follow-up seq 5 ns-low56 4822678189205111",
        "prio 0 time sync 100->all: probe seq 9",
        "prio 0 time sync 1->all: malformed: bad rank",
    ], lines


def test_dump_decodes_a_held_acquire(hub):
    # docs/protocols/remote-transactions.md, "Binary semaphores": node 1's
    # task 0x00011002 acquires node 2's binary semaphore 0xA004 waiting up to
    # 250 ms, transaction 0x35; then releases it; a holder part whose last
    # bytes are not zero.
    output, lines = decoded_dumps(hub, [
        Frame(0x18110201, extended=True, dlc=8, data=bytes([12, 0x35, 0xA0, 0x04, 0, 0, 0, 0xFA])),
        Frame(0x18110201, extended=True, dlc=8, data=bytes([0xB5, 0x00, 0x01, 0x10, 0x02, 0, 0, 0])),
        Frame(0x18110201, extended=True, dlc=8, data=bytes([13, 0x36, 0xA0, 0x04, 0x00, 0x01, 0x10, 0x02])),
        Frame(0x18110201, extended=True, dlc=8, data=bytes([0xB5, 0x00, 0x01, 0x10, 0x02, 0, 0, 1]))])
    remote = [json.loads(line)["dcos"]["remote"] for line in output.splitlines()]
    assert remote == [
        {"service": "held-acquire", "transaction": 0x35, "object": 0xA004, "argument": 250},
        {"service": "held-acquire", "part": 3, "slot": 5, "holder": 0x00011002},
        {"service": "held-release", "transaction": 0x36, "object": 0xA004, "argument": 0x00011002},
        {"malformed": "reserved bits set"},
    ], remote
    notes = annotations(lines)
    assert notes[1] == "prio 24 remote request 1->2: held-acquire holder 0x00011002 slot 5", lines


def test_dump_decodes_an_alarm_and_tells_its_parts_from_a_port_sends(hub):
    # docs/protocols/remote-transactions.md, "Timers": node 1's task
    # 0x00011002 sets a periodic alarm of 100 ms (flags 0x03, events 0x8) on
    # node 2's timer 0x3001, transaction 0x27: laid out as a port send, so the
    # dump names the parts by the request they continue.
    record = bytes.fromhex("00011002" "00000008") + (100_000_000).to_bytes(8, "big")
    output, lines = decoded_dumps(hub, [
        Frame(0x18110201, extended=True, dlc=8, data=bytes([14, 0x27, 0x30, 0x01, 0x03]) + record[0:3]),
        Frame(0x18110201, extended=True, dlc=8, data=bytes([0x97]) + record[3:10]),
        Frame(0x18110201, extended=True, dlc=7, data=bytes([0xA7]) + record[10:16]),
        Frame(0x18110201, extended=True, dlc=8, data=bytes([15, 0x28, 0x30, 0x01, 0x00, 0x01, 0x10, 0x02]))])
    remote = [json.loads(line)["dcos"]["remote"] for line in output.splitlines()]
    assert remote == [
        {"service": "set-alarm", "transaction": 0x27, "object": 0x3001, "argument": 0x03000110},
        {"service": "set-alarm", "part": 1, "slot": 7},
        {"service": "set-alarm", "part": 2, "slot": 7},
        {"service": "cancel-alarm", "transaction": 0x28, "object": 0x3001, "argument": 0x00011002},
    ], remote
    notes = annotations(lines)
    assert notes[2] == "prio 24 remote request 1->2: set-alarm part 3/3 slot 7", lines


def test_dump_decodes_a_relayed_publication(hub):
    # docs/protocols/publications.md, "Across a gateway": gateway node 2
    # relays node 3's publisher 0xA53 onto this bus, each frame behind a
    # relay header naming node 3; a relayed frame without its header.
    page = bytes(range(0x10, 0x20))
    parts = [bytes([0x3A, 0x53, 0x56, 0x77]) + page[0:4], bytes([0x7A, 0x53]) + page[4:10],
             bytes([0xBA, 0x53]) + page[10:16]]
    header = bytes([0xFF, 0, 0, 3])
    frames = []
    for part in parts:
        frames += [Frame(0x0A21FF02, extended=True, dlc=4, data=header),
                   Frame(0x0A21FF02, extended=True, dlc=8, data=part)]
    frames.append(Frame(0x0A21FF02, extended=True, dlc=8, data=parts[0]))
    output, lines = decoded_dumps(hub, frames)
    decoded = [json.loads(line)["dcos"]["publication"] for line in output.splitlines()]
    assert decoded[0] == {"relay_node": 3}
    assert decoded[1] == {"index": 0xA53, "part": 0, "sequence": 0x5677, "node": 3}
    assert decoded[5]["page"] == page.hex().upper() and decoded[5]["node"] == 3, decoded[5]
    assert decoded[6] == {"malformed": "relayed frame without its header"}
    notes = annotations(lines)
    assert notes[0] == "prio 10 relayed publication 2->all: relay header: node 3", lines


def test_dump_decodes_a_nodes_announcement_that_it_started(hub):
    # docs/protocols/remote-transactions.md, "A node that starts again":
    # node 2's announcement to every node, then one with a byte past the id
    # set and one naming no node, which no node sends.
    output, lines = decoded_dumps(hub, [
        Frame(0x1F14FF02, extended=True, dlc=8, data=bytes([0, 2, 0, 0, 0, 0, 0, 0])),
        Frame(0x1F14FF02, extended=True, dlc=8, data=bytes([0, 2, 0, 0, 0, 0, 0, 9])),
        Frame(0x1F14FF02, extended=True, dlc=8, data=bytes(8))])
    decoded = [json.loads(line)["dcos"]["node_started"] for line in output.splitlines()]
    assert decoded == [{"node": 2}, {"malformed": "reserved bits set"}, {"malformed": "unknown node"}]
    assert annotations(lines) == [
        "prio 31 node started 2->all: node 2 started",
        "prio 31 node started 2->all: malformed: reserved bits set",
        "prio 31 node started 2->all: malformed: unknown node",
    ], lines
