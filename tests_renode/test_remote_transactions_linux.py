"""Remote transactions and publications against a node we did not write: python-can on the Linux kernel's SocketCAN.

docs/protocols/remote-transactions.md specifies the request and the reply
byte by byte. Here a peer written from that page alone, in Python with
python-can and struct (PEER below, no code of ours), runs in the lab VM on
the kernel's can0 (slcan, bridged to the lab hub) as DCOS node 3 with CAN
node number 3. It holds one counting semaphore, object 0xA001, of count 5.
An emulated 486 board, node 1, uses that semaphore by its id through the
ordinary semaphore primitives; then the peer uses one of the board's
semaphores by sending the board requests of its own. Last, publications
(docs/protocols/publications.md): the board subscribes to the peer's
publisher, which publishes pages with a duplicate, a malformed frame and a
torn page among them, then withdraws it; and the peer reads the board's
publisher from its frames. Then the global time base
(docs/protocols/time.md): the peer decodes the board's Syncs and FollowUps,
and the board follows the peer as its time master. Last, the peer sends a
message to a port of the board (docs/protocols/remote-transactions.md,
"Port sends"), and asks the board, as its gateway, for its own semaphore
("Gateways"): the board forwards the routed request back to the peer as
its own request and relays the answer. Last, the peer's task holds a
binary semaphore of the board ("Binary semaphores") and owns a timer of
the board, whose alarm the board posts to it ("Timers"); and it is the
board's gateway to a publisher a bus away, whose frames it relays
(docs/protocols/publications.md, "Across a gateway"). Last, the peer's task
holds a binary semaphore of the board again, and the peer announces that
it started ("A node that starts again"): the board frees the semaphore. The
peer also checks the board's own announcement, sent when it attached.

Emulated time is paced at a fiftieth of wall time, so that the VM's
answers, slow under an emulated CPU on a busy host, come well within the
board's watchdog (4 periods of 50 ms emulated, 10 s of wall time); the
peer answers a retransmitted request again, from what it stored, as the
protocol asks.
"""

import re

import pytest

from dcoslab.board import load_board
from dcoslab.canbus import Frame
from dcoslab.canlab import CanLab
from dcoslab import remote
from dcoslab.labvm import LabVM, SlcanSetup
from dcoslab.remote import attach_node, created, page_of, wait_tally
from dcoslab.slcan_bridge import SlcanBridge
from dcoslab.vmworld import BridgedWorld, attach_reports, hold_world

pytestmark = pytest.mark.xdist_group("test_remote_transactions_linux")

BITRATE = 500_000
PACE = 0.02
BOOT_TIMEOUT = 240
STEP = 120
GO = 0x7F5

PEER = r"""
import struct, sys
import can

REQUEST, REPLY = 0x11, 0x10
ME, BOARD = 3, 1
GO = 0x7F5
OK, INVALID_ID, WOULD_BLOCK, NOT_SUPPORTED = 0, 1, 8, 18
ACQUIRE, RELEASE, COUNT = 1, 2, 3

bus = can.Bus(channel="can0", interface="socketcan")
print("@@READY peer@@", flush=True)

def identifier(priority, kind, destination, source):
    return priority << 24 | kind << 16 | destination << 8 | source

def fields(message):
    raw = message.arbitration_id
    return raw >> 24, (raw >> 16) & 0xFF, (raw >> 8) & 0xFF, raw & 0xFF

NODE_STARTED = 0x14

def receive(seconds=120):
    # A node's announcement that it started (docs/protocols/remote-
    # transactions.md, "A node that starts again") is printed, not returned:
    # no phase waits for one.
    while True:
        message = bus.recv(timeout=seconds)
        if message is None:
            print("@@PEER silence@@", flush=True)
            sys.exit(1)
        if message.is_extended_id and fields(message)[1] == NODE_STARTED:
            priority, kind, destination, source = fields(message)
            print(f"@@PEER ANNOUNCED priority={priority} destination={destination} source={source} "
                  f"data={bytes(message.data).hex()}@@", flush=True)
            continue
        return message

def await_reply(tag):
    # The board's reply to this node's request, printed field by field.
    while True:
        message = receive()
        if not message.is_extended_id:
            continue
        priority, kind, destination, source = fields(message)
        if kind == REPLY and destination == ME and source == BOARD:
            break
    got_service, got_transaction, status, flags, value = struct.unpack(">BBBBI", bytes(message.data))
    print(f"@@PEER {tag} priority={priority} service={got_service} transaction={got_transaction:02X} "
          f"status={status} flags={flags} value={value}@@", flush=True)

# Phase 1: serve node 1 until the go frame, whose data is the object of a
# semaphore of node 1. Semaphore 0xA003 has no unit: an Acquire that waits
# for it is kept alive with pending replies, one per retransmission, until
# the third retransmission, when a unit "arrives" and the final reply goes.
counts = {0xA001: 5, 0xA003: 0}
served = {}
waiting = {}
while True:
    message = receive()
    if not message.is_extended_id:
        if message.arbitration_id == GO:
            board_object = struct.unpack(">H", bytes(message.data))[0]
            break
        continue
    priority, kind, destination, source = fields(message)
    if kind != REQUEST or destination != ME:
        continue
    data = bytes(message.data)
    key = (source, data[1])
    service, transaction, obj, argument = struct.unpack(">BBHI", data)
    if key in waiting:
        waiting[key] += 1
        final = waiting[key] >= 3
        print(f"@@PEER RETRANSMISSION {waiting[key]}@@", flush=True)
        if final:
            del waiting[key]
            served[key] = struct.pack(">BBBBI", service, transaction, OK, 0, 0)
        else:
            bus.send(can.Message(arbitration_id=identifier(priority, REPLY, source, ME), is_extended_id=True,
                                 data=struct.pack(">BBBBI", service, transaction, OK, 1, 0)))
            continue
    if key not in served:
        print(f"@@PEER REQUEST priority={priority} service={service} transaction={transaction:02X} "
              f"object={obj:04X} argument={argument}@@", flush=True)
        status, value = OK, 0
        if obj not in counts:
            status = INVALID_ID
        elif service == COUNT:
            value = counts[obj]
        elif service == RELEASE:
            counts[obj] += 1
        elif service == ACQUIRE and counts[obj] > 0:
            counts[obj] -= 1
        elif service == ACQUIRE and argument > 0:
            waiting[key] = 0
            continue
        elif service == ACQUIRE:
            status = WOULD_BLOCK
        else:
            status = NOT_SUPPORTED
        served[key] = struct.pack(">BBBBI", service, transaction, status, 0, value)
    bus.send(can.Message(arbitration_id=identifier(priority, REPLY, source, ME), is_extended_id=True,
                         data=served[key]))

# Phase 2: use node 1's semaphore: release it, then read its count.
for transaction, service in ((0x21, RELEASE), (0x22, COUNT)):
    bus.send(can.Message(arbitration_id=identifier(9, REQUEST, BOARD, ME), is_extended_id=True,
                         data=struct.pack(">BBHI", service, transaction, board_object, 0)))
    await_reply("REPLY")

# Phase 3: publications (docs/protocols/publications.md). The board opens a
# subscription to this node's publisher 0x00038005: answer its DsmOpen
# request, then publish pages 1 to 4 with what a bus can do to them: page 1
# twice (as a second bus would bring it), a frame of the wrong length, page
# 2 with its second part lost, pages 3 and 4 whole. The withdrawal waits
# for the go frame WITHDRAW.
PUBLICATION, DSM_OPEN, WITHDRAW = 0x20, 9, 0x7F6

def page_of(counter):
    words = (counter, ~counter & 0xFFFFFFFF, (counter * 2654435761) & 0xFFFFFFFF, counter ^ 0x5A5A5A5A)
    return b"".join(word.to_bytes(4, "big") for word in words)

def parts(index, sequence, page):
    tag = sequence & 3
    def head(part):
        return bytes([part << 6 | tag << 4 | index >> 8, index & 0xFF])
    return [head(0) + sequence.to_bytes(2, "big") + page[0:4], head(1) + page[4:10], head(2) + page[10:16]]

def publish(data):
    bus.send(can.Message(arbitration_id=identifier(12, PUBLICATION, 0xFF, ME), is_extended_id=True, data=data))

while True:
    message = receive()
    if not message.is_extended_id:
        continue
    priority, kind, destination, source = fields(message)
    if kind == REQUEST and destination == ME and bytes(message.data)[0] == DSM_OPEN:
        break
service, transaction, obj, argument = struct.unpack(">BBHI", bytes(message.data))
print(f"@@PEER OPEN priority={priority} object={obj:04X} argument={argument}@@", flush=True)
bus.send(can.Message(arbitration_id=identifier(priority, REPLY, source, ME), is_extended_id=True,
                     data=struct.pack(">BBBBI", service, transaction, OK, 0, 0)))
one, two, three, four = (parts(0x005, n, page_of(n)) for n in (1, 2, 3, 4))
for data in one + one + [one[0][:7]] + [two[0], two[2]] + three + four:
    publish(data)
print("@@PEER PUBLISHED@@", flush=True)
while True:
    message = receive()
    if not message.is_extended_id and message.arbitration_id == WITHDRAW:
        break
publish(bytes([0xC0, 0x05]))
print("@@PEER WITHDRAWN@@", flush=True)

# Then read the board's own publications, three pages, and put them back
# together from the frames as the page above specifies.
pages = 0
gathering = None
while pages < 3:
    message = receive()
    if not message.is_extended_id:
        continue
    priority, kind, destination, source = fields(message)
    if kind != PUBLICATION or source != BOARD:
        continue
    data = bytes(message.data)
    part, tag, index = data[0] >> 6, (data[0] >> 4) & 3, (data[0] & 0x0F) << 8 | data[1]
    if part == 0 and len(data) == 8:
        gathering = [int.from_bytes(data[2:4], "big"), data[4:8], 1]
    elif gathering and part == gathering[2] and tag == gathering[0] & 3 and len(data) == 8:
        gathering[1] += data[2:8]
        gathering[2] += 1
        if part == 2:
            print(f"@@PEER PAGE priority={priority} destination={destination} index={index:03X} "
                  f"sequence={gathering[0]} page={gathering[1].hex()}@@", flush=True)
            pages += 1
            gathering = None
    else:
        gathering = None

# Phase 4: the global time base (docs/protocols/time.md). First the board is
# the master: read three of its Sync and FollowUp pairs and put each time
# back together from the Sync's seconds and the FollowUp's 56 bits.
TIME, TIME_GO = 0x01, 0x7F7
LOW56 = (1 << 56) - 1
syncs = {}
pairs = 0
while pairs < 3:
    message = receive()
    if not message.is_extended_id:
        continue
    priority, kind, destination, source = fields(message)
    if kind != TIME or source != BOARD:
        continue
    data = bytes(message.data)
    sort, sequence = data[0] >> 6, data[0] & 0x3F
    if sort == 0 and len(data) == 8:
        syncs[sequence] = (int.from_bytes(data[1:6], "big"), data[6], data[7] * 100)
    elif sort == 1 and len(data) == 8 and sequence in syncs:
        seconds, rank, interval = syncs.pop(sequence)
        low = int.from_bytes(data[1:8], "big")
        start = seconds * 1_000_000_000
        time = (start & ~LOW56) | low
        if time < start:
            time += 1 << 56
        print(f"@@PEER TIME priority={priority} destination={destination} sequence={sequence} rank={rank} "
              f"interval={interval} seconds={seconds} time={time}@@", flush=True)
        pairs += 1
# Then this node is the master, of rank 0, announcing a second's interval:
# its clock says 2030-01-01 00:00:00.5 UTC at the end of its first Sync.
# A second round follows 0.2 s later, which the paced lab makes 4 ms of
# emulated time, and says 4 ms later. It starts at the go frame.
while True:
    message = receive()
    if not message.is_extended_id and message.arbitration_id == TIME_GO:
        break
import time as wall
first = 1_893_456_000 * 1_000_000_000 + 500_000_000
for sequence in range(2):
    moment = first + sequence * 4_000_000
    bus.send(can.Message(arbitration_id=identifier(0, TIME, 0xFF, ME), is_extended_id=True,
                         data=bytes([sequence]) + (moment // 1_000_000_000).to_bytes(5, "big") + bytes([0, 10])))
    bus.send(can.Message(arbitration_id=identifier(0, TIME, 0xFF, ME), is_extended_id=True,
                         data=bytes([0x40 | sequence]) + (moment & LOW56).to_bytes(7, "big")))
    wall.sleep(0.2)
print("@@PEER SYNCED@@", flush=True)

# Phase 5: a port send (docs/protocols/remote-transactions.md, "Port sends")
# to the board's port, whose object comes in the go frame PORT: sixteen
# bytes 0xA0 to 0xAF at priority 4, transaction 0x35, in three frames;
# then the reply.
PORT_GO, PORT_SEND = 0x7F8, 11
while True:
    message = receive()
    if not message.is_extended_id and message.arbitration_id == PORT_GO:
        port = struct.unpack(">H", bytes(message.data))[0]
        break
body = bytes(range(0xA0, 0xB0))
transaction = 0x35
for data in (struct.pack(">BBHb", PORT_SEND, transaction, port, 4) + body[0:3],
             bytes([0x80 | 1 << 4 | transaction & 0x0F]) + body[3:10],
             bytes([0x80 | 2 << 4 | transaction & 0x0F]) + body[10:16]):
    bus.send(can.Message(arbitration_id=identifier(9, REQUEST, BOARD, ME), is_extended_id=True, data=data))
await_reply("PORTREPLY")

# Phase 6: the board as this node's gateway (docs/protocols/remote-
# transactions.md, "Gateways"). At the go frame ROUTE, ask the board, as a
# routed request (type 0x13), to count semaphore 0xA001 of node 3, which is
# this node: a route header with 4 hops left naming node 3, then the
# request, transaction 0x41. The board performs it as its own transaction
# with node 3, so this node serves the board's request (and any
# retransmission of it) until the board's reply to the routed request comes.
ROUTED, ROUTE_GO = 0x13, 0x7F9
while True:
    message = receive()
    if not message.is_extended_id and message.arbitration_id == ROUTE_GO:
        break
for data in (bytes([0xC0 | 4, 0x41, 0, ME]), struct.pack(">BBHI", COUNT, 0x41, 0xA001, 0)):
    bus.send(can.Message(arbitration_id=identifier(9, ROUTED, BOARD, ME), is_extended_id=True, data=data))
while True:
    message = receive()
    if not message.is_extended_id:
        continue
    priority, kind, destination, source = fields(message)
    if destination != ME or source != BOARD:
        continue
    if kind == REQUEST:
        service, transaction, obj, argument = struct.unpack(">BBHI", bytes(message.data))
        print(f"@@PEER GATEWAYREQUEST priority={priority} service={service} object={obj:04X} "
              f"argument={argument}@@", flush=True)
        bus.send(can.Message(arbitration_id=identifier(priority, REPLY, source, ME), is_extended_id=True,
                             data=struct.pack(">BBBBI", service, transaction, OK, 0, counts.get(obj, 0))))
    elif kind == REPLY and bytes(message.data)[1] == 0x41 and not bytes(message.data)[3] & 1:
        service, transaction, status, flags, value = struct.unpack(">BBBBI", bytes(message.data))
        print(f"@@PEER ROUTEDREPLY priority={priority} service={service} transaction={transaction:02X} "
              f"status={status} flags={flags} value={value}@@", flush=True)
        break

# Phase 7: a binary semaphore of the board, held by this node's task
# 0x00031005 (docs/protocols/remote-transactions.md, "Binary semaphores").
# At the go frame HELD, whose data is the semaphore's object: a plain
# Acquire, which the board refuses naming the held form (status 18, value
# 1); then the held acquire, two frames; at the go frame LET_GO, the held
# acquire again (the holder asking again: would deadlock, 17) and the held
# release.
HELD_GO, LET_GO, HELD_ACQUIRE, HELD_RELEASE = 0x7FA, 0x7FB, 12, 13
HOLDER = 0x00031005

def go(identifier_wanted):
    while True:
        message = receive()
        if not message.is_extended_id and message.arbitration_id == identifier_wanted:
            return bytes(message.data)

def held_acquire(transaction, semaphore):
    for data in (struct.pack(">BBHI", HELD_ACQUIRE, transaction, semaphore, 0),
                 bytes([0x80 | 3 << 4 | transaction & 0x0F]) + HOLDER.to_bytes(4, "big") + bytes(3)):
        bus.send(can.Message(arbitration_id=identifier(9, REQUEST, BOARD, ME), is_extended_id=True, data=data))

semaphore = struct.unpack(">H", go(HELD_GO))[0]
bus.send(can.Message(arbitration_id=identifier(9, REQUEST, BOARD, ME), is_extended_id=True,
                     data=struct.pack(">BBHI", ACQUIRE, 0x51, semaphore, 0)))
await_reply("HELDASK")
held_acquire(0x52, semaphore)
await_reply("HELD")
go(LET_GO)
held_acquire(0x53, semaphore)
await_reply("AGAIN")
bus.send(can.Message(arbitration_id=identifier(9, REQUEST, BOARD, ME), is_extended_id=True,
                     data=struct.pack(">BBHI", HELD_RELEASE, 0x54, semaphore, HOLDER)))
await_reply("LETGO")

# Phase 8: a timer of the board owned by this node's task 0x00031005
# (docs/protocols/remote-transactions.md, "Timers"). The board asks about
# the task first (TaskGetState of object 0x1005): answer it is ready (2).
# At the go frame ALARM, whose data is the timer's object, set a watch-dog
# alarm of 20 ms whose events are 0x40: three frames laid out as a port
# send's. Then answer the board's PostEvent of those events to the task.
ALARM_GO, SET_ALARM, GET_STATE, POST_EVENT = 0x7FC, 14, 6, 4

def serve_one(expected_service):
    while True:
        message = receive()
        if not message.is_extended_id:
            continue
        priority, kind, destination, source = fields(message)
        if kind != REQUEST or destination != ME or source != BOARD:
            continue
        service, transaction, obj, argument = struct.unpack(">BBHI", bytes(message.data))
        if service != expected_service:
            continue
        print(f"@@PEER SERVED priority={priority} service={service} object={obj:04X} argument={argument}@@", flush=True)
        value = 2 if service == GET_STATE else 0
        bus.send(can.Message(arbitration_id=identifier(priority, REPLY, source, ME), is_extended_id=True,
                             data=struct.pack(">BBBBI", service, transaction, OK, 0, value)))
        return

serve_one(GET_STATE)
timer = struct.unpack(">H", go(ALARM_GO))[0]
record = HOLDER.to_bytes(4, "big") + (0x40).to_bytes(4, "big") + (20_000_000).to_bytes(8, "big")
transaction = 0x61
for data in (struct.pack(">BBHB", SET_ALARM, transaction, timer, 0x01) + record[0:3],
             bytes([0x80 | 1 << 4 | transaction & 0x0F]) + record[3:10],
             bytes([0x80 | 2 << 4 | transaction & 0x0F]) + record[10:16]):
    bus.send(can.Message(arbitration_id=identifier(9, REQUEST, BOARD, ME), is_extended_id=True, data=data))
await_reply("ALARMSET")
serve_one(POST_EVENT)

# Phase 9: this node as the board's gateway to node 5, a bus away
# (docs/protocols/publications.md, "Across a gateway"). The board opens
# node 5's publisher 0x00058007 with a routed DsmOpen to this node: a route
# header naming node 5, then the request. Answer it, then relay pages 1 to
# 3 of that publisher, each frame behind a relay header naming node 5; a
# relayed frame without its header goes first, which the board must drop.
RELAYED = 0x21
while True:
    message = receive()
    if not message.is_extended_id:
        continue
    priority, kind, destination, source = fields(message)
    if kind == ROUTED and destination == ME and len(message.data) == 4:
        route = bytes(message.data)
        print(f"@@PEER ROUTE hops={route[0] & 0x0F} node={route[2] << 8 | route[3]}@@", flush=True)
    elif kind == ROUTED and destination == ME and bytes(message.data)[0] == DSM_OPEN:
        break
service, transaction, obj, argument = struct.unpack(">BBHI", bytes(message.data))
print(f"@@PEER RELAYOPEN priority={priority} object={obj:04X}@@", flush=True)
bus.send(can.Message(arbitration_id=identifier(priority, REPLY, source, ME), is_extended_id=True,
                     data=struct.pack(">BBBBI", service, transaction, OK, 0, 0)))

def relay(data):
    for frame in (bytes([0xFF, 0, 0, 5]), data):
        bus.send(can.Message(arbitration_id=identifier(12, RELAYED, 0xFF, ME), is_extended_id=True, data=frame))

first = parts(0x007, 1, page_of(1))
bus.send(can.Message(arbitration_id=identifier(12, RELAYED, 0xFF, ME), is_extended_id=True, data=first[0]))
for n in (1, 2, 3):
    for data in parts(0x007, n, page_of(n)):
        relay(data)
print("@@PEER RELAYED@@", flush=True)

# Phase 10: this node starts again ("A node that starts again"). At the go
# frame RESTART, whose data is a binary semaphore's object, its task
# 0x00031005 takes it in the held form; then the node announces that it
# started, as it would on its first attach after a restart, and its task
# of before holds nothing any more.
RESTART_GO = 0x7FD
semaphore = struct.unpack(">H", go(RESTART_GO))[0]
held_acquire(0x61, semaphore)
await_reply("HELDAGAIN")
bus.send(can.Message(arbitration_id=identifier(31, NODE_STARTED, 0xFF, ME), is_extended_id=True,
                     data=ME.to_bytes(2, "big") + bytes(6)))
print("@@PEER RESTARTED@@", flush=True)
bus.shutdown()
"""

VM_SCRIPT = r"""
. /run/labvm/lib.sh
cd /tmp
timeout 600 /usr/bin/python3 /run/labvm/files/peer.py
echo "@@PEER status=$?@@"
"""


@pytest.fixture(scope="module")
def world():
    def build(world):
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BITRATE},
                           {"board1": {"bus0": "can0", "append": "node=1"}}, pace=PACE, kind="test")
        world.board = world.lab.board("board1")
        world.vm = LabVM(VM_SCRIPT, slcan=SlcanSetup("can0", BITRATE), connect_slcan=False, files={"peer.py": PEER},
                         boot_timeout=BOOT_TIMEOUT, timeout=900)
        world.vm.start()
        world.bridge = SlcanBridge(world.vm.slcan_socket_path, world.lab.socket_path, "can0").start()
        world.bridge.wait_for(lambda b: b.is_open, BOOT_TIMEOUT, "slcand to open the channel")
        # The peer listens before the board attaches, so that it hears the
        # board's announcement that it started.
        world.vm.expect(r"@@READY peer@@", timeout=BOOT_TIMEOUT)
        attach_node(world.board, 1, [3], BITRATE, timeout=STEP)

    yield from hold_world(BridgedWorld(), build)


@pytest.fixture(autouse=True)
def _reports(request):
    attach_reports(request)


def call(world, line):
    """A `remote` primitive's status and value."""
    return remote.call(world.board, line, timeout=STEP)[:2]


def peer_line(world, tag):
    return world.vm.expect(rf"@@PEER {tag} ([^@]*)@@", timeout=STEP).group(1).decode()


def test_the_board_uses_a_semaphore_of_a_python_can_node(world):
    # The board announced at its attach that it had started: to every node,
    # its id in the first two bytes.
    assert peer_line(world, "ANNOUNCED") == "priority=31 destination=255 source=1 data=0001000000000000"
    assert call(world, "count 0x0003a001") == ("ok", 5)
    assert call(world, "acquire 0x0003a001 0") == ("ok", 0)
    assert call(world, "count 0x0003a001") == ("ok", 4)
    assert call(world, "release 0x0003a001") == ("ok", 0)
    assert call(world, "count 0x0003a002") == ("invalid id", 0)
    requests = [peer_line(world, "REQUEST") for _ in range(5)]
    # What the peer read, field by field, from the board's frames: the
    # console's priority (24), the service, the object, the time-out of a
    # polling Acquire (0 ms); each transaction number different.
    assert [re.sub(r" transaction=\w+", "", line) for line in requests] == [
        "priority=24 service=3 object=A001 argument=0",
        "priority=24 service=1 object=A001 argument=0",
        "priority=24 service=3 object=A001 argument=0",
        "priority=24 service=2 object=A001 argument=0",
        "priority=24 service=3 object=A002 argument=0",
    ]
    transactions = [re.search(r"transaction=(\w+)", line).group(1) for line in requests]
    assert len(set(transactions)) == len(transactions), transactions


def test_the_board_waits_on_a_python_can_node_kept_alive_by_its_pending_replies(world):
    # The peer answers the first two retransmissions "pending" and the third
    # with the unit: the board waited through three watchdog periods, the
    # last two of them not silent, and did not give up.
    status, value, us = remote.call(world.board, "acquire 0x0003a003 5000", timeout=STEP)
    assert (status, value) == ("ok", 0)
    assert us >= 3 * 50_000
    request = peer_line(world, "REQUEST")
    assert request.startswith("priority=24 service=1 ") and request.endswith("object=A003 argument=5000"), request
    assert [peer_line(world, "RETRANSMISSION") for _ in range(3)] == ["1", "2", "3"]
    counters = world.board.command("net remote")
    assert re.search(r"pending-replies [1-9]", counters), counters
    assert re.search(r"unreachable 0\r?$", counters, re.M), counters


def test_a_python_can_node_uses_a_semaphore_of_the_board(world):
    semaphore = created(world.board, "remote sem 0", "RSEM")
    index = int(semaphore, 16) & 0xFFFF
    # A hub node's go frame tells the peer the object (2 bytes, big-endian).
    world.lab.hub.inject("can0", "lab", Frame.data_frame(GO, index.to_bytes(2, "big")))
    replies = [peer_line(world, "REPLY") for _ in range(2)]
    assert replies == ["priority=9 service=2 transaction=21 status=0 flags=0 value=0",
                       "priority=9 service=3 transaction=22 status=0 flags=0 value=1"], replies
    assert call(world, f"count {semaphore}") == ("ok", 1)


def test_publications_between_the_board_and_a_python_can_node(world):
    # The board reads the peer's publisher 0x00038005 through a subscription.
    output = world.board.command("pubsub subscribe 0x00038005 5", timeout=STEP)
    assert "PTASK" in output, output
    assert peer_line(world, "OPEN") == "priority=5 object=8005 argument=0"
    world.vm.expect(r"@@PEER PUBLISHED@@", timeout=STEP)
    # Pages 1, 3 and 4, each once; page 2 lost its second part and was
    # dropped, never mixed with another (received, last, repeats, torn, gaps).
    status, counts = wait_tally(world.lab, world.board, lambda _, c: c["last"] == 4, "page 4", STEP)
    assert status == "ok", status
    assert (counts["received"], counts["repeats"], counts["torn"], counts["gaps"]) == (3, 0, 0, 1), counts
    statistics = world.board.command("net publications", timeout=STEP)
    assert re.search(r"^  duplicates 1\r?$", statistics, re.M), statistics
    assert re.search(r"^  torn 1\r?$", statistics, re.M), statistics
    assert "publisher 0x00038005  subscriptions 1  data 3" in statistics, statistics
    assert re.search(r"malformed [1-9]", world.board.command("net remote", timeout=STEP))
    # The withdrawal: the board's reader is told the publisher is gone.
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7F6, b""))
    world.vm.expect(r"@@PEER WITHDRAWN@@", timeout=STEP)
    status, counts = wait_tally(world.lab, world.board, lambda _, c: c["deleted"] == 1, "the withdrawal", STEP)
    assert counts["received"] == 3
    # The peer reads the board's publisher, written three times at priority 7.
    output = world.board.command("pubsub publish out global 7 10 3", timeout=STEP)
    index = int(re.search(r"PPUB (0x[0-9a-f]{8})", output).group(1), 16) & 0x0FFF
    world.board.command("pubsub go", timeout=STEP)
    pages = [peer_line(world, "PAGE") for _ in range(3)]
    assert pages == [f"priority=7 destination=255 index={index:03X} sequence={n} page={page_of(n).hex()}"
                     for n in (1, 2, 3)], pages


def test_the_global_time_base_between_the_board_and_a_python_can_node(world):
    # The board is the master, rank 2, once a second: the peer decodes its
    # Syncs and FollowUps (docs/protocols/time.md) and puts the times back
    # together; they follow one another by the interval of the board's clock.
    assert "error" not in world.board.command("net time master 2 1000", timeout=STEP)
    times = [peer_line(world, "TIME") for _ in range(3)]
    fields = [dict(item.split("=") for item in line.split()) for line in times]
    assert {(f["priority"], f["destination"], f["rank"], f["interval"]) for f in fields} == {("0", "255", "2", "1000")}
    moments = [int(f["time"]) for f in fields]
    for f, moment in zip(fields, moments):
        assert 0 <= moment - int(f["seconds"]) * 1_000_000_000 < 2_000_000_000, f
    # One Sync a second of the board's clock (its sync task's wake-up, a few
    # hundred microseconds late at most), in sequence.
    assert all(999_000_000 < b - a < 1_002_000_000 for a, b in zip(moments, moments[1:])), moments
    assert [int(f["sequence"]) for f in fields] == [int(fields[0]["sequence"]) + n for n in range(3)]
    # Then the board follows the peer, a master of rank 0 whose clock says
    # 2030: the board's clock goes there, only its base changing.
    assert "error" not in world.board.command("net time follow", timeout=STEP)
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7F7, b""))
    world.vm.expect(r"@@PEER SYNCED@@", timeout=STEP)
    status = world.board.command("net time", timeout=STEP)
    assert "following node 3, rank 0, every 1000 ms, interface 0" in status, status
    # The first correction steps the clock; the second, 4 ms of the peer's
    # time later, lands within the step limit of the first (10 ms).
    assert re.search(r"^  corrections 2\r?$", status, re.M), status
    assert re.search(r"^  unpaired 0\r?$", status, re.M) and re.search(r"^  malformed 0\r?$", status, re.M), status
    assert "2030-01-01 00:00:0" in world.board.command("date", timeout=STEP)


def test_a_python_can_node_sends_a_message_to_a_port_of_the_board(world):
    # docs/protocols/remote-transactions.md, "Port sends": the peer's three
    # frames, put together by the board and sent to its port; one reply.
    port = created(world.board, "remote port", "RPORT")
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7F8, (int(port, 16) & 0xFFFF).to_bytes(2, "big")))
    assert peer_line(world, "PORTREPLY") == "priority=9 service=11 transaction=35 status=0 flags=0 value=0"
    output = world.board.command("remote portgot", timeout=STEP)
    assert f"RPGOT 1 a0 {bytes(range(0xA0, 0xB0)).hex()}" in output, output


def test_a_python_can_node_asks_through_the_board_as_its_gateway(world):
    # The peer's routed request names node 3, itself: the board forwards it
    # as its own request to node 3, at the peer's priority, and replies with
    # what it got, the count of 0xA001 the peer keeps.
    before = remote.net_counters(world.board)
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7F9, b"\x00"))
    forwarded = peer_line(world, "GATEWAYREQUEST")
    assert forwarded == "priority=9 service=3 object=A001 argument=0", forwarded
    assert peer_line(world, "ROUTEDREPLY") == "priority=9 service=3 transaction=41 status=0 flags=0 value=5"
    after = remote.net_counters(world.board)
    assert after["forwarded"] - before["forwarded"] == 1 and after["unrouted"] == before["unrouted"]


def test_a_python_can_node_holds_a_binary_semaphore_of_the_board(world):
    # docs/protocols/remote-transactions.md, "Binary semaphores": the peer's
    # plain Acquire is refused naming the held form; its held acquire makes
    # its task 0x00031005 the holder, which the board's own task may not
    # release; asked again by the holder it would deadlock; its release frees it.
    binary = created(world.board, "remote sem binary", "RSEM")
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7FA, (int(binary, 16) & 0xFFFF).to_bytes(2, "big")))
    assert peer_line(world, "HELDASK") == "priority=9 service=1 transaction=51 status=18 flags=0 value=1"
    assert peer_line(world, "HELD") == "priority=9 service=12 transaction=52 status=0 flags=0 value=0"
    assert call(world, f"holder {binary}") == ("ok", 0x00031005)
    assert call(world, f"release {binary}") == ("not owner", 0)
    assert call(world, f"acquire {binary} 0") == ("would block", 0)
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7FB, b""))
    assert peer_line(world, "AGAIN") == "priority=9 service=12 transaction=53 status=17 flags=0 value=0"
    assert peer_line(world, "LETGO") == "priority=9 service=13 transaction=54 status=0 flags=0 value=0"
    assert call(world, f"holder {binary}") == ("ok", 0)
    assert call(world, f"acquire {binary} 0") == ("ok", 0)


def test_a_python_can_node_owns_a_timer_of_the_board_and_gets_its_alarm(world):
    # docs/protocols/remote-transactions.md, "Timers": the board gives its
    # timer to the peer's task, asking the peer about it first; the peer sets
    # a watch-dog alarm of 20 ms, and the board's notifier posts its events
    # to the peer's task at priority 1.
    timer = created(world.board, "remote timer", "RTIMER")
    assert call(world, f"give {timer} 0x00031005") == ("ok", 0)
    assert peer_line(world, "SERVED") == "priority=24 service=6 object=1005 argument=0"
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7FC, (int(timer, 16) & 0xFFFF).to_bytes(2, "big")))
    assert peer_line(world, "ALARMSET") == "priority=9 service=14 transaction=61 status=0 flags=0 value=0"
    assert peer_line(world, "SERVED") == "priority=1 service=4 object=1005 argument=64"
    # The board counts it once the peer's reply is in.
    end = world.lab.hub.now_ns + 2_000_000_000
    while remote.net_counters(world.board)["alarms-notified"] != 1:
        assert world.lab.hub.now_ns < end, "the notification was never answered"
        world.lab.hub.wait_until(world.lab.hub.now_ns + 20_000_000, STEP)


def test_the_board_reads_a_publisher_a_python_can_gateway_relays(world):
    # docs/protocols/publications.md, "Across a gateway": the peer is the
    # board's gateway to node 5; the board opens node 5's publisher through
    # it and takes the pages it relays, dropping a relayed frame without its header.
    for line in ("net map 5 130.2.0.5", "net route 130.2.0.0/16 130.1.0.3"):
        assert "error" not in world.board.command(line, timeout=STEP)
    before = remote.net_counters(world.board)
    output = world.board.command("pubsub subscribe 0x00058007 5", timeout=STEP)
    assert "PTASK" in output, output
    assert peer_line(world, "ROUTE") == "hops=4 node=5"
    assert peer_line(world, "RELAYOPEN") == "priority=5 object=8007"
    world.vm.expect(r"@@PEER RELAYED@@", timeout=STEP)
    status, counts = wait_tally(world.lab, world.board, lambda _, c: c["last"] == 3, "page 3", STEP)
    assert status == "ok", status
    assert (counts["received"], counts["repeats"], counts["torn"]) == (3, 0, 0), counts
    assert remote.net_counters(world.board)["unrouted"] - before["unrouted"] == 1


def test_a_python_can_node_that_starts_again_holds_nothing_of_before(world):
    # docs/protocols/remote-transactions.md, "A node that starts again": the
    # peer's task holds a binary semaphore of the board, then the peer
    # announces that node 3 started; the board frees the semaphore.
    binary = created(world.board, "remote sem binary", "RSEM")
    world.lab.hub.inject("can0", "lab", Frame.data_frame(0x7FD, (int(binary, 16) & 0xFFFF).to_bytes(2, "big")))
    assert peer_line(world, "HELDAGAIN") == "priority=9 service=12 transaction=61 status=0 flags=0 value=0"
    world.vm.expect(r"@@PEER RESTARTED@@", timeout=STEP)
    world.vm.expect(r"@@PEER status=0@@", timeout=STEP)
    # The announcement crossed the bridge before the peer's script ended; a
    # few emulated milliseconds later the board has taken it.
    world.lab.hub.wait_until(world.lab.hub.now_ns + 20_000_000, STEP)
    assert call(world, f"holder {binary}") == ("ok", 0)
    assert call(world, f"acquire {binary} 0") == ("ok", 0)
    counters = remote.net_counters(world.board)
    assert (counters["nodes-started"], counters["holds-freed"]) == (1, 1), counters
