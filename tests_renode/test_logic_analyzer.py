"""The logic analyzer on the DO trace (dcoslab/logic_analyzer.py), on the host only.

Every trace here is synthetic, written to tmp_path in the format the
isa-mfio model writes (docs/iobus/mfio-register-map.md, "DO trace"); the
emulator test of the model's side is in test_isa_mfio_model.py.
"""

import threading
import time

import pytest

from dcoslab.logic_analyzer import (
    Edge,
    NoWaveform,
    Sample,
    TraceTimeout,
    edges,
    level_at,
    measure,
    parse_trace,
    read_trace,
    wait_for_trace,
)

MS = 1_000_000  # ns


def write_trace(tmp_path, samples, name="do.trace", tail=""):
    """Writes (time_ns, value) pairs as a DO trace file and returns its path."""
    path = tmp_path / name
    path.write_text("".join(f"DO {time_ns} {value:04x}\n" for time_ns, value in samples) + tail, encoding="ascii")
    return path


def square_wave(bit, cycles, period_ns, high_ns, first_rise_ns, other_bits=0):
    """A reset line at 0 (all low, other_bits set) and `cycles` pulses of bit."""
    samples = [(0, other_bits)]
    for cycle in range(cycles):
        rise = first_rise_ns + cycle * period_ns
        samples += [(rise, other_bits | (1 << bit)), (rise + high_ns, other_bits)]
    return samples


# -- reading ------------------------------------------------------------------------


def test_read_trace_gives_the_samples_in_order(tmp_path):
    path = write_trace(tmp_path, [(0, 0x0000), (11135684, 0x0001), (12490105, 0x8000), (13439901, 0xA5A5)])
    assert read_trace(path) == [Sample(0, 0), Sample(11135684, 1), Sample(12490105, 0x8000), Sample(13439901, 0xA5A5)]


def test_upper_case_hex_is_accepted():
    assert parse_trace("DO 5 BEEF\n") == [Sample(5, 0xBEEF)]


def test_an_empty_trace_has_no_samples():
    assert parse_trace("") == []


@pytest.mark.parametrize("line", [
    "DO 12 001",         # three hex digits
    "DO 12 00001",       # five
    "DO -5 0001",        # negative time
    "DO 1.5 0001",       # fractional time
    "DX 1 0001",         # wrong tag
    "DO 1 0001 extra",   # trailing text
    "DO 1 00g1",         # not hex
    "DO  1 0001",        # two spaces
    "DO 1 0001\r",       # a carriage return
    "",                  # an empty line
])
def test_a_malformed_line_names_its_number_and_text(tmp_path, line):
    path = tmp_path / "bad.trace"
    path.write_text(f"DO 0 0000\n{line}\nDO 9 0001\n", encoding="ascii")
    with pytest.raises(ValueError) as error:
        read_trace(path)
    message = str(error.value)
    assert f"{path}:2: malformed DO trace line {line!r}" in message
    assert "expected 'DO <time in ns> <4 hex digits>'" in message


def test_time_going_backwards_is_refused():
    with pytest.raises(ValueError, match=r"<trace>:3: DO trace time goes backwards in 'DO 5 0000' "
                                         r"\(the line before is at 10 ns\)"):
        parse_trace("DO 0 0000\nDO 10 0001\nDO 5 0000\n")


def test_equal_times_are_allowed():
    assert parse_trace("DO 10 0001\nDO 10 0000\n") == [Sample(10, 1), Sample(10, 0)]


def test_a_partial_last_line_is_an_error_unless_ignored(tmp_path):
    path = write_trace(tmp_path, [(0, 0), (100, 1)], tail="DO 2")
    with pytest.raises(ValueError, match=r":3: malformed DO trace line 'DO 2'"):
        read_trace(path)
    assert read_trace(path, ignore_partial_last_line=True) == [Sample(0, 0), Sample(100, 1)]


# -- edges and levels ---------------------------------------------------------------


def test_edges_of_one_bit_ignore_the_other_bits_and_restated_values():
    samples = parse_trace("DO 0 0000\nDO 10 0004\nDO 20 0005\nDO 30 0005\nDO 40 0001\nDO 50 0000\nDO 60 0000\n")
    assert edges(samples, 0) == [Edge(20, True), Edge(50, False)]
    assert edges(samples, 2) == [Edge(10, True), Edge(40, False)]
    assert edges(samples, 2, start_ns=10, end_ns=40) == [Edge(10, True)], "the window is [start, end)"
    assert edges(samples, 15) == []


def test_the_first_sample_is_a_level_not_an_edge():
    assert edges(parse_trace("DO 0 0001\nDO 10 0000\n"), 0) == [Edge(10, False)]


def test_level_at():
    samples = parse_trace("DO 5 0000\nDO 10 0002\nDO 20 0000\n")
    assert level_at(samples, 1, 4) is None
    assert [level_at(samples, 1, t) for t in (5, 9, 10, 19, 20, 1000)] == [0, 0, 1, 1, 0, 0]


@pytest.mark.parametrize("bit", [-1, 16, "0", 1.0])
def test_a_bit_outside_do_is_refused(bit):
    with pytest.raises(ValueError, match="is not a DO bit 0..15"):
        measure([Sample(0, 0)], bit)


# -- measurements -------------------------------------------------------------------


def test_clean_square_wave(tmp_path):
    # 1 kHz, 50 %, on bit 0, with bit 3 held high all along.
    path = write_trace(tmp_path, square_wave(0, 10, 1 * MS, MS // 2, 2 * MS, other_bits=0x0008))
    result = measure(read_trace(path), 0)
    assert result.cycles == 9, "ten rising edges make nine complete cycles"
    assert result.rising_edges_ns == tuple(2 * MS + k * MS for k in range(10))
    assert result.falling_edges_ns == tuple(2 * MS + k * MS + MS // 2 for k in range(10))
    assert result.periods_ns == (MS,) * 9
    assert result.high_times_ns == (MS // 2,) * 9
    assert result.frequency_hz == pytest.approx(1000.0)
    assert result.duty_cycle == pytest.approx(0.5)
    assert (result.period_min_ns, result.period_max_ns) == (MS, MS)
    assert (result.high_min_ns, result.high_max_ns) == (MS // 2, MS // 2)
    assert result.duty_min == result.duty_max == pytest.approx(0.5)
    assert result.period_mean_ns == MS and result.high_mean_ns == MS // 2


def test_quarter_duty_wave_with_jitter(tmp_path):
    # 250 us high in periods that alternate 990 us and 1010 us: 1 kHz on average.
    samples = [(0, 0)]
    rise = 1 * MS
    for cycle in range(21):
        samples += [(rise, 0x0020), (rise + 250_000, 0)]
        rise += 990_000 if cycle % 2 == 0 else 1_010_000
    result = measure(read_trace(write_trace(tmp_path, samples)), 5)
    assert result.cycles == 20
    assert result.frequency_hz == pytest.approx(1000.0)
    assert result.duty_cycle == pytest.approx(0.25)
    assert (result.period_min_ns, result.period_max_ns) == (990_000, 1_010_000)
    assert (result.high_min_ns, result.high_max_ns) == (250_000, 250_000)
    assert result.duty_min == pytest.approx(250 / 1010)
    assert result.duty_max == pytest.approx(250 / 990)


def test_wave_that_starts_high(tmp_path):
    # High from the reset line, low at 0.3 ms, then 2 ms periods at 75 %.
    samples = [(0, 0x8000), (300_000, 0)]
    for cycle in range(5):
        rise = 1 * MS + cycle * 2 * MS
        samples += [(rise, 0x8000), (rise + 1_500_000, 0)]
    result = measure(read_trace(write_trace(tmp_path, samples)), 15)
    assert result.falling_edges_ns[0] == 300_000, "the first edge is a falling one"
    assert result.rising_edges_ns[0] == 1 * MS, "cycles start at the first rising edge"
    assert result.cycles == 4
    assert result.frequency_hz == pytest.approx(500.0)
    assert result.duty_cycle == pytest.approx(0.75)


def test_the_window_keeps_only_complete_cycles_inside_it(tmp_path):
    samples = read_trace(write_trace(tmp_path, square_wave(0, 10, 1 * MS, MS // 4, 1 * MS)))
    # Rising edges at 1..10 ms; [2.5 ms, 7.1 ms) holds those at 3..7 ms.
    result = measure(samples, 0, start_ns=2_500_000, end_ns=7_100_000)
    assert result.rising_edges_ns == (3 * MS, 4 * MS, 5 * MS, 6 * MS, 7 * MS)
    assert result.cycles == 4
    assert (result.start_ns, result.end_ns) == (2_500_000, 7_100_000)
    # An end exactly on a rising edge leaves that edge out.
    assert measure(samples, 0, start_ns=3 * MS, end_ns=7 * MS).cycles == 3


def test_a_bit_that_never_toggles_is_a_clear_error(tmp_path):
    samples = read_trace(write_trace(tmp_path, square_wave(0, 5, 1 * MS, MS // 2, 1 * MS, other_bits=0x0004)))
    with pytest.raises(NoWaveform, match=r"bit 2 never changes in \[0, 5500001\) ns: it stays at 1"):
        measure(samples, 2)
    with pytest.raises(NoWaveform, match=r"bit 7 never changes .*: it stays at 0"):
        measure(samples, 7)
    # NoWaveform is a ValueError, for callers that catch those.
    with pytest.raises(ValueError):
        measure(samples, 7, start_ns=2 * MS, end_ns=3 * MS)


def test_one_pulse_is_not_a_cycle():
    samples = parse_trace("DO 0 0000\nDO 100 0001\nDO 200 0000\n")
    with pytest.raises(NoWaveform, match=r"bit 0 has no complete cycle in \[0, 201\) ns: 1 rising and 1 falling edges"):
        measure(samples, 0)


def test_an_empty_trace_or_window_is_refused():
    with pytest.raises(NoWaveform, match="the DO trace is empty"):
        measure([], 0)
    with pytest.raises(ValueError, match=r"empty window \[10, 10\) ns"):
        measure([Sample(0, 0)], 0, start_ns=10, end_ns=10)


# -- waiting for a trace that is being written -----------------------------------------


def test_wait_for_trace_follows_a_growing_file(tmp_path):
    path = tmp_path / "live.trace"

    def writer():
        time.sleep(0.1)  # the file does not exist at first
        with open(path, "w", encoding="ascii") as handle:
            handle.write("DO 0 0000\nDO 1000 0001\n")
            handle.flush()
            time.sleep(0.1)
            handle.write("DO 2000 00")  # a line cut in the middle
            handle.flush()
            time.sleep(0.1)
            handle.write("00\nDO 3000 0001\n")
            handle.flush()

    thread = threading.Thread(target=writer)
    thread.start()
    try:
        samples = wait_for_trace(path, 2500, timeout=10, poll_interval=0.01)
    finally:
        thread.join()
    assert samples == [Sample(0, 0), Sample(1000, 1), Sample(2000, 0), Sample(3000, 1)]


def test_wait_for_trace_returns_at_once_when_the_time_is_reached(tmp_path):
    path = write_trace(tmp_path, [(0, 0), (500, 1)])
    assert wait_for_trace(path, 500, timeout=0) == [Sample(0, 0), Sample(500, 1)]


def test_wait_for_trace_times_out_naming_the_last_time(tmp_path):
    path = write_trace(tmp_path, [(0, 0), (500, 1)])
    with pytest.raises(TraceTimeout, match=r"did not reach 10000 ns of emulated time within 0.2 s; "
                                           r"its last line is at 500 ns"):
        wait_for_trace(path, 10_000, timeout=0.2)
    with pytest.raises(TraceTimeout, match="it has no complete line"):
        wait_for_trace(tmp_path / "missing.trace", 1, timeout=0.1)


def test_wait_for_trace_reports_a_malformed_line_with_its_number(tmp_path):
    path = tmp_path / "bad.trace"
    path.write_text("DO 0 0000\nDO 10 0001\nnoise\n", encoding="ascii")
    with pytest.raises(ValueError, match=r"bad.trace:3: malformed DO trace line 'noise'"):
        wait_for_trace(path, 100, timeout=1)
