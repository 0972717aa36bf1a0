"""Objects two gateways away (seed 6.4, 7.13): four 486 boards on three CAN buses in a row.

    node 1 --can0-- node 2 --can1-- node 4 --can2-- node 3

Node 2 joins can0 and can1, node 4 can1 and can2; each end node has routes to the networks beyond through its
gateway, and each gateway a route to the far network through the other gateway. A routed request from node 1
crosses node 2 and node 4 one hop at a time (docs/protocols/remote-transactions.md, "Gateways"); a name query
relayed to node 2 carries the relays it may still make, so node 2 passes it to node 4, which asks can2; a
publisher on node 3 opened from node 1 is relayed by node 4 onto can1 and by node 2 onto can0, each relay header
counting the gateways crossed before (docs/protocols/publications.md, "Across a gateway").

Times are emulated (-icount); every wait has a generous time-out that bounds a hung board, not a speed.
"""

import pytest

from dcoslab.remote import REPLY, REQUEST, SEMAPHORE_SEQUENCE as SEQUENCE, created, net_counters, \
    read_pages_across, semaphore_sequence, wait_tally
from dcoslab import remote

from test_remote_gateway import BIT_RATE, RELAYED, ROUTED, SILENT_PERIODS, WATCHDOG_MS, configure, frames

NAME_QUERY = 0x12


@pytest.fixture
def chain(canlab):
    lab = canlab({"can0": BIT_RATE, "can1": BIT_RATE, "can2": BIT_RATE},
                 {"node1": {"bus0": "can0", "append": "node=1"},
                  "node2": {"bus0": "can0", "bus1": "can1", "append": "node=2"},
                  "node4": {"bus0": "can1", "bus1": "can2", "append": "node=4"},
                  "node3": {"bus0": "can2", "append": "node=3"}})
    one, two, four, three = (lab.board(f"node{node}") for node in (1, 2, 4, 3))
    configure(one, [f"can up can0 {BIT_RATE}", "net interface can 0 130.1.0.1/16 1",
                    "net map 2 130.1.0.2", "net neighbour 130.1.0.2 2",
                    "net map 4 130.2.0.4", "net route 130.2.0.0/16 130.1.0.2",
                    "net map 3 130.4.0.3", "net route 130.4.0.0/16 130.1.0.2", "can attach can0"])
    configure(two, [f"can up can0 {BIT_RATE}", f"can up can1 {BIT_RATE}",
                    "net interface can 0 130.1.0.2/16 2", "net interface can 1 130.2.0.2/16 2",
                    "net map 1 130.1.0.1", "net neighbour 130.1.0.1 1",
                    "net map 4 130.2.0.4", "net neighbour 130.2.0.4 4",
                    "net map 3 130.4.0.3", "net route 130.4.0.0/16 130.2.0.4", "can attach can0", "can attach can1"])
    configure(four, [f"can up can0 {BIT_RATE}", f"can up can1 {BIT_RATE}",
                     "net interface can 0 130.2.0.4/16 4", "net interface can 1 130.4.0.4/16 4",
                     "net map 2 130.2.0.2", "net neighbour 130.2.0.2 2",
                     "net map 3 130.4.0.3", "net neighbour 130.4.0.3 3",
                     "net map 1 130.1.0.1", "net route 130.1.0.0/16 130.2.0.2", "can attach can0", "can attach can1"])
    configure(three, [f"can up can0 {BIT_RATE}", "net interface can 0 130.4.0.3/16 3",
                      "net map 4 130.4.0.4", "net neighbour 130.4.0.4 4",
                      "net map 2 130.2.0.2", "net route 130.2.0.0/16 130.4.0.4",
                      "net map 1 130.1.0.1", "net route 130.1.0.0/16 130.4.0.4", "can attach can0"])
    return lab, one, two, four, three


def test_a_semaphore_two_gateways_away_answers_as_a_local_one(chain):
    lab, one, two, four, three = chain
    semaphore, far = semaphore_sequence(one, three)
    assert semaphore.startswith("0x0003")
    # The 200 ms wait was node 3's; the answer came back through both gateways after it.
    assert 200 <= far[4][2] / 1000 < 200 + 4 * SILENT_PERIODS * WATCHDOG_MS
    # One hop at a time: node 1 asked node 2 with routed requests, node 2 asked node 4 with routed requests of
    # one hop fewer, node 4 asked node 3 plainly; each reply went back the same way.
    routed = {bus: frames(lab, bus, ROUTED) for bus in ("can0", "can1")}
    assert {(d, s) for _, d, s, _ in routed["can0"]} == {(2, 1)}
    assert {(d, s) for _, d, s, _ in routed["can1"]} == {(4, 2)}
    headers = {bus: {data[0] for *_, data in found if len(data) == 4} for bus, found in routed.items()}
    assert headers == {"can0": {0xC4}, "can1": {0xC3}}, headers
    assert {(d, s) for _, d, s, _ in frames(lab, "can2", REQUEST)} == {(3, 4)}
    assert {(d, s) for _, d, s, _ in frames(lab, "can2", REPLY)} == {(4, 3)}
    assert net_counters(two)["forwarded"] == net_counters(four)["forwarded"] == len(SEQUENCE)
    assert net_counters(one)["routed-requests"] == len(SEQUENCE)


def test_names_two_gateways_away_are_found_and_local_ones_stay_unseen(chain):
    lab, one, two, four, three = chain
    pump = created(three, "remote named pump global", "RSEM")
    status, value, _ = remote.call(one, "name semaphore pump")
    assert (status, f"0x{value:08x}") == ("ok", pump)
    lab.hub.wait_until(lab.hub.now_ns + 2_000_000, 60)
    # Node 1 broadcast its query on can0 and sent it to node 2 alone with 3 relays left; node 2 broadcast it on
    # can1 and sent it to node 4 alone with 2 left; node 4 broadcast it on can2 and had no gateway to pass it to.
    relays = {bus: sorted((d, s, data[6]) for _, d, s, data in frames(lab, bus, NAME_QUERY) if data[0] >> 6 == 2)
              for bus in ("can0", "can1", "can2")}
    assert relays == {"can0": [(2, 1, 3), (255, 1, 0)], "can1": [(4, 2, 2), (255, 2, 0)],
                      "can2": [(255, 4, 0)]}, relays
    assert net_counters(two)["forwarded"] == net_counters(four)["forwarded"] == 1
    # The way back: node 3 finds node 1's name through node 4 and node 2.
    vent = created(one, "remote named vent global", "RSEM")
    status, value, _ = remote.call(three, "name semaphore vent")
    assert (status, f"0x{value:08x}") == ("ok", vent)
    # A local object stays unseen two gateways away: not found, once every gateway's own query ran out, the
    # nearer ones answering their askers' retransmissions pending meanwhile.
    created(three, "remote named door local", "RSEM")
    status, _, us = remote.call(one, "name semaphore door")
    assert status == "not found"
    assert (3 * SILENT_PERIODS - 1) * WATCHDOG_MS * 1000 <= us < 5 * SILENT_PERIODS * WATCHDOG_MS * 1000, us
    # Found by name, used by id: the id works two gateways away.
    assert remote.call(one, f"count {pump}")[0] == "ok"


def test_a_publisher_two_gateways_away_is_read_through_both(chain):
    lab, one, two, four, three = chain
    publisher = read_pages_across(lab, three, one)
    assert publisher.startswith("0x00038")
    lab.hub.wait_until(lab.hub.now_ns + 5_000_000, 60)
    # Node 4 relays node 3's frames onto can1, headers saying no gateway before; node 2 relays those onto can0,
    # headers saying one gateway before; each frame once, in the order node 3 sent them.
    near, middle = frames(lab, "can0", RELAYED), frames(lab, "can1", RELAYED)
    assert {data for *_, data in near[0::2]} == {bytes([0xFF, 1, 0, 3])}
    assert {data for *_, data in middle[0::2]} == {bytes([0xFF, 0, 0, 3])}
    originals = [data for *_, data in frames(lab, "can2", 0x20)]
    middle_parts = [data for *_, data in middle[1::2]]
    near_parts = [data for *_, data in near[1::2]]
    assert middle_parts == originals[-len(middle_parts):]
    assert near_parts == middle_parts[-len(near_parts):]
    assert len(near_parts) >= 3 * 20
    assert {(d, s) for _, d, s, _ in near} == {(255, 2)} and {(d, s) for _, d, s, _ in middle} == {(255, 4)}
    assert net_counters(two)["publications-relayed"] == len(near_parts)
    # The withdrawal crosses both gateways too.
    three.command("pubsub delete")
    status, counts = wait_tally(lab, one, lambda _, c: c["deleted"] == 1, "the withdrawal")
    assert counts["received"] == 20
