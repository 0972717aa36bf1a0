"""Remote transactions (dissertation 6.4, Fig. 6.3) between emulated 486 boards on the lab's CAN bus.

Two boards, node 1 and node 2, each with its CAN channel 0 on the lab bus
can0 and attached to the network interfaces manager as interface 0. The
test image's `remote` console command (tests_renode/target/
RemoteTransactionsTest.cpp) calls a primitive by id; given the id of an
object on the other board, the primitive goes over the bus as a remote
transaction (docs/protocols/remote-transactions.md). Each test compares
what the remote call answers with what the same call answers locally, and
reads the bus log for the frames it cost.

Times are emulated (-icount, the hub's timing model); every wait has a
generous time-out that bounds a hung board, not a speed.
"""

import json
import os
import re
import subprocess
import sys

import pytest

from dcoslab import remote
from dcoslab.canbus import Frame
from dcoslab.remote import NODE_STARTED, REPLY, REQUEST, SEMAPHORE_SEQUENCE, attach_node, created, dcos_frames, \
    net_counters, semaphore_sequence

BIT_RATE = 500_000
WATCHDOG_MS = 50       # DCOS_CONFIG_REMOTE_WATCHDOG_MS
SILENT_PERIODS = 4     # DCOS_CONFIG_REMOTE_SILENT_PERIODS


@pytest.fixture
def pair(canlab):
    lab = canlab({"can0": BIT_RATE}, {"board1": {"bus0": "can0", "append": "node=1"},
                                      "board2": {"bus0": "can0", "append": "node=2"}})
    one, two = lab.board("board1"), lab.board("board2")
    attach_node(one, 1, [2], BIT_RATE)
    attach_node(two, 2, [1], BIT_RATE)
    return lab, one, two


def call(board, line):
    """A `remote` primitive's (status, value, milliseconds)."""
    status, value, us = remote.call(board, line)
    return status, value, us / 1000


def test_a_remote_counting_semaphore_answers_as_a_local_one(pair):
    lab, one, two = pair
    # One semaphore on node 2 used from node 1, its twin used on node 2 itself.
    remote_semaphore, far = semaphore_sequence(one, two)
    assert remote_semaphore.startswith("0x0002")
    assert [value for _, value, _ in far][::8] == [1, 2]
    # The 200 ms wait was the serving node's, and the answer came after it.
    assert 200 <= far[4][2] / 1000 < 200 + SILENT_PERIODS * WATCHDOG_MS
    # Fixed-size primitives: one request frame and one final reply per call,
    # plus the keep-alives of the 200 ms wait (a retransmission, a pending reply).
    requests, replies = dcos_frames(lab, REQUEST), dcos_frames(lab, REPLY)
    statistics = net_counters(one)
    assert statistics["requests"] == len(SEMAPHORE_SEQUENCE)
    assert statistics["replies"] == len(SEMAPHORE_SEQUENCE)
    assert len(requests) == len(SEMAPHORE_SEQUENCE) + statistics["retransmissions"]
    assert len(replies) == len(SEMAPHORE_SEQUENCE) + statistics["pending-replies"]
    assert statistics["pending-replies"] >= 1 and statistics["unreachable"] == 0
    # Every request went from CAN node 1 to 2, every reply back, 8 bytes each.
    assert {(destination, source, len(data)) for _, destination, source, data in requests} == {(2, 1, 8)}
    assert {(destination, source, len(data)) for _, destination, source, data in replies} == {(1, 2, 8)}
    assert net_counters(two)["duplicates"] == statistics["retransmissions"]
    assert net_counters(two)["served"] == len(SEMAPHORE_SEQUENCE)


def test_a_remote_acquire_waits_for_a_release_on_the_serving_node(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 0", "RSEM")
    sleeper = created(two, "remote sem 0", "RSEM")
    one.emulator.send(f"remote acquire {semaphore} 5000\r")
    # Once the request is on the bus, node 2 waits 300 ms of its own time, then releases.
    lab.hub.wait_for_records(lambda records: dcos_frames(lab, REQUEST, records), 120, "node 1's request")
    assert call(two, f"acquire {sleeper} 300")[0] == "timed out"
    assert call(two, f"release {semaphore}")[0] == "ok"
    match = one.emulator.expect(r"RRES (.+) (\d+) (\d+)\r\n", timeout=120)
    one.emulator.expect(r"dcos> ")
    assert match.group(1) == b"ok"
    assert 300_000 <= int(match.group(3)) < 5_000_000
    assert call(two, f"count {semaphore}")[:2] == ("ok", 0)
    statistics = net_counters(one)
    # The wait was kept alive: at least one retransmission answered as pending.
    assert statistics["pending-replies"] >= 300 // WATCHDOG_MS - 2
    assert statistics["unreachable"] == 0


def test_events_and_signals_reach_a_task_on_another_node(pair):
    lab, one, two = pair
    listener = created(two, "remote listener", "RTASK")
    assert call(one, f"post {listener} 0x5")[:2] == ("ok", 0)
    assert call(one, f"signal {listener} 3")[:2] == ("ok", 0)
    assert call(one, f"post {listener} 0")[0] == "invalid argument"  # refused before it leaves node 1
    assert call(one, f"signal {listener} 40")[0] == "invalid argument"  # refused by node 2
    # A signal is delivered when its task next runs (dissertation 7.6.1): the
    # next event wakes the listener, and its handler runs first.
    assert call(one, f"post {listener} 0x10")[:2] == ("ok", 0)
    got = two.command("remote got")
    assert "RGOT 0x15 0x8" in got, got


def test_a_task_and_a_semaphore_of_another_node_can_be_read(pair):
    lab, one, two = pair
    listener = created(two, "remote listener", "RTASK")
    binary = created(two, "remote sem binary", "RSEM")
    assert call(two, f"acquire {binary} 0")[0] == "ok"  # held by node 2's console task
    holder = call(two, f"holder {binary}")[:2]
    assert holder[0] == "ok" and holder[1] >> 16 == 2
    # Each read gives the value the same call gives on node 2 itself.
    for line in (f"state {listener}", f"priority {listener}", f"holder {binary}"):
        assert call(one, line)[:2] == call(two, line)[:2], line
    assert call(one, f"priority {listener}")[:2] == ("ok", 10)
    assert call(one, f"state {listener}")[:2] == ("ok", 4)  # TaskState::Blocked, in its ReceiveEvent


def test_errors_come_back_as_the_local_call_gives_them(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 1", "RSEM")
    never_issued = "0x%08x" % (int(semaphore, 16) + 0x100)
    assert call(one, f"count {never_issued}")[0] == call(two, f"count {never_issued}")[0] == "invalid id"
    wrong_type = "0x0002" + "1" + semaphore[7:]  # a task id of node 2 that was never handed out
    assert call(one, f"release {wrong_type}")[0] == call(two, f"release {wrong_type}")[0]
    # A binary semaphore is released only by its holder, here as on node 2.
    binary = created(two, "remote sem binary", "RSEM")
    assert call(one, f"release {binary}")[0] == call(two, f"release {binary}")[0] == "not owner"
    # A node the tables do not know.
    assert call(one, "count 0x0007" + semaphore[6:])[0] == "remote object unreachable"


def test_a_pool_or_heap_of_a_node_across_the_bus_is_refused_without_a_frame(pair):
    """A buffer or segment is memory of its node (seed 7.7, 7.8): over CAN nobody can address it, so the call is
    refused on the caller's node at once, before anything is sent (docs/protocols/remote-transactions.md)."""
    lab, one, two = pair
    pool = created(two, "remote pool", "RPOOL")
    heap = created(two, "remote heap", "RHEAP")
    before = len(dcos_frames(lab, REQUEST))
    assert call(one, f"alloc {pool}")[:2] == ("not supported", 0)
    assert call(one, f"free {pool} 1048576")[0] == "not supported"
    assert call(one, f"halloc {heap} 64")[:2] == ("not supported", 0)
    assert call(one, f"hfree {heap} 1048576")[0] == "not supported"
    assert len(dcos_frames(lab, REQUEST)) == before
    # On its own node the pool works as ever.
    status, buffer, _ = call(two, f"alloc {pool}")
    assert status == "ok" and call(two, f"free {pool} {buffer}")[0] == "ok"


def test_a_dead_node_gives_unreachable_within_the_watchdog_and_node_1_carries_on(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 1", "RSEM")
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)
    output = two.command("can down can0")
    assert "error:" in output  # an attached channel is not taken down under the network
    assert "error:" not in two.command("can detach can0")
    status, _, ms = call(one, f"acquire {semaphore} 10000")
    assert status == "node unreachable"
    assert SILENT_PERIODS * WATCHDOG_MS <= ms < (SILENT_PERIODS + 2) * WATCHDOG_MS
    assert net_counters(one)["unreachable"] == 1
    # Node 1 is unharmed: its own objects work, and node 2 serves again once attached.
    local = created(one, "remote sem 1", "RSEM")
    assert call(one, f"acquire {local} 0")[0] == "ok"
    assert "carries interface 0" in two.command("can attach can0")
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)


def test_a_duplicated_request_is_answered_but_not_executed_again(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 0", "RSEM")
    index = int(semaphore, 16) & 0xFFFF
    # A release request "from CAN node 1" with a transaction node 1 has not
    # begun, put on the bus twice by a hub node, as a retransmission would be.
    identifier = (8 << 24) | (REQUEST << 16) | (2 << 8) | 1
    request = bytes([2, 0xF7, index >> 8, index & 0xFF, 0, 0, 0, 0])
    for sent in (1, 2):
        lab.hub.inject("can0", "injector", Frame.data_frame(identifier, request, extended=True))
        lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, REPLY, records)) >= sent, 60, "the reply")
    # And a request of 3 bytes, which no node sends.
    lab.hub.inject("can0", "injector", Frame.data_frame(identifier, request[:3], extended=True))
    lab.hub.wait_for_records(lambda records: any(len(data) == 3 for _, _, _, data in dcos_frames(lab, REQUEST, records)),
                             60, "the short request")
    # The hub logs a frame when it ends; the boards may not have reached that
    # time yet. 2 ms later node 2's receiver has surely taken it.
    lab.hub.wait_until(lab.hub.frames()[-1].end + 2_000_000, 60)
    assert call(two, f"count {semaphore}")[:2] == ("ok", 1)  # released once
    served = net_counters(two)
    assert served["served"] == 1 and served["duplicates"] == 1 and served["malformed"] == 1
    replies = dcos_frames(lab, REPLY)
    assert len(replies) == 2 and replies[0][3] == replies[1][3] == bytes([2, 0xF7, 0, 0, 0, 0, 0, 0])
    # Node 1 had no such transaction: both replies are stray, and nothing else changed.
    assert net_counters(one)["stray-replies"] == 2


def test_a_transaction_number_met_again_in_a_new_request_is_performed(pair):
    """A node that restarts numbers its first transactions as it did after
    its last boot, so node 2 may still hold a finished entry of the same
    caller slot and number. Only an exact repetition heard while its
    requester can still be waiting for the reply is a retransmission; the
    same number in another request, or in the same request later than that,
    is a new transaction and is performed."""
    lab, one, two = pair
    first = created(two, "remote sem 0", "RSEM")
    second = created(two, "remote sem 0", "RSEM")
    identifier = (8 << 24) | (REQUEST << 16) | (2 << 8) | 1

    def release(semaphore):
        index = int(semaphore, 16) & 0xFFFF
        return bytes([2, 0xF7, index >> 8, index & 0xFF, 0, 0, 0, 0])

    def inject(request):
        replies = len(dcos_frames(lab, REPLY))
        lab.hub.inject("can0", "injector", Frame.data_frame(identifier, request, extended=True))
        lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, REPLY, records)) > replies, 60, "the reply")

    inject(release(first))
    inject(release(second))  # Transaction 0xF7 again, another semaphore: a new request.
    inject(release(second))  # At once, exactly as before: a retransmission.
    assert call(two, f"count {first}")[:2] == ("ok", 1)
    assert call(two, f"count {second}")[:2] == ("ok", 1)
    served = net_counters(two)
    assert served["served"] == 2 and served["duplicates"] == 1
    # The same request once its requester would long have given up on the
    # reply (twice its silence of 4 watchdog periods): a new transaction.
    lab.hub.wait_until(lab.hub.now_ns + 2 * (SILENT_PERIODS + 1) * WATCHDOG_MS * 1_000_000, 60)
    inject(release(second))
    assert call(two, f"count {second}")[:2] == ("ok", 2)
    served = net_counters(two)
    assert served["served"] == 3 and served["duplicates"] == 1


def test_a_request_runs_at_the_requesters_priority_on_the_serving_node(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 1", "RSEM")
    results = {}
    for priority in (20, 2):
        # A local task of priority 5 keeps node 2 busy for 1 s.
        two.emulator.send("remote hog 5 1000\r")
        two.emulator.expect(r"remote hog 5 1000\r\n")
        results[priority] = call(one, f"count at={priority} {semaphore}")
        two.emulator.expect(r"RHOG (\d+)\r\n", timeout=120)
        two.emulator.expect(r"dcos> ")
    # Less urgent than the busy task: served only when it is done.
    assert results[20][:2] == ("ok", 1) and results[20][2] >= 500
    # More urgent: served at once, the busy task preempted.
    assert results[2][:2] == ("ok", 1) and results[2][2] < WATCHDOG_MS
    priorities = [priority for priority, _, _, _ in dcos_frames(lab, REQUEST)]
    assert 20 in priorities and 2 in priorities


def run_remote_bench(output):
    """bench/remote_bench.py with 3 calls per primitive and 10 publications; its report."""
    run = subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__), "bench", "remote_bench.py"),
                          "--calls", "3", "--writes", "10", "--output", str(output)], capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    return json.loads(output.read_text())


def test_the_benchs_remote_figures_are_their_frames_and_at_least_their_bus_time(tmp_path):
    """make bench's remote figures (bench/remote_bench.py), checked against the physics of the bus."""
    report = run_remote_bench(tmp_path / "remote.json")
    # A request and its reply: two extended 8-byte frames one after the
    # other, each at least its length with no stuff bit at all (54 + 8n + 13
    # bits, docs/protocols/labbus.md), at 1 Mbit/s; a port send's request is
    # three frames.
    frame_us = (54 + 64 + 13) * 1_000_000 / report["bit_rate"]
    for name, entry in report["primitives"].items():
        requests = 3 if name == "MessagePortSend" else 1
        # The port send's third frame carries 7 bytes: 8 bits fewer.
        shorter_us = 8 * 1_000_000 / report["bit_rate"] if requests == 3 else 0
        assert entry["status"] == ["ok"], name
        assert entry["request_frames_per_call"] == requests and entry["reply_frames_per_call"] == 1, name
        assert entry["round_trip_us"]["min"] >= (requests + 1) * frame_us - shorter_us, (name, entry, frame_us)
    # A publication: three such frames on each bus, one after the other.
    publications = report["publications"]
    assert publications["subscriber"]["received"] == publications["writes"] == 10
    for bus, entry in publications["buses"].items():
        assert entry["frames_per_publication"] == 3, bus
        assert entry["bus_time_us"]["min"] >= 3 * frame_us, (bus, entry, frame_us)


# Instructions a node retires between the chip's transmit request and the
# counter's read that ends the callee's count (the return through the link),
# or between a frame's end and the start of its receive routine (the
# kernel's interrupt entry): the callee's count and the bus gap between
# request and reply measure one interval and differ by no more.
COUNT_TO_BUS_SLACK = 200


def test_the_benchs_remote_instruction_counts_are_exact_and_fit_the_bus(tmp_path):
    """The instructions per remote primitive on each node (remote.json's "instructions"): present, positive,
    the same on every call and from run to run, the caller's own work a small part of its span, the
    callee's within the bus gap."""
    report = run_remote_bench(tmp_path / "first.json")
    assert report["cpu"] == "pentium" and report["image"].endswith("dcos486-test-counting.elf")
    for name, entry in report["primitives"].items():
        counts = entry["instructions"]
        calls = counts["per_call"]
        assert len(calls) == report["calls_per_primitive"] == 3, name
        # A second identical call counts exactly what the first did, on both nodes.
        assert all(call == calls[0] for call in calls), (name, calls)
        first = calls[0]
        for figure in ("caller_request", "caller_reply", "caller_span", "callee"):
            assert first[figure] > 0, (name, figure, first)
        assert counts["receive_interrupt_caller"] > 0 and counts["receive_interrupt_callee"] > 0, (name, counts)
        # The caller's own work is a few thousand instructions of a span that
        # is mostly the bus: under -icount the halted processor's time counts
        # one per ns, so the span is the round trip in ns.
        assert first["caller_own"] == first["caller_request"] + first["caller_reply"], (name, first)
        assert first["caller_own"] * 20 < first["caller_span"], (name, first)
        assert first["caller_waiting"] == first["caller_span"] - first["caller_own"], (name, first)
        trip = entry["round_trip_us"]
        assert (trip["min"] - 1) * 1000 <= first["caller_span"] <= (trip["max"] + 1) * 1000, (name, trip, first)
        # The reply's receive routine is part of the caller's reply share.
        assert counts["receive_interrupt_caller"] < first["caller_reply"], (name, counts)
        # The callee's share, from the request's last frame to the reply,
        # is the time between them on the bus (one instruction per ns, no
        # halt in it), and holds the request's receive routine.
        gap = entry["bus_gap_ns"]
        assert gap["min"] == gap["max"], (name, gap)
        last_frame = first["callee"] - first["callee_parts_before"]
        assert abs(last_frame - gap["min"]) <= COUNT_TO_BUS_SLACK, (name, first, gap)
        assert counts["receive_interrupt_callee"] < last_frame < 10_000, (name, counts, first)
        if name == "MessagePortSend":
            # Two earlier frames, each an interrupt and the receiver's share.
            assert 2 * counts["receive_interrupt_callee"] < first["callee_parts_before"] < 10_000, (name, first)
        else:
            assert first["callee_parts_before"] == 0, (name, first)
        # Every [remote] budget of budgets.toml holds.
        assert entry["budgets"] and all(not row["offences"] for row in entry["budgets"]), (name, entry["budgets"])
    # Exact: a second run of the two boards counts exactly the same.
    again = run_remote_bench(tmp_path / "again.json")
    for name, entry in report["primitives"].items():
        assert again["primitives"][name]["instructions"] == entry["instructions"], name


def test_a_requester_that_dies_while_it_waits_frees_the_serving_nodes_workers(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 0", "RSEM")
    # Two tasks of node 1 wait for node 2's semaphore for ever: both of node
    # 2's workers wait for them.
    waiters = [created(one, f"remote waiter {semaphore}", "RTASK") for _ in range(2)]
    lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, REQUEST, records)) >= 2, 120, "both requests")
    for waiter in waiters:
        assert "RKILL ok" in one.command(f"remote kill {waiter}")
    # The killed tasks retransmit no more; within 4 watchdog periods node 2
    # stops waiting for them, and its workers serve the next request.
    status, value, ms = call(one, f"count {semaphore}")
    assert (status, value) == ("ok", 0)
    assert ms < 3 * SILENT_PERIODS * WATCHDOG_MS
    # The other worker's wait ends within two more slices of 200 ms: node 2
    # lets 500 ms of its own time pass.
    sleeper = created(two, "remote sem 0", "RSEM")
    assert call(two, f"acquire {sleeper} 500")[0] == "timed out"
    assert net_counters(two)["abandoned"] == 2
    # Nobody waits any more: a unit released on node 2 stays there.
    assert call(two, f"release {semaphore}")[0] == "ok"
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)
    # Node 1 lists no transaction of the dead tasks.
    assert "  call " not in one.command("net remote")


def test_a_remote_request_overtakes_a_bulk_transfer_of_lower_priority(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 3", "RSEM")
    # A hub node floods the bus with priority-31 segmented frames, back to
    # back, as a bulk transfer would.
    bulk = Frame.data_frame((31 << 24) | (0x30 << 16) | (2 << 8) | 9, bytes(8), extended=True)
    lab.hub.babble("can0", "bulk", bulk)
    try:
        lab.hub.wait_for_records(lambda records: sum(r.frame == bulk for r in records) >= 3, 120, "the bulk transfer")
        status, value, ms = call(one, f"count at=2 {semaphore}")
        lab.hub.wait_for_records(lambda records: records[-1].frame == bulk and dcos_frames(lab, REPLY, records),
                                 120, "the bulk transfer after the reply")
    finally:
        lab.hub.stop_babble("bulk")
    assert (status, value) == ("ok", 3)
    assert ms < WATCHDOG_MS  # answered at once: no retransmission needed
    # In the bus log the request and then the reply each won arbitration
    # against a bulk frame at its first bit, in the midst of the bulk frames.
    records = lab.hub.frames()
    request = next(i for i, r in enumerate(records) if (r.frame.id >> 16) & 0xFF == REQUEST)
    assert records[request - 1].frame == bulk, lab.hub.log_text()
    assert (records[request + 1].frame.id >> 16) & 0xFF == REPLY, lab.hub.log_text()
    assert records[request + 2].frame == bulk, lab.hub.log_text()
    for record in records[request:request + 2]:
        assert record.frame.id >> 24 == 2
        assert record.lost == (("hub.bulk", 0),), lab.hub.log_text()
    # Node 1's link passed its one reply to the remote agent and dropped the
    # bulk frames, which are no remote transaction. Besides, each node
    # announced at attach that it had started: node 1 sent its announcement
    # and the request, and received node 2's announcement and the reply.
    link = re.search(r"can0 link interface=0 sent=(\d+) received=(\d+) foreign=(\d+)", one.command("can stats can0"))
    assert link and (int(link.group(1)), int(link.group(2))) == (2, 2) and int(link.group(3)) >= 3, link


def test_a_corrupted_request_and_reply_change_no_result(pair):
    lab, one, two = pair
    semaphore = created(two, "remote sem 0", "RSEM")
    # The next frame each board sends is destroyed at its CRC delimiter; the
    # controllers repeat them, as CAN does, and the transaction's result is
    # that of an undisturbed one.
    lab.hub.corrupt("board1.0", 1)
    lab.hub.corrupt("board2.0", 1)
    assert call(one, f"release {semaphore}")[:2] == ("ok", 0)
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)
    outcomes = [r.outcome for r in lab.hub.frames() if r.frame.extended]
    assert outcomes.count("form-error") == 2, lab.hub.log_text()
    assert net_counters(two)["served"] == 2 and net_counters(two)["duplicates"] == 0


def test_every_one_of_many_calls_runs_exactly_once(pair):
    lab, one, two = pair
    # More calls from one call slot than its transaction numbers' 16
    # generations, and than the serving node's 32 remembered requests.
    semaphore = created(two, "remote sem 0", "RSEM")
    calls = 40
    for _ in range(calls):
        assert call(one, f"release {semaphore}")[0] == "ok"
    assert call(two, f"count {semaphore}")[:2] == ("ok", calls)
    served = net_counters(two)
    assert served["served"] == calls and served["duplicates"] == 0
    transactions = [data[1] for _, _, _, data in dcos_frames(lab, REQUEST)]
    assert len(transactions) == calls and len(set(transactions)) == 16  # the numbers did wrap


NAME_QUERY = 0x12


def test_names_are_found_on_the_other_node_as_their_visibility_allows(pair):
    lab, one, two = pair
    pump = created(two, "remote named pump global", "RSEM")
    created(two, "remote named valve local", "RSEM")
    created(two, "remote named door regional", "RSEM")
    publisher = re.search(r"PPUB (0x[0-9a-f]{8})", two.command("pubsub publish level global 10 10 0")).group(1)
    # Global: found from node 1, with node 2's id, in one query and one reply.
    queries_before = len(dcos_frames(lab, NAME_QUERY))
    status, value, us = remote.call(one, "name semaphore pump")
    assert (status, f"0x{value:08x}") == ("ok", pump)
    assert us < WATCHDOG_MS * 1000, "answered at once, not after a retransmission"
    lab.hub.wait_until(lab.hub.now_ns + 2_000_000, 60)
    queries = dcos_frames(lab, NAME_QUERY)[queries_before:]
    assert len(queries) == 3 and {(destination, source, len(data)) for _, destination, source, data in queries} \
        == {(255, 1, 8)}
    assert bytes(queries[0][3][2:6]) == b"pump"
    status, value, _ = remote.call(one, "name publisher level")
    assert (status, f"0x{value:08x}") == ("ok", publisher)
    # Local and regional objects are not seen from another node over the
    # fieldbus, nor is a task of local visibility: every node stays silent,
    # and after the watchdog's silent periods the answer is "not found".
    created(two, "remote listener", "RTASK")
    for kind, name in (("semaphore", "valve"), ("semaphore", "door"), ("task", "listener"), ("timer", "nothing")):
        status, _, us = remote.call(one, f"name {kind} {name}")
        assert status == "not found", (kind, name)
        assert (SILENT_PERIODS - 1) * WATCHDOG_MS * 1000 <= us < 2 * SILENT_PERIODS * WATCHDOG_MS * 1000, (name, us)
    # A node's own object comes first, without asking the bus.
    own = created(one, "remote named pump local", "RSEM")
    queries_before = len(dcos_frames(lab, NAME_QUERY))
    status, value, _ = remote.call(one, "name semaphore pump")
    assert (status, f"0x{value:08x}") == ("ok", own)
    assert len(dcos_frames(lab, NAME_QUERY)) == queries_before
    # Names follow deletion: node 2's pump deleted, node 1 finds only its own.
    assert "RRES ok" in two.command(f"remote delete {pump}")
    assert "RRES ok" in one.command(f"remote delete {own}")
    assert remote.call(one, "name semaphore pump")[0] == "not found"
    statistics = net_counters(two)
    assert statistics["malformed"] == 0 and statistics["refused-busy"] == 0
    # Node 1's misses are names nobody has, not dead nodes.
    assert net_counters(one)["names-not-found"] == 5 and net_counters(one)["unreachable"] == 0


def test_a_name_query_nobody_can_answer_is_refused_not_served(pair):
    lab, one, two = pair
    # A name query for a type without names, and a torn one, from node 1's
    # CAN node number: node 2 counts them as malformed and answers nothing.
    before = net_counters(two)["malformed"]
    lab.hub.inject("can0", "lab", Frame(0x00120201, extended=True, dlc=8,
                                         data=bytes([0x09, 0x01]) + b"abcdef"))
    lab.hub.inject("can0", "lab", Frame(0x00120201, extended=True, dlc=3, data=bytes([0x08, 0x01, 0x00])))
    lab.hub.wait_until(lab.hub.now_ns + 5_000_000, 60)
    assert net_counters(two)["malformed"] == before + 2
    assert not [frame for frame in dcos_frames(lab, REPLY) if frame[2] == 2 and frame[1] == 1]


def porter_got(board):
    """What node's porter received: (count, first bytes in order, the last message), in hex."""
    output = board.command("remote portgot")
    count, firsts, last = re.search(r"RPGOT (\d+) (\S+) ([0-9a-f]{32})", output).groups()
    return int(count), firsts, last


def test_a_message_sent_to_a_port_of_another_node_arrives_whole_and_once(pair):
    lab, one, two = pair
    port = created(two, "remote port", "RPORT")
    assert port.startswith("0x00027"), port  # Node 2's message port (type 7).
    # Three messages at priorities 5, 5 and 3, each sixteen bytes counting
    # up from 0x10, 0x20 and 0x30: node 2's porter takes them most urgent first
    # when they wait, else as they come.
    results = [call(one, f"send {port} {priority * 256 + first}") for priority, first in ((5, 0x10), (5, 0x20),
                                                                                          (3, 0x30))]
    assert [(status, value) for status, value, _ in results] == [("ok", 0)] * 3
    count, firsts, last = porter_got(two)
    assert (count, firsts) == (3, "102030")
    assert last == bytes(range(0x30, 0x40)).hex()
    # The same call locally on node 2 answers alike.
    assert call(two, f"send {port} {5 * 256 + 0x40}")[:2] == ("ok", 0)
    assert porter_got(two)[:2] == (4, "10203040")
    # Three request frames (8, 8 and 7 bytes) and one reply per remote Send,
    # from CAN node 1 to 2 at the caller's priority.
    requests, replies = dcos_frames(lab, REQUEST), dcos_frames(lab, REPLY)
    assert len(requests) == 3 * 3 and len(replies) == 3, (requests, replies)
    assert [len(data) for *_, data in requests] == [8, 8, 7] * 3
    assert all(data[0] == 11 for *_, data in requests[::3])
    assert all(data[0] & 0xF0 == 0x90 for *_, data in requests[1::3])
    assert all(data[0] & 0xF0 == 0xA0 for *_, data in requests[2::3])


def test_a_port_of_another_node_refuses_as_a_local_port_would(pair):
    lab, one, two = pair
    port = created(two, "remote port", "RPORT")
    missing = f"0x{int(port, 16) + 1:08x}"
    # Priority 40 is refused before anything is sent; a port nobody has is an
    # invalid id on node 2; only the owner receives, and it is on node 2.
    assert call(one, f"send {port} {40 * 256}")[:2] == ("invalid argument", 0)
    assert call(one, f"send {missing} {5 * 256}")[:2] == ("invalid id", 0)
    assert call(one, f"receive {port}")[:2] == ("not owner", 0)
    assert call(two, f"send {missing} {5 * 256}")[:2] == ("invalid id", 0)
    assert porter_got(two)[0] == 0
    assert len(dcos_frames(lab, REQUEST)) == 3, "only the Send to the missing port went over the bus"


def test_a_port_send_duplicated_or_torn_on_the_bus_is_sent_to_the_port_once(pair):
    lab, one, two = pair
    port = created(two, "remote port", "RPORT")
    index = int(port, 16) & 0xFFFF
    # A port send "from CAN node 1" (transaction 0xE6, priority 2, bytes 0x50
    # to 0x5F) put on the bus by a hub node: first torn (its part 1 lost, so
    # part 2 comes out of turn), then whole, then whole again as a
    # retransmission would be.
    identifier = (8 << 24) | (REQUEST << 16) | (2 << 8) | 1
    body = bytes(range(0x50, 0x60))
    parts = [bytes([11, 0xE6, index >> 8, index & 0xFF, 2]) + body[0:3], bytes([0x80 | 1 << 4 | 6]) + body[3:10],
             bytes([0x80 | 2 << 4 | 6]) + body[10:16]]
    for frames, replies in (([parts[0], parts[2]], 0), (parts, 1), (parts, 2)):
        for data in frames:
            lab.hub.inject("can0", "injector", Frame.data_frame(identifier, data, extended=True))
        lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, REQUEST, records)) >= 2 + 3 * replies, 60,
                                 "the frames")
        if replies:
            lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, REPLY, records)) >= replies, 60,
                                     "the reply")
    lab.hub.wait_until(lab.hub.frames()[-1].end + 2_000_000, 60)
    assert porter_got(two) == (1, "50", body.hex()), "sent to the port once, whole"
    served = net_counters(two)
    assert served["served"] == 1 and served["duplicates"] == 1, served
    replies = dcos_frames(lab, REPLY)
    assert [data for *_, data in replies] == [bytes([11, 0xE6, 0, 0, 0, 0, 0, 0])] * 2


HELD_PART = 0xB0  # A held acquire's continuation: 0x80 | 3 << 4 | slot.


def is_task_of(value, node):
    return value >> 16 == node and (value >> 12) & 0xF == 1


def test_a_task_of_another_node_holds_a_binary_semaphore_as_a_local_task_would(pair):
    lab, one, two = pair
    binary = created(two, "remote sem binary", "RSEM")
    # Node 1's console task takes it: node 2 names that task as its holder.
    assert call(one, f"acquire {binary} 0")[:2] == ("ok", 0)
    status, holder, _ = call(two, f"holder {binary}")
    assert status == "ok" and is_task_of(holder, 1), hex(holder)
    assert call(one, f"holder {binary}")[:2] == ("ok", holder)
    assert call(two, f"count {binary}")[:2] == ("ok", 0)
    # The rules of a local binary semaphore: asked again by its holder, it
    # would deadlock; no other task may release it; others wait.
    assert call(one, f"acquire {binary} 100")[0] == "would deadlock"
    assert call(two, f"release {binary}")[0] == "not owner"
    assert call(two, f"acquire {binary} 0")[0] == "would block"
    assert call(one, f"release {binary}")[:2] == ("ok", 0)
    assert call(one, f"release {binary}")[0] == "not owner"
    assert call(two, f"holder {binary}")[:2] == ("ok", 0)
    assert call(two, f"count {binary}")[:2] == ("ok", 1)
    # The first acquire asked in the plain form, was told to name its task,
    # and asked again in the held form: two frames naming node 1's console.
    # Later ones went in the held form at once.
    requests = dcos_frames(lab, REQUEST)
    held = [data for _, _, _, data in requests if data[0] & 0xF0 == HELD_PART]
    assert len(held) == 2 and all(len(data) == 8 and data[5:] == bytes(3) for data in held)
    assert all(int.from_bytes(data[1:5], "big") == holder for data in held)
    services = [data[0] for _, _, _, data in requests if data[0] & 0x80 == 0]
    assert services[:2] == [1, 12], services  # acquire, then held-acquire
    assert services.count(1) == 1 and services.count(2) == 0, services


def test_a_binary_semaphore_passes_between_tasks_of_two_nodes(pair):
    lab, one, two = pair
    binary = created(two, "remote sem binary", "RSEM")
    assert call(two, f"acquire {binary} 0")[0] == "ok"  # node 2's console holds it
    one.emulator.send(f"remote acquire {binary} 5000\r")
    lab.hub.wait_for_records(
        lambda records: any(data[0] & 0xF0 == HELD_PART for _, _, _, data in dcos_frames(lab, REQUEST, records)),
        120, "node 1's held acquire")
    assert call(two, f"release {binary}")[0] == "ok"  # handed to node 1's waiting task
    match = one.emulator.expect(r"RRES (.+) (\d+) (\d+)\r\n", timeout=120)
    one.emulator.expect(r"dcos> ")
    assert match.group(1) == b"ok"
    status, holder, _ = call(two, f"holder {binary}")
    assert status == "ok" and is_task_of(holder, 1), hex(holder)
    # And back: node 2's task waits, node 1 releases.
    two.emulator.send(f"remote acquire {binary} 5000\r")
    two.emulator.expect(r"remote acquire", timeout=60)
    assert call(one, f"release {binary}")[0] == "ok"
    match = two.emulator.expect(r"RRES (.+) (\d+) (\d+)\r\n", timeout=120)
    two.emulator.expect(r"dcos> ")
    assert match.group(1) == b"ok"
    status, holder, _ = call(two, f"holder {binary}")
    assert status == "ok" and is_task_of(holder, 2), hex(holder)


def test_a_binary_semaphore_whose_remote_holder_is_gone_is_given_back_to_its_waiters(pair):
    lab, one, two = pair
    binary = created(two, "remote sem binary", "RSEM")
    # A task of node 1 takes it and ends, holding it.
    waiter = created(one, f"remote waiter {binary}", "RTASK")
    lab.hub.wait_until(lab.hub.now_ns + 300_000_000, 120)
    status, holder, _ = call(two, f"holder {binary}")
    assert status == "ok" and f"0x{holder:08x}" == waiter
    assert call(one, f"state {waiter}")[0] in ("invalid id", "stale id")
    # Node 2 waits for it: after one probe slice it asks node 1 about the
    # holder, learns it is gone, and the wait ends "holder ended", as when a
    # local holder dies; the semaphore is free again.
    status, _, ms = call(two, f"acquire {binary} 5000")
    assert status == "holder ended"
    assert SILENT_PERIODS * WATCHDOG_MS <= ms < 2 * SILENT_PERIODS * WATCHDOG_MS, ms
    assert call(two, f"holder {binary}")[:2] == ("ok", 0)
    assert call(two, f"acquire {binary} 0")[0] == "ok"
    assert call(two, f"release {binary}")[0] == "ok"
    # A remote waiter is served the same: node 2's worker waits for node 1's
    # console task and probes the holder, another task of node 1 that ended.
    waiter = created(one, f"remote waiter {binary}", "RTASK")
    lab.hub.wait_until(lab.hub.now_ns + 300_000_000, 120)
    assert f"0x{call(two, f'holder {binary}')[1]:08x}" == waiter
    status, _, ms = call(one, f"acquire {binary} 5000")
    assert status == "holder ended"
    assert SILENT_PERIODS * WATCHDOG_MS <= ms < 3 * SILENT_PERIODS * WATCHDOG_MS, ms
    assert call(one, f"acquire {binary} 0")[0] == "ok"
    assert call(one, f"release {binary}")[0] == "ok"
    # A holder whose node is lost: node 1's console holds it, node 1 leaves the bus.
    assert call(one, f"acquire {binary} 0")[0] == "ok"
    assert call(two, f"acquire {binary} 0")[0] == "would block"
    assert "error:" not in one.command("can detach can0")
    status, _, ms = call(two, f"acquire {binary} 5000")
    assert status == "holder ended"
    # One slice, then the probe's own watchdog: 4 silent periods.
    assert 2 * SILENT_PERIODS * WATCHDOG_MS <= ms < (2 * SILENT_PERIODS + 2) * WATCHDOG_MS, ms
    assert call(two, f"acquire {binary} 0")[0] == "ok"


def self_id(board):
    return created(board, "remote self", "RTASK")


def test_a_timer_of_another_node_is_set_by_its_owner_there_and_its_alarms_reach_it(pair):
    lab, one, two = pair
    console = self_id(one)
    timer = created(two, "remote timer", "RTIMER")
    # Node 2's console gives its timer to node 1's console task, which node 2
    # asks about first; a task that does not exist is refused.
    assert call(two, f"give {timer} 0x{int(console, 16) + 0x100:08x}")[0] in ("invalid id", "stale id")
    assert call(two, f"give {timer} {console}")[0] == "ok"
    # Over the network only the owner sets a timer's alarms (a privilege is
    # not carried): node 1's console may not touch another timer of node 2.
    others = created(two, "remote timer", "RTIMER")
    assert call(one, f"alarm {others} watchdog 50 4")[0] == "not owner"
    assert call(one, f"cancel {others}")[0] == "not owner"
    assert call(one, f"alarm {timer} watchdog 50 4")[0] == "ok"
    status, events, ms = call(one, "events 2000")
    assert (status, events) == ("ok", 4)
    assert 40 <= ms < 50 + 2 * WATCHDOG_MS, ms
    assert call(one, "events 0")[0] == "would block"
    # A periodic alarm: each period's events come, until the owner cancels it.
    assert call(one, f"alarm {timer} periodic 100 8")[0] == "ok"
    for _ in range(3):
        assert call(one, "events 2000")[:2] == ("ok", 8)
    assert call(one, f"cancel {timer}")[0] == "ok"
    call(one, "events 150")  # one notification may have been on its way
    assert call(one, "events 300")[0] == "timed out"
    assert call(one, f"cancel {timer}")[0] == "invalid argument"  # no alarm set, as locally
    # A day-clock alarm, by node 2's calendar.
    assert call(one, f"alarm {timer} day 100 16")[0] == "ok"
    assert call(one, "events 2000")[:2] == ("ok", 16)
    # Node 2 counts the last once node 1's answer is back.
    lab.hub.wait_until(lab.hub.now_ns + 20_000_000, 60)
    counters = net_counters(two)
    assert counters["alarms-notified"] in (5, 6), counters
    assert counters["alarm-owners-lost"] == 0 and counters["alarms-dropped"] == 0, counters
    # The alarm's frames: three to set it (laid out as a port send's), one reply;
    # each notification an ordinary PostEvent from node 2, at the notifier's priority 1.
    sets = [data for _, _, _, data in dcos_frames(lab, REQUEST) if data[0] == 14]
    assert len(sets) == 4 and all(data[4] & 0x03 in (1, 2, 3) for data in sets), sets
    posts = [(priority, destination, source, data) for priority, destination, source, data in dcos_frames(lab, REQUEST)
             if data[0] == 4]
    assert posts and all(priority == 1 and (destination, source) == (1, 2) for priority, destination, source, _ in posts)


def test_a_timer_whose_owner_on_another_node_is_gone_is_deleted(pair):
    lab, one, two = pair
    listener = created(one, "remote listener", "RTASK")
    timer = created(two, "remote timer", "RTIMER")
    # Node 2's console sets a periodic alarm, then gives the timer to node 1's
    # listener: the alarm goes on, its events to the new owner.
    assert call(two, f"alarm {timer} periodic 50 1")[0] == "ok"
    assert call(two, f"give {timer} {listener}")[0] == "ok"
    lab.hub.wait_until(lab.hub.now_ns + 300_000_000, 120)
    got = one.command("remote got")
    assert "RGOT 0x1 " in got, got
    # The listener is killed: the next notification finds no owner, and node 2
    # deletes the timer, as a local owner's death deletes its timers.
    assert "RKILL ok" in one.command(f"remote kill {listener}")
    lab.hub.wait_until(lab.hub.now_ns + 300_000_000, 120)
    counters = net_counters(two)
    assert counters["alarm-owners-lost"] == 1, counters
    assert call(two, f"cancel {timer}")[0] in ("invalid id", "stale id")
    sent = counters["alarms-notified"]
    lab.hub.wait_until(lab.hub.now_ns + 200_000_000, 120)
    assert net_counters(two)["alarms-notified"] == sent


def test_a_node_that_starts_again_leaves_no_hold_or_timer_to_its_tasks_of_before(pair):
    """A node that restarts gives its boot tasks the ids they had, so a hold
    or a timer another node keeps for such a task would outlive it. Each
    node therefore announces, at its first attach of an interface since it
    started, that it started; the others give up what they keep for its
    tasks of before, as when those tasks are found gone."""
    lab, one, two = pair
    # Both announced at attach: 8 bytes to every node, the node's id in front.
    # Node 2's may still be on its way when its attach command returns.
    lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, NODE_STARTED, records)) >= 2, 60,
                             "both nodes' announcements")
    announcements = sorted((source, destination, priority, data)
                           for priority, destination, source, data in dcos_frames(lab, NODE_STARTED))
    assert announcements == [(1, 255, 31, bytes([0, 1, 0, 0, 0, 0, 0, 0])),
                             (2, 255, 31, bytes([0, 2, 0, 0, 0, 0, 0, 0]))], lab.hub.log_text()
    # Node 1's console holds node 2's binary semaphore; a listener of node 1
    # owns a timer of node 2 with a periodic alarm.
    binary = created(two, "remote sem binary", "RSEM")
    assert call(one, f"acquire {binary} 0")[0] == "ok"
    listener = created(one, "remote listener", "RTASK")
    timer = created(two, "remote timer", "RTIMER")
    assert call(two, f"alarm {timer} periodic 50 1")[0] == "ok"
    assert call(two, f"give {timer} {listener}")[0] == "ok"
    identifier = (31 << 24) | (NODE_STARTED << 16) | (255 << 8) | 1
    # Node 1's own announcement may have reached node 2 already: a frame
    # nobody acknowledged is sent again until node 2's controller comes up,
    # which can be after node 2 attached its link, as the consoles' timing
    # falls. It came before the hold and the timer, so it freed neither.
    before = net_counters(two)
    # Announcements node 2 must refuse: its own id, and a byte past the id set.
    for data in (bytes([0, 2, 0, 0, 0, 0, 0, 0]), bytes([0, 1, 0, 0, 0, 0, 0, 1])):
        lab.hub.inject("can0", "injector", Frame.data_frame(identifier, data, extended=True))
    lab.hub.wait_until(lab.hub.now_ns + 20_000_000, 60)
    counters = net_counters(two)
    assert counters["malformed"] == before["malformed"] + 2, counters
    assert counters["nodes-started"] == before["nodes-started"], counters
    assert call(two, f"acquire {binary} 0")[0] == "would block"
    # "Node 1 started" while node 2's console waits for the semaphore: the
    # wait ends "holder ended" when the announcement comes, 100 ms in, not a
    # probe slice (200 ms) later, and the timer is deleted.
    lab.hub.inject("can0", "injector", Frame.data_frame(identifier, bytes([0, 1, 0, 0, 0, 0, 0, 0]), extended=True),
                   at_ns=lab.hub.now_ns + 100_000_000)
    status, _, ms = call(two, f"acquire {binary} 5000")
    assert status == "holder ended"
    assert ms < SILENT_PERIODS * WATCHDOG_MS, ms
    assert call(two, f"acquire {binary} 0")[0] == "ok"
    assert call(two, f"cancel {timer}")[0] in ("invalid id", "stale id")
    counters = net_counters(two)
    assert (counters["nodes-started"] - before["nodes-started"], counters["holds-freed"] - before["holds-freed"],
            counters["timers-of-restarted"] - before["timers-of-restarted"]) == (1, 1, 1), counters
    # A link attached again is no restart: node 1 says nothing more.
    assert "error:" not in one.command("can detach can0")
    assert "carries interface 0" in one.command("can attach can0")
    lab.hub.wait_until(lab.hub.now_ns + 20_000_000, 60)
    assert len(dcos_frames(lab, NODE_STARTED)) == 2 + 3


def test_a_held_acquire_and_an_alarm_torn_or_duplicated_on_the_bus_are_performed_once(pair):
    lab, one, two = pair
    binary = created(two, "remote sem binary", "RSEM")
    timer = created(two, "remote timer", "RTIMER")
    console = self_id(one)
    assert call(two, f"give {timer} {console}")[0] == "ok"
    before = net_counters(two)
    identifier = (8 << 24) | (REQUEST << 16) | (2 << 8) | 1  # "from CAN node 1", priority 8
    # A held acquire for node 1's console, transaction 0xE7: its holder part
    # alone (part 0 lost), then whole, then whole again as a retransmission
    # would be. Performed twice, the second would say "would deadlock".
    semaphore = int(binary, 16) & 0xFFFF
    held = [bytes([12, 0xE7, semaphore >> 8, semaphore & 0xFF, 0, 0, 0, 0]),
            bytes([0xB7]) + int(console, 16).to_bytes(4, "big") + bytes(3)]
    # An alarm for the same task, transaction 0xE8: a watch-dog of 100 ms,
    # events 0x20; torn (part 1 lost), then whole twice.
    index = int(timer, 16) & 0xFFFF
    record = int(console, 16).to_bytes(4, "big") + (0x20).to_bytes(4, "big") + (100_000_000).to_bytes(8, "big")
    alarm = [bytes([14, 0xE8, index >> 8, index & 0xFF, 0x01]) + record[0:3], bytes([0x98]) + record[3:10],
             bytes([0xA8]) + record[10:16]]
    def answers(records=None):
        return [data for _, destination, _, data in dcos_frames(lab, REPLY, records)
                if destination == 1 and data[1] in (0xE7, 0xE8)]

    replies = 0
    for frames, answered in (([held[1]], 0), (held, 1), (held, 1), ([alarm[0], alarm[2]], 0), (alarm, 1),
                             (alarm, 1)):
        for data in frames:
            lab.hub.inject("can0", "injector", Frame.data_frame(identifier, data, extended=True))
        replies += answered
        # The frames' time on the bus, then the answer when one is due.
        lab.hub.wait_until(lab.hub.now_ns + 5_000_000, 60)
        lab.hub.wait_for_records(lambda records: len(answers(records)) >= replies, 60, "the reply")
    ours = answers()
    assert ours == [bytes([12, 0xE7, 0, 0, 0, 0, 0, 0])] * 2 + [bytes([14, 0xE8, 0, 0, 0, 0, 0, 0])] * 2, ours
    status, holder, _ = call(two, f"holder {binary}")
    assert (status, f"0x{holder:08x}") == ("ok", console)
    served = net_counters(two)
    assert served["served"] - before["served"] == 2 and served["duplicates"] - before["duplicates"] == 2, served
    # The alarm went off once, to node 1's console.
    assert call(one, "events 2000")[:2] == ("ok", 0x20)
    assert call(one, "events 300")[0] == "timed out"


def test_nodes_whose_command_line_names_a_bit_rate_are_on_the_network_from_boot(canlab):
    # "can0=RATE" (the stage loader puts the card configuration's bit rate
    # there) brings can0 up as interface 0 before the console starts: only
    # the peers' maps are typed, and a remote call works at once.
    lab = canlab({"can0": BIT_RATE}, {"board1": {"bus0": "can0", "append": f"node=1 can0={BIT_RATE}"},
                                      "board2": {"bus0": "can0", "append": f"node=2 can0={BIT_RATE}"},
                                      "board3": {"bus0": "can0", "append": "node=3 can0=12345"},
                                      "board4": {"bus0": "can0", "append": f"node=300 can0={BIT_RATE}"}})
    one, two, three, four = (lab.board(name) for name in ("board1", "board2", "board3", "board4"))
    for board, node in ((one, 1), (two, 2)):
        booted = board.emulator.transcript
        assert f"can0 up at 0x280 irq 10: {BIT_RATE} bit/s" in booted, booted
        assert f"can0 carries interface 0: 130.1.0.{node}/16, CAN node {node}" in booted, booted
        assert f"  0  can    0  130.1.0.{node}/16  physical {node}" in board.command("net"), board.command("net")
    # Each announced itself as it came up (NodeStarted), as 'can attach' makes it.
    lab.hub.wait_for_records(lambda records: len(dcos_frames(lab, NODE_STARTED, records)) >= 2, 60,
                             "both nodes' announcements")
    assert sorted(source for _, _, source, _ in dcos_frames(lab, NODE_STARTED)) == [1, 2], lab.hub.log_text()
    for board, peer in ((one, 2), (two, 1)):
        for line in (f"net map {peer} 130.1.0.{peer}", f"net neighbour 130.1.0.{peer} {peer}"):
            assert "error:" not in board.command(line)
    semaphore = created(two, "remote sem 1 2", "RSEM")
    assert call(one, f"acquire {semaphore} 0")[0] == "ok"
    # A rate the chip cannot make, and a node id no CAN node number can
    # carry: each said at boot, the channel left down, the node running on.
    booted = three.emulator.transcript
    assert "error: bit rate '12345' cannot be made exactly" in booted and "can0: not started" in booted, booted
    assert "can0 is down" in three.command("can stats can0")
    booted = four.emulator.transcript
    assert "error: node 300 is no CAN node number (1 to 254); can0: not started" in booted, booted
    assert f"can0 up at 0x280 irq 10: {BIT_RATE} bit/s" in four.command(f"can up can0 {BIT_RATE}")
