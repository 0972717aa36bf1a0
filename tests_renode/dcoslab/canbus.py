#!/usr/bin/env python3
"""The lab's CAN bus hub: emulated boards (and host tools) on shared CAN buses.

Every board that carries an `isa-sja1000` card with channels wired to lab
buses joins this hub through the card's link (properties hub and hub-name,
tests_renode/models/isa_sja1000.c). The hub keeps the boards' emulated clocks in step and models
each bus: its bit rate, every frame's length with worst-case bit stuffing,
arbitration among frames pending at once, acknowledgement, error frames and
the faults a test asks for. docs/protocols/labbus.md specifies the protocol,
the lock-step and the timing model; this module implements exactly that page.

In-process, from pytest (see dcoslab/canlab.py for the fixture):

    hub = Hub(socket_path, {"can0": 500_000}, expect=["board1", "board2"])
    hub.start()
    ...                       # boot boards with -device isa-sja1000,hub=<socket_path>,hub-name=board1,bus0=can0
    hub.corrupt("board1.0", 2)
    print(hub.log_text())
    hub.stop()

Standalone:

    tests_renode/dcoslab/canbus.py --socket /tmp/lab.sock --bus can0=500000 \\
        --expect board1 --expect board2 --log bus.log

The bus log has one line per frame attempt (see LogRecord) and is the same
from run to run for the same test: every decision is a function of emulated
times only.
"""

import argparse
import collections
import dataclasses
import os
import selectors
import socket
import sys
import threading
import time

try:
    from .rs485 import Line, LineError, LinePort, LineRecord, parse_format
except ImportError:  # run as a program: tests_renode/dcoslab/canbus.py
    from rs485 import Line, LineError, LinePort, LineRecord, parse_format

PROTOCOL_VERSION = 1

# The quantum is this many bit times of the fastest bus (docs/protocols/
# labbus.md, "Choice of the quantum"): below the 43 bit times from a frame's
# start to the earliest error the model detects (the CRC delimiter of a
# standard frame without data), so every frame's end and every error event
# is still in every board's future when the hub announces it.
QUANTUM_BITS = 40

# Frame geometry with worst-case bit stuffing (Davis, Burns, Bril, Lukkien,
# "Controller Area Network schedulability analysis", 2007): g bits from SOF
# to the end of the CRC sequence without data, 8n data bits and at most
# floor((g + 8n - 1) / 4) stuff bits, then CRC delimiter, ACK slot, ACK
# delimiter, 7 bits of EOF and 3 of intermission.
STANDARD_BITS = 34
EXTENDED_BITS = 54
TAIL_BITS = 13
ERROR_FLAG_BITS = 6
ERROR_DELIMITER_BITS = 8
INTERMISSION_BITS = 3
SUSPEND_BITS = 8
BUS_FREE_BITS = 11
RECOVERY_SIGNALS = 128

# ECC bytes as the SJA1000 captures them (error code, direction, segment).
ECC_BIT = 0x00
ECC_FORM = 0x40
ECC_STUFF = 0x80
ECC_OTHER = 0xC0
ECC_RX = 0x20
SEG_ID28_21 = 0x02
SEG_DATA = 0x0A
SEG_DLC = 0x0B
SEG_CRC_DELIMITER = 0x18
SEG_ACK_SLOT = 0x19
SEG_ACK_DELIMITER = 0x1B

MODES = ("off", "wait", "on", "recover", "sleep")

# Participant kinds (HELLO): "emulated" has a clock the hub holds at every
# boundary; "host" is a tool without a chip or a clock; "realtime" is a chip
# on a machine that runs in real time (the lab VM's card): its port takes
# part like a board's (states, fault confinement, bus-free signals, forced
# faults) but, like a host tool, it is never held, its messages count from
# the next boundary and it takes events as they come.
KINDS = ("emulated", "host", "realtime")
CHIP_KINDS = ("emulated", "realtime")

# How long the hub waits for a participant that owes it a message.
DEFAULT_TIMEOUT = 60.0


class ProtocolError(Exception):
    """A participant sent something the protocol does not allow."""


class HubError(RuntimeError):
    """The hub failed or refused a request from the test."""


# -- frames ------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Frame:
    """A CAN frame as it travels on the bus.

    dlc is the 4-bit data length code as sent (0..15); a data frame carries
    min(dlc, 8) bytes, a remote frame none.
    """

    id: int
    extended: bool = False
    remote: bool = False
    dlc: int = 0
    data: bytes = b""

    def __post_init__(self):
        limit = 0x1FFFFFFF if self.extended else 0x7FF
        if not 0 <= self.id <= limit:
            raise ValueError(f"identifier {self.id:#x} does not fit a {'extended' if self.extended else 'standard'} frame")
        if not 0 <= self.dlc <= 15:
            raise ValueError(f"DLC {self.dlc} is not 0..15")
        expected = 0 if self.remote else min(self.dlc, 8)
        if len(self.data) != expected:
            raise ValueError(f"DLC {self.dlc} {'remote' if self.remote else 'data'} frame needs {expected} data bytes, "
                             f"not {len(self.data)}")

    @classmethod
    def data_frame(cls, id, data=b"", extended=False):
        return cls(id, extended, False, len(data), bytes(data))

    @property
    def format(self):
        return ("X" if self.extended else "S") + ("R" if self.remote else "D")

    def words(self):
        """The four protocol words: id, format, dlc, data."""
        return [f"{self.id:x}", self.format, str(self.dlc), self.data.hex() if self.data else "-"]

    @classmethod
    def from_words(cls, words):
        if len(words) != 4:
            raise ProtocolError(f"a frame is four words (id format dlc data), not {' '.join(words)!r}")
        id_text, form, dlc_text, data_text = words
        if len(form) != 2 or form[0] not in "SX" or form[1] not in "DR":
            raise ProtocolError(f"frame format {form!r} is not SD, SR, XD or XR")
        try:
            data = b"" if data_text == "-" else bytes.fromhex(data_text)
            return cls(int(id_text, 16), form[0] == "X", form[1] == "R", int(dlc_text), data)
        except ValueError as error:
            raise ProtocolError(f"bad frame {' '.join(words)!r}: {error}") from None

    def __str__(self):
        return " ".join(self.words())


def data_bits(frame):
    return 0 if frame.remote else 8 * min(frame.dlc, 8)


def stuffable_bits(frame):
    """Bits from SOF to the end of the CRC sequence, before stuffing."""
    return (EXTENDED_BITS if frame.extended else STANDARD_BITS) + data_bits(frame)


def crc_delimiter_index(frame):
    """Bit index (from SOF, 0) of the CRC delimiter, with worst-case stuffing."""
    stuffable = stuffable_bits(frame)
    return stuffable + (stuffable - 1) // 4


def frame_bits(frame):
    """The frame's length on the bus in bit times, intermission included."""
    return crc_delimiter_index(frame) + TAIL_BITS


def completion_bits(frame):
    """Bit times from SOF to the end of EOF, where the frame is complete."""
    return crc_delimiter_index(frame) + 10


def stuffed_index(unstuffed):
    """The stuffed position of unstuffed bit index u, with worst-case stuffing."""
    return unstuffed + unstuffed // 4


def arbitration_bits(frame):
    """The arbitration field, bit by bit, in the order of the SJA1000's ALC.

    Positions 0-10 are ID.28-ID.18 (a standard identifier's 11 bits), 11 is
    RTR of a standard frame or SRR of an extended one, 12 is IDE, 13-30 are
    ID.17-ID.0 and 31 the RTR of an extended frame; 0 is dominant.
    """
    if frame.extended:
        base = frame.id >> 18
        rest = frame.id & 0x3FFFF
        return ([(base >> (10 - i)) & 1 for i in range(11)] + [1, 1]
                + [(rest >> (17 - i)) & 1 for i in range(18)] + [1 if frame.remote else 0])
    return [(frame.id >> (10 - i)) & 1 for i in range(11)] + [1 if frame.remote else 0, 0]


def content_bits(frame):
    """Control field and data after the arbitration field, unstuffed."""
    bits = [0, 0] if frame.extended else [0]
    bits += [(frame.dlc >> (3 - i)) & 1 for i in range(4)]
    for byte in frame.data:
        bits += [(byte >> (7 - i)) & 1 for i in range(8)]
    return bits


# -- the bus log ---------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class LogRecord:
    """One frame attempt on one bus.

    start is the emulated time of its SOF; end the end of its EOF, or of the
    error delimiter for an attempt that ended in an error frame. outcome is
    ok, ack-error, form-error (a corrupted frame), collision (two senders of
    one identifier with different data) or rate-mismatch. rx lists the
    ports that received it as a valid frame, ack those that acknowledged it,
    lost the contenders that lost arbitration, with the ALC bit.
    """

    start: int
    end: int
    bus: str
    frame: Frame
    sender: str
    outcome: str
    rx: tuple = ()
    ack: tuple = ()
    lost: tuple = ()

    def line(self):
        fields = [str(self.start), str(self.end), self.bus, *self.frame.words(), f"from={self.sender}", self.outcome,
                  "rx=" + (",".join(self.rx) or "-"), "ack=" + (",".join(self.ack) or "-")]
        if self.lost:
            fields.append("lost=" + ",".join(f"{name}@{bit}" for name, bit in self.lost))
        return " ".join(fields)

    @classmethod
    def parse(cls, line):
        words = line.split()
        if len(words) < 11:
            raise ValueError(f"not a bus log line: {line!r}")
        named = dict(word.split("=", 1) for word in words[9:] if "=" in word)

        def names(key):
            value = named.get(key, "-")
            return () if value == "-" else tuple(value.split(","))

        lost = tuple((name, int(bit)) for name, bit in (item.rsplit("@", 1) for item in names("lost")))
        return cls(int(words[0]), int(words[1]), words[2], Frame.from_words(words[3:7]), words[7][len("from="):],
                   words[8], names("rx"), names("ack"), lost)


def candump_line(record):
    """A frame that went through, as `candump -l` logs it: its emulated completion time, bus and frame.

    The time is the end of its EOF, when its receivers take it, in seconds
    of emulated time; the frame is written as can-utils' lib.c writes it
    (upper-case hex, R for a remote frame with its DLC, the data in pairs).
    """
    frame = record.frame
    ident = f"{frame.id:08X}" if frame.extended else f"{frame.id:03X}"
    if frame.remote:
        # A remote frame's DLC follows R when it is not 0; one of 9-15 is
        # written as 8 and then the raw code, as can-utils does.
        body = "R" + ("" if frame.dlc == 0 else f"{frame.dlc:X}" if frame.dlc <= 8 else f"8{frame.dlc:X}")
    else:
        body = frame.data.hex().upper()
        if frame.dlc > 8:
            # A DLC of 9-15 carries 8 bytes; can-utils writes it after an underscore.
            body += f"_{frame.dlc:X}"
    seconds, nanoseconds = divmod(record.end, 1_000_000_000)
    return f"({seconds:010d}.{nanoseconds // 1000:06d}) {record.bus} {ident}#{body}"


def parse_log(text):
    """The records of a bus log, skipping its comment lines."""
    return [LogRecord.parse(line) for line in text.splitlines() if line.strip() and not line.startswith("#")]


# -- participants and ports -------------------------------------------------------


@dataclasses.dataclass
class PortState:
    """A port's participation from `time` on (docs/protocols/labbus.md, STATE)."""

    time: int
    epoch: int
    mode: str
    bit_ns: int
    sample_permille: int = 0
    passive: bool = False
    listen: bool = False
    selftest: bool = False


@dataclasses.dataclass
class TxRequest:
    port: "Port"
    time: int
    frame: Frame
    once: bool
    self_rx: bool
    seq: int
    aborted_at: int = None
    # The last attempt: start, and when its outcome was known (the error,
    # the lost arbitration or the end of EOF).
    attempt_start: int = None
    attempt_outcome: int = None
    # The bus is free for this request's next attempt from here.
    not_before: int = 0


class Port:
    """One CAN node on a bus: a board's channel, a host tool's, or the hub's own."""

    def __init__(self, participant, label, bus):
        self.participant = participant
        self.label = label
        self.name = f"{participant.name}.{label}"
        self.bus = bus
        self.timeline = []
        self.pending = collections.deque()
        self.corrupt_left = 0
        self.corrupt_from = 0
        self.drop_ack_from = None
        # When the bus was free after this port's last transmission: an
        # error-passive transmitter waits 8 more bits (suspend transmission).
        self.last_tx_free = None
        # Bus-free signal counting (wait and recover).
        self.bf_key = None
        self.bf_window = 0
        self.bf_in_window = 0
        self.bf_cursor = 0
        self.recover_key = None
        self.recover_signals = 0
        # A host tool or the hub's own node is always on, at the bus's rate.
        if participant.kind not in CHIP_KINDS:
            self.timeline.append(PortState(0, 0, "on", bus.bit_ns))

    def state_at(self, t):
        """The state in force at emulated time t (the last with time <= t)."""
        found = None
        for state in self.timeline:
            if state.time <= t:
                found = state
            else:
                break
        return found or PortState(0, 0, "off", 0)

    def next_change_after(self, t):
        for state in self.timeline:
            if state.time > t:
                return state.time
        return None

    def insert_state(self, state):
        """Adds a state, after any with the same time (the later one wins)."""
        index = len(self.timeline)
        while index > 0 and self.timeline[index - 1].time > state.time:
            index -= 1
        self.timeline.insert(index, state)

    def prune(self, before):
        """Forgets states superseded before emulated time `before`."""
        while len(self.timeline) > 1 and self.timeline[1].time <= before:
            self.timeline.pop(0)

    def on_from(self, t, horizon):
        """The first time >= t, before horizon, at which the port is on, or None."""
        if self.state_at(t).mode == "on":
            return t
        for state in self.timeline:
            if t < state.time < horizon and state.mode == "on":
                return state.time
        return None

    def bit_ns_at(self, t):
        state = self.state_at(t)
        return state.bit_ns or self.bus.bit_ns

    def acknowledges_at(self, t):
        state = self.state_at(t)
        return not state.listen and (self.drop_ack_from is None or t < self.drop_ack_from)


class Participant:
    """A connection to the hub (or the hub's own nodes, with no socket)."""

    def __init__(self, name, kind, sock=None):
        self.name = name
        self.kind = kind
        self.sock = sock
        self.buffer = b""
        self.inbox = []
        self.seq = 0
        self.ports = {}
        self.synced = None
        self.in_step = False
        self.out = []
        self.last_heard = time.monotonic()
        self.closed = False
        self.dropped = False
        # A board that joined late enters the bus at this boundary.
        self.entered_at = 0

    def queue(self, line):
        self.out.append(line)

    def flush(self):
        if self.sock is None or not self.out:
            self.out.clear()
            return
        data = ("\n".join(self.out) + "\n").encode("ascii")
        self.out.clear()
        try:
            self.sock.sendall(data)
        except OSError:
            self.closed = True


# -- the hub -------------------------------------------------------------------


class Bus:
    def __init__(self, name, bitrate):
        if bitrate <= 0 or 1_000_000_000 % bitrate:
            raise ValueError(f"bus {name}: {bitrate} bit/s is not a whole number of nanoseconds per bit")
        self.name = name
        self.bitrate = bitrate
        self.bit_ns = 1_000_000_000 // bitrate
        self.ports = {}
        self.free_at = 0
        # The bus is recessive from here until the next SOF.
        self.recessive_from = 0

    def sorted_ports(self):
        return [self.ports[name] for name in sorted(self.ports)]


class Hub:
    """The hub, run in a thread of this process (start/stop) or in the foreground (serve_forever)."""

    def __init__(self, socket_path, buses, expect=(), quantum_ns=None, pace=None, timeout=DEFAULT_TIMEOUT,
                 log_path=None, echo_log=False, candump_path=None, lines=None):
        """buses maps CAN bus names to bit rates; lines maps RS-485 line names to a baud rate or a
        (baud, format) pair, e.g. {"rs485": (19200, "8E1")} (dcoslab/rs485.py)."""
        if not buses and not lines:
            raise ValueError("the hub needs at least one bus or line")
        self.socket_path = socket_path
        self.buses = {name: Bus(name, rate) for name, rate in sorted(buses.items())}
        self.lines = {}
        for name, spec in sorted((lines or {}).items()):
            if name in self.buses:
                raise ValueError(f"{name} names both a bus and a line")
            self.lines[name] = Line(name, *(spec if isinstance(spec, tuple) else (spec,)))
        limits = [QUANTUM_BITS * bus.bit_ns for bus in self.buses.values()]
        limits += [line.quantum_limit_ns() for line in self.lines.values()]
        limit = min(limits)
        if quantum_ns is not None and not 0 < quantum_ns <= limit:
            raise ValueError(f"a quantum of {quantum_ns} ns is not in 1..{limit} ns ({QUANTUM_BITS} bit times of the "
                             f"fastest bus, half a bit time of the fastest line); a longer one would announce "
                             f"frame and character ends in the boards' past")
        self.quantum_ns = quantum_ns or limit
        self.expect = set(expect)
        self.pace = pace
        self.timeout = timeout
        self.log_path = log_path
        self.echo_log = echo_log
        self.candump_path = candump_path

        self.boundary = self.quantum_ns
        self.started = False
        self.participants = {}
        self.hub_nodes = Participant("hub", "hub")
        self.records = []
        # The RS-485 lines' characters (dcoslab/rs485.py, LineRecord).
        self._line_records = []
        self._log_lines = []
        self.errors = []
        # Boundaries a board reached late: (name, boundary, nanoseconds).
        self.overruns = []
        self._events = []
        self._event_seq = 0
        self._request_seq = 0
        self._babblers = {}
        self._commands = collections.deque()
        self._lock = threading.Lock()
        self._progress = threading.Condition(self._lock)
        self._stop = False
        self._thread = None
        self._wall_origin = None
        # When the first expected board said HELLO (the others have timeout s).
        self._expect_since = None
        self._selector = None
        self._listener = None
        self._wake_r, self._wake_w = os.pipe()
        self._log_file = None
        self._candump_file = None
        # Per port and per bus counters, kept as records come (statistics()).
        self._port_counts = collections.defaultdict(collections.Counter)
        self._bus_busy_ns = collections.Counter()

    # -- life cycle -----------------------------------------------------------

    def _listen(self):
        try:
            os.unlink(self.socket_path)
        except FileNotFoundError:
            pass
        self._listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        # The path appears only once the socket listens: bound under another
        # name and renamed, so a client that waits for the path (a host tool,
        # a test) cannot connect between bind and listen and be refused.
        binding_path = f"{self.socket_path}.{os.getpid()}.binding"
        try:
            os.unlink(binding_path)
        except FileNotFoundError:
            pass
        self._listener.bind(binding_path)
        self._listener.listen(16)
        os.rename(binding_path, self.socket_path)
        self._listener.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._listener, selectors.EVENT_READ, "listen")
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        if self.log_path:
            self._log_file = open(self.log_path, "w", encoding="ascii")
        if self.candump_path:
            self._candump_file = open(self.candump_path, "w", encoding="ascii")

    def start(self):
        """Listens and runs the hub in a background thread."""
        self._listen()
        self._thread = threading.Thread(target=self._run, name="canbus-hub", daemon=True)
        self._thread.start()
        return self

    def serve_forever(self):
        self._listen()
        self._run()

    def stop(self, timeout=10.0):
        """Stops the hub and closes every connection (the boards then stop)."""
        with self._lock:
            if self._stop:
                return
            self._stop = True
        os.write(self._wake_w, b"x")
        if self._thread is not None:
            self._thread.join(timeout)
        self._close_all()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()

    def _close_all(self):
        for participant in list(self.participants.values()):
            if participant.sock is not None:
                try:
                    participant.sock.close()
                except OSError:
                    pass
        if self._listener is not None:
            self._listener.close()
            self._listener = None
            try:
                os.unlink(self.socket_path)
            except OSError:
                pass
        if self._log_file is not None:
            for line in self.statistics_lines():
                self._log_file.write(line + "\n")
            self._log_file.close()
            self._log_file = None
        if self._candump_file is not None:
            self._candump_file.close()
            self._candump_file = None
        for fd in (self._wake_r, self._wake_w):
            try:
                os.close(fd)
            except OSError:
                pass
        self._wake_r = self._wake_w = -1

    # -- the test's interface (thread-safe) ---------------------------------

    @property
    def now_ns(self):
        """The last boundary every board has passed."""
        with self._lock:
            return self.boundary - self.quantum_ns

    def log_lines(self):
        with self._lock:
            return list(self._log_lines)

    def log_text(self):
        return "".join(line + "\n" for line in self.log_lines())

    def frames(self):
        """The log's records (comment lines left out)."""
        with self._lock:
            return list(self.records)

    def wait_until(self, ns, timeout):
        """Waits until every board has passed emulated time ns."""
        self.wait_for(lambda: self.boundary - self.quantum_ns >= ns, timeout, f"emulated time {ns} ns")

    def wait_on_bus(self, port_names, timeout):
        """Waits until every named port is on the bus (it has counted the 11
        recessive bits by which a starting node integrates, ISO 11898-1):
        a node still waiting neither receives nor acknowledges a frame."""
        def joined():
            now = self.boundary - self.quantum_ns
            return all(port.state_at(now).mode == "on" for name in port_names for port in self._find_ports(name))
        self.wait_for(joined, timeout, f"{', '.join(port_names)} to join the bus")

    def wait_for_records(self, predicate, timeout, what="the frames asked for"):
        """Waits until predicate(records) is true; returns the records."""
        self.wait_for(lambda: predicate(self.records), timeout, what)
        return self.frames()

    def wait_for(self, condition, timeout, what):
        deadline = time.monotonic() + timeout
        with self._progress:
            while not condition():
                if self.errors:
                    raise HubError(f"the hub failed while waiting for {what}: {'; '.join(self.errors)}")
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise HubError(f"timed out after {timeout:.0f} s waiting for {what} (hub at "
                                   f"{self.boundary - self.quantum_ns} ns)")
                self._progress.wait(min(remaining, 0.5))

    def _command(self, function, *args):
        with self._lock:
            if self._stop:
                raise HubError("the hub has stopped")
            self._commands.append((function, args))
        os.write(self._wake_w, b"x")

    def sync_commands(self, timeout=30.0):
        """Returns once every command given so far (a fault, a babbler, a line
        send) is in effect: the hub applied it at a boundary and every board
        has passed that boundary. A fault applies from the next boundary, and a
        board runs up to that boundary meanwhile, so without this a frame the
        test has a board send right after corrupt() can start in the quantum
        before the fault."""
        applied = []

        def mark(boundary):
            applied.append(boundary)

        self._command(mark)
        self.wait_for(lambda: bool(applied) and self.boundary - self.quantum_ns >= applied[0], timeout,
                      "the hub's commands to take effect")

    def force_passive(self, port_name):
        """The port's TEC is raised to 128 at the next boundary: error passive."""
        self._command(self._fault_event, port_name, "passive")

    def force_bus_off(self, port_name):
        """The port goes bus-off at the next boundary (TEC past 255)."""
        self._command(self._fault_event, port_name, "busoff")

    def corrupt(self, port_name, count):
        """The next `count` frames the port sends are corrupted at the CRC delimiter."""
        self._command(self._fault_corrupt, port_name, count)

    def drop_ack(self, port_name, drop=True):
        """The port (or every port of a participant) stops (or resumes) acknowledging."""
        self._command(self._fault_drop_ack, port_name, drop)

    def babble(self, bus, name, frame):
        """A hub node `name` floods `bus` with `frame`, back to back, until stop_babble."""
        self._command(self._start_babble, bus, name, frame)

    def stop_babble(self, name):
        self._command(self._stop_babble, name)

    def line_send(self, line, name, data, at_ns=None, gaps_ns=None):
        """A hub station `name` on RS-485 line `line` sends data at exact emulated times.

        The first character starts at at_ns (default: the next boundary);
        each one follows the one before it after gaps_ns[i] ns of silence
        (gaps_ns[0] is added to the start), at the line's bit rate and
        format. So a test puts a silence of its choice inside a frame, or
        starts a frame a chosen time after the last one.
        """
        self.line_send_together(line, [(name, data, gaps_ns)], at_ns)

    def line_send_together(self, line, sends, at_ns=None):
        """Several hub stations send from the same instant: sends is [(name, data, gaps_ns)], each as line_send."""
        checked = []
        for name, data, gaps_ns in sends:
            data = bytes(data)
            gaps = list(gaps_ns) if gaps_ns is not None else [0] * len(data)
            if len(gaps) != len(data):
                raise HubError(f"{len(data)} bytes need {len(data)} gaps, not {len(gaps)}")
            checked.append((name, data, gaps))
        self._command(self._line_send, line, checked, at_ns)

    def line_records(self, line=None):
        """The characters on the RS-485 lines so far (LineRecord), in order of start."""
        with self._lock:
            return [r for r in self._line_records if line is None or r.line == line]

    def wait_for_line_records(self, predicate, timeout, what="the characters asked for"):
        """Waits until predicate(line records) is true; returns the records."""
        self.wait_for(lambda: predicate(self._line_records), timeout, what)
        return self.line_records()

    def inject(self, bus, name, frame, at_ns=None, once=False):
        """A hub node `name` requests `frame` at emulated time at_ns (default: the next boundary)."""
        self._command(self._inject, bus, name, frame, at_ns, once)

    # -- the loop -------------------------------------------------------------

    def _run(self):
        try:
            self._loop()
        except Exception as error:  # a bug in the hub: make it visible to the waiting test
            with self._progress:
                self.errors.append(f"hub failure: {type(error).__name__}: {error}")
                self._progress.notify_all()
            raise
        finally:
            with self._progress:
                self._progress.notify_all()

    def _loop(self):
        while True:
            with self._lock:
                if self._stop:
                    return
            timeout = self._select_timeout()
            for key, _ in self._selector.select(timeout):
                if key.data == "listen":
                    self._accept()
                elif key.data == "wake":
                    os.read(self._wake_r, 4096)
                else:
                    self._receive(key.data)
            self._check_silence()
            while self._advance():
                pass

    def _select_timeout(self):
        if not self._emulated() and self._may_tick_alone():
            # Host tools' time follows the wall clock, a millisecond at a time.
            wait = self._wall_deadline(self.boundary) - time.monotonic()
            return max(0.001, wait)
        return 0.5

    def _emulated(self):
        return [p for p in self.participants.values() if p.kind == "emulated" and not p.closed]

    def _may_tick_alone(self):
        """With host tools and no board, time runs with the wall clock (unless boards are expected)."""
        if self.expect and not self.started:
            return False
        return any(p.kind in ("host", "realtime") for p in self.participants.values()) or bool(self._babblers)

    def _wall_deadline(self, boundary):
        pace = self.pace or 1.0
        if self._wall_origin is None:
            self._wall_origin = time.monotonic() - (boundary - self.quantum_ns) / 1e9 / pace
        return self._wall_origin + boundary / 1e9 / pace

    def _accept(self):
        try:
            sock, _ = self._listener.accept()
        except OSError:
            return
        sock.setblocking(True)
        participant = Participant(None, None, sock)
        self._selector.register(sock, selectors.EVENT_READ, participant)

    def _receive(self, participant):
        try:
            data = participant.sock.recv(65536)
        except OSError:
            data = b""
        if not data:
            self._drop(participant, "closed the connection")
            return
        participant.last_heard = time.monotonic()
        participant.buffer += data
        while b"\n" in participant.buffer:
            raw, participant.buffer = participant.buffer.split(b"\n", 1)
            line = raw.decode("ascii", "replace").strip()
            if not line:
                continue
            try:
                self._handle(participant, line)
            except (ProtocolError, ValueError, IndexError) as error:
                self._refuse(participant, f"{line!r}: {error}")
                return
            if participant.closed:
                return

    def _refuse(self, participant, reason):
        try:
            participant.sock.sendall(f"ERROR {reason}\n".encode("ascii", "replace"))
        except OSError:
            pass
        self._drop(participant, f"protocol error: {reason}")

    def _drop(self, participant, why):
        if participant.dropped:
            return
        participant.dropped = True
        participant.closed = True
        try:
            self._selector.unregister(participant.sock)
        except (KeyError, ValueError):
            pass
        try:
            participant.sock.close()
        except OSError:
            pass
        if participant.name and self.participants.get(participant.name) is participant:
            del self.participants[participant.name]
            for port in participant.ports.values():
                port.bus.ports.pop(port.name, None)
            self._comment(f"{participant.name} left: {why}")

    def _check_silence(self):
        now = time.monotonic()
        for participant in self._emulated():
            if participant.in_step and participant.synced != self.boundary and now - participant.last_heard > self.timeout:
                with self._progress:
                    self.errors.append(f"{participant.name} sent no SYNC for {self.timeout:.0f} s at boundary "
                                       f"{self.boundary} ns")
                    self._progress.notify_all()
                self._drop(participant, "silent")
        if self.expect and not self.started and self._expect_since is not None:
            if now - self._expect_since > self.timeout:
                missing = sorted(self.expect - set(self.participants))
                with self._progress:
                    self.errors.append(f"expected boards never joined: {', '.join(missing)}")
                    self._progress.notify_all()
                self._expect_since = None

    # -- messages ---------------------------------------------------------------

    def _handle(self, participant, line):
        words = line.split()
        verb = words[0]
        if participant.name is None:
            if verb != "HELLO":
                raise ProtocolError(f"the first message must be HELLO, not {verb}")
            self._hello(participant, words)
            return
        if verb == "SYNC":
            self._sync(participant, words)
        elif verb in ("STATE", "TX", "ABORT", "CHAR", "DRIVE", "SILENCE"):
            participant.inbox.append((participant.seq, words))
            participant.seq += 1
        elif verb == "ATTACH":
            self._attach(participant, words)
        elif verb in ("FAULT", "BABBLE", "INJECT"):
            self._control(participant, words)
        elif verb == "BYE":
            self._drop(participant, "said BYE")
        else:
            raise ProtocolError(f"unknown message {verb}")

    def _hello(self, participant, words):
        if len(words) != 4 or words[1] != str(PROTOCOL_VERSION) or words[3] not in KINDS:
            raise ProtocolError(f"HELLO must be 'HELLO {PROTOCOL_VERSION} <name> {'|'.join(KINDS)}', "
                                f"not {' '.join(words)!r}")
        name = words[2]
        if name in self.participants or name == "hub" or "." in name:
            raise ProtocolError(f"the name {name!r} is taken or not allowed (no dots, not 'hub')")
        participant.name = name
        participant.kind = words[3]
        self.participants[name] = participant
        if participant.kind == "emulated":
            # A board that comes after the clock started catches up alone.
            participant.in_step = not self.started
        if self.expect and self._expect_since is None and not self.started:
            self._expect_since = time.monotonic()
        participant.queue(f"WELCOME {PROTOCOL_VERSION} {self.quantum_ns} {self.boundary - self.quantum_ns}")
        participant.flush()
        self._comment(f"{name} joined ({participant.kind})")

    def _attach(self, participant, words):
        if len(words) not in (3, 4):
            raise ProtocolError("ATTACH is 'ATTACH <port> <bus> [<label>]'")
        port_id, bus_name = words[1], words[2]
        label = words[3] if len(words) == 4 else port_id
        bus = self.buses.get(bus_name) or self.lines.get(bus_name)
        if bus is None:
            participant.queue(f"REFUSED {port_id} no bus {bus_name}; the buses are {', '.join(self.buses)}"
                              + (f"; the lines are {', '.join(self.lines)}" if self.lines else ""))
        elif port_id in participant.ports or any(p.label == label for p in participant.ports.values()):
            participant.queue(f"REFUSED {port_id} port {port_id} ({label}) is attached already")
        else:
            port = (LinePort if isinstance(bus, Line) else Port)(participant, label, bus)
            if participant.kind == "host" and isinstance(port, Port):
                port.timeline[0].time = self.boundary
            participant.ports[port_id] = port
            bus.ports[port.name] = port
            participant.queue(f"ATTACHED {port_id} {bus_name} {bus.bit_ns} {port.name}")
        participant.flush()

    def _sync(self, participant, words):
        if participant.kind != "emulated" or len(words) not in (2, 3):
            raise ProtocolError("SYNC is 'SYNC <time> [<overrun>]', from emulated participants only")
        t = int(words[1])
        if t % self.quantum_ns:
            raise ProtocolError(f"SYNC {t} is not on a quantum boundary ({self.quantum_ns} ns)")
        if len(words) == 3:
            # QEMU's icount clock skip raced with a wake-up (see the link).
            self.overruns.append((participant.name, t, int(words[2])))
            self._comment(f"{participant.name} reached {t} ns {int(words[2])} ns late", t)
        participant.synced = t
        if not participant.in_step:
            if t < self.boundary:
                # Catching up: run alone to the boundary the others wait at.
                participant.queue(f"GO {t + self.quantum_ns}")
                participant.flush()
            elif t == self.boundary:
                participant.in_step = True
                participant.entered_at = t
                self._comment(f"{participant.name} caught up at {t} ns")
            else:
                raise ProtocolError(f"SYNC {t} is past the hub's boundary {self.boundary}")

    def _control(self, participant, words):
        """FAULT, BABBLE and INJECT from a participant: the same as the test's calls."""
        verb = words[0]
        try:
            if verb == "FAULT" and len(words) in (3, 4):
                kind = words[2]
                if kind in ("passive", "busoff"):
                    self._fault_event(words[1], kind)
                elif kind == "corrupt":
                    self._fault_corrupt(words[1], int(words[3]) if len(words) == 4 else 1)
                elif kind == "dropack":
                    self._fault_drop_ack(words[1], len(words) == 3 or words[3] != "off")
                else:
                    raise HubError(f"no fault {kind!r}")
            elif verb == "BABBLE" and len(words) == 4 and words[3] == "off":
                self._stop_babble(words[2])
            elif verb == "BABBLE" and len(words) == 7:
                self._start_babble(words[1], words[2], Frame.from_words(words[3:7]))
            elif verb == "INJECT" and len(words) == 8:
                at = None if words[3] == "-" else int(words[3])
                self._inject(words[1], words[2], Frame.from_words(words[4:8]), at, False)
            else:
                raise HubError(f"malformed {verb}")
            participant.queue(f"DONE {verb}")
        except (HubError, ValueError, ProtocolError) as error:
            participant.queue(f"NAK {verb} {error}")
        participant.flush()

    # -- boundaries ---------------------------------------------------------------

    def _ready(self):
        """Is every board at the current boundary (and every expected board here)?"""
        emulated = self._emulated()
        if not self.started and self.expect:
            if not self.expect <= {p.name for p in emulated}:
                return False
        if emulated:
            # Catching-up boards are answered at once; the boundary waits for them too.
            return all(p.synced == self.boundary for p in emulated)
        if not self._may_tick_alone():
            return False
        return time.monotonic() >= self._wall_deadline(self.boundary)

    def _advance(self):
        if not self._ready():
            return False
        self._skip_idle_quanta()
        boundary = self.boundary
        if not self.started:
            self.started = True
            self._comment(f"clock started with {', '.join(sorted(p.name for p in self._emulated())) or 'no boards'}; "
                          f"quantum {self.quantum_ns} ns")
        self._apply_commands(boundary)
        self._ingest(boundary)
        for bus in self.buses.values():
            self._simulate(bus, boundary)
        for line in self.lines.values():
            self._simulate_line(line, boundary)
        self._send_events(boundary)
        if self.pace and self._emulated():
            delay = self._wall_deadline(boundary + self.quantum_ns) - time.monotonic()
            if delay > 0:
                time.sleep(delay)
        with self._progress:
            self.boundary = boundary + self.quantum_ns
            self._progress.notify_all()
        for participant in self._emulated():
            participant.queue(f"GO {boundary + self.quantum_ns}")
            participant.flush()
        for participant in list(self.participants.values()):
            if participant.closed:
                self._drop(participant, "connection lost")
        return True

    def _skip_idle_quanta(self):
        """With no board, an idle hub that fell behind the wall clock catches up at once.

        Host tools alone tick one quantum at a time with the wall clock; on a
        busy machine the hub thread can fall seconds behind, and a tool's
        frame would wait for every quantum in between. While nothing is
        pending (no request, command, event or babbler) a quantum decides
        nothing but bus-free signals, which are counted by time over any
        stretch, so the hub moves to the wall clock's last boundary.
        """
        if self._emulated() or self._commands or self._events or self._babblers or self._wall_origin is None:
            return
        if any(port.pending for bus in self.buses.values() for port in bus.ports.values()):
            return
        if any(line.chars for line in self.lines.values()):
            return
        pace = self.pace or 1.0
        behind = int((time.monotonic() - self._wall_origin) * 1e9 * pace) // self.quantum_ns * self.quantum_ns
        if behind > self.boundary:
            with self._progress:
                self.boundary = behind
                self._progress.notify_all()

    def _apply_commands(self, boundary):
        while True:
            with self._lock:
                if not self._commands:
                    return
                function, args = self._commands.popleft()
            try:
                function(*args, boundary=boundary)
            except (HubError, ValueError) as error:
                with self._progress:
                    self.errors.append(str(error))
                    self._progress.notify_all()

    def _find_ports(self, name):
        if "." in name:
            participant_name, label = name.split(".", 1)
            participant = self.participants.get(participant_name) if participant_name != "hub" else self.hub_nodes
            ports = [p for p in (participant.ports.values() if participant else []) if p.label == label]
        else:
            participant = self.participants.get(name) if name != "hub" else self.hub_nodes
            ports = list(participant.ports.values()) if participant else []
        if not ports:
            raise HubError(f"no port {name!r}; the ports are "
                           f"{', '.join(sorted(p for bus in self.buses.values() for p in bus.ports)) or 'none'}")
        return ports

    def _fault_event(self, name, kind, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        for port in self._find_ports(name):
            if port.participant.kind not in CHIP_KINDS:
                raise HubError(f"{port.name} is not a board: only a board's chip can be forced {kind}")
            self._event(port, boundary, "FAULT", kind)
        self._comment(f"fault {name} {kind}", boundary)

    def _fault_corrupt(self, name, count, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        for port in self._find_ports(name):
            port.corrupt_left = count
            port.corrupt_from = boundary
        self._comment(f"fault {name} corrupt {count}", boundary)

    def _fault_drop_ack(self, name, drop, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        for port in self._find_ports(name):
            port.drop_ack_from = boundary if drop else None
        self._comment(f"fault {name} dropack {'on' if drop else 'off'}", boundary)

    def _hub_port(self, bus_name, name, kind="bus"):
        """The hub's own node `name` on a CAN bus (kind "bus") or an RS-485 line (kind "line"), made on first use."""
        media, port_class = (self.buses, Port) if kind == "bus" else (self.lines, LinePort)
        bus = media.get(bus_name)
        if bus is None:
            raise HubError(f"no {kind} {bus_name!r}")
        if "." in name or " " in name:
            raise HubError(f"hub node name {name!r} must be one word without dots")
        key = f"{name}@{bus_name}"
        port = self.hub_nodes.ports.get(key)
        if port is None:
            port = port_class(self.hub_nodes, name, bus)
            self.hub_nodes.ports[key] = port
            bus.ports[port.name] = port
        return port

    def _start_babble(self, bus_name, name, frame, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        port = self._hub_port(bus_name, name)
        self._babblers[name] = (port, frame)
        port.pending.clear()
        self._add_request(port, boundary, frame, False, False)
        self._comment(f"babble {port.name} {frame} on", boundary)

    def _stop_babble(self, name, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        entry = self._babblers.pop(name, None)
        if entry is None:
            raise HubError(f"no babbling node {name!r}")
        port = entry[0]
        # A frame already on the bus finishes; the next is not sent.
        for request in list(port.pending):
            if request.attempt_start is None or request.attempt_outcome is not None:
                port.pending.remove(request)
        self._comment(f"babble {port.name} off", boundary)

    def _inject(self, bus_name, name, frame, at_ns, once, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        at = boundary if at_ns is None else at_ns
        if at < boundary:
            raise HubError(f"cannot inject at {at} ns: the boards are already at {boundary} ns")
        port = self._hub_port(bus_name, name)
        self._add_request(port, at, frame, once, False)
        self._comment(f"inject {port.name} {frame} at {at}", boundary)

    def _line_send(self, line_name, sends, at_ns, boundary=None):
        boundary = self.boundary if boundary is None else boundary
        at = boundary if at_ns is None else at_ns
        if at < boundary:
            raise HubError(f"cannot send on {line_name} at {at} ns: the boards are already at {boundary} ns")
        for name, data, gaps in sends:
            port = self._hub_port(line_name, name, "line")
            line = port.line
            t = max(at, port.next_start)
            for byte, gap in zip(data, gaps):
                char = line.add_char(port, t + gap, line.bit_ps, line.format, byte)
                t = char.end
            self._comment(f"{port.name} sends {data.hex()} from {at} ns", boundary)

    def _apply_line_message(self, participant, port, t, words, boundary):
        """CHAR and DRIVE from a station of an RS-485 line (docs/protocols/labbus.md, "The RS-485 line")."""
        verb = words[0]
        if not isinstance(port, LinePort):
            raise ProtocolError(f"{verb} is for a port on an RS-485 line; {port.name} is on a CAN bus")
        line = port.line
        if verb == "CHAR":
            if len(words) != 6:
                raise ProtocolError("CHAR is 'CHAR <port> <time> <bit ps> <format> <byte hex>'")
            bit_ps = line.bit_ps if words[3] == "-" else int(words[3])
            fmt = line.format if words[4] == "-" else words[4]
            try:
                byte = int(words[5], 16)
                if participant.kind != "emulated":
                    # A host's bytes follow each other at the line's rate from the boundary they came at;
                    # the first of a burst waits for the silence the station asked for (SILENCE).
                    if t > port.next_start and port.min_silence_ns:
                        t = max(t, line.last_end + port.min_silence_ns)
                    t = max(t, port.next_start)
                line.add_char(port, t, bit_ps, fmt, byte)
            except LineError as error:
                raise ProtocolError(str(error)) from None
        elif verb == "SILENCE":
            if len(words) != 4 or not words[3].isdigit() or participant.kind == "emulated":
                raise ProtocolError("SILENCE is 'SILENCE <port> - <ns>', from a host station")
            port.min_silence_ns = int(words[3])
        elif verb == "DRIVE":
            if len(words) != 4 or words[3] not in ("on", "off"):
                raise ProtocolError("DRIVE is 'DRIVE <port> <time> on|off'")
            if participant.kind != "emulated":
                raise ProtocolError("only a board's UART has a driver enable; a host drives the line while it sends")
            on = words[3] == "on"
            if port.drive_on_at(t) != on:
                port.drive.append((t, on))
        else:
            raise ProtocolError(f"{verb} is not a message for an RS-485 line")

    def _simulate_line(self, line, boundary):
        """Announces every character whose end lies before the next boundary, to its receivers."""
        for char, garbled, byte, receivers in line.decide(boundary, self.quantum_ns):
            at = max(char.end, boundary)
            flags = "garbled" if garbled else "-"
            for port in receivers:
                self._events.append((at, self._event_seq, port,
                                     f"RX {{port}} 0 {{time}} {char.bit_ps} {char.format} {byte:02x} {flags}"))
                self._event_seq += 1
            record = LineRecord(char.start, char.end, line.name, byte, char.format, char.sender,
                                "garbled" if garbled else "ok", tuple(p.name for p in receivers))
            with self._lock:
                self._line_records.append(record)
                self._log_lines.append(record.text())
            self._write_log(record.text())
        line.prune(boundary)

    def _add_request(self, port, t, frame, once, self_rx):
        request = TxRequest(port, t, frame, once, self_rx, self._request_seq)
        self._request_seq += 1
        port.pending.append(request)
        return request

    def _ingest(self, boundary):
        """Applies the participants' messages in emulated-time order."""
        messages = []
        for participant in sorted(self.participants.values(), key=lambda p: p.name):
            catching_up = participant.kind == "emulated" and not participant.in_step
            if catching_up:
                continue
            later = []
            for seq, words in participant.inbox:
                time_word = words[2] if len(words) > 2 else "-"
                if time_word == "-" or participant.kind != "emulated":
                    t = boundary
                else:
                    if not time_word.isdigit():
                        self._refuse(participant, f"bad time {time_word!r} in {words[0]}")
                        later = []
                        break
                    t = int(time_word)
                    if t >= boundary:
                        # Sent at or after this boundary (at it, or by a board
                        # that overran it): it belongs to the next quantum.
                        later.append((seq, words))
                        continue
                # A board that caught up late reported its past: it enters now.
                t = max(t, participant.entered_at)
                messages.append((t, participant.name, seq, participant, words))
            participant.inbox = later
        messages.sort(key=lambda m: (m[0], m[1], m[2]))
        for t, _, _, participant, words in messages:
            if participant.dropped:
                continue
            try:
                self._apply_message(participant, t, words, boundary)
            except (ProtocolError, ValueError) as error:
                self._refuse(participant, f"{' '.join(words)!r}: {error}")

    def _apply_message(self, participant, t, words, boundary):
        verb = words[0]
        port = participant.ports.get(words[1]) if len(words) > 1 else None
        if port is None:
            raise ProtocolError(f"{verb} names port {words[1] if len(words) > 1 else '?'}, which is not attached")
        if isinstance(port, LinePort) or verb in ("CHAR", "DRIVE"):
            self._apply_line_message(participant, port, t, words, boundary)
        elif verb == "STATE":
            if len(words) != 8 or words[4] not in MODES:
                raise ProtocolError("STATE is 'STATE <port> <time> <epoch> <mode> <bit_ns> <sample_permille> <flags>'")
            flags = set() if words[7] == "-" else set(words[7].split(","))
            state = PortState(t, int(words[3]), words[4], int(words[5]) or port.bus.bit_ns, int(words[6]),
                              "passive" in flags, "listen" in flags, "selftest" in flags)
            if participant.kind == "host" and state.mode not in ("on", "off"):
                raise ProtocolError("a host port is on or off")
            previous = port.state_at(t)
            port.insert_state(state)
            if (state.mode, state.bit_ns, state.passive, state.listen, state.selftest) != (
                    previous.mode, previous.bit_ns, previous.passive, previous.listen, previous.selftest):
                flags = "".join(f", {flag}" for flag in ("passive", "listen", "selftest") if getattr(state, flag))
                self._comment(f"{port.name} {state.mode} from {t} ns: {state.bit_ns} ns/bit, sample point "
                              f"{state.sample_permille / 10:g} %{flags}", boundary)
            if state.mode in ("off", "sleep") and previous.mode not in ("off", "sleep"):
                # Leaving the bus drops the request (the chip's reset mode).
                port.pending.clear()
            if state.mode == "recover" and previous.mode != "recover":
                port.recover_key = (state.time, state.epoch)
                port.recover_signals = 0
        elif verb == "TX":
            if len(words) != 8:
                raise ProtocolError("TX is 'TX <port> <time> <id> <format> <dlc> <data> <options>'")
            options = set() if words[7] == "-" else set(words[7].split(","))
            if options - {"once", "self"}:
                raise ProtocolError(f"unknown TX options {','.join(sorted(options - {'once', 'self'}))}")
            if participant.kind in CHIP_KINDS and port.pending:
                raise ProtocolError(f"{port.name} requested a transmission while one is pending (TBS is locked)")
            self._add_request(port, t, Frame.from_words(words[3:7]), "once" in options, "self" in options)
        elif verb == "ABORT":
            if len(words) != 3:
                raise ProtocolError("ABORT is 'ABORT <port> <time>'")
            # Settled once no attempt can still start before t (_settle_aborts).
            for request in port.pending:
                if request.aborted_at is None:
                    request.aborted_at = t
                    break

    # -- the bus -------------------------------------------------------------------

    def _event(self, port, t, verb, *args, epoch_at=None):
        """Queues an event for emulated time t, tagged with the port's epoch at epoch_at (default t)."""
        state = port.state_at(t if epoch_at is None else epoch_at)
        self._events.append((t, self._event_seq, port, f"{verb} {{port}} {state.epoch} {{time}}"
                             + "".join(f" {a}" for a in args)))
        self._event_seq += 1

    def _ready_time(self, request, horizon):
        """When the request could start (>= its time, bus free, port on), or None before horizon."""
        port = request.port
        bus = port.bus
        base = max(request.time, request.not_before, bus.free_at)
        if (port.last_tx_free is not None and port.last_tx_free == bus.free_at
                and port.state_at(port.last_tx_free).passive):
            # Nobody else sent since this port did: it suspends transmission.
            base = max(base, port.last_tx_free + SUSPEND_BITS * bus.bit_ns)
        if base >= horizon:
            return None
        return port.on_from(base, horizon)

    def _candidates(self, bus, horizon):
        candidates = []
        for port in bus.sorted_ports():
            if not port.pending:
                continue
            request = port.pending[0]
            ready = self._ready_time(request, horizon)
            if ready is None:
                continue
            if request.aborted_at is not None and ready >= request.aborted_at:
                continue
            candidates.append((ready, request))
        return candidates

    def _simulate(self, bus, boundary):
        """Decides every frame that starts early enough to be known at this boundary."""
        T = bus.bit_ns
        while True:
            candidates = self._candidates(bus, boundary)
            start = min((ready for ready, _ in candidates), default=None)
            # Another request may still join within the first bit: decide
            # only starts at least one bit before the boundary.
            decidable = start is not None and start + T <= boundary
            limit = start if decidable else (min(start, boundary) if start is not None else boundary)
            if self._count_bus_free(bus, limit, boundary):
                continue  # a port joined: it may have a request of its own
            if not decidable:
                break
            contenders = [request for ready, request in candidates if ready < start + T]
            self._resolve(bus, start, contenders, boundary)
        self._settle_aborts(bus, boundary)
        for port in bus.ports.values():
            port.prune(min(bus.recessive_from, bus.free_at) - 1)

    def _count_bus_free(self, bus, until, boundary):
        """Bus-free signals (11 recessive bits) for waiting and recovering ports up to `until`.

        Returns True if a port joined the bus (its state changed to on).
        """
        joined = False
        run_start = bus.recessive_from
        for port in bus.sorted_ports():
            if port.participant.kind not in CHIP_KINDS:
                continue
            t = max(run_start, port.bf_cursor)
            while t < until:
                state = port.state_at(t)
                change = port.next_change_after(t)
                segment_end = until if change is None else min(until, change)
                if state.mode in ("wait", "recover"):
                    key = (state.time, state.epoch, state.mode, run_start)
                    if port.bf_key != key:
                        port.bf_key = key
                        port.bf_window = max(run_start, state.time)
                        port.bf_in_window = 0
                    step = BUS_FREE_BITS * (state.bit_ns or bus.bit_ns)
                    while True:
                        at = port.bf_window + (port.bf_in_window + 1) * step
                        if at > segment_end:
                            break
                        port.bf_in_window += 1
                        if state.mode == "wait":
                            self._event(port, max(at, boundary), "JOIN")
                            port.insert_state(dataclasses.replace(state, time=at, mode="on"))
                            joined = True
                            segment_end = at
                            break
                        if port.recover_key != (state.time, state.epoch):
                            port.recover_key = (state.time, state.epoch)
                            port.recover_signals = 0
                        port.recover_signals += 1
                        self._event(port, max(at, boundary), "BUSFREE", port.recover_signals)
                        if port.recover_signals >= RECOVERY_SIGNALS:
                            port.insert_state(dataclasses.replace(state, time=at, mode="on", passive=False))
                            joined = True
                            segment_end = at
                            break
                t = segment_end
            port.bf_cursor = max(port.bf_cursor, min(until, t))
        return joined

    def _arbitrate(self, contenders):
        remaining = list(contenders)
        lost = []
        bits = {id(r): arbitration_bits(r.frame) for r in contenders}
        for position in range(32):
            active = [r for r in remaining if position < len(bits[id(r)])]
            if len(active) < 2:
                break
            lowest = min(bits[id(r)][position] for r in active)
            if lowest == 0:
                for r in active:
                    if bits[id(r)][position] == 1:
                        lost.append((r, position))
                remaining = [r for r in remaining if r not in [loser for loser, _ in lost]]
        return remaining, lost

    def _resolve(self, bus, s, contenders, boundary):
        T = bus.bit_ns
        on_ports = [p for p in bus.sorted_ports() if p.state_at(s).mode == "on"]
        for port in bus.sorted_ports():
            if port.state_at(s).mode == "sleep":
                self._event(port, max(s, boundary), "SOF", "wake", epoch_at=s)
        contender_ports = {r.port.name for r in contenders}
        # A sender at another bit rate puts garbage on the bus.
        mismatched = [r for r in contenders if r.port.bit_ns_at(s) != T]
        if mismatched:
            self._resolve_garbage(bus, s, contenders, mismatched[0], on_ports, boundary)
            return
        winners, lost = self._arbitrate(contenders)
        frame = winners[0].frame
        c = crc_delimiter_index(frame)
        winner_ports = {r.port.name for r in winners}
        receivers = [p for p in on_ports if p.name not in winner_ports]
        able = [p for p in receivers if p.bit_ns_at(s) == T]
        deaf = [p for p in receivers if p.bit_ns_at(s) != T]
        ackers = [p for p in able if p.acknowledges_at(s)]
        for r in contenders:
            self._event(r.port, max(s, boundary), "SOF", "tx", epoch_at=s)
            r.attempt_start = s
        for p in receivers:
            if p.name not in contender_ports:
                self._event(p, max(s, boundary), "SOF", "rx", epoch_at=s)
        lost_names = []
        for r, position in lost:
            at = s + (stuffed_index(1 + position) + 1) * T
            final = r.once or (r.aborted_at is not None and r.aborted_at < at)
            r.attempt_outcome = at
            self._event(r.port, max(at, boundary), "LOST", position, int(final), epoch_at=s)
            lost_names.append((r.port.name, position))
            if final:
                r.port.pending.remove(r)
        for p in deaf:
            # Another bit rate: it cannot decode the frame and sees a stuff error.
            self._event(p, max(s + 2 * T, boundary), "ERR", "rx", f"{ECC_STUFF | ECC_RX | SEG_ID28_21:02x}", "-",
                        epoch_at=s)

        difference = self._first_difference(winners)
        corrupted = any([self._take_corrupt(r.port, s) for r in winners])
        selftest = any(r.port.state_at(s).selftest for r in winners)
        if difference is not None:
            self._resolve_collision(bus, s, winners, able, deaf, difference, lost_names, boundary)
            return
        if corrupted:
            # A dominant CRC delimiter: a bit error for the sender, a form
            # error for every receiver, all at the same bit.
            d = s + (c + 1) * T
            self._error_frame(bus, s, d, winners, able, deaf, ECC_BIT | SEG_CRC_DELIMITER,
                              ECC_FORM | ECC_RX | SEG_CRC_DELIMITER, "form-error", lost_names, boundary, ack=False)
            return
        if not ackers and not selftest:
            self._resolve_ack_error(bus, s, c, winners, able, deaf, lost_names, boundary)
            return
        e = s + completion_bits(frame) * T
        for r in winners:
            self._event(r.port, max(e, boundary), "TXOK", epoch_at=s)
            if r.self_rx:
                self._event(r.port, max(e, boundary), "RX", *frame.words(), 1, epoch_at=s)
        for p in able:
            self._event(p, max(e, boundary), "RX", *frame.words(), 0, epoch_at=s)
        for p in receivers + [r.port for r in winners]:
            self._event(p, max(e, boundary), "IDLE", epoch_at=s)
        bus.free_at = e + INTERMISSION_BITS * T
        bus.recessive_from = s + (c + 2) * T
        for r in winners:
            r.port.last_tx_free = bus.free_at
            self._finish(r, e)
        self._record(LogRecord(s, e, bus.name, frame, self._sender_name(winners), "ok",
                               tuple(p.name for p in able), tuple(p.name for p in ackers), tuple(lost_names)))

    def _sender_name(self, winners):
        return "+".join(sorted(r.port.name for r in winners))

    def _first_difference(self, winners):
        """Unstuffed index of the first bit where winners of one identifier differ, or None."""
        if len(winners) < 2:
            return None
        sequences = [content_bits(r.frame) for r in winners]
        first_bit = (33 if winners[0].frame.extended else 14)
        for index in range(max(len(seq) for seq in sequences)):
            values = {seq[index] if index < len(seq) else None for seq in sequences}
            if len(values) > 1:
                return first_bit + index
        return None

    def _take_corrupt(self, port, s):
        if port.corrupt_left > 0 and s >= port.corrupt_from:
            port.corrupt_left -= 1
            return True
        return False

    def _error_frame(self, bus, s, d, senders, able, deaf, tx_ecc, rx_ecc, outcome, lost_names, boundary, ack,
                     sender=None):
        """An attempt that ends in an error frame: the error seen at d, flags, delimiter, intermission."""
        T = bus.bit_ns
        flags_end = d + ERROR_FLAG_BITS * T
        idle = flags_end + ERROR_DELIMITER_BITS * T
        free = idle + INTERMISSION_BITS * T
        for r in senders:
            final = self._attempt_failed(r, d, free, boundary)
            flags = ",".join(f for f in (("ack" if ack else ""), ("final" if final else "")) if f) or "-"
            self._event(r.port, max(d, boundary), "ERR", "tx", f"{tx_ecc:02x}", flags, epoch_at=s)
        for p in able:
            self._event(p, max(d, boundary), "ERR", "rx", f"{rx_ecc:02x}", "-", epoch_at=s)
        for p in able + deaf + [r.port for r in senders]:
            self._event(p, max(idle, boundary), "IDLE", epoch_at=s)
        bus.free_at = free
        bus.recessive_from = flags_end
        self._record(LogRecord(s, idle, bus.name, senders[0].frame, sender or self._sender_name(senders), outcome,
                               (), (), tuple(lost_names)))

    def _resolve_ack_error(self, bus, s, c, winners, able, deaf, lost_names, boundary):
        """Nobody acknowledged: the sender sees an ACK error at the end of the ACK slot."""
        T = bus.bit_ns
        d = s + (c + 2) * T
        passive_sender = all(r.port.state_at(s).passive for r in winners)
        if not passive_sender:
            # The active error flag starts in the ACK delimiter: a form error for the receivers.
            self._error_frame(bus, s, d, winners, able, deaf, ECC_OTHER | SEG_ACK_SLOT,
                              ECC_FORM | ECC_RX | SEG_ACK_DELIMITER, "ack-error", lost_names, boundary, ack=True)
            return
        # A passive error flag is recessive: to every receiver (listen-only
        # or not acknowledging) the frame looks valid, and it takes it.
        frame = winners[0].frame
        e = s + completion_bits(frame) * T
        flags_end = d + ERROR_FLAG_BITS * T
        idle = flags_end + ERROR_DELIMITER_BITS * T
        free = idle + INTERMISSION_BITS * T
        for r in winners:
            final = self._attempt_failed(r, d, free, boundary)
            self._event(r.port, max(d, boundary), "ERR", "tx", f"{ECC_OTHER | SEG_ACK_SLOT:02x}",
                        "ack,final" if final else "ack", epoch_at=s)
        for p in able:
            self._event(p, max(e, boundary), "RX", *frame.words(), 0, epoch_at=s)
        for p in able + deaf + [r.port for r in winners]:
            self._event(p, max(idle, boundary), "IDLE", epoch_at=s)
        bus.free_at = free
        bus.recessive_from = d
        self._record(LogRecord(s, idle, bus.name, frame, self._sender_name(winners), "ack-error",
                               tuple(p.name for p in able), (), tuple(lost_names)))

    def _resolve_collision(self, bus, s, winners, able, deaf, difference, lost_names, boundary):
        """Two senders of one identifier with different content: both see an error."""
        T = bus.bit_ns
        d = s + (stuffed_index(difference) + 1) * T
        data_start = 39 if winners[0].frame.extended else 19
        segment = SEG_DATA if difference >= data_start else SEG_DLC
        flags_end = d + ERROR_FLAG_BITS * T
        idle = flags_end + ERROR_DELIMITER_BITS * T
        free = idle + INTERMISSION_BITS * T
        bit_index = difference - (33 if winners[0].frame.extended else 14)
        for r in winners:
            bits = content_bits(r.frame)
            recessive = bit_index < len(bits) and bits[bit_index] == 1
            ecc = (ECC_BIT if recessive else ECC_STUFF) | segment
            final = self._attempt_failed(r, d, free, boundary)
            self._event(r.port, max(d, boundary), "ERR", "tx", f"{ecc:02x}", "final" if final else "-", epoch_at=s)
        for p in able:
            self._event(p, max(d, boundary), "ERR", "rx", f"{ECC_STUFF | ECC_RX | segment:02x}", "-", epoch_at=s)
        for p in able + deaf + [r.port for r in winners]:
            self._event(p, max(idle, boundary), "IDLE", epoch_at=s)
        bus.free_at = free
        bus.recessive_from = flags_end
        self._record(LogRecord(s, idle, bus.name, winners[0].frame, self._sender_name(winners), "collision", (), (),
                               tuple(lost_names)))

    def _resolve_garbage(self, bus, s, contenders, culprit, on_ports, boundary):
        """A sender at another bit rate: nothing on the bus is valid.

        Every contender sees a bit error in the first identifier bits and
        every other port a stuff error; the attempt occupies the bus for its
        error frame. Its sender retransmits until it is bus-off, as a
        misconfigured node does.
        """
        T = bus.bit_ns
        d = s + 2 * T
        senders = {r.port.name for r in contenders}
        for r in contenders:
            self._event(r.port, max(s, boundary), "SOF", "tx", epoch_at=s)
            r.attempt_start = s
        others = [p for p in on_ports if p.name not in senders]
        for p in others:
            self._event(p, max(s, boundary), "SOF", "rx", epoch_at=s)
        # The log names the node with the wrong rate.
        self._error_frame(bus, s, d, contenders, others, [], ECC_BIT | SEG_ID28_21, ECC_STUFF | ECC_RX | SEG_ID28_21,
                          "rate-mismatch", [], boundary, ack=False, sender=culprit.port.name)

    def _attempt_failed(self, request, outcome_time, free, boundary):
        """An attempt ended in an error at outcome_time; returns True if no retry follows.

        The retransmission waits for the bus to be free, and for the sender
        to have been told of the error: an error less than a quantum after
        the start of frame (a sender at another bit rate, a collision in the
        control field) reaches the board only at this boundary, and the
        hub must see what it does about it (bus-off) before it sends again.
        """
        request.attempt_outcome = outcome_time
        request.not_before = max(free, boundary)
        request.port.last_tx_free = free
        final = request.once or (request.aborted_at is not None and request.aborted_at < outcome_time)
        if final:
            if request in request.port.pending:
                request.port.pending.remove(request)
            self._babble_next(request, outcome_time)
        return final

    def _finish(self, request, end):
        """The request's frame went out; the port's next request may follow."""
        request.attempt_outcome = end
        if request in request.port.pending:
            request.port.pending.remove(request)
        self._babble_next(request, end)

    def _babble_next(self, request, at):
        entry = self._babblers.get(request.port.label)
        if entry is not None and entry[0] is request.port and not request.port.pending:
            self._add_request(request.port, at, entry[1], False, False)

    def _settle_aborts(self, bus, boundary):
        """Cancels aborted requests that no attempt was under way for."""
        horizon = boundary - bus.bit_ns
        for port in bus.sorted_ports():
            for request in list(port.pending):
                if request.aborted_at is None or request.aborted_at > horizon:
                    continue
                under_way = (request.attempt_start is not None and request.attempt_start <= request.aborted_at
                             and request.aborted_at < request.attempt_outcome)
                port.pending.remove(request)
                if not under_way:
                    self._event(port, max(request.aborted_at, boundary), "ABORTED")
                # An attempt under way at the abort finished on its own: the
                # chip released its buffer with that attempt's outcome.

    # -- output -----------------------------------------------------------------

    def _record(self, record):
        bus = self.buses[record.bus]
        with self._lock:
            self.records.append(record)
            self._log_lines.append(record.line())
            # The attempt holds the bus from SOF to its end and the 3-bit
            # intermission after it; nothing else can use that time.
            self._bus_busy_ns[record.bus] += record.end - record.start + 3 * bus.bit_ns
            sender = self._port_counts[record.sender]
            if record.outcome == "ok":
                sender["sent"] += 1
            else:
                sender["failed"] += 1
            for name, _ in record.lost:
                self._port_counts[name]["lost"] += 1
            for name in record.rx:
                if name != record.sender:
                    self._port_counts[name]["received"] += 1
        self._write_log(record.line())
        if self._candump_file is not None and record.outcome == "ok":
            self._candump_file.write(candump_line(record) + "\n")
            self._candump_file.flush()

    def statistics(self):
        """Frames, errors and bus load so far, per bus and per port.

        A port's "sent" counts its frames that went through, "failed" its
        attempts that ended in an error frame, "lost" the arbitrations it
        lost, "received" the valid frames of others it took. A bus's load is
        the share of the emulated time so far its frames and error frames
        (with their intermission) held it.
        """
        with self._lock:
            elapsed = self.boundary - self.quantum_ns
            buses = {}
            for name, bus in self.buses.items():
                records = [r for r in self.records if r.bus == name]
                buses[name] = {
                    "bitrate": bus.bitrate,
                    "frames": sum(1 for r in records if r.outcome == "ok"),
                    "errors": sum(1 for r in records if r.outcome != "ok"),
                    "load": self._bus_busy_ns[name] / elapsed if elapsed > 0 else 0.0,
                }
            ports = {}
            for bus in self.buses.values():
                for name in sorted(bus.ports):
                    counts = self._port_counts.get(name, collections.Counter())
                    ports[name] = {"bus": bus.name, **{key: counts[key] for key in
                                                       ("sent", "failed", "lost", "received")}}
            return {"time_ns": elapsed, "buses": buses, "ports": ports}

    def statistics_lines(self):
        """statistics() as the bus log's closing comment lines."""
        stats = self.statistics()
        lines = [f"# {stats['time_ns']} statistics"]
        with self._lock:
            line_records = list(self._line_records)
        for line in self.lines.values():
            records = [r for r in line_records if r.line == line.name]
            garbled = sum(1 for r in records if r.outcome == "garbled")
            lines.append(f"# {stats['time_ns']} line {line.name} {line.baud} baud {line.format} "
                         f"characters={len(records)} garbled={garbled}")
        for name, bus in stats["buses"].items():
            lines.append(f"# {stats['time_ns']} bus {name} {bus['bitrate']} bit/s frames={bus['frames']} "
                         f"errors={bus['errors']} load={100 * bus['load']:.2f}%")
        for name, port in stats["ports"].items():
            lines.append(f"# {stats['time_ns']} port {name} sent={port['sent']} failed={port['failed']} "
                         f"lost={port['lost']} received={port['received']}")
        return lines

    def _comment(self, text, boundary=None):
        at = self.boundary if boundary is None else boundary
        line = f"# {at} {text}"
        with self._lock:
            self._log_lines.append(line)
        self._write_log(line)

    def _write_log(self, line):
        if self._log_file is not None:
            self._log_file.write(line + "\n")
            self._log_file.flush()
        if self.echo_log:
            print(line, flush=True)

    def _send_events(self, boundary):
        if not self._events:
            return
        self._events.sort(key=lambda e: (e[0], e[1]))
        for t, _, port, template in self._events:
            participant = port.participant
            if participant is self.hub_nodes:
                continue
            port_id = next((key for key, value in participant.ports.items() if value is port), None)
            if port_id is None or participant.closed:
                continue
            participant.queue(template.format(port=port_id, time=t))
        self._events.clear()
        for participant in self.participants.values():
            if participant.kind in ("host", "realtime"):
                participant.flush()


# -- a participant in Python ---------------------------------------------------------


class Client:
    """One participant of the hub, speaking the protocol directly.

    A host tool's "lab bus" transport joins as kind "host": it sends frames
    with the time "-" (they enter at the next boundary) and reads events as
    they come. Kind "emulated" is a participant with its own clock, which
    must call sync() at every boundary; the lab's tests use it to check the
    hub without an emulator. Kind "realtime" is a chip without such a clock
    (the lab VM's card): it sends like a host tool and reports its states
    like a board.
    """

    def __init__(self, socket_path, name, kind="host", timeout=10.0):
        self.name = name
        self.kind = kind
        self.timeout = timeout
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock.settimeout(timeout)
        self.sock.connect(socket_path)
        self._buffer = b""
        self.send_line(f"HELLO {PROTOCOL_VERSION} {name} {kind}")
        words = self.read_line().split()
        if len(words) != 4 or words[0] != "WELCOME":
            raise ProtocolError(f"the hub answered HELLO with {' '.join(words)!r}")
        self.quantum_ns = int(words[2])
        self.time_ns = int(words[3])
        self.boundary = self.quantum_ns

    def send_line(self, line):
        self.sock.sendall((line + "\n").encode("ascii"))

    def read_line(self):
        while b"\n" not in self._buffer:
            data = self.sock.recv(65536)
            if not data:
                raise ProtocolError("the hub closed the connection")
            self._buffer += data
        line, self._buffer = self._buffer.split(b"\n", 1)
        return line.decode("ascii")

    def attach(self, port, bus, label=None):
        """Attaches port (a small number) to bus; returns the bus's bit time in ns."""
        self.send_line(f"ATTACH {port} {bus}" + (f" {label}" if label is not None else ""))
        words = self.read_line().split()
        if words[0] != "ATTACHED":
            raise ProtocolError(" ".join(words))
        return int(words[3])

    def state(self, port, mode="on", t="-", epoch=0, bit_ns=0, sample_permille=0, flags="-"):
        self.send_line(f"STATE {port} {t} {epoch} {mode} {bit_ns} {sample_permille} {flags}")

    def transmit(self, port, frame, t="-", once=False, self_rx=False):
        options = ",".join(o for o, on in (("once", once), ("self", self_rx)) if on) or "-"
        self.send_line(f"TX {port} {t} {' '.join(frame.words())} {options}")

    def abort(self, port, t="-"):
        self.send_line(f"ABORT {port} {t}")

    def control(self, line):
        """FAULT, BABBLE or INJECT; returns the hub's DONE or NAK line."""
        self.send_line(line)
        return self.read_line()

    def sync(self):
        """Emulated participants: reports the boundary, returns the events up to GO."""
        return sync_together([self])[0]

    def events(self, until, timeout=None):
        """Host participants: reads event lines until until(lines) is true."""
        lines = []
        deadline = time.monotonic() + (timeout or self.timeout)
        while not until(lines):
            if time.monotonic() > deadline:
                raise ProtocolError(f"no such events within the time-out; got {lines}")
            lines.append(self.read_line())
        return lines

    def close(self):
        try:
            self.send_line("BYE")
        except OSError:
            pass
        self.sock.close()


def sync_together(clients):
    """Several emulated participants of one process pass a boundary together.

    Each reports its boundary first and only then reads its events up to
    GO, since the hub answers a boundary only once every participant is
    there. Returns each client's event lines, in the clients' order.
    """
    for client in clients:
        client.send_line(f"SYNC {client.boundary}")
    events = []
    for client in clients:
        lines = []
        while True:
            line = client.read_line()
            if line.startswith("GO "):
                client.boundary = int(line.split()[1])
                break
            lines.append(line)
        events.append(lines)
    return events


# -- command line ------------------------------------------------------------------


def _bus_argument(text):
    name, equals, rate = text.partition("=")
    if not equals or not name or not rate.isdigit():
        raise argparse.ArgumentTypeError(f"'{text}' is not NAME=BITRATE, e.g. can0=500000")
    return name, int(rate)


def _line_argument(text):
    name, equals, spec = text.partition("=")
    baud, _, fmt = spec.partition(",")
    try:
        if not equals or not name or not baud.isdigit():
            raise LineError("expected NAME=BAUD[,FORMAT]")
        parse_format(fmt or "8E1")
    except LineError as error:
        raise argparse.ArgumentTypeError(f"'{text}': {error}, e.g. rs485=19200,8E1") from None
    return name, (int(baud), fmt or "8E1")


def main(argv=None):
    parser = argparse.ArgumentParser(description="The DCOS lab's CAN bus hub (docs/protocols/labbus.md).")
    parser.add_argument("--socket", required=True, help="unix socket the boards' cards connect to (isa-sja1000 hub=)")
    parser.add_argument("--bus", type=_bus_argument, action="append", default=[], metavar="NAME=BITRATE",
                        help="a bus and its bit rate in bit/s, e.g. can0=500000 (repeatable)")
    parser.add_argument("--line", type=_line_argument, action="append", default=[], metavar="NAME=BAUD[,FORMAT]",
                        help="an RS-485 line, its baud rate and the format of host stations, e.g. rs485=19200,8E1 "
                             "(repeatable)")
    parser.add_argument("--expect", action="append", default=[], metavar="NAME",
                        help="hold the clock until this board has joined (repeatable)")
    parser.add_argument("--pace", type=float, default=None,
                        help="at most this many emulated seconds per wall second (default: as fast as possible)")
    parser.add_argument("--log", default=None, help="also write the bus log to this file (statistics at its end)")
    parser.add_argument("--candump", default=None, metavar="FILE",
                        help="write the frames that went through to FILE in candump -l format, with emulated times")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT,
                        help="seconds to wait for a silent board before dropping it")
    arguments = parser.parse_args(argv)
    if not arguments.bus and not arguments.line:
        parser.error("name at least one --bus or --line")
    hub = Hub(arguments.socket, dict(arguments.bus), expect=arguments.expect, pace=arguments.pace,
              timeout=arguments.timeout, log_path=arguments.log, echo_log=True, candump_path=arguments.candump,
              lines=dict(arguments.line))
    print(f"# hub on {arguments.socket}: "
          + ", ".join([f"{bus.name} {bus.bitrate} bit/s" for bus in hub.buses.values()]
                      + [f"{line.name} {line.baud} baud {line.format}" for line in hub.lines.values()])
          + f", quantum {hub.quantum_ns} ns", flush=True)
    try:
        hub.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        for line in hub.statistics_lines():
            print(line, flush=True)
        hub._close_all()
    return 0


if __name__ == "__main__":
    sys.exit(main())
