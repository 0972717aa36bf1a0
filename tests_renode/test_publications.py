"""Publications over the network (dissertation 7.10, Fig. 7.12) between emulated 486 boards on two CAN buses.

Two boards, node 1 and node 2, each with CAN channel 0 on the lab bus can0
and channel 1 on can1, attached to the network interfaces manager as
interfaces 0 and 1 (each node multi-homed, one subnet per bus). A global
publisher on one board is published on both buses at each Write
(docs/protocols/publications.md); a task on the other board opens a
subscription to it by id and reads every page. The test image's `pubsub`
command (tests_renode/target/PublicationsTest.cpp) writes pages whose
four words derive from one counter, so the reading task tells a whole page
from a torn one, and counts repeats (a duplicate or old page, which a
subscriber must never see) and gaps (writes it missed).

Times are emulated (-icount, the hub's timing model); every wait has a
generous time-out that bounds a hung board, not a speed.
"""

import re

import pytest

from dcoslab.remote import (attach_redundant, created, net_counters, parse_result, publication_records, publish,
                            subscribe, wait_tally)

BIT_RATE = 500_000
STEP = 120


@pytest.fixture
def pair(canlab):
    lab = canlab({"can0": BIT_RATE, "can1": BIT_RATE},
                 {"board1": {"bus0": "can0", "bus1": "can1", "append": "node=1"},
                  "board2": {"bus0": "can0", "bus1": "can1", "append": "node=2"}})
    one, two = lab.board("board1"), lab.board("board2")
    attach_redundant(one, 1, [2], BIT_RATE)
    # After a bus-off a channel of node 2 stays off, as a cut cable would leave it.
    attach_redundant(two, 2, [1], BIT_RATE, policy="manual")
    return lab, one, two


def published(board):
    output = board.command("pubsub published")
    return int(re.search(r"PCOUNT (\d+)", output).group(1))



def publication_frames(lab, bus=None):
    """The publication frames on the bus log: (bus, priority, destination, source, data)."""
    return [(record.bus, record.frame.id >> 24, (record.frame.id >> 8) & 0xFF, record.frame.id & 0xFF,
             bytes(record.frame.data)) for record in publication_records(lab, bus)]


def open_result(board, publisher):
    return parse_result(board.command(f"pubsub open {publisher}", timeout=STEP))


def test_every_write_reaches_a_remote_subscriber_once_over_two_buses(pair):
    lab, one, two = pair
    publisher = publish(two, "level", count=40)
    assert publisher.startswith("0x00028")
    subscribe(one, publisher)
    wait_tally(lab, one, lambda status, _: status != "busy", "the subscriber to open")
    two.command("pubsub go")
    status, counts = wait_tally(lab, one, lambda _, c: c["last"] == 40, "the 40th page")
    assert status == "ok"
    assert counts == {"received": 40, "last": 40, "repeats": 0, "torn": 0, "gaps": 0, "deleted": 0,
                      "timeouts": 0}
    # Three frames per publication on each bus, at the writer's priority,
    # to the broadcast address, from CAN node 2, eight bytes each.
    lab.hub.wait_until(lab.hub.now_ns + 5_000_000, STEP)
    for bus in ("can0", "can1"):
        frames = publication_frames(lab, bus)
        assert len(frames) == 3 * 40, bus
        assert {(priority, destination, source, len(data)) for _, priority, destination, source, data in frames} \
            == {(10, 255, 2, 8)}
        # The parts in order, and the sequence numbers 1 to 40.
        assert [data[0] >> 6 for *_, data in frames] == [0, 1, 2] * 40
        assert [int.from_bytes(data[2:4], "big") for *_, data in frames[::3]] == list(range(1, 41))
    statistics = net_counters(one, "publications")
    assert statistics["received"] == 40 and statistics["duplicates"] == 40, statistics
    assert statistics["torn"] == 0 and statistics["withdrawals"] == 0
    assert net_counters(two, "remote")["publications-sent"] == 80


def test_a_bus_lost_during_publication_loses_no_sample(pair):
    lab, one, two = pair
    publisher = publish(two, "flow", count=60, period_ms=20)
    subscribe(one, publisher)
    wait_tally(lab, one, lambda status, _: status != "busy", "the subscriber to open")
    two.command("pubsub go")
    wait_tally(lab, one, lambda _, c: c["last"] >= 20, "the 20th page")
    # Node 2's channel 0 goes bus-off and stays off: can0 carries nothing
    # more from it, and its transmit queue fills.
    lab.hub.force_bus_off("board2.0")
    status, counts = wait_tally(lab, one, lambda _, c: c["last"] == 60, "the 60th page")
    assert status == "ok"
    assert counts["received"] == 60 and counts["gaps"] == 0, counts
    assert counts["repeats"] == 0 and counts["torn"] == 0, counts
    can0, can1 = publication_frames(lab, "can0"), publication_frames(lab, "can1")
    assert len(can1) == 3 * 60
    assert len(can0) < 3 * 45, "can0 went quiet after the bus-off"
    statistics = net_counters(one, "publications")
    assert statistics["received"] == 60
    assert statistics["duplicates"] < 45
    # A publication cut off on can0 half-way is dropped there, never mixed.
    assert net_counters(two, "remote")["send-failures"] > 0


def test_a_new_subscriber_gets_the_latest_page_at_once_and_the_deletion(pair):
    lab, one, two = pair
    publisher = publish(two, "setpoint", count=5, period_ms=5)
    two.command("pubsub go")
    lab.hub.wait_until(lab.hub.now_ns + 100_000_000, STEP)
    assert published(two) == 5
    # The publisher writes no more; a subscriber opened now has page 5 at
    # once, sent again by node 2 on receiving the Open.
    subscribe(one, publisher)
    status, counts = wait_tally(lab, one, lambda _, c: c["received"] == 1, "the latest page")
    assert status == "ok" and counts["last"] == 5 and counts["repeats"] == 0
    assert net_counters(one, "publications")["received"] == 1
    # Deleting the publisher withdraws it: the waiting reader gets Deleted.
    two.command("pubsub delete")
    status, counts = wait_tally(lab, one, lambda _, c: c["deleted"] == 1, "the withdrawal")
    assert counts["received"] == 1
    statistics = net_counters(one, "publications")
    assert statistics["withdrawals"] == 1
    # The remote publisher is free again once its subscription is closed.
    assert "publisher 0x" not in one.command("net publications")


def test_an_interrupt_handlers_write_is_published_by_the_network_task(pair):
    lab, one, two = pair
    publisher = publish(two, "sampled", count=0)
    subscribe(one, publisher)
    wait_tally(lab, one, lambda status, _: status != "busy", "the subscriber to open")
    # The spare line's routine writes pages 1 and 2 of the publisher; the
    # handler cannot use a driver, node 2's network receiver publishes them.
    for counter in (1, 2):
        assert parse_result(two.command(f"pubsub isr {counter}"))[0] == "ok"
        status, counts = wait_tally(lab, one, lambda _, c, n=counter: c["last"] == n, f"page {counter}")
    assert counts["received"] == 2 and counts["repeats"] == 0 and counts["torn"] == 0, counts
    assert net_counters(two, "publications")["deferred"] == 2
    # At the priority of the task that last wrote it, or created it: 10.
    assert {priority for _, priority, _, _, _ in publication_frames(lab)} == {10}


def test_opening_a_remote_publisher_is_refused_as_a_local_open_would_be(pair):
    lab, one, two = pair
    local_only = publish(two, "private", visibility="local", count=0)
    regional = publish(two, "cabinet", visibility="regional", count=0)
    semaphore = created(two, "remote sem 1", "RSEM")
    assert open_result(one, local_only)[0] == "not permitted"
    assert open_result(one, regional)[0] == "not permitted", "regional: the nodes of one controller, not the bus"
    assert open_result(one, semaphore)[0] == "wrong object type"
    # A publisher index no publisher has, on node 2: node 2's own refusal.
    assert open_result(one, "0x00028fff")[0] == open_result(two, "0x00028fff")[0]
    # A node the tables do not know.
    assert open_result(one, "0x00098001")[0] == "remote object unreachable"
    # Refusals leave nothing behind: no remote publisher is held.
    assert "publisher 0x" not in one.command("net publications")
    global_one = publish(two, "shared", count=0)
    status, subscription, _ = open_result(one, global_one)
    assert status == "ok" and subscription != 0
    # Open and Close: its remote publisher is free again.
    assert "publisher 0x" not in one.command("net publications")


def remote_publishers(board):
    return re.findall(r"^  publisher (0x[0-9a-f]{8})", board.command("net publications"), re.M)


def test_a_dead_node_gives_unreachable_and_leaves_nothing_held(pair):
    lab, one, two = pair
    # Node 3 is mapped, with a CAN node number, but no board answers.
    for line in ("net map 3 130.1.0.3", "net neighbour 130.1.0.3 3"):
        assert "error:" not in one.command(line)
    status, _, microseconds = open_result(one, "0x00038000")
    assert status == "node unreachable"
    assert microseconds < 1_000_000, "given up by the watchdog, not a time-out of its own"
    assert remote_publishers(one) == []
    # A task killed while it waits for the dead node leaves nothing either.
    subscriber = re.search(r"PTASK (0x[0-9a-f]{8})", one.command("pubsub subscribe 0x00038000 5")).group(1)
    lab.hub.wait_until(lab.hub.now_ns + 60_000_000, STEP)
    assert remote_publishers(one) == ["0x00038000"], "held while the Open waits"
    assert "RKILL ok" in one.command(f"remote kill {subscriber}")
    assert remote_publishers(one) == []


def test_a_subscriber_killed_while_it_reads_gives_its_remote_publisher_back(pair):
    lab, one, two = pair
    publisher = publish(two, "quiet", count=0)
    subscriber = re.search(r"PTASK (0x[0-9a-f]{8})", one.command(f"pubsub subscribe {publisher} 5")).group(1)
    wait_tally(lab, one, lambda status, _: status == "ok", "the subscriber to open")
    assert remote_publishers(one) == [publisher]
    assert "RKILL ok" in one.command(f"remote kill {subscriber}")
    assert remote_publishers(one) == []
    # Node 2 does not know or care: its publisher carries on.
    assert open_result(one, publisher)[0] == "ok"


def test_the_remote_publisher_table_full_is_refused_and_recovers(pair):
    lab, one, two = pair
    capacity = 16  # DCOS_CONFIG_REMOTE_PUBLISHERS
    publishers = [publish(two, f"p{index}", count=0) for index in range(capacity + 1)]
    for publisher in publishers[:capacity]:
        assert parse_result(one.command(f"pubsub hold {publisher}"))[0] == "ok"
    # Another subscription to one already read shares its slot.
    assert parse_result(one.command(f"pubsub hold {publishers[0]}"))[0] == "ok"
    assert parse_result(one.command(f"pubsub hold {publishers[capacity]}"))[0] == "object table full"
    assert net_counters(one, "publications")["no-remote-publisher"] == 1
    assert len(remote_publishers(one)) == capacity
    assert parse_result(one.command("pubsub release"))[1] == capacity + 1
    assert remote_publishers(one) == []
    assert parse_result(one.command(f"pubsub hold {publishers[capacity]}"))[0] == "ok"
