"""A logic analyzer on the I/O board's digital outputs, from the model's DO trace.

The emulated board (isa-mfio) writes one line per change of its DO register
to the chardev named by its `do-trace` property (docs/iobus/mfio-register-map.md,
"DO trace"):

    DO <emulated time in ns> <DO as 4 hex digits>

This module reads such a trace and measures one output bit over a window of
emulated time: its edges, the period of every complete cycle (rising edge to
rising edge), the high time within it, the mean frequency and duty cycle and
the extremes, so a test can bound the jitter of a waveform an application
produces without asking the firmware. Under -icount the times are exact
emulated time, so the measurements are repeatable.

Typical use in an emulator test:

    samples = wait_for_trace(trace_path, 50_000_000)
    result = measure(samples, bit=0, start_ns=10_000_000, end_ns=50_000_000)
    assert abs(result.frequency_hz - 1000.0) < 1.0
    assert 0.49 <= result.duty_min <= result.duty_max <= 0.51
"""

import re
import time
from dataclasses import dataclass

# One trace line, without its newline.
_LINE = re.compile(r"DO ([0-9]+) ([0-9a-fA-F]{4})")
_EXPECTED = "expected 'DO <time in ns> <4 hex digits>'"

DO_BITS = 16


class TraceTimeout(TimeoutError):
    """The trace did not reach the wanted emulated time within the time-out."""


class NoWaveform(ValueError):
    """The bit has too few edges in the window for a period to be measured."""


@dataclass(frozen=True)
class Sample:
    """One trace line: DO became `value` at emulated time `time_ns`."""

    time_ns: int
    value: int


@dataclass(frozen=True)
class Edge:
    """A change of one bit at emulated time `time_ns`; `rising` is True for 0 -> 1."""

    time_ns: int
    rising: bool


@dataclass(frozen=True)
class Measurement:
    """The measurement of one bit over the window [start_ns, end_ns).

    A cycle is a rising edge, the falling edge after it and the next rising
    edge, all three in the window. `periods_ns[i]`, `high_times_ns[i]` and
    `duty_cycles[i]` describe cycle i, in order. `frequency_hz` is 1e9 over
    the mean period; `duty_cycle` is the total high time over the total
    period of the cycles (the mean high time over the mean period). The
    `*_min` and `*_max` fields bound the jitter.
    """

    bit: int
    start_ns: int
    end_ns: int
    rising_edges_ns: tuple
    falling_edges_ns: tuple
    periods_ns: tuple
    high_times_ns: tuple
    duty_cycles: tuple
    frequency_hz: float
    duty_cycle: float
    period_min_ns: int
    period_max_ns: int
    high_min_ns: int
    high_max_ns: int
    duty_min: float
    duty_max: float

    @property
    def cycles(self):
        """The number of complete cycles measured."""
        return len(self.periods_ns)

    @property
    def period_mean_ns(self):
        """The mean period in ns."""
        return sum(self.periods_ns) / len(self.periods_ns)

    @property
    def high_mean_ns(self):
        """The mean high time in ns."""
        return sum(self.high_times_ns) / len(self.high_times_ns)


# -- reading a trace ----------------------------------------------------------------


def _parse_lines(lines, first_line_number, source, previous_time_ns=None):
    """Parses complete lines (without newlines) numbered from first_line_number."""
    samples = []
    for number, text in enumerate(lines, start=first_line_number):
        match = _LINE.fullmatch(text)
        if not match:
            raise ValueError(f"{source}:{number}: malformed DO trace line {text!r}: {_EXPECTED}")
        sample = Sample(int(match.group(1)), int(match.group(2), 16))
        if previous_time_ns is not None and sample.time_ns < previous_time_ns:
            raise ValueError(f"{source}:{number}: DO trace time goes backwards in {text!r} "
                             f"(the line before is at {previous_time_ns} ns)")
        previous_time_ns = sample.time_ns
        samples.append(sample)
    return samples


def parse_trace(text, source="<trace>", ignore_partial_last_line=False):
    """Parses the text of a DO trace into a list of Sample, in file order.

    Every line must be exactly `DO <decimal ns> <4 hex digits>` and times
    must not decrease; otherwise a ValueError names `source`, the line
    number (from 1) and the line's text. A last line without its newline is
    an error too, unless ignore_partial_last_line is set (for a file the
    emulator is still writing), in which case it is left out.
    """
    lines = text.split("\n")
    # After the last newline: "" for a complete text, else a partial line.
    tail = lines.pop()
    if tail and not ignore_partial_last_line:
        lines.append(tail)
    return _parse_lines(lines, 1, source)


def read_trace(path, ignore_partial_last_line=False):
    """Reads and parses the DO trace file at path (see parse_trace)."""
    with open(path, encoding="ascii", errors="replace", newline="") as handle:
        return parse_trace(handle.read(), source=str(path), ignore_partial_last_line=ignore_partial_last_line)


def wait_for_trace(path, time_ns, timeout=60.0, poll_interval=0.02):
    """Waits until the trace file at path has a line at or after emulated time_ns.

    The emulator writes the trace while it runs, so this polls the file
    (every poll_interval seconds of host time, reading only what is new) and
    returns every complete sample so far, as read_trace would. A file that
    does not exist yet counts as empty. The trace only advances when DO
    changes, so wait for a time the waveform is known to pass. Raises
    TraceTimeout, naming the last time reached, after timeout seconds of
    host time, and ValueError for a malformed line.
    """
    deadline = time.monotonic() + timeout
    samples = []
    pending = b""
    offset = 0
    line_number = 1
    while True:
        try:
            with open(path, "rb") as handle:
                handle.seek(offset)
                data = handle.read()
        except FileNotFoundError:
            data = b""
        if data:
            offset += len(data)
            pending += data
            *complete, pending = pending.split(b"\n")
            text = [line.decode("ascii", errors="replace") for line in complete]
            samples += _parse_lines(text, line_number, str(path),
                                    samples[-1].time_ns if samples else None)
            line_number += len(complete)
        if samples and samples[-1].time_ns >= time_ns:
            return samples
        if time.monotonic() >= deadline:
            reached = f"its last line is at {samples[-1].time_ns} ns" if samples else "it has no complete line"
            raise TraceTimeout(f"the DO trace {path} did not reach {time_ns} ns of emulated time within "
                               f"{timeout:g} s; {reached}")
        time.sleep(poll_interval)


# -- measuring one bit --------------------------------------------------------------


def _check_bit(bit):
    if not isinstance(bit, int) or not 0 <= bit < DO_BITS:
        raise ValueError(f"bit {bit!r} is not a DO bit 0..{DO_BITS - 1}")


def level_at(samples, bit, time_ns):
    """The level (0 or 1) of bit at emulated time_ns, or None before the first sample.

    A sample at exactly time_ns counts: the level is the one after it.
    """
    _check_bit(bit)
    level = None
    for sample in samples:
        if sample.time_ns > time_ns:
            break
        level = (sample.value >> bit) & 1
    return level


def edges(samples, bit, start_ns=None, end_ns=None):
    """The edges of bit in [start_ns, end_ns), as a list of Edge in time order.

    start_ns None means from the beginning, end_ns None to the end. The
    first sample states the initial level and is never an edge; samples that
    leave the bit unchanged (another bit changed, or the value was
    restated after a reset) are not edges either.
    """
    _check_bit(bit)
    found = []
    previous = None
    for sample in samples:
        level = (sample.value >> bit) & 1
        if previous is not None and level != previous:
            if (start_ns is None or sample.time_ns >= start_ns) and (end_ns is None or sample.time_ns < end_ns):
                found.append(Edge(sample.time_ns, level == 1))
        previous = level
    return found


def measure(samples, bit, start_ns=None, end_ns=None):
    """Measures bit over the window [start_ns, end_ns) and returns a Measurement.

    start_ns None means from the first sample, end_ns None to just after the
    last one. Only complete cycles inside the window count (see
    Measurement), so a window may start and end anywhere in the waveform.
    Raises NoWaveform (a ValueError) when the window holds no complete
    cycle, saying how many edges it found and, for a bit that never
    changes, the level it stays at; ValueError for a bit outside 0..15 or
    an empty window.
    """
    _check_bit(bit)
    if not samples:
        raise NoWaveform(f"bit {bit}: the DO trace is empty")
    if start_ns is None:
        start_ns = samples[0].time_ns
    if end_ns is None:
        end_ns = samples[-1].time_ns + 1
    if end_ns <= start_ns:
        raise ValueError(f"empty window [{start_ns}, {end_ns}) ns")
    found = edges(samples, bit, start_ns, end_ns)
    rising = [edge.time_ns for edge in found if edge.rising]
    falling = [edge.time_ns for edge in found if not edge.rising]

    # Edges of one bit alternate, so a cycle is a rising edge, the falling
    # edge that follows it and the rising edge after that.
    periods = []
    highs = []
    rise = None
    fall = None
    for edge in found:
        if edge.rising:
            if rise is not None and fall is not None:
                periods.append(edge.time_ns - rise)
                highs.append(fall - rise)
            rise, fall = edge.time_ns, None
        elif rise is not None:
            fall = edge.time_ns

    if not periods:
        if not found:
            level = level_at(samples, bit, start_ns)
            state = "has no sample before the window" if level is None else f"stays at {level}"
            raise NoWaveform(f"bit {bit} never changes in [{start_ns}, {end_ns}) ns: it {state}")
        raise NoWaveform(f"bit {bit} has no complete cycle in [{start_ns}, {end_ns}) ns: "
                         f"{len(rising)} rising and {len(falling)} falling edges; a cycle needs two rising "
                         f"edges with a falling edge between them")

    duties = [high / period if period else 0.0 for high, period in zip(highs, periods)]
    total = sum(periods)
    return Measurement(
        bit=bit,
        start_ns=start_ns,
        end_ns=end_ns,
        rising_edges_ns=tuple(rising),
        falling_edges_ns=tuple(falling),
        periods_ns=tuple(periods),
        high_times_ns=tuple(highs),
        duty_cycles=tuple(duties),
        frequency_hz=1e9 * len(periods) / total if total else float("inf"),
        duty_cycle=sum(highs) / total if total else 0.0,
        period_min_ns=min(periods),
        period_max_ns=max(periods),
        high_min_ns=min(highs),
        high_max_ns=max(highs),
        duty_min=min(duties),
        duty_max=max(duties),
    )
