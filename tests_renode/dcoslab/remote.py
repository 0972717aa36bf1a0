"""Boards that use each other's objects: the lab side of remote transactions and publications.

The words the emulator tests (test_remote_transactions*.py) and the bench's
remote figures (bench/remote_bench.py) share: bringing a board's CAN
channel up as a network interface of the network interfaces manager, and
calling a primitive through the test image's `remote` console command
(tests_renode/target/RemoteTransactionsTest.cpp), publishing and
subscribing through its `pubsub` command (tests_renode/target/
PublicationsTest.cpp). docs/guide/remote-objects.md walks through the same
commands.
"""

import re

_RESULT = re.compile(r"RRES (.+) (\d+) (\d+)\r?$", re.M)

# The CAN message types of remote transactions and publications (docs/protocols/can.md).
REQUEST, REPLY, PUBLICATION = 0x11, 0x10, 0x20
# A node's announcement that it started (docs/protocols/remote-transactions.md, "A node that starts again").
NODE_STARTED = 0x14


def attach_node(board, node, peers, bitrate, timeout=120):
    """Channel 0 up as interface 0: network address 130.1.0.<node>, CAN node <node>; each peer mapped alike."""
    lines = [f"can up can0 {bitrate}", f"net interface can 0 130.1.0.{node}/16 {node}"]
    for peer in peers:
        lines += [f"net map {peer} 130.1.0.{peer}", f"net neighbour 130.1.0.{peer} {peer}"]
    for line in lines:
        output = board.command(line, timeout=timeout)
        assert "error:" not in output, (line, output)
    output = board.command("can attach can0", timeout=timeout)
    assert f"can0 carries interface 0: 130.1.0.{node}/16, CAN node {node}" in output, output


def attach_redundant(board, node, peers, bitrate, timeout=120, policy="auto"):
    """Both channels up as interfaces 0 and 1, on subnets 130.1 and 130.2: CAN node <node> on each.

    Each peer is mapped onto both subnets (multi-homed), 130.1 first, so a
    remote transaction goes over channel 0 and a publication over both.
    policy: what a channel does after bus-off ("manual": it stays off)."""
    lines = []
    for channel in (0, 1):
        lines += [f"can up can{channel} {bitrate}", f"can policy can{channel} {policy}",
                  f"net interface can {channel} 130.{channel + 1}.0.{node}/16 {node}"]
    for peer in peers:
        for channel in (0, 1):
            lines += [f"net map {peer} 130.{channel + 1}.0.{peer}", f"net neighbour 130.{channel + 1}.0.{peer} {peer}"]
    for line in lines:
        output = board.command(line, timeout=timeout)
        assert "error:" not in output, (line, output)
    for channel in (0, 1):
        output = board.command(f"can attach can{channel}", timeout=timeout)
        assert f"can{channel} carries interface {channel}: 130.{channel + 1}.0.{node}/16, CAN node {node}" in output, \
            output


def net_counters(board, verb="remote"):
    """The counters `net remote` or `net publications` prints, by name."""
    output = board.command(f"net {verb}")
    return {name: int(value) for name, value in re.findall(r"^  ([a-z-]+) (\d+)\r?$", output, re.M)}


def created(board, line, tag):
    """Runs a `remote` command that creates an object ("remote sem 1", tag RSEM); its id."""
    output = board.command(line)
    match = re.search(tag + r" (0x[0-9a-f]{8})", output)
    assert match, output
    return match.group(1)


def parse_result(text):
    """(status, value, microseconds) from a `remote` primitive's RRES line."""
    match = _RESULT.search(text)
    assert match, text
    return match.group(1), int(match.group(2)), int(match.group(3))


def call(board, line, timeout=120):
    """Runs a `remote` primitive ("count 0x0002a001"); (status, value, microseconds)."""
    return parse_result(board.command("remote " + line, timeout=timeout))


# The calls the remote semaphore tests make on a counting semaphore of count 1 and maximum 2, and what each
# answers, remote or local: the same sequence wherever the semaphore is.
SEMAPHORE_SEQUENCE = ["count {}", "acquire {} 0", "count {}", "acquire {} 0", "acquire {} 200", "release {}",
                      "release {}", "release {}", "count {}"]
SEMAPHORE_STATUSES = ["ok", "ok", "ok", "would block", "timed out", "ok", "ok", "invalid argument", "ok"]


def semaphore_sequence(caller, owner):
    """SEMAPHORE_SEQUENCE from caller on a new semaphore of owner's, and from owner on a twin of it.

    Checks that the two give the same statuses and values, those of
    SEMAPHORE_STATUSES, and returns the far semaphore's id and the caller's
    results as call() gives them: (status, value, microseconds) per call."""
    far_semaphore = created(owner, "remote sem 1 2", "RSEM")
    local_semaphore = created(owner, "remote sem 1 2", "RSEM")
    far = [call(caller, step.format(far_semaphore)) for step in SEMAPHORE_SEQUENCE]
    local = [call(owner, step.format(local_semaphore)) for step in SEMAPHORE_SEQUENCE]
    assert [(status, value) for status, value, _ in far] == [(status, value) for status, value, _ in local], \
        (far, local)
    assert [status for status, _, _ in far] == SEMAPHORE_STATUSES, far
    return far_semaphore, far


def dcos_frames(lab, kind, records=None):
    """The bus log's DCOS frames of a message type, as (priority, destination, source, data).

    records: the hub's records as a wait_for_records predicate is given them
    (it holds the hub's lock, so lab.hub.frames() cannot be called there)."""
    frames = []
    for frame in (lab.hub.frames() if records is None else records):
        if frame.outcome != "ok" or not frame.frame.extended:
            continue
        raw = frame.frame.id
        if (raw >> 16) & 0xFF == kind:
            frames.append((raw >> 24, (raw >> 8) & 0xFF, raw & 0xFF, bytes(frame.frame.data)))
    return frames


def publish(board, name, visibility="global", priority=10, period_ms=20, count=40, timeout=120):
    """A publishing task on board (`pubsub publish`): the publisher's id. It writes after `pubsub go`."""
    output = board.command(f"pubsub publish {name} {visibility} {priority} {period_ms} {count}", timeout=timeout)
    match = re.search(r"PPUB (0x[0-9a-f]{8})", output)
    assert match, output
    return match.group(1)


def subscribe(board, publisher, priority=5, timeout_ms=None, timeout=120):
    """A subscribing task on board that reads every new page of publisher (`pubsub subscribe`)."""
    line = f"pubsub subscribe {publisher} {priority}" + ("" if timeout_ms is None else f" {timeout_ms}")
    output = board.command(line, timeout=timeout)
    assert "PTASK" in output, output


def page_of(counter):
    """The page the test image's publishing task writes for write number counter (PublicationsTest.cpp)."""
    words = (counter, ~counter & 0xFFFFFFFF, (counter * 2654435761) & 0xFFFFFFFF, counter ^ 0x5A5A5A5A)
    return b"".join(word.to_bytes(4, "big") for word in words)


TALLY_NAMES = ("received", "last", "repeats", "torn", "gaps", "deleted", "timeouts")


def tally(board, timeout=120):
    """The subscribing task's open status and its counts (`pubsub tally`), by TALLY_NAMES."""
    output = board.command("pubsub tally", timeout=timeout)
    match = re.search(r"PSUB (.+?) (\d+) (\d+) (\d+) (\d+) (\d+) (\d+) (\d+)\r?$", output, re.M)
    assert match, output
    return match.group(1), dict(zip(TALLY_NAMES, map(int, match.groups()[1:])))


def wait_tally(lab, board, predicate, what, timeout=120):
    """Polls the tally every 20 ms of emulated time until predicate(status, counts) holds.

    timeout is in seconds of emulated time: it bounds a board that stopped publishing."""
    end = lab.hub.now_ns + timeout * 1_000_000_000
    while True:
        status, counts = tally(board)
        if predicate(status, counts):
            return status, counts
        assert lab.hub.now_ns < end, f"{what}: {status} {counts}"
        lab.hub.wait_until(lab.hub.now_ns + 20_000_000, timeout)


def read_pages_across(lab, writer, reader, pages=20):
    """A global publisher "level" on writer, read by a subscriber on reader until its pages-th page.

    Checks the subscriber saw every page once, none torn, none missing, and
    returns the publisher's id; the writer goes on publishing nothing more."""
    publisher = publish(writer, "level", count=pages)
    subscribe(reader, publisher)
    wait_tally(lab, reader, lambda status, _: status != "busy", "the subscriber to open")
    writer.command("pubsub go")
    status, counts = wait_tally(lab, reader, lambda _, c: c["last"] == pages, f"page {pages}")
    assert status == "ok"
    assert (counts["received"], counts["repeats"], counts["torn"], counts["gaps"]) == (pages, 0, 0, 0), counts
    return publisher


def publication_records(lab, bus=None):
    """The bus log's publication frames (of any bus, or of bus), as the hub's records."""
    records = []
    for record in lab.hub.frames():
        raw = record.frame.id
        if record.outcome == "ok" and record.frame.extended and (raw >> 16) & 0xFF == PUBLICATION:
            if bus is None or record.bus == bus:
                records.append(record)
    return records
