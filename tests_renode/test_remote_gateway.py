"""Remote transactions through a gateway (dissertation 6.4 and 7.13, Fig. 7.15): three boards on two CAN buses.

Node 1 is on the lab bus can0 only, node 3 on can1 only, and node 2, with
both channels, is on both: the gateway. Node 1 reaches node 3's network
(130.2.0.0/16) through a route via node 2 (130.1.0.2), node 3 reaches node
1's the other way. A primitive on node 1 given the id of node 3's object
goes to node 2 as a routed request (message type 0x13: a route header that
names node 3, then the request's frames); node 2's worker performs it as
its own remote transaction to node 3 over can1 and replies with what it
got (docs/protocols/remote-transactions.md, "Gateways"). Each test
compares the answers with the same calls made on node 3 itself, and reads
each bus's log for the frames.

Times are emulated (-icount); every wait has a generous time-out that
bounds a hung board, not a speed.
"""

import re

import pytest

from dcoslab import remote
from dcoslab.canbus import Frame
from dcoslab.remote import REPLY, REQUEST, SEMAPHORE_SEQUENCE, created, net_counters, read_pages_across, \
    semaphore_sequence, wait_tally

BIT_RATE = 500_000
ROUTED = 0x13
WATCHDOG_MS = 50       # DCOS_CONFIG_REMOTE_WATCHDOG_MS
SILENT_PERIODS = 4     # DCOS_CONFIG_REMOTE_SILENT_PERIODS


def configure(board, lines, timeout=120):
    for line in lines:
        output = board.command(line, timeout=timeout)
        assert "error:" not in output, (line, output)


@pytest.fixture
def triple(canlab):
    lab = canlab({"can0": BIT_RATE, "can1": BIT_RATE},
                 {"node1": {"bus0": "can0", "append": "node=1"},
                  "node2": {"bus0": "can0", "bus1": "can1", "append": "node=2"},
                  "node3": {"bus0": "can1", "append": "node=3"}})
    one, two, three = (lab.board(f"node{node}") for node in (1, 2, 3))
    configure(one, [f"can up can0 {BIT_RATE}", "net interface can 0 130.1.0.1/16 1",
                    "net map 2 130.1.0.2", "net neighbour 130.1.0.2 2",
                    "net map 3 130.2.0.3", "net route 130.2.0.0/16 130.1.0.2", "can attach can0"])
    configure(two, [f"can up can0 {BIT_RATE}", f"can up can1 {BIT_RATE}",
                    "net interface can 0 130.1.0.2/16 2", "net interface can 1 130.2.0.2/16 2",
                    "net map 1 130.1.0.1", "net neighbour 130.1.0.1 1",
                    "net map 3 130.2.0.3", "net neighbour 130.2.0.3 3", "can attach can0", "can attach can1"])
    configure(three, [f"can up can0 {BIT_RATE}", "net interface can 0 130.2.0.3/16 3",
                      "net map 2 130.2.0.2", "net neighbour 130.2.0.2 2",
                      "net map 1 130.1.0.1", "net route 130.1.0.0/16 130.2.0.2", "can attach can0"])
    return lab, one, two, three


def call(board, line):
    """A `remote` primitive's (status, value, milliseconds)."""
    status, value, us = remote.call(board, line)
    return status, value, us / 1000


def frames(lab, bus, kind):
    """The bus log's DCOS frames of one message type on one bus: (priority, destination, source, data)."""
    found = []
    for record in lab.hub.frames():
        raw = record.frame.id
        if record.bus == bus and record.outcome == "ok" and record.frame.extended and (raw >> 16) & 0xFF == kind:
            found.append((raw >> 24, (raw >> 8) & 0xFF, raw & 0xFF, bytes(record.frame.data)))
    return found


SEQUENCE = SEMAPHORE_SEQUENCE


def test_a_semaphore_behind_a_gateway_answers_as_a_local_one(triple):
    lab, one, two, three = triple
    far_semaphore, far = semaphore_sequence(one, three)
    assert far_semaphore.startswith("0x0003")
    # A call that does not wait crosses both buses: the header and the
    # request on can0, the request on can1, a reply on each; against node 2's
    # direct call on node 3, two frames, it takes two to three times as long.
    direct = call(two, f"count {far_semaphore}")[2]
    routed_trips = {us / 1000 for (status, _, us), step in zip(far, SEQUENCE) if "200" not in step}
    assert all(2 * direct < trip < 3 * direct for trip in routed_trips), (far, direct)
    # The 200 ms wait was node 3's; the answer came back through node 2 after it.
    assert 200 <= far[4][2] / 1000 < 200 + 2 * SILENT_PERIODS * WATCHDOG_MS
    # On can0: node 1's routed requests to node 2, each a route header naming
    # node 3 and the request; node 2's replies. On can1: node 2's own requests
    # to node 3 and node 3's replies. No routed frame reaches can1.
    routed = frames(lab, "can0", ROUTED)
    headers = [data for _, _, _, data in routed if data[0] & 0xC0 == 0xC0]
    assert {(destination, source) for _, destination, source, _ in routed} == {(2, 1)}
    assert len(headers) == len(routed) // 2 >= len(SEQUENCE)
    assert {(data[0] & 0x0F, data[2] << 8 | data[3]) for data in headers} == {(4, 3)}, "4 hops left, to node 3"
    assert frames(lab, "can0", REQUEST) == [] and frames(lab, "can1", ROUTED) == []
    assert {(d, s) for _, d, s, _ in frames(lab, "can1", REQUEST)} == {(3, 2)}
    assert {(d, s) for _, d, s, _ in frames(lab, "can1", REPLY)} == {(2, 3)}
    assert {(d, s) for _, d, s, _ in frames(lab, "can0", REPLY)} == {(1, 2)}
    asker, gateway, server = net_counters(one), net_counters(two), net_counters(three)
    assert asker["routed-requests"] == asker["replies"] == len(SEQUENCE) and asker["unreachable"] == 0
    # The gateway served each once (retransmissions answered as pending) and asked node 3 in turn.
    assert gateway["forwarded"] == gateway["served"] == len(SEQUENCE)
    assert gateway["requests"] >= len(SEQUENCE) and gateway["unrouted"] == 0
    assert server["served"] == len(SEQUENCE) + 1 and server["routed-requests"] == 0  # and node 2's direct count
    # Requests run at the caller's priority on every hop.
    priorities = {p for p, _, _, _ in routed} | {p for p, _, _, _ in frames(lab, "can1", REQUEST)}
    assert len(priorities) == 1


def test_events_signals_reads_and_port_sends_cross_the_gateway(triple):
    lab, one, two, three = triple
    listener = created(three, "remote listener", "RTASK")
    assert call(one, f"post {listener} 0x5")[:2] == ("ok", 0)
    assert call(one, f"signal {listener} 3")[:2] == ("ok", 0)
    assert call(one, f"signal {listener} 40")[0] == call(three, f"signal {listener} 40")[0] == "invalid argument"
    assert call(one, f"post {listener} 0x10")[:2] == ("ok", 0)
    assert "RGOT 0x15 0x8" in three.command("remote got")
    for line in (f"state {listener}", f"priority {listener}"):
        assert call(one, line)[:2] == call(three, line)[:2], line
    # A 16-byte port message: a route header and the three frames of a port send.
    port = created(three, "remote port", "RPORT")
    assert call(one, f"send {port} {5 * 256 + 0x10}")[:2] == ("ok", 0)
    got = re.search(r"RPGOT (\d+) (\S+) ([0-9a-f]{32})", three.command("remote portgot"))
    assert got and got.groups() == ("1", "10", bytes(range(0x10, 0x20)).hex()), got
    routed = frames(lab, "can0", ROUTED)
    assert [len(data) for *_, data in routed[-4:]] == [4, 8, 8, 7]
    # A binary semaphore refuses as it does from any other node.
    binary = created(three, "remote sem binary", "RSEM")
    assert call(one, f"release {binary}")[0] == call(three, f"release {binary}")[0] == "not owner"
    # An object node 3 never issued.
    never = "0x%08x" % (int(listener, 16) + 0x100)
    assert call(one, f"state {never}")[0] == call(three, f"state {never}")[0]


def test_a_dead_node_behind_the_gateway_gives_unreachable_and_the_others_carry_on(triple):
    lab, one, two, three = triple
    semaphore = created(three, "remote sem 1", "RSEM")
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)
    assert "error:" not in three.command("can detach can0")
    status, _, ms = call(one, f"acquire {semaphore} 10000")
    assert status == "node unreachable"
    # The gateway's watchdog gives up on node 3 and says so; node 1's own
    # watchdog was kept alive by the gateway's pending replies meanwhile.
    assert SILENT_PERIODS * WATCHDOG_MS <= ms < (SILENT_PERIODS + 3) * WATCHDOG_MS
    assert net_counters(two)["unreachable"] == 1 and net_counters(one)["unreachable"] == 0
    # The gateway and node 1 are unharmed; node 3 serves again once attached.
    gateway_semaphore = created(two, "remote sem 1", "RSEM")
    assert call(one, f"count {gateway_semaphore}")[:2] == ("ok", 1)
    assert "carries interface 0" in three.command("can attach can0")
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)


def test_a_dead_gateway_gives_unreachable_within_the_askers_watchdog(triple):
    lab, one, two, three = triple
    semaphore = created(three, "remote sem 1", "RSEM")
    assert "error:" not in two.command("can detach can0")
    status, _, ms = call(one, f"count {semaphore}")
    assert status == "node unreachable"
    assert SILENT_PERIODS * WATCHDOG_MS <= ms < (SILENT_PERIODS + 2) * WATCHDOG_MS
    assert net_counters(one)["unreachable"] == 1


def test_a_loop_in_the_routes_ends_after_four_crossings(triple):
    lab, one, two, three = triple
    # Node 4's network routed from node 1 through node 2 and from node 2 back
    # through node 1: a misconfiguration, which must cost a few transactions.
    configure(one, ["net map 4 130.3.0.4", "net route 130.3.0.0/16 130.1.0.2"])
    configure(two, ["net map 4 130.3.0.4", "net route 130.3.0.0/16 130.1.0.1"])
    status, _, ms = call(one, "count 0x0004a001")
    assert status == "node unreachable"
    assert ms < SILENT_PERIODS * WATCHDOG_MS, "refused by the hop count, not by a watchdog"
    headers = [data for _, _, _, data in frames(lab, "can0", ROUTED) if data[0] & 0xC0 == 0xC0]
    # Hops left 4 (node 1 to 2), 3 (2 to 1), 2 (1 to 2) and 1 (2 to 1): four
    # crossings, and node 1, with one hop left, may not pass it on again.
    assert sorted(data[0] & 0x0F for data in headers) == [1, 2, 3, 4]
    assert net_counters(one)["forwarded"] == 2 and net_counters(two)["forwarded"] == 2
    # Every worker is free again: node 3's objects are still reached.
    semaphore = created(three, "remote sem 1", "RSEM")
    assert call(one, f"count {semaphore}")[:2] == ("ok", 1)


def test_a_routed_request_without_its_header_is_dropped_not_served_as_the_gateways(triple):
    lab, one, two, three = triple
    # A semaphore on the gateway with the index node 3's will have: served as
    # node 2's own, the headerless request would release it.
    gateway_semaphore = created(two, "remote sem 0", "RSEM")
    far_semaphore = created(three, "remote sem 0", "RSEM")
    index = int(far_semaphore, 16) & 0xFFFF
    assert int(gateway_semaphore, 16) & 0xFFFF == index
    identifier = (8 << 24) | (ROUTED << 16) | (2 << 8) | 1
    release = bytes([2, 0x37, index >> 8, index & 0xFF, 0, 0, 0, 0])
    lab.hub.inject("can0", "injector", Frame.data_frame(identifier, release, extended=True))
    # And a malformed header: three bytes.
    lab.hub.inject("can0", "injector", Frame.data_frame(identifier, bytes([0xC4, 0x37, 0x00]), extended=True))
    lab.hub.wait_for_records(lambda records: sum(1 for r in records if r.bus == "can0" and
                                                 (r.frame.id >> 16) & 0xFF == ROUTED) >= 2, 60, "the frames")
    lab.hub.wait_until(lab.hub.frames()[-1].end + 2_000_000, 60)
    gateway = net_counters(two)
    assert gateway["unrouted"] == 1 and gateway["malformed"] == 1 and gateway["served"] == 0
    assert call(two, f"count {gateway_semaphore}")[:2] == ("ok", 0)
    assert call(three, f"count {far_semaphore}")[:2] == ("ok", 0)
    assert frames(lab, "can0", REPLY) == []


NAME_QUERY = 0x12


def test_names_behind_the_gateway_are_found_through_it(triple):
    lab, one, two, three = triple
    pump = created(three, "remote named pump global", "RSEM")
    status, value, _ = remote.call(one, "name semaphore pump")
    assert (status, f"0x{value:08x}") == ("ok", pump)
    # Node 1 broadcast its query on can0 and sent it to the gateway, which
    # broadcast it on can1, the bus beyond, once; node 3 answered node 2, and
    # node 2 node 1.
    lab.hub.wait_until(lab.hub.now_ns + 2_000_000, 60)
    near = frames(lab, "can0", NAME_QUERY)
    assert sorted((destination, source) for _, destination, source, _ in near) == [(2, 1)] * 3 + [(255, 1)] * 3
    assert [(destination, source) for _, destination, source, _ in frames(lab, "can1", NAME_QUERY)] == [(255, 2)] * 3
    assert net_counters(two)["forwarded"] == 1
    # The same the other way: node 3 finds node 1's global name through node 2.
    vent = created(one, "remote named vent global", "RSEM")
    status, value, _ = remote.call(three, "name semaphore vent")
    assert (status, f"0x{value:08x}") == ("ok", vent)
    # A local object stays unseen through the gateway too: not found, after the
    # gateway's own query ran out (4 silent periods, node 1's retransmissions
    # answered pending) and node 1's silent periods after it (407 ms measured).
    created(three, "remote named door local", "RSEM")
    status, _, us = remote.call(one, "name semaphore door")
    assert status == "not found"
    assert (2 * SILENT_PERIODS - 1) * WATCHDOG_MS * 1000 <= us < 3 * SILENT_PERIODS * WATCHDOG_MS * 1000, us
    # The gateway's own object is found without asking beyond it.
    before = len(frames(lab, "can1", NAME_QUERY))
    gate = created(two, "remote named gate global", "RSEM")
    status, value, _ = remote.call(one, "name semaphore gate")
    assert (status, f"0x{value:08x}") == ("ok", gate)
    assert len(frames(lab, "can1", NAME_QUERY)) == before


def test_a_binary_semaphore_behind_the_gateway_is_held_by_the_far_task(triple):
    lab, one, two, three = triple
    binary = created(three, "remote sem binary", "RSEM")
    # Node 1's console takes node 3's binary semaphore through node 2: node 3
    # names node 1's task as the holder, not the gateway's worker.
    assert call(one, f"acquire {binary} 0")[:2] == ("ok", 0)
    status, holder, _ = call(three, f"holder {binary}")
    assert status == "ok" and holder >> 16 == 1 and (holder >> 12) & 0xF == 1, hex(holder)
    assert call(one, f"acquire {binary} 0")[0] == "would deadlock"
    assert call(two, f"release {binary}")[0] == "not owner"
    assert call(three, f"release {binary}")[0] == "not owner"
    assert call(one, f"release {binary}")[:2] == ("ok", 0)
    assert call(three, f"holder {binary}")[:2] == ("ok", 0)
    # The held acquire crossed both buses, its holder unchanged.
    for bus in ("can0", "can1"):
        held = [data for _, _, _, data in frames(lab, bus, REQUEST) if data[0] & 0xF0 == 0xB0]
        held += [data for _, _, _, data in frames(lab, bus, ROUTED) if data[0] & 0xF0 == 0xB0]
        assert held and all(int.from_bytes(data[1:5], "big") == holder for data in held), bus
    # Node 1 leaves while holding it: node 3's waiter probes node 1's task
    # through the gateway, learns node 1 is unreachable, and gets it back.
    assert call(one, f"acquire {binary} 0")[0] == "ok"
    assert "error:" not in one.command("can detach can0")
    status, _, us = remote.call(three, f"acquire {binary} 5000")
    assert status == "holder ended", status
    assert call(three, f"acquire {binary} 0")[0] == "ok"


def test_a_timer_behind_the_gateway_is_set_by_its_owner_and_notifies_it_through_the_gateway(triple):
    lab, one, two, three = triple
    console = created(one, "remote self", "RTASK")
    timer = created(three, "remote timer", "RTIMER")
    assert call(three, f"give {timer} {console}")[0] == "ok"  # node 3 asks node 1 about its task through node 2
    assert call(one, f"alarm {timer} watchdog 50 2")[0] == "ok"
    # The alarm goes off on node 3; its PostEvent reaches node 1 through node 2.
    assert call(one, "events 2000")[:2] == ("ok", 2)
    # Node 3 counts it once the answer came back through node 2.
    lab.hub.wait_until(lab.hub.now_ns + 20_000_000, 60)
    assert net_counters(three)["alarms-notified"] == 1
    assert call(one, f"cancel {timer}")[0] == "invalid argument"  # the watch-dog went off: no alarm is set
    assert call(one, f"alarm {timer} periodic 100 4")[0] == "ok"
    assert call(one, "events 2000")[:2] == ("ok", 4)
    assert call(one, f"cancel {timer}")[0] == "ok"
    assert net_counters(two)["forwarded"] >= 5


RELAYED = 0x21


def test_a_publisher_behind_the_gateway_is_read_through_it(triple):
    lab, one, two, three = triple
    # Node 1 opens node 3's publisher through node 2, which from then on
    # relays its frames onto can0, each behind a header naming node 3.
    publisher = read_pages_across(lab, three, one)
    assert publisher.startswith("0x00038")
    lab.hub.wait_until(lab.hub.now_ns + 5_000_000, 60)
    relayed = frames(lab, "can0", RELAYED)
    headers, parts = relayed[0::2], relayed[1::2]
    assert {data for *_, data in headers} == {bytes([0xFF, 0, 0, 3])}
    # Every frame of node 3's on can1 after the Open, once, in order, from
    # node 2 to all, at the writer's priority.
    originals = [data for *_, data in frames(lab, "can1", 0x20)]
    assert [data for *_, data in parts] == originals[-len(parts):]
    assert len(parts) >= 3 * 20
    assert {(priority, destination, source) for priority, destination, source, _ in relayed} == {(10, 255, 2)}
    assert net_counters(two)["publications-relayed"] == len(parts)
    # The publisher's deletion is relayed too: node 1's reader learns it.
    three.command("pubsub delete")
    status, counts = wait_tally(lab, one, lambda _, c: c["deleted"] == 1, "the withdrawal")
    assert counts["received"] == 20
    # A relayed frame without its header is dropped, never taken as node 2's.
    lab.hub.inject("can0", "injector", Frame.data_frame((10 << 24) | (RELAYED << 16) | (255 << 8) | 2,
                                                       parts[0][3], extended=True))
    lab.hub.wait_until(lab.hub.now_ns + 2_000_000, 60)
    assert net_counters(one)["unrouted"] == 1
