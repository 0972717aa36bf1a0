"""The lab's RS-485 line (docs/protocols/labbus.md, "The RS-485 line") and Modbus RTU over it at exact timing.

Two layers:
- the line model of the hub (dcoslab/rs485.py in dcoslab/canbus.py's Hub),
  with stations written in Python: character lengths, delivery at the end
  of the stop bit, collisions, driver enable and echo;
- emulated 486 boards whose RS-485 port (COM2) is the isa-rs485-uart model
  on a lab line, against pymodbus's RTU framer (an implementation we did
  not write), libmodbus's dcos-modbus and dcos-modbus-sim through a
  pseudo-terminal station, and each other.

Every time asserted is emulated time, from the line log or the boards'
counters; every wait has a time-out that only bounds a hung run.
"""

import json
import os
import time

import pytest

from dcoslab.canbus import Client, sync_together
from dcoslab.rs485 import baud_bit_ps, char_ns, parse_line_log, sample_offset_ns

TIMEOUT = 60.0
BAUD = 19200
FORMAT = "8E1"
BIT_PS = baud_bit_ps(BAUD)
CHAR_NS = char_ns(BIT_PS, FORMAT)
# t1.5 and t3.5 at 19200 baud: 1.5 and 3.5 characters of 11 bits ([SL] 2.5.1.1), rounded up as
# fieldbus/modbus's RtuTiming rounds them.
T15_NS = -(-15 * 11 * 1_000_000_000 // (10 * BAUD))
T35_NS = -(-35 * 11 * 1_000_000_000 // (10 * BAUD))
# A host station's turnaround: t3.5 and 100 us. The controller takes an answer begun exactly t3.5
# after its request (drivers/modbus LineRunner::finishIfSent; LineRunnerTest proves it with a late
# interrupt); the margin keeps these tests about the controller. (Runs with exactly t3.5 saw
# dcos-modbus-sim leave requests unanswered, but those runs were also the most loaded ones, and the
# simulator frames requests by wall-clock silences, which load stretches: see the every-function test.)
HOST_TURNAROUND_NS = T35_NS + 100_000


# -- the line model, with stations in Python ------------------------------------------


class FakeUart:
    """An emulated station: its clock moves only at the hub's GO; it reports its driver and characters."""

    def __init__(self, socket_path, name, line="line0"):
        self.client = Client(socket_path, name, "emulated", timeout=TIMEOUT)
        self.name = name
        self.events = []
        self.client.attach(0, line, "rs485")

    def drive(self, t, on):
        self.client.send_line(f"DRIVE 0 {t} {'on' if on else 'off'}")

    def char(self, t, byte, bit_ps=BIT_PS, fmt=FORMAT):
        self.client.send_line(f"CHAR 0 {t} {bit_ps} {fmt} {byte:02x}")

    def received(self):
        """(time, byte, flags) of every RX event so far."""
        return [(int(w[3]), int(w[6], 16), w[7]) for w in (e.split() for e in self.events) if w[0] == "RX"]


def run(stations, until_ns):
    """Every fake station syncs at each boundary up to until_ns."""
    while stations[0].client.boundary <= until_ns:
        for station, lines in zip(stations, sync_together([station.client for station in stations])):
            station.events += lines


@pytest.fixture
def line_hub(hub_factory):
    def make(expect):
        return hub_factory({}, expect=expect, lines={"line0": (BAUD, FORMAT)})

    return make


def test_characters_take_their_length_and_arrive_at_the_end_of_the_stop_bit(line_hub):
    hub = line_hub(["a", "b", "c"])
    a, b, c = (FakeUart(hub.socket_path, name) for name in "abc")
    # Half a bit time: what garbles a character is known before its end is announced.
    assert hub.quantum_ns == BIT_PS // 2000
    # 8E1: 11 bits of 52083.333 ns.
    assert CHAR_NS == 572917
    start = 10 * hub.quantum_ns + 17
    a.drive(start - 1000, True)
    a.char(start, 0x11)
    a.char(start + CHAR_NS, 0x22)
    a.drive(start + 2 * CHAR_NS, False)
    run([a, b, c], start + 3 * CHAR_NS + 2 * hub.quantum_ns)
    expected = [(start + CHAR_NS, 0x11, "-"), (start + 2 * CHAR_NS, 0x22, "-")]
    assert b.received() == expected and c.received() == expected, hub.log_text()
    # No echo: a transceiver with RE tied to /DE does not hear itself.
    assert a.received() == [], hub.log_text()
    records = parse_line_log(hub.log_text())
    assert [(r.start, r.end, r.byte, r.sender, r.outcome, r.rx) for r in records] == [
        (start, start + CHAR_NS, 0x11, "a.rs485", "ok", ("b.rs485", "c.rs485")),
        (start + CHAR_NS, start + 2 * CHAR_NS, 0x22, "a.rs485", "ok", ("b.rs485", "c.rs485")),
    ], hub.log_text()


def test_two_talkers_at_once_garble_each_other(line_hub):
    hub = line_hub(["a", "b", "c"])
    a, b, c = (FakeUart(hub.socket_path, name) for name in "abc")
    start = 10 * hub.quantum_ns
    a.drive(start, True)
    a.char(start, 0xF0)
    a.drive(start + CHAR_NS, False)
    # b starts half a character later: both characters overlap the other's stop-bit sample point or start.
    b.drive(start + CHAR_NS // 2, True)
    b.char(start + CHAR_NS // 2, 0x3C)
    b.drive(start + CHAR_NS // 2 + CHAR_NS, False)
    run([a, b, c], start + 3 * CHAR_NS)
    assert c.received() == [(start + CHAR_NS, 0xF0 & 0x3C, "garbled"),
                            (start + CHAR_NS // 2 + CHAR_NS, 0xF0 & 0x3C, "garbled")], hub.log_text()
    # A talker's receiver is off while its own driver is on: b hears nothing of a's character; a's
    # driver is off again when b's stop bit is sampled, so a hears b's, garbled.
    assert b.received() == [], hub.log_text()
    assert a.received() == [(start + CHAR_NS // 2 + CHAR_NS, 0xF0 & 0x3C, "garbled")], hub.log_text()
    assert [r.outcome for r in parse_line_log(hub.log_text())] == ["garbled", "garbled"]


def test_an_enabled_idle_driver_garbles_and_a_late_start_does_not(line_hub):
    hub = line_hub(["a", "b", "c"])
    a, b, c = (FakeUart(hub.socket_path, name) for name in "abc")
    start = 10 * hub.quantum_ns
    sample = start + sample_offset_ns(BIT_PS, FORMAT)
    a.drive(start, True)
    a.char(start, 0x55)
    a.char(start + CHAR_NS, 0x66)
    a.drive(start + 2 * CHAR_NS, False)
    # b enables its driver just before the first character's stop bit is sampled: it holds the
    # line at the idle level against a's start of the second character as well.
    b.drive(sample - 1, True)
    b.drive(start + CHAR_NS + 1000, False)
    run([a, b, c], start + 3 * CHAR_NS)
    assert [(byte, flags) for _, byte, flags in c.received()] == [(0x55, "garbled"), (0x66, "garbled")], \
        hub.log_text()
    # b heard nothing while its driver was on, and the second character's stop bit came after it was off.
    assert [(byte, flags) for _, byte, flags in b.received()] == [(0x66, "garbled")], hub.log_text()
    # A driver enabled just after the sample point changes nothing for that character.
    records_before = len(parse_line_log(hub.log_text()))
    later = c.client.boundary + 10 * hub.quantum_ns
    a.drive(later, True)
    a.char(later, 0x77)
    a.drive(later + CHAR_NS, False)
    b.drive(later + sample_offset_ns(BIT_PS, FORMAT) + 1, True)
    b.drive(later + CHAR_NS + 1, False)
    run([a, b, c], later + 2 * CHAR_NS)
    assert c.received()[-1] == (later + CHAR_NS, 0x77, "-"), hub.log_text()
    assert len(parse_line_log(hub.log_text())) == records_before + 1


def test_a_host_station_is_paced_at_the_line_rate_from_the_next_boundary(line_hub):
    hub = line_hub(["a"])
    a = FakeUart(hub.socket_path, "a")
    host = Client(hub.socket_path, "host", "host", timeout=TIMEOUT)
    assert host.attach(0, "line0") == BIT_PS // 1000
    run([a], 4 * hub.quantum_ns)
    for byte in b"\x01\x02\x03":
        host.send_line(f"CHAR 0 - - - {byte:02x}")
    # The host's characters enter at the first boundary after the hub reads them: the board runs
    # boundary by boundary (a wall-clock deadline bounds only a hung hub) until it has them all.
    deadline = time.monotonic() + TIMEOUT
    while len(a.received()) < 3:
        assert time.monotonic() < deadline, hub.log_text()
        run([a], a.client.boundary)
    received = a.received()
    assert [byte for _, byte, _ in received] == [1, 2, 3], hub.log_text()
    # Back to back: each ends one character time after the one before.
    assert received[1][0] - received[0][0] == CHAR_NS and received[2][0] - received[1][0] == CHAR_NS
    records = hub.line_records()
    assert records[0].start % hub.quantum_ns == 0, "a host's first character starts at a boundary"
    host.close()


def test_the_hub_sends_a_frame_with_chosen_silences(line_hub):
    hub = line_hub(["a"])
    a = FakeUart(hub.socket_path, "a")
    run([a], 2 * hub.quantum_ns)
    at = 20 * hub.quantum_ns
    hub.line_send("line0", "lab", b"\x11\x03\x00", at_ns=at, gaps_ns=[0, 0, 900_000])
    run([a], at + 4 * CHAR_NS + 900_000)
    assert a.received() == [(at + CHAR_NS, 0x11, "-"), (at + 2 * CHAR_NS, 0x03, "-"),
                            (at + 3 * CHAR_NS + 900_000, 0x00, "-")], hub.log_text()
    assert [r.sender for r in hub.line_records()] == ["hub.lab"] * 3


# -- boards on the line: Modbus RTU at exact timing ------------------------------------------

pytest.importorskip("pymodbus")
from pymodbus.datastore import ModbusSequentialDataBlock, ModbusSlaveContext  # noqa: E402
from pymodbus.factory import ClientDecoder, ServerDecoder  # noqa: E402
from pymodbus.framer.rtu_framer import ModbusRtuFramer  # noqa: E402
from pymodbus.register_read_message import (  # noqa: E402
    ReadHoldingRegistersRequest,
    ReadHoldingRegistersResponse,
    ReadInputRegistersRequest,
)
from pymodbus.register_write_message import WriteSingleRegisterRequest  # noqa: E402

from dcoslab.board import REPOSITORY  # noqa: E402
from dcoslab.modbus_console import modbus_state, wait_for_state  # noqa: E402
from dcoslab.rs485 import LinePty  # noqa: E402

UNIT = 17
LINE = "line0"
# As test_modbus_rs485.py: a 10 kHz tick, so that the controller's t1.5 and
# t3.5 timers are not rounded up to a 1 ms tick.
APPEND = "tick_hz=10000"
# Real-time bounds for waits that end on an emulated event; they only fail a hung run.
WAIT = 60.0
DCOS_MODBUS = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-modbus")
DCOS_MODBUS_SIM = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-modbus-sim")
SENSOR = os.path.join(REPOSITORY, "host_tools", "modbus", "examples", "sensor.toml")


def request_bytes(request):
    return ModbusRtuFramer(ClientDecoder()).buildPacket(request)


def response_bytes(response):
    return ModbusRtuFramer(ServerDecoder()).buildPacket(response)


def timing_and_state(board):
    """`modbus state`'s counters, and t1.5 and t3.5 in ns (the console prints whole microseconds of T15_NS, T35_NS)."""
    output = board.command("modbus state")
    for name, exact in (("t1.5", T15_NS), ("t3.5", T35_NS)):
        assert f"{name} {exact // 1000} us" in output, output
    return {**modbus_state(board), "t1.5": T15_NS, "t3.5": T35_NS}


def wait_state(board, predicate, what):
    """Runs `modbus state` until predicate(state) holds: a wait in the controller's own time."""
    return wait_for_state(board, predicate, what, WAIT)


def wait_idle(board):
    return wait_state(board, lambda s: s["frames.receiver"] == "idle", "receiver idle")


def from_port(records, port):
    return [r for r in records if r.sender == port]


def answer_records(lab, port, count_before, what, length=None):
    """The records of the next whole message `port` puts on the line (decoded by pymodbus's client framer)."""
    messages = []

    def complete(records):
        mine = from_port(records, port)[count_before:]
        if length is not None:
            return len(mine) >= length
        framer = ModbusRtuFramer(ClientDecoder())
        messages.clear()
        try:
            framer.processIncomingPacket(bytes(r.byte for r in mine), messages.append, unit=UNIT, single=True)
        except Exception:  # a cut-off frame: not all here yet
            return False
        return bool(messages)

    records = lab.hub.wait_for_line_records(complete, WAIT, what)
    return from_port(records, port)[count_before:]


def decode_answer(records):
    framer = ModbusRtuFramer(ClientDecoder())
    messages = []
    framer.processIncomingPacket(bytes(r.byte for r in records), messages.append, unit=UNIT, single=True)
    assert messages, f"no message in {bytes(r.byte for r in records).hex()}"
    return messages[0]


@pytest.fixture
def slave_on_line(canlab):
    """One board, the controller as slave 17 at 19200 8E1, its COM2 on line0 with the lab's station."""
    lab = canlab({}, {"board1": {"rs485": LINE}}, lines={LINE: (BAUD, FORMAT)}, kind="production", append=APPEND)
    board = lab.board("board1")
    out = board.command(f"modbus slave {UNIT} {BAUD}")
    assert f"slave {UNIT} on COM2 at {BAUD} baud 8E1" in out, out
    # A receiver just started ignores a frame until the line has been silent
    # for t3.5 ([SL] 2.5.1.1); a host program on a pty station writes its
    # first request at once, which a loaded host can make sooner than that
    # in the controller's time.
    wait_idle(board)
    return lab, board


def send_and_answer(lab, board, frame, gaps_ns=None):
    """Puts frame on the idle line from the hub's station; returns the request's and the answer's records."""
    wait_idle(board)
    before = len(lab.hub.line_records())
    answers_before = len(from_port(lab.hub.line_records(), "board1.rs485"))
    lab.hub.line_send(LINE, "lab", frame, gaps_ns=gaps_ns)
    answer = answer_records(lab, "board1.rs485", answers_before, f"the answer to {frame.hex()}")
    request = from_port(lab.hub.line_records()[before:], "hub.lab")
    return request, answer


def test_pymodbus_frames_are_answered_at_exact_rtu_timing(slave_on_line):
    lab, board = slave_on_line
    timing = timing_and_state(board)
    t15, t35 = timing["t1.5"], timing["t3.5"]
    request, answer = send_and_answer(lab, board, request_bytes(WriteSingleRegisterRequest(3, 4321, unit=UNIT)))
    assert decode_answer(answer).value == 4321
    request, answer = send_and_answer(lab, board, request_bytes(ReadHoldingRegistersRequest(3, 1, unit=UNIT)))
    # Byte for byte the answer pymodbus builds for the same data.
    assert bytes(r.byte for r in answer) == response_bytes(ReadHoldingRegistersResponse([4321], unit=UNIT))
    request, answer = send_and_answer(lab, board, request_bytes(ReadInputRegistersRequest(5, 40, unit=UNIT)))
    assert decode_answer(answer).registers == [0x1000 + 5 + i for i in range(40)]
    # 85 characters: more than the 16-byte FIFO, so the driver refilled it while the line ran.
    assert len(answer) == 85
    # In emulated time, from the line log: the slave waits t3.5 after the request's last stop bit
    # ([SL] 2.5.1.1), and its answer goes out without a silence of t1.5 inside it.
    assert answer[0].start - request[-1].end >= t35, lab.hub.log_text()
    gaps = [b.start - a.end for a, b in zip(answer, answer[1:])]
    assert max(gaps) < t15, (gaps, lab.hub.log_text())
    assert all(r.outcome == "ok" and r.rx == ("hub.lab",) for r in answer)
    seen = modbus_state(board)
    assert seen["slave.messages"] == 3 and seen["frames.gap-errors"] == 0 and seen["line.framing-errors"] == 0


def test_a_silence_just_over_t15_inside_a_frame_gets_no_answer_and_just_under_gets_one(slave_on_line):
    lab, board = slave_on_line
    t15 = timing_and_state(board)["t1.5"]
    frame = request_bytes(ReadHoldingRegistersRequest(0, 1, unit=UNIT))
    # The silence is from one character's last stop bit to the next one's start bit.
    margin = 60_000
    wait_idle(board)
    before = modbus_state(board)
    lab.hub.line_send(LINE, "lab", frame, gaps_ns=[0, 0, 0, t15 + margin, 0, 0, 0, 0])
    wait_state(board, lambda s: s["frames.seen"] > before["frames.seen"], "the frame with a silence counted")
    after = modbus_state(board)
    # Two frames on the controller's side: the first four characters, then a silence over t1.5
    # and the rest, which [SL] 2.5.1.1 makes one damaged frame: none is answered.
    assert after["frames.gap-errors"] + after["frames.short"] + after["frames.crc-errors"] > \
        before["frames.gap-errors"] + before["frames.short"] + before["frames.crc-errors"], (before, after)
    assert after["slave.messages"] == before["slave.messages"]
    assert from_port(lab.hub.line_records(), "board1.rs485") == [], lab.hub.log_text()
    # The same frame with a silence just under t1.5 is one frame, and answered.
    request, answer = send_and_answer(lab, board, frame, gaps_ns=[0, 0, 0, t15 - margin, 0, 0, 0, 0])
    assert request[3].start - request[2].end == t15 - margin
    assert decode_answer(answer).registers == [0]


def test_a_frame_started_before_t35_of_silence_is_ignored(slave_on_line):
    lab, board = slave_on_line
    timing = timing_and_state(board)
    t15, t35 = timing["t1.5"], timing["t3.5"]
    other = request_bytes(ReadHoldingRegistersRequest(0, 1, unit=UNIT + 1))
    mine = request_bytes(ReadHoldingRegistersRequest(0, 1, unit=UNIT))
    wait_idle(board)
    before = modbus_state(board)
    # A frame for another slave, then ours after more than t1.5 but less than t3.5 of silence:
    # the controller cannot see where ours begins, and answers nothing.
    gap = (t15 + t35) // 2
    lab.hub.line_send(LINE, "lab", other + mine, gaps_ns=[0] * len(other) + [gap] + [0] * (len(mine) - 1))
    wait_state(board, lambda s: s["frames.seen"] > before["frames.seen"], "the two frames counted")
    after = modbus_state(board)
    assert after["frames.gap-errors"] == before["frames.gap-errors"] + 1, (before, after)
    assert after["slave.messages"] == before["slave.messages"]
    assert after["slave.other-addresses"] == before["slave.other-addresses"]
    assert from_port(lab.hub.line_records(), "board1.rs485") == [], lab.hub.log_text()
    # With t3.5 and a little of silence the second frame is a frame of its own, and answered.
    wait_idle(board)
    records_before = len(lab.hub.line_records())
    lab.hub.line_send(LINE, "lab", other + mine, gaps_ns=[0] * len(other) + [t35 + 20_000] + [0] * (len(mine) - 1))
    answer = answer_records(lab, "board1.rs485", 0, "the answer to the second frame")
    assert decode_answer(answer).registers == [0]
    sent = from_port(lab.hub.line_records()[records_before:], "hub.lab")
    assert answer[0].start - sent[-1].end >= t35
    assert modbus_state(board)["slave.other-addresses"] == before["slave.other-addresses"] + 1


def test_two_talkers_at_once_are_dropped_and_counted_and_nothing_is_delivered_wrong(slave_on_line):
    lab, board = slave_on_line
    first = request_bytes(WriteSingleRegisterRequest(9, 0x1111, unit=UNIT))
    second = request_bytes(WriteSingleRegisterRequest(9, 0x2222, unit=UNIT))
    wait_idle(board)
    before = modbus_state(board)
    # Two stations start their frames 3 bit times apart: every character of each overlaps the other's.
    lab.hub.line_send_together(LINE, [("a", first, None),
                                      ("b", second, [3 * BIT_PS // 1000] + [0] * (len(second) - 1))])
    wait_state(board, lambda s: s["frames.seen"] > before["frames.seen"], "the collision counted")
    after = wait_idle(board)
    records = [r for r in lab.hub.line_records() if r.sender in ("hub.a", "hub.b")]
    assert len(records) == 16 and all(r.outcome == "garbled" for r in records), lab.hub.log_text()
    # The UART saw framing errors; the damaged frame was dropped and counted, nothing executed or answered.
    assert after["line.framing-errors"] >= before["line.framing-errors"] + 8, (before, after)
    dropped = sum(after[k] - before[k]
                  for k in ("frames.crc-errors", "frames.gap-errors", "frames.damaged", "frames.short"))
    assert dropped >= 1, (before, after)
    assert after["frames.delivered"] == before["frames.delivered"]
    assert after["slave.messages"] == before["slave.messages"]
    assert "data: 0" in board.command("modbus data holding 9 1")
    assert from_port(lab.hub.line_records(), "board1.rs485") == [], lab.hub.log_text()
    # The line recovers: the next frame alone is served.
    _, answer = send_and_answer(lab, board, first)
    assert decode_answer(answer).value == 0x1111


# -- host programs on the line through a pseudo-terminal station ----------------------------------

import select  # noqa: E402
import subprocess  # noqa: E402
import threading  # noqa: E402

import serial  # noqa: E402


def host_gaps(records):
    """Silences between a host station's characters: it sends back to back at the line's rate."""
    return [b.start - a.end for a, b in zip(records, records[1:])]


@pytest.fixture
def master_on_line(canlab):
    """One board on line0, paced to at most real time: a host program's time-outs are wall time,
    the controller's master time-out emulated time, and so at least as long in wall time."""
    lab = canlab({}, {"board1": {"rs485": LINE}}, lines={LINE: (BAUD, FORMAT)}, kind="production", append=APPEND,
                 pace=1.0)
    return lab, lab.board("board1")


def start_master(board):
    out = board.command(f"modbus master {BAUD} e 2000 2")
    assert f"master on COM2 at {BAUD} baud 8E1" in out, out


def read_json_line(process, what):
    """The next stdout line of a host program, within WAIT seconds."""
    ready, _, _ = select.select([process.stdout], [], [], WAIT)
    if not ready:
        raise AssertionError(f"no {what} from {process.args[0]} within {WAIT:.0f} s")
    return process.stdout.readline()


def test_the_controller_as_master_reads_dcos_modbus_sim_over_the_line(master_on_line):
    lab, board = master_on_line
    with LinePty(lab.socket_path, LINE, "sim", silence_ns=HOST_TURNAROUND_NS) as station:
        sim = subprocess.Popen([DCOS_MODBUS_SIM, "-d", station.pty_path, "-b", str(BAUD), "--parity", "E",
                                "--seed", "1", "--json", SENSOR], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)
        try:
            assert '"ready"' in read_json_line(sim, "ready line")
            start_master(board)
            # The sensor's holding register 0 is 2, input register 1 is 24000 with noise of 20.
            out = board.command("modbus read 5 holding 0 1", timeout=WAIT)
            assert "ok 03: 2" in out, (out, lab.hub.log_text())
            out = board.command("modbus read 5 input-registers 1 1", timeout=WAIT)
            match = [int(w) for w in out.split("ok 04:")[1].split()] if "ok 04:" in out else None
            assert match and abs(match[0] - 24000) <= 20, (out, lab.hub.log_text())
        finally:
            sim.terminate()
            sim.wait(timeout=WAIT)
    records = lab.hub.line_records()
    answers = from_port(records, "sim.0")
    # Two answers of 7 characters, each paced back to back from a boundary, heard by the board.
    assert len(answers) == 14 and all(r.rx == ("board1.rs485",) for r in answers), lab.hub.log_text()
    assert host_gaps(answers[:7]) == [0] * 6 and host_gaps(answers[7:]) == [0] * 6
    # Each answer starts t3.5 or later after the last stop bit of the request it answers, the last
    # request character before it (a retry, below, comes between).
    requests = from_port(records, "board1.rs485")
    for answer in (answers[0], answers[7]):
        assert answer.start - max(r.end for r in requests if r.end <= answer.start) >= T35_NS
    # Both reads ended well. A time-out followed by a good retry is allowed, as in the every-function
    # test below: dcos-modbus-sim frames requests by silences of the host's wall clock, which a loaded
    # host stretches inside a request (a fresh CI run saw it once here).
    seen = modbus_state(board)
    assert seen["master.failures"] == 0, (seen, lab.hub.log_text())


EVERY_TABLE_SIM = """\
# A slave with a few points in each of the four tables, for the controller's master.
[device]
slave = 5
vendor_name = "DCOS"
product_code = "SIM-EVERY-TABLE"
revision = "1.0"

[[coil]]
address = 0
value = true

[[coil]]
address = 1
count = 7

[[discrete_input]]
address = 0
value = true

[[discrete_input]]
address = 1
value = false

[[discrete_input]]
address = 2
value = true

[[holding_register]]
address = 0
value = 1234

[[holding_register]]
address = 1
count = 9

[[input_register]]
address = 0
value = 4321
"""


def test_the_controller_as_master_sends_every_function_code_to_dcos_modbus_sim(master_on_line, tmp_path):
    """The controller's master against libmodbus's slave (dcos-modbus-sim) over the line, with every
    function code its console sends: 01 to 06, 0F and 10, each write read back through the slave."""
    config = tmp_path / "every_table.toml"
    config.write_text(EVERY_TABLE_SIM)
    lab, board = master_on_line
    with LinePty(lab.socket_path, LINE, "sim", silence_ns=HOST_TURNAROUND_NS) as station:
        sim = subprocess.Popen([DCOS_MODBUS_SIM, "-d", station.pty_path, "-b", str(BAUD), "--parity", "E",
                                "--json", str(config)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            assert '"ready"' in read_json_line(sim, "ready line")
            start_master(board)
            for command, expected in [
                ("modbus read 5 coils 0 3", "ok 01: 1 0 0"),
                ("modbus read 5 inputs 0 3", "ok 02: 1 0 1"),
                ("modbus read 5 holding 0 2", "ok 03: 1234 0"),
                ("modbus read 5 input-registers 0 1", "ok 04: 4321"),
                ("modbus write 5 coils 2 1", "ok 05:"),
                ("modbus write 5 holding 1 777", "ok 06:"),
                ("modbus write 5 coils 4 1 0 1", "ok 0f:"),
                ("modbus write 5 holding 3 10 20 30", "ok 10:"),
                ("modbus read 5 coils 0 7", "ok 01: 1 0 1 0 1 0 1"),
                ("modbus read 5 holding 0 6", "ok 03: 1234 777 0 10 20 30"),
            ]:
                out = board.command(command, timeout=WAIT)
                assert expected in out, (command, out, lab.hub.log_text())
            # An address the slave does not have: libmodbus's exception 02, named by the controller.
            out = board.command("modbus read 5 input-registers 7 1", timeout=WAIT)
            assert "exception 02" in out, (out, lab.hub.log_text())
        finally:
            sim.terminate()
            sim.wait(timeout=WAIT)
    seen = modbus_state(board)
    # Every transaction ended well. A time-out followed by a good retry is allowed: dcos-modbus-sim
    # frames requests by silences of the host's wall clock (t3.5 of it), and a loaded host can hand
    # it a request's characters through the pty with such a gap inside, which it rightly drops as
    # noise; that is the host program's time, not the line's.
    assert seen["master.failures"] == 0 and seen["frames.crc-errors"] == 0, (seen, lab.hub.log_text())


class PymodbusSlave:
    """pymodbus's RTU framer and request classes as slave UNIT on a serial device: each request is
    decoded and executed by pymodbus against its own data store, and the answer framed by it."""

    def __init__(self, path):
        self.port = serial.Serial(path, BAUD, parity=serial.PARITY_EVEN, timeout=0.05)
        self.context = ModbusSlaveContext(hr=ModbusSequentialDataBlock(0, [100 + i for i in range(100)]),
                                          zero_mode=True)
        self.framer = ModbusRtuFramer(ServerDecoder())
        self.requests = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self):
        while not self._stop.is_set():
            data = self.port.read(256)
            if data:
                self.framer.processIncomingPacket(data, self._answer, unit=UNIT, single=False)

    def _answer(self, request):
        self.requests.append(request)
        response = request.execute(self.context)
        response.unit_id = request.unit_id
        response.transaction_id = request.transaction_id
        self.port.write(self.framer.buildPacket(response))

    def close(self):
        self._stop.set()
        self._thread.join(timeout=5)
        self.port.close()


def test_the_controller_as_master_against_a_pymodbus_slave_on_the_pty_station(master_on_line):
    lab, board = master_on_line
    with LinePty(lab.socket_path, LINE, "pymodbus", silence_ns=HOST_TURNAROUND_NS) as station:
        slave = PymodbusSlave(station.pty_path)
        try:
            start_master(board)
            out = board.command(f"modbus read {UNIT} holding 2 3", timeout=WAIT)
            assert "ok 03: 102 103 104" in out, (out, lab.hub.log_text())
            out = board.command(f"modbus write {UNIT} holding 5 777", timeout=WAIT)
            assert out.strip().startswith("ok 06"), (out, lab.hub.log_text())
            assert slave.context.getValues(3, 5, 1) == [777]
            out = board.command(f"modbus write {UNIT} holding 10 1 2 3", timeout=WAIT)
            assert out.strip().startswith("ok 10"), (out, lab.hub.log_text())
            assert slave.context.getValues(3, 10, 3) == [1, 2, 3]
        finally:
            slave.close()
    assert [type(r).__name__ for r in slave.requests] == ["ReadHoldingRegistersRequest", "WriteSingleRegisterRequest",
                                                          "WriteMultipleRegistersRequest"]
    # The controller's requests on the line: back to back, heard by the station only.
    requests = from_port(lab.hub.line_records(), "board1.rs485")
    assert all(r.outcome == "ok" and r.rx == ("pymodbus.0",) for r in requests), lab.hub.log_text()


def test_libmodbus_master_against_the_controllers_slave_over_the_line(slave_on_line):
    lab, board = slave_on_line
    t35 = timing_and_state(board)["t3.5"]
    with LinePty(lab.socket_path, LINE, "libmodbus") as station:
        for arguments, check in ((["read-input-registers", "5", "3"], lambda a: a["values"] == [0x1005, 0x1006, 0x1007]),
                                 (["write-registers", "40=7,8,65535"], lambda a: True),
                                 (["read-holding-registers", "40", "3"], lambda a: a["values"] == [7, 8, 65535])):
            wait_idle(board)
            result = subprocess.run([DCOS_MODBUS, "-d", station.pty_path, "-b", str(BAUD), "-a", str(UNIT), "-r", "0",
                                     "-t", "10000", "--json", *arguments], capture_output=True, text=True, timeout=WAIT)
            answer = json.loads(result.stdout) if result.stdout.strip() else None
            assert result.returncode == 0 and check(answer), (arguments, answer, result.stderr, lab.hub.log_text())
    assert "data: 7 8 65535" in board.command("modbus data holding 40 3")
    records = lab.hub.line_records()
    sent = from_port(records, "libmodbus.0")
    answers = from_port(records, "board1.rs485")
    # libmodbus's first request (8 characters), paced back to back; the answer after t3.5.
    assert host_gaps(sent[:8]) == [0] * 7, lab.hub.log_text()
    assert answers[0].start - sent[7].end >= t35, lab.hub.log_text()


def test_two_boards_on_one_line_master_and_slave(canlab):
    lab = canlab({}, {"board1": {"rs485": LINE}, "board2": {"rs485": LINE}}, lines={LINE: (BAUD, FORMAT)},
                 kind="production", append=APPEND)
    master, slave = lab.board("board1"), lab.board("board2")
    out = slave.command(f"modbus slave {UNIT} {BAUD}")
    assert f"slave {UNIT} on COM2" in out, out
    start_master(master)
    out = master.command(f"modbus read {UNIT} input-registers 5 3", timeout=WAIT)
    assert "ok 04: 4101 4102 4103" in out, (out, lab.hub.log_text())
    out = master.command(f"modbus write {UNIT} holding 7 4242", timeout=WAIT)
    assert out.strip().startswith("ok 06"), (out, lab.hub.log_text())
    assert "data: 4242" in slave.command("modbus data holding 7 1")
    records = lab.hub.line_records()
    assert all(r.outcome == "ok" for r in records), lab.hub.log_text()
    # Each board hears the other and never itself.
    assert {r.rx for r in from_port(records, "board1.rs485")} == {("board2.rs485",)}
    assert {r.rx for r in from_port(records, "board2.rs485")} == {("board1.rs485",)}
    assert modbus_state(master)["master.timeouts"] == 0


def test_a_station_at_another_baud_rate_is_heard_as_damaged_characters_and_no_frame(canlab):
    # The line's stations send at 9600 baud; the controller listens at 19200 and samples each
    # character at its own rate: wrong bits, framing errors where it finds a stop bit low.
    lab = canlab({}, {"board1": {"rs485": LINE}}, lines={LINE: (9600, FORMAT)}, kind="production", append=APPEND)
    board = lab.board("board1")
    assert f"slave {UNIT} on COM2" in board.command(f"modbus slave {UNIT} {BAUD}")
    wait_idle(board)
    before = modbus_state(board)
    frame = request_bytes(ReadHoldingRegistersRequest(0, 1, unit=UNIT))
    lab.hub.line_send(LINE, "lab", frame)
    after = wait_state(board, lambda s: s["frames.seen"] > before["frames.seen"], "the damaged frame counted")
    wait_idle(board)
    assert after["line.characters"] == before["line.characters"] + len(frame)
    assert after["line.framing-errors"] + after["line.parity-errors"] > \
        before["line.framing-errors"] + before["line.parity-errors"], (before, after)
    assert after["frames.delivered"] == before["frames.delivered"]
    assert modbus_state(board)["slave.messages"] == before["slave.messages"]
    assert from_port(lab.hub.line_records(), "board1.rs485") == [], lab.hub.log_text()
    # The hub logs them as sent well: the damage is the receiver's, at its own rate.
    assert all(r.outcome == "ok" for r in lab.hub.line_records())


# The on-target tests this module runs (test_kernel_core.py checks that every one in the image is run somewhere).
LINE_TARGET_TESTS = ["rs485uart"]


@pytest.mark.parametrize("name", LINE_TARGET_TESTS)
def test_the_uart_model_register_by_register(boot, isa486, name):
    """The isa-rs485-uart alone (no line), from the test image: registers, loopback character timing,
    THRE/TEMT, trigger level and character time-out interrupts, overrun (tests_renode/target/
    Rs485UartModelTest.cpp)."""
    from dcoslab.target import run_target_test

    run_target_test(boot(isa486, "test", icount=True, line_ports={"rs485": {}}), name)


def test_pymodbus_serial_client_as_master_of_the_controllers_slave(slave_on_line):
    """pymodbus's own serial client (pyserial on the pty station), paced by the station to keep t3.5
    before each request, which the client itself does not ([SL] 2.5.1.1)."""
    from pymodbus.client import ModbusSerialClient

    lab, board = slave_on_line
    with LinePty(lab.socket_path, LINE, "pymodbus", silence_ns=HOST_TURNAROUND_NS) as station:
        # strict=False: pymodbus's strict mode times t1.5 between received bytes with pyserial's
        # inter-byte time-out, in wall time, which a pseudo-terminal refuses (tcsetattr EINVAL).
        client = ModbusSerialClient(station.pty_path, baudrate=BAUD, parity="E", timeout=WAIT, strict=False)
        assert client.connect()
        try:
            written = client.write_registers(20, [11, 22, 33], slave=UNIT)
            assert not written.isError(), (written, lab.hub.log_text())
            answer = client.read_holding_registers(20, 3, slave=UNIT)
            assert not answer.isError() and answer.registers == [11, 22, 33], (answer, lab.hub.log_text())
            answer = client.read_input_registers(7, 2, slave=UNIT)
            assert answer.registers == [0x1007, 0x1008], (answer, lab.hub.log_text())
        finally:
            client.close()
    assert "data: 11 22 33" in board.command("modbus data holding 20 3")
    records = lab.hub.line_records()
    requests = from_port(records, "pymodbus.0")
    answers = from_port(records, "board1.rs485")
    # Every request starts t3.5 or more after the answer before it, and every answer t3.5 after its request.
    # Requests of 15 (10), 8 (03) and 8 (04) characters; answers of 8, 11 and 9.
    assert len(requests) == 15 + 8 + 8 and len(answers) == 8 + 11 + 9, lab.hub.log_text()
    assert requests[15].start - answers[7].end >= T35_NS and requests[23].start - answers[18].end >= T35_NS
    assert answers[0].start - requests[14].end >= T35_NS and answers[8].start - requests[22].end >= T35_NS
    assert modbus_state(board)["slave.messages"] == 3
