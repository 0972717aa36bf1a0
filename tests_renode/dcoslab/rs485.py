"""The lab's RS-485 line: characters in emulated time, collisions, and host programs on a pseudo-terminal.

A line is a second kind of medium of the lab hub (dcoslab/canbus.py's Hub,
its `lines` argument), beside the CAN buses: the hub keeps the boards in
lock-step as for CAN, and this module decides what happens on each line.
A board's port is its `isa-rs485-uart` (tests_renode/models/isa_rs485.c)
with the properties hub, hub-name and line; a host program joins as a
host participant, or through a pseudo-terminal with LinePty.
docs/protocols/labbus.md, "The RS-485 line", specifies the messages and
the timing and collision model this module implements:

- a character lasts start + data + parity + stop bits at its sender's bit
  time and reaches the receivers when its last stop bit ends;
- a receiver samples the first stop bit in its middle, so a character is
  decided by everything that drove the line from its start bit to that
  sample point: if another driver was enabled in that time (a second
  character, or a board's driver enable, which drives the idle level),
  every receiver gets it garbled (framing error; the data bits of the
  characters that overlapped ANDed, as on a line where the low level wins);
- a port does not hear what is on the line while its own driver is on
  (a half-duplex transceiver with RE tied to /DE), so no one hears their
  own echo.

The quantum of a hub with lines is at most half a bit time of the fastest
line, so everything that can garble a character is known at the boundary
its end is announced at (see Line.quantum_limit_ns).

    hub = Hub(socket_path, {}, lines={"rs485": (19200, "8E1")}, expect=["board1"])
    hub.line_send("rs485", "lab", frame, gaps_ns=[0, 0, 900_000, 0])   # a silence inside a frame
    hub.line_records()                                                   # what was on the line
"""

import dataclasses
import os
import select
import threading
import tty

# Parity letters of a format: none, odd, even, mark, space (PC16550D, LCR bits 3-5).
PARITIES = "NOEMS"
# Picoseconds per second: bit times are kept in ps (the UART's divisor gives
# divisor * 78125000 / 9 ps with the PC's 1.8432 MHz clock).
PS_PER_SECOND = 1_000_000_000_000


class LineError(ValueError):
    """A malformed line message, format or request."""


def parse_format(text):
    """'8E1' -> (8, 'E', 2): data bits, parity letter, stop bits in half bits."""
    if len(text) < 3 or not text[0].isdigit() or text[1] not in PARITIES or text[2:] not in ("1", "1.5", "2"):
        raise LineError(f"format {text!r} is not <data bits 5-8><parity N|O|E|M|S><stop bits 1|1.5|2>, e.g. 8E1")
    data = int(text[0])
    if not 5 <= data <= 8:
        raise LineError(f"format {text!r}: {data} data bits is not 5..8")
    stop = {"1": 2, "1.5": 3, "2": 4}[text[2:]]
    return data, text[1], stop


def char_half_bits(fmt):
    """A character's length in half bits: start, data, parity and stop (as isa_rs485.c computes it)."""
    data, parity, stop_half = parse_format(fmt)
    return 2 * (1 + data + (parity != "N")) + stop_half


def char_ns(bit_ps, fmt):
    """A character's length in ns, rounded as the UART model rounds it."""
    return (char_half_bits(fmt) * bit_ps + 1000) // 2000


def sample_offset_ns(bit_ps, fmt):
    """From the start bit to the middle of the first stop bit, where a receiver decides the character."""
    data, parity, _ = parse_format(fmt)
    return ((2 * (1 + data + (parity != "N")) + 1) * bit_ps + 1000) // 2000


def baud_bit_ps(baud):
    """The bit time of a baud rate in ps, rounded (19200 -> 52083333, as divisor 6 gives)."""
    return (PS_PER_SECOND + baud // 2) // baud


@dataclasses.dataclass
class LineChar:
    """One character on the line: who drove it, when, and what it carried."""

    sender: str
    start: int
    bit_ps: int
    format: str
    byte: int
    seq: int = 0
    # Announced to the receivers (at the boundary before its end).
    decided: bool = False

    @property
    def end(self):
        return self.start + char_ns(self.bit_ps, self.format)

    @property
    def sample(self):
        return self.start + sample_offset_ns(self.bit_ps, self.format)


@dataclasses.dataclass(frozen=True)
class LineRecord:
    """One character of the line log.

    start is the emulated time of its start bit, end of its last stop bit;
    outcome is ok or garbled (another driver was on the line before its stop
    bit's sample point); byte is what the receivers got (for a garbled one,
    the AND of the overlapping characters); rx the ports that took it.
    """

    start: int
    end: int
    line: str
    byte: int
    format: str
    sender: str
    outcome: str
    rx: tuple = ()

    def text(self):
        return (f"{self.start} {self.end} {self.line} {self.byte:02x} {self.format} from={self.sender} "
                f"{self.outcome} rx={','.join(self.rx) or '-'}")

    @classmethod
    def parse(cls, text):
        words = text.split()
        if len(words) != 8 or not words[5].startswith("from=") or not words[7].startswith("rx="):
            raise ValueError(f"not a line log record: {text!r}")
        rx = words[7][3:]
        return cls(int(words[0]), int(words[1]), words[2], int(words[3], 16), words[4], words[5][5:], words[6],
                   () if rx == "-" else tuple(rx.split(",")))


def parse_line_log(text, line=None):
    """The character records of a hub log (CAN frames and comments left out)."""
    records = []
    for text_line in text.splitlines():
        words = text_line.split()
        if len(words) == 8 and words[5].startswith("from=") and words[7].startswith("rx="):
            record = LineRecord.parse(text_line)
            if line is None or record.line == line:
                records.append(record)
    return records


class LinePort:
    """One station on a line: a board's UART, a host program, or the hub's own node."""

    def __init__(self, participant, label, line):
        self.participant = participant
        self.label = label
        self.name = f"{participant.name}.{label}"
        # The hub's code for CAN ports finds a port's medium as `bus`.
        self.bus = line
        self.line = line
        # Driver enable changes [(time, on)]; a board's comes from DRIVE,
        # a host's or the hub's driver is on only while it sends.
        self.drive = []
        # Where this port's next character may start (host and hub ports
        # send back to back, from the boundary their bytes arrive at).
        self.next_start = 0
        # A host station's burst starts only after this much silence on the line (SILENCE).
        self.min_silence_ns = 0
        self.pending = []

    def drive_on_at(self, t):
        on = False
        for when, state in self.drive:
            if when > t:
                break
            on = state
        return on

    def drive_on_during(self, a, b):
        """Whether the driver was enabled at any time in [a, b)."""
        if self.drive_on_at(a):
            return True
        return any(a < when < b and state for when, state in self.drive)

    def prune(self, before):
        while len(self.drive) > 1 and self.drive[1][0] <= before:
            self.drive.pop(0)


class Line:
    """One RS-485 line: its bit rate and format (those of host and hub stations), its ports and characters."""

    def __init__(self, name, baud, fmt="8E1"):
        if baud <= 0:
            raise ValueError(f"line {name}: {baud} baud is not a rate")
        parse_format(fmt)
        self.name = name
        self.baud = baud
        self.format = fmt
        self.bit_ps = baud_bit_ps(baud)
        self.ports = {}
        # Characters not yet decided, and the decided ones that may still
        # overlap an undecided one.
        self.chars = []
        self.seq = 0
        # The end of the last character anyone put on the line.
        self.last_end = 0

    @property
    def bit_ns(self):
        return self.bit_ps // 1000

    def quantum_limit_ns(self):
        """Half a bit time: a character's end announced at boundary B lies before B + Q, so the middle
        of its stop bit, which decides it, lies before B, and everything that could garble it is known."""
        return self.bit_ps // 2000

    def sorted_ports(self):
        return [self.ports[name] for name in sorted(self.ports)]

    def add_char(self, port, start, bit_ps, fmt, byte):
        if not 0 <= byte <= 0xFF:
            raise LineError(f"byte {byte} is not 0..ff")
        parse_format(fmt)
        char = LineChar(port.name, start, bit_ps, fmt, byte, self.seq)
        self.seq += 1
        self.chars.append(char)
        port.next_start = max(port.next_start, char.end)
        self.last_end = max(self.last_end, char.end)
        return char

    def decide(self, boundary, quantum):
        """The characters whose end must be announced at this boundary (it lies before the next), with what
        the receivers hear: [(char, garbled, byte, receivers)], in time order."""
        due = sorted((c for c in self.chars if not c.decided and c.end < boundary + quantum),
                     key=lambda c: (c.start, c.seq))
        decisions = []
        for char in due:
            char.decided = True
            others = [c for c in self.chars if c.sender != char.sender and c.start < char.sample and c.end > char.start]
            enabled = [p for p in self.sorted_ports()
                       if p.name != char.sender and p.drive_on_during(char.start, char.sample)]
            garbled = bool(others or enabled)
            byte = char.byte
            for other in others:
                byte &= other.byte
            receivers = [p for p in self.sorted_ports() if p.name != char.sender and not self._driving(p, char.sample)]
            decisions.append((char, garbled, byte, receivers))
        return decisions

    def _driving(self, port, t):
        """A port's receiver is off while its driver is on (RE tied to /DE): its DE, or its own character."""
        if port.drive_on_at(t):
            return True
        return any(c.sender == port.name and c.start <= t < c.end for c in self.chars)

    def prune(self, boundary):
        """Forgets characters that can no longer overlap an undecided one."""
        undecided = [c.start for c in self.chars if not c.decided]
        horizon = min(undecided + [boundary]) - max((char_ns(c.bit_ps, c.format) for c in self.chars), default=0)
        self.chars = [c for c in self.chars if not c.decided or c.end > horizon]
        for port in self.ports.values():
            port.prune(horizon)


# -- a host program on the line through a pseudo-terminal ------------------------------


class LinePty:
    """A pseudo-terminal whose other end is a host station on a line of the hub.

    A program that expects a serial device (libmodbus's dcos-modbus and
    dcos-modbus-sim, pymodbus's serial client) opens `pty_path` as it would
    /dev/ttyUSB0. What it writes enters the line at the hub's next boundary
    and goes out back to back at the line's bit rate and format; what the
    line carries to this station is written to it as it is announced
    (garbled characters as the byte the receivers got: a USB adapter hands
    those on as well, and the program's CRC check rejects the frame). The
    program runs in wall time, the boards in emulated time: its time-outs
    must allow for the lab's pace.
    """

    def __init__(self, socket_path, line, name="host", timeout=10.0, silence_ns=0):
        """silence_ns: the station starts a burst of bytes only after the line has been silent that
        long, as a Modbus RTU station must wait t3.5 ([SL] 2.5.1.1) and a host program in wall time
        cannot: pymodbus 3.0's serial slave and dcos-modbus-sim answer as soon as a request is in,
        which the lab's emulated time may make sooner than t3.5."""
        from .canbus import Client

        self.line = line
        self.name = name
        self.client = Client(socket_path, name, "host", timeout)
        self.client.attach(0, line)
        if silence_ns:
            self.client.send_line(f"SILENCE 0 - {silence_ns}")
        self._master, slave = os.openpty()
        tty.setraw(slave)
        self.pty_path = os.ttyname(slave)
        # Kept open so that the pty does not hang up between a program's opens.
        self._slave = slave
        self.sent = bytearray()
        self.received = bytearray()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._copy, name=f"line-pty-{name}", daemon=True)
        self._thread.start()

    def _copy(self):
        sock = self.client.sock
        buffer = b""
        while not self._stop.is_set():
            ready, _, _ = select.select([sock, self._master], [], [], 0.1)
            try:
                if self._master in ready:
                    data = os.read(self._master, 4096)
                    self.sent += data
                    if data:
                        self.client.send_line("\n".join(f"CHAR 0 - - - {byte:02x}" for byte in data))
                if sock in ready:
                    chunk = sock.recv(65536)
                    if not chunk:
                        return
                    buffer += chunk
                    while b"\n" in buffer:
                        raw, buffer = buffer.split(b"\n", 1)
                        words = raw.decode("ascii", "replace").split()
                        if len(words) == 8 and words[0] == "RX":
                            byte = int(words[6], 16)
                            self.received.append(byte)
                            os.write(self._master, bytes([byte]))
            except OSError:
                return

    def close(self):
        self._stop.set()
        self._thread.join(timeout=5)
        self.client.close()
        for fd in (self._master, self._slave):
            try:
                os.close(fd)
            except OSError:
                pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
