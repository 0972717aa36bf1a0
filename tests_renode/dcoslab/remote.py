"""Boards that use each other's objects: the lab side of remote transactions.

The words the emulator tests (test_remote_transactions*.py) and the bench's
remote figures (bench/remote_bench.py) share: bringing a board's CAN
channel up as a network interface of the network interfaces manager, and
calling a primitive through the test image's `remote` console command
(tests_renode/target/RemoteTransactionsTest.cpp). docs/guide/remote-objects.md
walks through the same commands.
"""

import re

_RESULT = re.compile(r"RRES (.+) (\d+) (\d+)\r?$", re.M)

# The CAN message types of remote transactions and publications (docs/protocols/can.md).
REQUEST, REPLY, PUBLICATION = 0x11, 0x10, 0x20


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
