"""Following a node live over CAN (docs/protocols/monitor.md,
docs/guide/monitor.md): dcos-mon on the lab's CAN bus against the system
engineering interface agent of a running node, booted from its card with
an application that publishes a ramp (tests_renode/monitor/ramp_app): the
ramp's fields arrive once a period, the console arrives as lines, the plot
is a PNG of the asked size, a tool killed outright leaves a stream that
ends with its lease, a publisher the node does not have is refused, and a
node with closed queries needs the key.

Every wait is on the lab's emulated time or has a generous bound, so the
test does not depend on how fast the host runs the boards: dcos-mon is
stopped by a signal once the bus has carried what the test needs, not
after host seconds. Every stream frame on the bus is read by an observer
written from the protocol's page alone (dcoslab/monitorwire.py).
"""
import json
import os
import re
import signal
import struct
import subprocess

import pytest

from dcoslab.cards import BIN, config_key, new_card, signed_application
from dcoslab.monitorwire import read_stream

BITRATE = 1_000_000
# Bounds on a hung board or tool, not speeds.
TIMEOUT = 900
NODE = 3
HOST = 254
# The ramp application is built once for the module's tests, so they run in
# one worker.
pytestmark = pytest.mark.xdist_group("test_mon_can")
SAMPLE = re.compile(r"^(?P<t>\d+\.\d{3}) (?P<node>\d+) (?P<label>\S+) (?P<value>-?\d+)$")


@pytest.fixture(scope="module")
def ramp_image(tmp_path_factory):
    """tests_renode/monitor/ramp_app built against the staged SDK, signed with the development key."""
    return signed_application(tmp_path_factory.mktemp("apps"), "tests_renode/monitor/ramp_app")


def ramp_card(tmp_path, image, serial, node, key=None, options=()):
    """A card with the ramp's image, the serial number, node id and key given."""
    directory = tmp_path / f"n{serial}"
    directory.mkdir()
    extra = ["--serial", str(serial), "--bitrate", str(BITRATE), *options]
    if key is not None:
        extra += ["--config-key", key]
    return new_card(directory, ("A", image, False), append=f"node={node}", options=tuple(extra))


def ramp_lab(canlab, tmp_path, image, serial, key=None, options=(), witness=False):
    """The ramp's node (board1, node 3); with @p witness a second node on the
    bus (board2, node 4), which acknowledges frames as every other node of a
    real bus does once the host tool has gone: a frame nobody acknowledges is
    sent again and again, and the stream's end would never leave."""
    wiring = {"board1": {"bus0": "can0", "card": ramp_card(tmp_path, image, serial, NODE, key, options)}}
    if witness:
        wiring["board2"] = {"bus0": "can0", "card": ramp_card(tmp_path, image, serial + 1000, NODE + 1)}
    lab = canlab({"can0": BITRATE}, wiring)
    board = lab.board("board1")
    # The lab waited for the console's prompt, which comes after the loader's report.
    listing = board.command("app", timeout=TIMEOUT)
    assert "application 'ramp': running" in listing, listing
    lab.hub.wait_on_bus([f"{name}.0" for name in wiring], TIMEOUT)
    return lab, board


def interface(lab):
    return f"lab:{lab.socket_path}:can0"


def mon(lab, *arguments, code=0):
    """dcos-mon run to its end; its (standard output, standard error)."""
    result = subprocess.run([os.path.join(BIN, "dcos-mon"), "-i", interface(lab), *arguments], capture_output=True,
                            text=True, timeout=TIMEOUT)
    assert result.returncode == code, (result.returncode, result.stdout, result.stderr, lab.hub.log_text()[-4000:])
    return result.stdout, result.stderr


class Following:
    """dcos-mon started in the background, its output into files (no pipe to fill)."""

    def __init__(self, lab, tmp_path, name, *arguments):
        self.out_path = tmp_path / f"{name}.out"
        self.err_path = tmp_path / f"{name}.err"
        self.out = open(self.out_path, "w")
        self.err = open(self.err_path, "w")
        self.process = subprocess.Popen([os.path.join(BIN, "dcos-mon"), "-i", interface(lab), *arguments],
                                        stdout=self.out, stderr=self.err)

    def stop(self, how=signal.SIGINT):
        self.process.send_signal(how)
        code = self.process.wait(timeout=TIMEOUT)
        self.out.close()
        self.err.close()
        return code, self.out_path.read_text(), self.err_path.read_text()


def stream(lab):
    return read_stream(lab.hub.frames())


def wait_for_stream(lab, predicate, what):
    lab.hub.wait_for(lambda: predicate(read_stream(lab.hub.records)), TIMEOUT, what)
    return stream(lab)


def png_size(path):
    with open(path, "rb") as handle:
        head = handle.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR", head
    return struct.unpack(">II", head[16:24])


def test_dcos_mon_follows_a_ramp_and_the_console_and_plots_it(canlab, tmp_path, ramp_image):
    lab, board = ramp_lab(canlab, tmp_path, ramp_image, 7007)
    plot = tmp_path / "ramp.png"
    following = Following(lab, tmp_path, "ramp", "-n", str(NODE), "--log", "--data", "ramp:u32",
                          "--data", "ramp@4:i16=negative", "--data", "ramp@6:u8=low", "--period-ms", "100",
                          "--lease-s", "60", "--silence-s", "600", "--png", str(plot), "--png-size", "640x400")
    # Three seconds of the node's time from the first sample on.
    first = wait_for_stream(lab, lambda s: any(f["kind"] == "sample" for f in s), "the first sample")
    started = next(f["end_ns"] for f in first if f["kind"] == "sample")
    lab.hub.wait_until(started + 3_000_000_000, TIMEOUT)
    # Something typed on the node's console arrives as a log line.
    board.command("echo watched-from-the-host")
    wait_for_stream(lab, lambda s: b"watched-from-the-host" in b"".join(f["text"] for f in s if f["kind"] == "log"),
                    "the echoed text in the stream")
    lab.hub.wait_until(lab.hub.now_ns + 1_500_000_000, TIMEOUT)
    code, out, err = following.stop(signal.SIGINT)
    assert code == 0, (code, out, err)

    samples = {}
    logs = []
    for line in out.splitlines():
        match = SAMPLE.match(line)
        if match:
            assert int(match["node"]) == NODE, line
            samples.setdefault(match["label"], []).append((float(match["t"]), int(match["value"])))
        elif line.startswith("log: "):
            logs.append(line[5:])
        else:
            raise AssertionError(f"a line that is neither a sample nor a log line: {line!r}")
    assert set(samples) == {"ramp:u32", "negative", "low"}, samples.keys()
    ramp = samples["ramp:u32"]
    assert len(ramp) >= 30, ramp
    # The ramp rises by two per 100 ms period (it counts 50 ms periods),
    # and the node's time between samples is the period.
    for (t0, v0), (t1, v1) in zip(ramp, ramp[1:]):
        assert v1 > v0, ramp
        assert 0.09 <= t1 - t0 <= 0.21, ramp
    assert abs((ramp[-1][1] - ramp[0][1]) / (ramp[-1][0] - ramp[0][0]) - 20) < 2, ramp
    # The signed field is the ramp's negative, sign-extended; the byte its low bits.
    for (t, value), (tn, negative), (tl, low) in zip(ramp, samples["negative"], samples["low"]):
        assert t == tn == tl
        assert negative == -value and low == value % 256, (value, negative, low)
    # The application's own lines and the echo.
    assert any(re.fullmatch(r"ramp: \d+", line) for line in logs), logs
    assert any("watched-from-the-host" in line for line in logs), logs
    assert "frames lost" not in out, out
    assert png_size(plot) == (640, 400)

    # On the wire: every stream frame decodes by the page, goes to the host
    # from the node at the request's priority, and SIGINT stopped the stream.
    frames = stream(lab)
    assert {(f["priority"], f["destination"], f["source"]) for f in frames} == {(31, HOST, NODE)}, frames[:5]
    ends = [f for f in frames if f["kind"] == "end"]
    assert [e["reason"] for e in ends] == ["stopped"], ends
    assert frames[-1]["kind"] == "end", frames[-3:]
    log_frames = [f for f in frames if f["kind"] == "log"]
    assert [f["sequence"] for f in log_frames] == [i % 256 for i in range(len(log_frames))], log_frames[:5]


def test_a_killed_tool_leaves_a_stream_that_ends_with_its_lease(canlab, tmp_path, ramp_image):
    lab, _ = ramp_lab(canlab, tmp_path, ramp_image, 7008, witness=True)
    following = Following(lab, tmp_path, "killed", "-n", str(NODE), "--data", "ramp", "--period-ms", "50",
                          "--lease-s", "3", "--silence-s", "600")
    wait_for_stream(lab, lambda s: sum(f["kind"] == "sample" for f in s) >= 5, "five samples")
    code, _, _ = following.stop(signal.SIGKILL)
    assert code == -signal.SIGKILL
    killed = lab.hub.now_ns
    # The lease is 3 s of the node's time from the last renewal, which was
    # before the kill (or on its way): the end within 3 s and a margin.
    lab.hub.wait_until(killed + 5_000_000_000, TIMEOUT)
    frames = stream(lab)
    ends = [f for f in frames if f["kind"] == "end"]
    assert [e["reason"] for e in ends] == ["lease expired"], ends
    assert ends[0]["end_ns"] <= killed + 4_000_000_000, (ends[0], killed)
    assert frames[-1]["kind"] == "end", frames[-3:]
    # And nothing more, however long the bus is watched.
    count = len(frames)
    lab.hub.wait_until(lab.hub.now_ns + 2_000_000_000, TIMEOUT)
    assert len(stream(lab)) == count

    # A publisher the node does not have is refused, and the kernel's status named.
    _, errors = mon(lab, "-n", str(NODE), "--data", "nosuch", code=1)
    assert "not found" in errors and "nosuch" in errors, errors
    _, errors = mon(lab, "-n", str(NODE), "--data", f"0x{(NODE << 16) | (8 << 12) | 0xFFF:08x}", code=1)
    assert "kernel refused it" in errors and "(Monitor)" in errors, errors
    assert re.search(r"invalid id|stale id", errors), errors
    _, errors = mon(lab, "-n", str(NODE), "--data", f"0x{(9 << 16) | (8 << 12) | 1:08x}", code=1)
    assert "invalid id" in errors, errors   # Another node's publisher.
    # A period the node does not take.
    _, errors = mon(lab, "-n", str(NODE), "--data", "ramp", "--period-ms", "5", code=2)
    # Nobody at a number: silence, exit 4.
    mon(lab, "-n", "77", "--data", "ramp", "--retries", "1", "--timeout-ms", "500", code=4)
    # None of these started a stream.
    assert len(stream(lab)) == count


def test_a_node_with_closed_queries_needs_the_key(canlab, tmp_path, ramp_image):
    key = config_key(tmp_path, "k")
    lab, _ = ramp_lab(canlab, tmp_path, ramp_image, 7009, key, options=("--closed-queries",))
    _, errors = mon(lab, "-n", str(NODE), "--data", "ramp", code=2)
    assert "-K" in errors and "closed queries" in errors, errors
    assert not stream(lab)
    following = Following(lab, tmp_path, "keyed", "-n", str(NODE), "-K", key, "--json", "--data", "ramp=count",
                          "--lease-s", "60", "--silence-s", "600")
    wait_for_stream(lab, lambda s: sum(f["kind"] == "sample" for f in s) >= 10, "ten samples")
    code, out, err = following.stop(signal.SIGTERM)
    assert code == 0, (code, out, err)
    events = [json.loads(line) for line in out.splitlines()]
    values = [e["value"] for e in events if e.get("label") == "count"]
    assert len(values) >= 5 and values == sorted(values), events
    assert all(e["node"] == NODE for e in events), events
    assert [f["reason"] for f in stream(lab) if f["kind"] == "end"] == ["stopped"]
