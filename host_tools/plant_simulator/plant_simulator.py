#!/usr/bin/python3
"""A plant simulator for the emulated multi-function I/O board (isa-mfio).

The emulator's isa-mfio model, started with wiring=plant, connects to this
program and exchanges one line per conversion (docs/iobus/mfio-register-map.md,
"Plant protocol"):

    model -> plant:  SAMPLE <time ns> <DAC0 V> ... <DAC7 V> <DO hex>
    plant -> model:  INPUT <AI0 V> ... <AI7 V> <DI hex>

The simulated process is a first-order-plus-dead-time (FOPDT) system

    tau * dy/dt = -y + offset + K * u(t - theta) + d(t)

where u is one DAC output, y is fed to one ADC input, and d is an optional
load disturbance that steps at a given time. Between two SAMPLE timestamps
the program integrates exactly: the analog outputs are held constant from the
sample at which they were seen (zero-order hold), the dead time is a FIFO of
input changes keyed by the emulated time at which they reach the process, and
every interval is split at those changes and at the disturbance step, each
piece solved by the analytical step response. The result depends only on the
lines received, so a closed loop under -icount is repeatable run for run.

With --boards N the simulator serves N emulated boards at once over the
socket, one connection each: every board's ADC reads the same process, and
the process input is the highest of the connected boards' DAC outputs, as
when several controllers' outputs are wired through diodes to one actuator
(redundant outputs). A board whose connection closes (its emulator stopped,
its node dead) no longer drives the process, as de-energised outputs would
not. The boards are kept in lock-step by the lab, so their lines arrive
within its quantum of each other; a line slightly behind the simulation is
taken at the simulation's time.

The digital part copies DO to DI by default, or follows a configurable
mapping. Every line in gets exactly one line out: a malformed line is
answered with the previous inputs and counted, never fatal. Every line is
checked in full before it touches the simulation: a time beyond 2^63 - 1 ns,
a DAC value that is not finite or outside the DAC's +-10 V, a line longer
than 4096 characters are each rejected with a message on stderr, and a line
that would make the state or an answer non-finite is rejected and leaves the
state as it was. The options are checked the same way (finite, in range), so
the simulation stays finite whatever it is sent.

Exit status: 0 at a normal end (end of input, the client disconnected,
SIGTERM or Ctrl-C), 2 for bad options (a value out of range, NaN or
infinite, or a --csv file that cannot be created), 3 when the socket cannot
be opened or no client connects within --accept-timeout.

Run `plant_simulator.py --help` for every option; README.md next to this file
explains them with examples.
"""

import argparse
import csv
import math
import re
import os
import random
import select
import signal
import socket
import stat
import sys
import time

CHANNELS = 8
DIGITAL_BITS = 16
PROTOCOL_INPUT_FIELDS = 1 + 1 + CHANNELS + 1  # keyword, time, 8 volts, DO
# A SAMPLE line is about 100 characters; anything this long is not one, and
# the reader drops the rest of it instead of buffering without end.
MAX_LINE_LENGTH = 4096
# The model sends its virtual clock, a signed 64-bit count of nanoseconds.
MAX_TIME_NS = 2**63 - 1
# The DACs span -10 V to +10 V (docs/iobus/mfio-register-map.md).
DAC_LIMIT_V = 10.0
# Bounds of the options: wide enough for any plant, small enough that every
# product and sum of them stays finite.
MAX_VOLTS = 1e6
MAX_GAIN = 1e6
MAX_SECONDS = 1e9
MAX_TIMEOUT_S = 1e6
TIME_TEXT = re.compile(r"-?[0-9]+")

EXIT_OK = 0
EXIT_USAGE = 2
EXIT_CONNECTION = 3


class ProtocolError(ValueError):
    """A SAMPLE line that does not follow the protocol."""


class OverlongLine(str):
    """The start of a line longer than MAX_LINE_LENGTH; the reader dropped the rest."""


def _short(text):
    return repr(text) if len(text) <= 20 else repr(text[:20]) + f"... ({len(text)} characters)"


def parse_sample(line):
    """Parses one SAMPLE line into (time_ns, [8 volts], do_word).

    Raises ProtocolError with a message that says what is wrong; anything it
    returns is in range: 0 <= time_ns <= 2^63 - 1, every volt finite and
    within the DACs' +-10 V, the DO word 16 bits.
    """
    if isinstance(line, OverlongLine) or len(line) > MAX_LINE_LENGTH:
        raise ProtocolError(f"line longer than {MAX_LINE_LENGTH} characters")
    fields = line.split()
    if not fields:
        raise ProtocolError("empty line")
    if fields[0] != "SAMPLE":
        raise ProtocolError(f"expected the keyword SAMPLE, got {_short(fields[0])}")
    if len(fields) != PROTOCOL_INPUT_FIELDS:
        raise ProtocolError(f"expected {PROTOCOL_INPUT_FIELDS} fields, got {len(fields)}")
    if not TIME_TEXT.fullmatch(fields[1]):
        raise ProtocolError(f"time {_short(fields[1])} is not a whole number of ns")
    if fields[1].startswith("-"):
        raise ProtocolError(f"time {_short(fields[1])} is negative")
    # Checked by length before conversion: int() of thousands of digits is slow or refused.
    if len(fields[1].lstrip("0")) > 19 or int(fields[1], 10) > MAX_TIME_NS:
        raise ProtocolError(f"time {_short(fields[1])} is beyond 2^63 - 1 ns, the model's clock")
    time_ns = int(fields[1], 10)
    volts = []
    for index, text in enumerate(fields[2:2 + CHANNELS]):
        try:
            value = float(text) if len(text) <= 40 else None
        except ValueError:
            value = None
        if value is None:
            raise ProtocolError(f"DAC{index} value {_short(text)} is not a number")
        if not math.isfinite(value):
            raise ProtocolError(f"DAC{index} value {_short(text)} is not finite")
        if abs(value) > DAC_LIMIT_V:
            raise ProtocolError(f"DAC{index} value {_short(text)} is outside the DAC's -10..+10 V")
        volts.append(value)
    do_text = fields[-1]
    if len(do_text) != 4 or any(c not in "0123456789abcdefABCDEF" for c in do_text):
        raise ProtocolError(f"DO {do_text[:20]!r} is not 4 hex digits")
    return time_ns, volts, int(do_text, 16)


def format_input(volts, di_word):
    """The INPUT reply line (without the newline) for 8 volts and a DI word."""
    return "INPUT " + " ".join(f"{v:.6f}" for v in volts) + f" {di_word & 0xFFFF:04x}"


class Fopdt:
    """A first-order-plus-dead-time process integrated exactly between events.

    Times are integer nanoseconds of emulated time. The input is held from
    the time it is applied (zero-order hold); before the first input the
    process sees `input_before`. The state starts at `initial` at the time
    of the first call to advance().
    """

    def __init__(self, gain, tau_s, dead_time_s, initial=0.0, offset=0.0, input_before=0.0,
                 disturbance=0.0, disturbance_at_s=None):
        if tau_s < 0 or dead_time_s < 0:
            raise ValueError("tau and the dead time must not be negative")
        self.gain = gain
        self.tau_ns = tau_s * 1e9
        self.dead_ns = int(round(dead_time_s * 1e9))
        self.offset = offset
        self.disturbance = disturbance
        self.disturbance_at_ns = None if disturbance_at_s is None else int(round(disturbance_at_s * 1e9))
        self.y = initial
        self.time_ns = None
        # The input as the process sees it (after the dead time) and the
        # pending changes, each as (time it reaches the process, value),
        # in time order.
        self.delayed_input = input_before
        self.fifo = []

    def _target(self, time_ns):
        """The steady state the lag is heading for at time_ns (inputs at or before it)."""
        target = self.offset + self.gain * self.delayed_input
        if self.disturbance_at_ns is not None and time_ns >= self.disturbance_at_ns:
            target += self.disturbance
        return target

    def apply_input(self, time_ns, value):
        """The input changes to value at time_ns; the process sees it dead_ns later."""
        if self.time_ns is not None and time_ns < self.time_ns:
            raise ValueError(f"time went backwards from {self.time_ns} to {time_ns} ns")
        latest = self.fifo[-1][1] if self.fifo else self.delayed_input
        if value != latest:
            self.fifo.append((time_ns + self.dead_ns, value))

    def save(self):
        """The whole state, for restore() when a step must be undone."""
        return self.y, self.time_ns, self.delayed_input, list(self.fifo)

    def restore(self, state):
        self.y, self.time_ns, self.delayed_input, fifo = state
        self.fifo = list(fifo)

    def _pop_arrived(self, time_ns):
        while self.fifo and self.fifo[0][0] <= time_ns:
            self.delayed_input = self.fifo.pop(0)[1]

    def _relax(self, duration_ns, target):
        if duration_ns <= 0:
            return
        if self.tau_ns == 0:
            self.y = target
        else:
            self.y = target + (self.y - target) * math.exp(-duration_ns / self.tau_ns)

    def advance(self, time_ns):
        """Integrates up to time_ns and returns y there (right-continuous)."""
        if self.time_ns is None:
            self.time_ns = time_ns
        if time_ns < self.time_ns:
            raise ValueError(f"time went backwards from {self.time_ns} to {time_ns} ns")
        self._pop_arrived(self.time_ns)
        while True:
            # The next event inside (now, time_ns]: an input arriving or the disturbance.
            events = [time_ns]
            if self.fifo:
                events.append(self.fifo[0][0])
            if self.disturbance_at_ns is not None and self.disturbance_at_ns > self.time_ns:
                events.append(self.disturbance_at_ns)
            step_end = min(events)
            self._relax(step_end - self.time_ns, self._target(self.time_ns))
            self.time_ns = step_end
            self._pop_arrived(self.time_ns)
            if self.time_ns >= time_ns:
                break
        if self.tau_ns == 0:
            self.y = self._target(self.time_ns)
        return self.y


def parse_di_map(text):
    """Parses 'DI=DO,DI=DO,...' into {di_bit: do_bit}."""
    mapping = {}
    if not text:
        return mapping
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        left, sep, right = item.partition("=")
        if not sep:
            raise argparse.ArgumentTypeError(f"DI map entry {item!r} is not DI=DO")
        try:
            di_bit, do_bit = int(left), int(right)
        except ValueError:
            raise argparse.ArgumentTypeError(f"DI map entry {item!r}: bits are numbers 0..15") from None
        if not (0 <= di_bit < DIGITAL_BITS and 0 <= do_bit < DIGITAL_BITS):
            raise argparse.ArgumentTypeError(f"DI map entry {item!r}: bits are numbers 0..15")
        mapping[di_bit] = do_bit
    return mapping


def float_in(low, high):
    """An argparse type: a finite number from low to high (NaN and the infinities are refused)."""
    def parse(text):
        try:
            value = float(text) if len(text) <= 40 else math.nan
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{_short(text)} is not a finite number from {low:g} to {high:g}")
        return value
    return parse


def int_in(low, high):
    """An argparse type: a whole number from low to high."""
    def parse(text):
        try:
            value = int(text, 10) if len(text) <= 40 else None
        except ValueError:
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{_short(text)} is not a whole number from {low} to {high}")
        return value
    return parse


def parse_constant(text):
    """Parses 'CH=VOLTS' for --ai-constant."""
    left, sep, right = text.partition("=")
    try:
        channel, volts = int(left), (float(right) if len(right) <= 40 else math.nan)
    except ValueError:
        channel = -1
        volts = 0.0
    if not sep or not 0 <= channel < CHANNELS or not math.isfinite(volts) or abs(volts) > MAX_VOLTS:
        raise argparse.ArgumentTypeError(f"{_short(text)} is not CH=VOLTS with CH in 0..7 and |VOLTS| <= 1e6")
    return channel, volts


def hex_word(text):
    try:
        value = int(text, 16)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a hex number") from None
    if not 0 <= value <= 0xFFFF:
        raise argparse.ArgumentTypeError(f"{text!r} does not fit 16 bits")
    return value


def channel_number(text):
    try:
        value = int(text) if len(text) <= 8 else -1
    except ValueError:
        value = -1
    if not 0 <= value < CHANNELS:
        raise argparse.ArgumentTypeError(f"channel {_short(text)} is not in 0..7")
    return value


class PlantSimulator:
    """The whole plant: the FOPDT loop, the other analog inputs and the digital wiring."""

    def __init__(self, options, log=sys.stderr):
        self.options = options
        self.log = log
        self.process = Fopdt(
            options.gain, options.tau, options.dead_time, initial=options.initial, offset=options.offset,
            input_before=options.initial_input, disturbance=options.disturbance,
            disturbance_at_s=options.disturbance_at,
        )
        self.random = random.Random(options.seed)
        self.constants = dict(options.ai_constant or [])
        self.di_map = options.di_map
        self.samples = 0
        self.errors = 0
        # With several boards (--boards), each board's DAC --input-channel
        # as its last SAMPLE gave it; the process sees the highest.
        self.drives = {}
        self.max_skew_ns = int(round(options.max_skew * 1e6))
        self.messages_left = options.max_error_messages
        # What a malformed line is answered with: its board's previous
        # answer, or before the board's first sample the initial inputs.
        self.initial_reply = format_input(self._analog(options.initial, [0.0] * CHANNELS, noise=False),
                                          self._digital(0))
        self.last_replies = {}
        self.csv_writer = None
        self._csv_file = None
        if options.csv:
            # An OSError here (a missing directory) is the caller's to report as a bad option.
            self._csv_file = open(options.csv, "w", newline="", encoding="utf-8")
            self.csv_writer = csv.writer(self._csv_file)
            self.csv_writer.writerow(
                ["time_ns", "time_s"] + [f"dac{i}" for i in range(CHANNELS)]
                + ["do", "process_input", "process_output", "disturbance"]
                + [f"ai{i}" for i in range(CHANNELS)] + ["di"]
                + (["board"] if options.boards > 1 else [])
            )

    def close(self):
        if self._csv_file is not None:
            self._csv_file.close()
            self._csv_file = None

    def _digital(self, do_word):
        if not self.di_map:
            di = do_word
        else:
            di = self.options.di_fixed
            for di_bit, do_bit in self.di_map.items():
                di &= ~(1 << di_bit)
                di |= ((do_word >> do_bit) & 1) << di_bit
        return (di ^ self.options.di_invert) & 0xFFFF

    def _analog(self, y, dacs, noise=True):
        if self.options.other_inputs == "loopback":
            volts = list(dacs)
        else:
            volts = [0.0] * CHANNELS
        for channel, value in self.constants.items():
            volts[channel] = value
        measured = y
        if noise and self.options.noise > 0:
            measured += self.random.gauss(0.0, self.options.noise)
        volts[self.options.output_channel] = measured
        return volts

    def _error(self, number, reason):
        self.errors += 1
        if self.messages_left > 0:
            self.messages_left -= 1
            print(f"plant: line {number}: {reason}; answered with the previous inputs", file=self.log)
            if self.messages_left == 0:
                print("plant: further line errors are counted but not printed", file=self.log)

    def _step(self, time_ns, dacs, do_word, board):
        """Advances the simulation to one sample; undoes it all and raises ProtocolError if anything would
        not be finite, so that no line can poison the state for the lines after it."""
        if self.process.time_ns is not None and time_ns < self.process.time_ns:
            # Boards kept in step (--boards) differ by less than the lab's
            # quantum: a sample that far behind is taken at the simulation's time.
            if self.options.boards == 1 or self.process.time_ns - time_ns > self.max_skew_ns:
                raise ProtocolError(f"time went backwards from {self.process.time_ns} to {time_ns} ns")
            time_ns = self.process.time_ns
        drives = dict(self.drives)
        drives[board] = dacs[self.options.input_channel]
        saved, noise_state = self.process.save(), self.random.getstate()
        try:
            self.process.apply_input(time_ns, max(drives.values()))
            y = self.process.advance(time_ns)
            volts = self._analog(y, dacs)
            if not math.isfinite(y) or not all(math.isfinite(v) for v in volts):
                raise ProtocolError("the sample would make the simulation non-finite")
        except (ValueError, ArithmeticError) as error:
            self.process.restore(saved)
            self.random.setstate(noise_state)
            raise ProtocolError(str(error)) from None
        self.drives = drives
        return time_ns, y, volts

    def disconnect(self, board):
        """The board numbered board has gone (its emulator stopped): its
        outputs no longer drive the process, from the simulation's present
        time on, as a controller's de-energised outputs would not."""
        if self.drives.pop(board, None) is None or self.process.time_ns is None:
            return
        self.process.apply_input(self.process.time_ns, max(self.drives.values(), default=0.0))

    def handle_line(self, line, number=0, board=0):
        """Returns the reply (without newline) to one received line of the
        board numbered board (0 to --boards - 1); never raises for what the
        line holds."""
        if not isinstance(line, OverlongLine):
            line = line.strip("\r\n")
        try:
            time_ns, dacs, do_word = parse_sample(line)
            time_ns, y, volts = self._step(time_ns, dacs, do_word, board)
        except ProtocolError as error:
            self._error(number if self.options.boards == 1 else f"{number} of board {board}", error)
            return self.last_replies.get(board, self.initial_reply)
        self.samples += 1
        di = self._digital(do_word)
        reply = format_input(volts, di)
        if self.csv_writer is not None:
            self._log(time_ns, dacs, do_word, y, volts, di, board)
        self.last_replies[board] = reply
        return reply

    def _log(self, time_ns, dacs, do_word, y, volts, di, board):
        disturbance = 0.0
        if self.process.disturbance_at_ns is not None and time_ns >= self.process.disturbance_at_ns:
            disturbance = self.process.disturbance
        try:
            self.csv_writer.writerow(
                [time_ns, f"{time_ns / 1e9:.9f}"] + [f"{v:.6f}" for v in dacs]
                + [f"{do_word:04x}", f"{self.process.delayed_input:.6f}", f"{y:.6f}", f"{disturbance:.6f}"]
                + [f"{v:.6f}" for v in volts] + [f"{di:04x}"]
                + ([board] if self.options.boards > 1 else [])
            )
            self._csv_file.flush()
        except OSError as error:
            # A full disk ends the log, not the simulation the emulator depends on.
            print(f"plant: the CSV log stops here: {error}", file=self.log)
            self.csv_writer = None
            try:
                self._csv_file.close()
            except OSError:
                pass
            self._csv_file = None

    def summary(self):
        return f"plant: {self.samples} samples, {self.errors} malformed lines"


def serve_stream(simulator, read_line, write_line, idle_timeout):
    """Answers lines until end of input, the output closing, or idle_timeout seconds without a line."""
    number = 0
    while True:
        line = read_line(idle_timeout)
        if line is None:
            return "end of input"
        if line == "":
            return f"no line for {idle_timeout:g} s (--idle-timeout)"
        number += 1
        try:
            write_line(simulator.handle_line(line, number))
        except OSError as error:
            return f"the output closed ({error.strerror or error})"


class LineReader:
    """Reads whole lines from a file descriptor with a time-out per line.

    A line longer than MAX_LINE_LENGTH is not buffered whole: its start is
    kept, the rest is dropped up to its newline, and it comes back as an
    OverlongLine that the simulator rejects.
    """

    def __init__(self, fd):
        self.fd = fd
        self.buffer = b""
        self.eof = False
        self.overlong = None  # the start of a line being dropped

    def take(self):
        """The next whole line already read: a str ending in a newline, an
        OverlongLine, or at end of input the unterminated rest; None when
        there is none (yet, or at end of input any more)."""
        if b"\n" in self.buffer:
            line, _, self.buffer = self.buffer.partition(b"\n")
            if self.overlong is not None or len(line) > MAX_LINE_LENGTH:
                start = self.overlong if self.overlong is not None else line[:40].decode("latin-1")
                self.overlong = None
                return OverlongLine(start)
            # A line is at least "\n"-terminated; keep it non-empty so '' means time-out.
            return line.decode("latin-1") + "\n"
        if len(self.buffer) > MAX_LINE_LENGTH:
            if self.overlong is None:
                self.overlong = self.buffer[:40].decode("latin-1")
            self.buffer = b""
        if self.eof:
            if self.overlong is not None:
                line, self.overlong, self.buffer = self.overlong, None, b""
                return OverlongLine(line)
            if self.buffer:
                line, self.buffer = self.buffer, b""
                return line.decode("latin-1")
        return None

    def fill(self, timeout=None):
        """Reads what the descriptor has, waiting at most timeout seconds
        (None: without a limit); False on time-out."""
        ready, _, _ = select.select([self.fd], [], [], timeout)
        if not ready:
            return False
        data = os.read(self.fd, 65536)
        if not data:
            self.eof = True
        self.buffer += data
        return True

    def __call__(self, timeout):
        """A decoded line, None at end of input, '' on time-out."""
        deadline = time.monotonic() + timeout if timeout > 0 else None
        while True:
            line = self.take()
            if line is not None:
                return line
            if self.eof:
                return None
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return ""
            if not self.fill(remaining):
                return ""


def run_stdio(simulator, options):
    reader = LineReader(sys.stdin.fileno())

    def write_line(text):
        sys.stdout.write(text + "\n")
        sys.stdout.flush()

    why = serve_stream(simulator, reader, write_line, options.idle_timeout)
    if why.startswith("the output closed"):
        # Nothing reads the answers any more; the interpreter's final flush must not fail on them too.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return why


class Board:
    """One connected board of several (--boards): its socket, its reader, its number."""

    def __init__(self, connection, number):
        self.connection = connection
        self.number = number
        self.reader = LineReader(connection.fileno())
        self.lines = 0

    def fileno(self):
        return self.connection.fileno()

    def answer(self, text):
        """Sends one answer; False when the board is gone."""
        try:
            self.connection.sendall((text + "\n").encode("latin-1"))
        except OSError:
            return False
        return True


def serve_boards(simulator, listener, options):
    """Serves up to --boards connections at once, each one board, in the
    order their lines arrive. A board's number is the lowest free one. The
    session ends when every board that came has gone (unless
    --keep-listening), when none comes within --accept-timeout, or after
    --idle-timeout seconds without a line from any."""
    boards = []
    came = False
    started = time.monotonic()
    last_line = started
    while True:
        now = time.monotonic()
        if not boards and not came and options.accept_timeout > 0 and now - started > options.accept_timeout:
            print(f"plant: no client connected within {options.accept_timeout:g} s (--accept-timeout)",
                  file=sys.stderr)
            return EXIT_CONNECTION
        if options.idle_timeout > 0 and came and now - last_line > options.idle_timeout:
            print(f"plant: no line for {options.idle_timeout:g} s (--idle-timeout)", file=sys.stderr, flush=True)
            return EXIT_OK
        waiting = list(boards) + ([listener] if len(boards) < options.boards else [])
        ready, _, _ = select.select(waiting, [], [], 0.2)
        for source in ready:
            if source is listener:
                connection, _ = listener.accept()
                connection.settimeout(None)
                taken = {board.number for board in boards}
                number = min(n for n in range(options.boards) if n not in taken)
                boards.append(Board(connection, number))
                came = True
                print(f"plant: board {number} connected", file=sys.stderr, flush=True)
                continue
            board = source
            board.reader.fill(0)
            gone = None
            while gone is None:
                line = board.reader.take()
                if line is None:
                    gone = "end of input" if board.reader.eof else ""
                    break
                board.lines += 1
                last_line = time.monotonic()
                if not board.answer(simulator.handle_line(line, board.lines, board.number)):
                    gone = "the output closed"
            if gone:
                boards.remove(board)
                board.connection.close()
                simulator.disconnect(board.number)
                print(f"plant: board {board.number} gone ({gone}); it no longer drives the process",
                      file=sys.stderr, flush=True)
                if not boards and not options.keep_listening:
                    return EXIT_OK


def run_socket(simulator, options):
    path = options.socket
    if os.path.exists(path):
        # Only a stale socket is removed; any other file is left alone.
        if not stat.S_ISSOCK(os.stat(path).st_mode):
            print(f"plant: {path} exists and is not a socket", file=sys.stderr)
            return EXIT_CONNECTION
        os.unlink(path)
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        listener.bind(path)
        listener.listen(options.boards)
    except OSError as error:
        print(f"plant: cannot listen on {path}: {error}", file=sys.stderr)
        return EXIT_CONNECTION
    print(f"plant: listening on {path}", file=sys.stderr, flush=True)
    try:
        if options.boards > 1:
            return serve_boards(simulator, listener, options)
        while True:
            listener.settimeout(options.accept_timeout if options.accept_timeout > 0 else None)
            try:
                connection, _ = listener.accept()
            except socket.timeout:
                print(f"plant: no client connected within {options.accept_timeout:g} s (--accept-timeout)",
                      file=sys.stderr)
                return EXIT_CONNECTION
            print("plant: client connected", file=sys.stderr, flush=True)
            with connection:
                connection.settimeout(None)
                reader = LineReader(connection.fileno())

                def write_line(text, connection=connection):
                    try:
                        connection.sendall((text + "\n").encode("latin-1"))
                    except OSError:
                        pass

                why = serve_stream(simulator, reader, write_line, options.idle_timeout)
            print(f"plant: client gone ({why})", file=sys.stderr, flush=True)
            if not options.keep_listening:
                return EXIT_OK
    finally:
        listener.close()
        try:
            os.unlink(path)
        except OSError:
            pass


def build_parser():
    parser = argparse.ArgumentParser(
        prog="plant_simulator.py",
        description=(
            "Plant simulator for the emulated isa-mfio I/O board (wiring=plant). It answers each "
            "'SAMPLE <ns> <8 DAC volts> <DO hex>' line with 'INPUT <8 AI volts> <DI hex>', simulating a "
            "first-order-plus-dead-time process tau*dy/dt = -y + offset + K*u(t-theta) + d(t) from DAC "
            "--input-channel to ADC --output-channel, integrated exactly between the emulated timestamps."
        ),
        epilog=(
            "Transport: with --socket the program listens on a Unix socket and the emulator connects as the "
            "client (QEMU: -chardev socket,id=plant,path=SOCK -device isa-mfio,wiring=plant,plant=plant); "
            "without it, lines are read from stdin and answered on stdout. A malformed line (wrong keyword or "
            "field count, a time that is not 0 to 2^63-1 ns or goes backwards, a DAC value that is not finite or "
            "outside -10..+10 V, a line over 4096 characters) is answered with the previous inputs, reported "
            "on stderr and counted; it never ends the program. Volts options are finite and at most 1e6 in size. "
            "Exit status: 0 normal end (end of input, client gone, SIGTERM or Ctrl-C), 2 bad options (out of "
            "range, NaN, infinite, or a --csv file that cannot be created), 3 socket error or no client within "
            "--accept-timeout."
        ),
    )
    process = parser.add_argument_group("process (FOPDT)")
    process.add_argument("--gain", "-K", type=float_in(-MAX_GAIN, MAX_GAIN), default=1.0, help="process gain K, output volts per input volt, |K| <= 1e6 (default 1.0)")
    process.add_argument("--tau", type=float_in(0.0, MAX_SECONDS), default=1.0, help="time constant tau in seconds of emulated time, 0 to 1e9; 0 makes a pure gain with dead time (default 1.0)")
    process.add_argument("--dead-time", "--theta", type=float_in(0.0, MAX_SECONDS), default=0.0, help="dead time theta in seconds of emulated time, 0 to 1e9 (default 0)")
    process.add_argument("--input-channel", type=channel_number, default=0, help="DAC channel n (0..7) that drives the process (default 0)")
    process.add_argument("--output-channel", type=channel_number, default=0, help="ADC channel m (0..7) that measures the process output (default 0)")
    process.add_argument("--initial", type=float_in(-MAX_VOLTS, MAX_VOLTS), default=0.0, help="process output y in volts at the first SAMPLE's time (default 0)")
    process.add_argument("--initial-input", type=float_in(-DAC_LIMIT_V, DAC_LIMIT_V), default=0.0, help="input u in volts (-10 to 10, the DAC's range) assumed before the first SAMPLE, seen during the first dead time (default 0, the DAC's reset value)")
    process.add_argument("--offset", type=float_in(-MAX_VOLTS, MAX_VOLTS), default=0.0, help="steady-state output in volts at zero input (default 0)")
    process.add_argument("--disturbance", type=float_in(-MAX_VOLTS, MAX_VOLTS), default=0.0, help="size in volts of a load disturbance step added to the lag's target (default 0: none)")
    process.add_argument("--disturbance-at", type=float_in(0.0, MAX_SECONDS), default=None, help="emulated time in seconds at which the disturbance steps in (default: never)")
    process.add_argument("--noise", type=float_in(0.0, MAX_VOLTS), default=0.0, help="standard deviation in volts of Gaussian measurement noise on the output channel; the process state is noise-free (default 0)")
    process.add_argument("--seed", type=int_in(-2**63, 2**63 - 1), default=1, help="seed of the noise generator; equal seeds give equal noise (default 1)")
    analog = parser.add_argument_group("other analog inputs")
    analog.add_argument("--other-inputs", choices=("zero", "loopback"), default="zero", help="what the ADC channels other than --output-channel read: 0 V, or the DAC of the same channel (default zero)")
    analog.add_argument("--ai-constant", type=parse_constant, action="append", metavar="CH=VOLTS", help="ADC channel CH reads a constant VOLTS; may be repeated; overrides --other-inputs for that channel")
    digital = parser.add_argument_group("digital inputs")
    digital.add_argument("--di-map", type=parse_di_map, default={}, metavar="DI=DO,...", help="DI bit follows DO bit, e.g. '0=1,1=0'; unlisted DI bits take --di-fixed. Default: no map, DI = DO")
    digital.add_argument("--di-fixed", type=hex_word, default=0, metavar="HEX", help="levels of the DI bits not in --di-map, as hex (default 0000)")
    digital.add_argument("--di-invert", type=hex_word, default=0, metavar="HEX", help="DI bits to invert after the mapping, as hex (default 0000)")
    transport = parser.add_argument_group("transport and logging")
    transport.add_argument("--socket", metavar="PATH", help="listen on this Unix socket for the emulator (default: use stdin and stdout)")
    transport.add_argument("--accept-timeout", type=float_in(0.0, MAX_TIMEOUT_S), default=120.0, help="seconds to wait for the emulator to connect, 0 to 1e6; 0 waits forever (default 120)")
    transport.add_argument("--idle-timeout", type=float_in(0.0, MAX_TIMEOUT_S), default=3600.0, help="seconds without a line after which the session ends, 0 to 1e6; 0 waits forever (default 3600)")
    transport.add_argument("--boards", type=int_in(1, 16), default=1, help="with --socket, serve this many emulated boards at once, 1 to 16: every board's ADC reads the process, and the process input is the highest of the connected boards' DAC --input-channel (their outputs wired through diodes); a board that disconnects no longer drives it (default 1)")
    transport.add_argument("--max-skew", type=float_in(0.0, 1000.0), default=1.0, metavar="MS", help="with --boards, a SAMPLE at most this many milliseconds behind the simulation (boards in lock-step differ by the lab's quantum) is taken at the simulation's time, 0 to 1000 (default 1)")
    transport.add_argument("--keep-listening", action="store_true", help="after the client disconnects, wait for the next one (the process state carries on)")
    transport.add_argument("--csv", metavar="PATH", help="write the trajectory, one row per SAMPLE: time, DACs, DO, process input (after the dead time), output, disturbance, AIs, DI")
    transport.add_argument("--max-error-messages", type=int_in(0, 10**9), default=20, help="print at most this many malformed-line messages on stderr; all are counted (default 20)")
    return parser


def main(argv=None):
    parser = build_parser()
    options = parser.parse_args(argv)
    if options.boards > 1 and not options.socket:
        parser.error("--boards: several boards need --socket; stdin and stdout serve one")
    try:
        simulator = PlantSimulator(options)
    except OSError as error:
        parser.error(f"--csv {options.csv}: cannot create it: {error.strerror or error}")

    def stop(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, stop)
    status = EXIT_OK
    try:
        if options.socket:
            status = run_socket(simulator, options)
        else:
            run_stdio(simulator, options)
    except KeyboardInterrupt:
        pass
    finally:
        simulator.close()
        print(simulator.summary(), file=sys.stderr, flush=True)
    return status


if __name__ == "__main__":
    sys.exit(main())
