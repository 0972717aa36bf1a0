"""The frequency multiplier (seed 9.4.1) measured with a logic analyzer.

The emulated I/O board writes every change of its digital outputs, with
the exact emulated time, to a DO trace (docs/iobus/mfio-register-map.md);
under -icount those times do not depend on the host. Each test sets the
waves with `freqmul set`, waits for the trace to cover a few source
periods and measures DO0 (A), DO1 (B) and DO2 (Y = A XOR B).

Every edge is E_CYCLE's or E_DELAY's tick plus the time the event takes
through the blocks to the DO register, so the expected times are whole
numbers of ticks and the tolerances come from two small terms:

- TICK_ROUNDING_NS per tick: the node counts time in whole nanoseconds of
  its tick (149 / 1193182 s, printed as 124876 ns) and the emulated 8254's
  tick is within a fraction of a nanosecond of that (0.17 ns measured), so
  a time of n ticks is off by at most n ns: 8 us over a 1 Hz period.
- LATENCY_SPREAD_NS: how much the time from a tick to the DO write can
  differ between two edges. An edge's path is the tick interrupt and four
  or five task switches, a few thousand instructions at 1 ns each under
  -icount. The paths of A's and B's edges differ by about 0.1 us when the
  console is idle, and by under 1 us while it runs commands (its serial
  interrupts can hold a tick off); 5 us bounds that with a wide margin.

So a time of n ticks is n * tick_ns within n * TICK_ROUNDING_NS +
LATENCY_SPREAD_NS. Y's duty cycle, its high time over its period, is then
exact to within about 10 us over Y's period: 2 % at 1 kHz, 0.2 % at
100 Hz, 0.02 % at 10 Hz and 0.003 % at 1 Hz. Frequencies are compared
with the nominal ones within NOMINAL_TOLERANCE, 0.15 %: the 8254 makes
the 8000 Hz tick by dividing 1193182 Hz by 149, which gives 8007.9 Hz,
0.099 % fast; everything else is exact in ticks.
"""

import re
import time

import pytest

from dcoslab.logic_analyzer import edges, measure, read_trace, wait_for_trace

MFIO = "isa-mfio"
BIT_A, BIT_B, BIT_Y = 0, 1, 2
TICK_ROUNDING_NS = 1
LATENCY_SPREAD_NS = 5_000
NOMINAL_TOLERANCE = 0.0015
# Complete source cycles measured per test: enough to see every edge
# pattern repeat, few enough to keep a 1 Hz test to seconds.
SOURCE_CYCLES = 3

STATUS = re.compile(
    r"freqmul: source (?P<frequency_hz>\d+) Hz, shift (?P<shift_degrees>\d+) degrees: "
    r"output (?P<output_hz>\d+) Hz, duty (?P<duty>\d+\.\d\d) %; "
    r"tick (?P<tick_hz>\d+) Hz \((?P<tick_ns>\d+) ns\): "
    r"half period (?P<half_period_ticks>\d+) ticks, shift (?P<shift_ticks>\d+) ticks; "
    r"generation (?P<generation>\d+), rejected (?P<rejected>\d+), board (?P<board>[a-z ]+)"
)
CHECKER = re.compile(
    r"checker: do writes (?P<do_writes>\d+), write errors (?P<write_errors>\d+), samples (?P<samples>\d+), "
    r"edges A (?P<edges_a>\d+) B (?P<edges_b>\d+) Y (?P<edges_y>\d+), "
    r"xor mismatches (?P<xor_mismatches>\d+), loopback mismatches (?P<loopback_mismatches>\d+), "
    r"read errors (?P<read_errors>\d+)"
)


def parse(pattern, line):
    match = pattern.fullmatch(line)
    assert match, f"unexpected line {line!r}"
    return {key: value if key in ("board", "duty") else int(value) for key, value in match.groupdict().items()}


def status(emulator):
    """Runs `freqmul` and returns (waves, checker) as dicts."""
    lines = emulator.command("freqmul").strip().split("\r\n")
    assert len(lines) == 2, lines
    return parse(STATUS, lines[0]), parse(CHECKER, lines[1])


@pytest.fixture
def traced(boot, dcos_board, dcos_image, tmp_path):
    """The application booted with exact time and a logic analyzer on DO: (emulator, trace path)."""
    return start_traced(boot, dcos_board, dcos_image, tmp_path)


def start_traced(boot, dcos_board, dcos_image, tmp_path, **properties):
    trace = tmp_path / "do.trace"
    emulator = boot(dcos_board, dcos_image, icount=True,
                    device_properties={MFIO: {"do-trace": "dotrace", **properties}},
                    extra_args=["-chardev", f"file,id=dotrace,path={trace}"])
    emulator.expect(r"dcos> ")
    return emulator, trace


def last_time(trace):
    return read_trace(trace, ignore_partial_last_line=True)[-1].time_ns


def set_waves(emulator, trace, frequency_hz, shift_degrees):
    """Sets the waves; returns their settings and a time after which the trace holds only them."""
    output = emulator.command(f"freqmul set {frequency_hz} {shift_degrees}").strip()
    waves = parse(STATUS, output)
    assert (waves["frequency_hz"], waves["shift_degrees"]) == (frequency_hz, shift_degrees)
    assert waves["output_hz"] == 2 * frequency_hz
    # The command returns once E_CYCLE has stopped the old waves, so every
    # line written after the last one in the trace now is of the new waves.
    return waves, last_time(trace)


def ticks_ns(waves, ticks):
    return ticks * waves["tick_ns"]


def tolerance_ns(ticks):
    return ticks * TICK_ROUNDING_NS + LATENCY_SPREAD_NS


def assert_all_near(values, expected, tolerance, what):
    worst = max(abs(value - expected) for value in values)
    assert worst <= tolerance, f"{what}: expected {expected} ns +- {tolerance} ns, worst {worst} ns off in {values}"


def assert_one_write_per_change(samples):
    """Every DO word has Y == A XOR B, and each changes exactly one source."""
    for before, after in zip(samples, samples[1:]):
        value = after.value
        assert (value >> BIT_Y) & 1 == ((value >> BIT_A) ^ (value >> BIT_B)) & 1, f"Y != A XOR B in {after}"
        changed = (before.value ^ value) & 0b011
        assert changed in (0b001, 0b010), f"{before} -> {after} changes both sources or neither"


def first_rising_edge(trace, bit, after_ns, timeout=120.0):
    """Waits for the first rising edge of bit after after_ns in the trace and returns its time."""
    deadline = time.monotonic() + timeout
    while True:
        samples = read_trace(trace, ignore_partial_last_line=True)
        rising = [edge.time_ns for edge in edges(samples, bit, after_ns) if edge.rising]
        if rising:
            return rising[0]
        assert time.monotonic() < deadline, f"DO{bit} never rose after {after_ns} ns"
        time.sleep(0.02)


def record(emulator, trace, frequency_hz, shift_degrees, cycles=SOURCE_CYCLES):
    """Sets the waves and waits for `cycles` complete source cycles of them.

    Returns (waves, samples, start_ns, end_ns): the window starts at A's
    first rising edge, and ends after B's last rising edge but before A's
    next edge, so that it holds exactly `cycles` cycles of A and B and
    twice as many of Y.
    """
    waves, set_ns = set_waves(emulator, trace, frequency_hz, shift_degrees)
    half = waves["half_period_ticks"]
    shift = waves["shift_ticks"]
    start_ns = first_rising_edge(trace, BIT_A, set_ns + 1)
    end_ns = start_ns + ticks_ns(waves, 2 * cycles * half + shift) + ticks_ns(waves, half - shift) // 2
    samples = wait_for_trace(trace, end_ns, timeout=120.0)
    assert_one_write_per_change([sample for sample in samples if sample.time_ns > set_ns])
    return waves, samples, start_ns, end_ns


def check_waves(waves, samples, start_ns, end_ns, cycles=SOURCE_CYCLES):
    """Measures A, B and Y in [start_ns, end_ns) against the settings.

    With cycles None the window may start and end anywhere in the waves;
    otherwise it must hold exactly `cycles` cycles of each source.
    """
    frequency_hz = waves["frequency_hz"]
    half = waves["half_period_ticks"]
    shift = waves["shift_ticks"]
    window = [sample for sample in samples if start_ns <= sample.time_ns < end_ns]
    assert_one_write_per_change(window)

    # The sources: f, a square wave, B behind A by the shift.
    for bit in (BIT_A, BIT_B):
        source = measure(samples, bit, start_ns, end_ns)
        assert source.cycles == cycles if cycles else source.cycles >= 3, f"DO{bit}: {source.cycles} cycles"
        assert abs(source.frequency_hz / frequency_hz - 1) <= NOMINAL_TOLERANCE, f"DO{bit}: {source.frequency_hz} Hz"
        assert_all_near(source.periods_ns, ticks_ns(waves, 2 * half), tolerance_ns(2 * half), f"DO{bit} periods")
        assert_all_near(source.high_times_ns, ticks_ns(waves, half), tolerance_ns(half), f"DO{bit} high times")
    rising_a = [edge.time_ns for edge in edges(samples, BIT_A, start_ns, end_ns) if edge.rising]
    rising_b = [edge.time_ns for edge in edges(samples, BIT_B, start_ns, end_ns) if edge.rising]
    # Each rise of A is followed by a rise of B, the shift later.
    delays = [min(b for b in rising_b if b > a) - a for a in rising_a if rising_b and rising_b[-1] > a]
    assert len(delays) >= (cycles or 3)
    assert_all_near(delays, ticks_ns(waves, shift), tolerance_ns(shift), "B behind A")

    # The output: 2f, high for the shift out of every half period.
    output = measure(samples, BIT_Y, start_ns, end_ns)
    assert output.cycles == 2 * cycles if cycles else output.cycles >= 6, f"DO2: {output.cycles} cycles"
    assert abs(output.frequency_hz / (2 * frequency_hz) - 1) <= NOMINAL_TOLERANCE, f"DO2: {output.frequency_hz} Hz"
    assert_all_near(output.periods_ns, ticks_ns(waves, half), tolerance_ns(half), "DO2 periods")
    assert_all_near(output.high_times_ns, ticks_ns(waves, shift), tolerance_ns(shift), "DO2 high times")
    duty = waves["shift_degrees"] / 180
    duty_tolerance = (tolerance_ns(shift) + tolerance_ns(half)) / ticks_ns(waves, half)
    assert abs(output.duty_min - duty) <= duty_tolerance and abs(output.duty_max - duty) <= duty_tolerance, (
        f"DO2 duty {output.duty_min:.6f} to {output.duty_max:.6f}, expected {duty:.6f} +- {duty_tolerance:.6f}")
    return output


def check_checker(emulator):
    """The checker read back every DO write at DI and found no mismatch."""
    waves, checker = status(emulator)
    assert waves["board"] == "ok"
    assert checker["samples"] > 0
    assert checker["samples"] == checker["do_writes"]
    assert checker["write_errors"] == checker["read_errors"] == 0
    assert checker["xor_mismatches"] == 0
    assert checker["loopback_mismatches"] == 0
    # Every write changes one source, and so Y.
    assert checker["edges_y"] == checker["edges_a"] + checker["edges_b"]
    return waves, checker


@pytest.mark.parametrize("frequency_hz", [1, 10, 100, 1000])
def test_the_output_is_twice_the_source_frequency_at_half_duty_for_a_quarter_period_shift(traced, frequency_hz):
    emulator, trace = traced
    waves, samples, start_ns, end_ns = record(emulator, trace, frequency_hz, 90)
    assert waves["half_period_ticks"] == 4000 // frequency_hz
    assert waves["shift_ticks"] == 2000 // frequency_hz
    assert waves["duty"] == "50.00"
    check_waves(waves, samples, start_ns, end_ns)
    check_checker(emulator)


@pytest.mark.parametrize("frequency_hz, shift_degrees, duty", [(1000, 45, "25.00"), (10, 135, "75.00")])
def test_the_shift_sets_the_output_duty_cycle(traced, frequency_hz, shift_degrees, duty):
    emulator, trace = traced
    waves, samples, start_ns, end_ns = record(emulator, trace, frequency_hz, shift_degrees)
    assert waves["duty"] == duty
    check_waves(waves, samples, start_ns, end_ns)
    check_checker(emulator)


# What the tick cannot make, and what the command says about it.
REFUSED = {
    "freqmul set 3000": "cannot make 3000 Hz with the 8000 Hz tick: half a period would be 4000/3000 ticks, not a "
                        "whole number (the source frequency must divide 4000 Hz)",
    "freqmul set 4000": "cannot make 4000 Hz with the 8000 Hz tick: half a period is 1 tick, which leaves no room "
                        "for a phase shift (at most 2000 Hz)",
    "freqmul set 0": "the source frequency must be at least 1 Hz",
    "freqmul set 1000 30": "cannot shift 1000 Hz by 30 degrees with the 8000 Hz tick: the shift must be a whole "
                           "number of ticks, a multiple of 45 degrees at this frequency",
    "freqmul set 2000 45": "cannot shift 2000 Hz by 45 degrees with the 8000 Hz tick: the shift must be a whole "
                           "number of ticks, a multiple of 90 degrees at this frequency",
    "freqmul set 1000 180": "the phase shift must be from 1 to 179 degrees (0 and 180 make the output constant)",
    "freqmul set 1000 0": "the phase shift must be from 1 to 179 degrees (0 and 180 make the output constant)",
}
USAGE = "usage: freqmul [set <hz> [shift_degrees]]"


def test_settings_the_tick_cannot_make_are_refused_and_the_waves_run_on(traced):
    emulator, trace = traced
    waves, samples, start_ns, end_ns = record(emulator, trace, 1000, 90, cycles=2)
    check_waves(waves, samples, start_ns, end_ns, cycles=2)
    before_ns = last_time(trace)
    for command, error in REFUSED.items():
        assert emulator.command(command).strip() == "error: " + error, command
    for command in ("freqmul set", "freqmul set 1k", "freqmul set 100 90 1", "freqmul bogus"):
        assert emulator.command(command).strip() == USAGE, command
    after_ns = last_time(trace)
    # The same waves, not even restarted (the generation counts restarts).
    unchanged, _ = check_checker(emulator)
    assert unchanged == waves
    # The waves ran through the refused commands without a restart or a
    # missing edge: a window from before them to after them measures as
    # one steady wave.
    half = waves["half_period_ticks"]
    window_start = before_ns - ticks_ns(waves, 4 * half)
    window_end = after_ns + ticks_ns(waves, 4 * half)
    samples = wait_for_trace(trace, window_end)
    check_waves(waves, samples, window_start, window_end, cycles=None)


def test_the_checker_detects_a_stuck_input(boot, dcos_board, dcos_image, tmp_path):
    # DI2 stuck low: the outputs are right, but what the checker reads back
    # says Y is low while A XOR B is high, in every other sample.
    emulator, trace = start_traced(boot, dcos_board, dcos_image, tmp_path, **{"stuck-di-bit": "2",
                                                                             "stuck-di-value": "0"})
    wait_for_trace(trace, 100_000_000)
    _, checker = status(emulator)
    assert checker["samples"] > 100
    assert checker["xor_mismatches"] == checker["loopback_mismatches"]
    assert abs(2 * checker["xor_mismatches"] - checker["samples"]) <= 1, checker
    assert_one_write_per_change(read_trace(trace, ignore_partial_last_line=True))
