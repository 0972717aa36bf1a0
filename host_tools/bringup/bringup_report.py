"""Parsing and judging of the controller's I/O board bring-up report.

The controller's console command `iobus bringup` prints one `BRINGUP` line
per result (docs/iobus/bringup-protocol.md). This module turns a console
transcript into a parsed report, judges it against the user's limits and
describes every failure in one line that names the channel and gain, the DI
bit, or the interrupt exactly. It does no input or output of its own apart
from the optional picture, so it is tested on canned transcripts without an
emulator.

A transcript is hostile input: a noisy serial line, a wrong program on the
other end or a corrupted file. Every field is checked against the range the
protocol allows before it is used, so parsing never raises, every number kept
is finite, and a line that does not follow the protocol becomes a named
failure instead of a crash.
"""

import functools
import io
import json
import math
import os
import re
import statistics
import tempfile
from dataclasses import asdict, dataclass, field

CHANNELS = 8
GAINS = (1, 10, 100, 1000)
DIGITAL_BITS = 16
ADC_FULL_SCALE = 4095
ADC_MID_SCALE = 2048

# Exit statuses of the bring-up tool; the judging decides among 0, 1, 3 and 4.
EXIT_PASS = 0
EXIT_FAILURES = 1
EXIT_USAGE = 2
EXIT_BOARD_ABSENT = 3
EXIT_NO_CONNECTION = 4
EXIT_OUTPUT = 5
EXIT_INTERRUPTED = 130

VERDICT_EXIT = {
    "pass": EXIT_PASS,
    "fail": EXIT_FAILURES,
    "board-absent": EXIT_BOARD_ABSENT,
    "incomplete": EXIT_NO_CONNECTION,
    "interrupted": EXIT_INTERRUPTED,
}

# The result file's format; version 2 added the pooled noise, the firmware and the time stamp.
RESULT_FORMAT = "dcos-iobus-bringup-result"
RESULT_VERSION = 2

# Bounds of what a report may say. The controller never prints more than
# these; a line beyond them is garbled, and the bounds keep every number the
# judging computes with finite and every message short.
MAX_LINE_LENGTH = 4096
MAX_POINTS = 64
MAX_METRIC = 1e6          # |offset|, |gain error|, max error
MAX_NOISE_LSB = 4096.0    # a standard deviation cannot exceed the converter's span
MAX_COUNT = 10**6         # conversions, degrees of freedom, interrupts, failures
MAX_OVERRANGE = 10**9
MAX_LATENCY_NS = 1e15
MAX_GARBLED_LISTED = 50   # unreadable lines named one by one; the rest are counted


@dataclass
class Limits:
    """The pass/fail limits. Every field has a command-line option of the same name."""

    max_offset_lsb: float = 2.0
    max_gain_error_pct: float = 1.0
    max_error_lsb: float = 2.0
    max_noise_lsb: float = 1.0
    noise_confidence: float = 0.999
    min_irq_delivered_pct: float = 100.0
    max_irq_latency_ns: float = 1_000_000.0
    min_points: int = 3


LIMIT_DESCRIPTIONS = {
    "max_offset_lsb": "largest |offset| of the fitted line at 0 V, in LSB",
    "max_gain_error_pct": "largest |gain error| of the fitted slope against the ideal, in percent",
    "max_error_lsb": "largest deviation of any point from the ideal transfer, in LSB",
    "max_noise_lsb": "largest noise (standard deviation of one conversion), in LSB; a sweep fails only when its "
                     "pooled noise is above this with --noise-confidence",
    "noise_confidence": "one-sided confidence with which a sweep's noise must be shown to exceed --max-noise-lsb "
                        "before the sweep fails (chi-square lower bound on sigma)",
    "min_irq_delivered_pct": "smallest share of requested conversion interrupts that must arrive, in percent",
    "max_irq_latency_ns": "largest interrupt latency (expected completion to handler), in ns",
    "min_points": "smallest number of DAC steps in each channel's and gain's sweep",
}

# The range each limit may take: (lowest, highest). The tool refuses others
# before it runs: a NaN limit compares false with everything and would pass
# every board, an infinite or negative one means nothing.
LIMIT_RANGES = {
    "max_offset_lsb": (0.0, MAX_METRIC),
    "max_gain_error_pct": (0.0, MAX_METRIC),
    "max_error_lsb": (0.0, MAX_METRIC),
    "max_noise_lsb": (0.0, MAX_NOISE_LSB),
    "noise_confidence": (0.5, 0.999999),
    "min_irq_delivered_pct": (0.0, 100.0),
    "max_irq_latency_ns": (0.0, MAX_LATENCY_NS),
    "min_points": (1, MAX_POINTS),
}


def check_limit(name, value):
    """The error message for a limit outside its range (NaN and infinities included), or None."""
    low, high = LIMIT_RANGES[name]
    if isinstance(value, float) and not math.isfinite(value):
        return f"{value} is not a finite number"
    if not low <= value <= high:
        return f"{format_limit(value)} is not between {format_limit(low)} and {format_limit(high)}"
    return None


def validate_limits(limits):
    """Raises ValueError naming the first limit outside its range."""
    for name in LIMIT_RANGES:
        problem = check_limit(name, getattr(limits, name))
        if problem:
            raise ValueError(f"{name}: {problem}")


@dataclass
class DioResult:
    pattern: str  # "walking-ones" or "walking-zeros"
    ok: bool
    bits: int = 0
    wrote: int = 0
    read: int = 0


@dataclass
class AdcResult:
    channel: int
    gain: int
    offset_lsb: float
    gain_error_pct: float
    max_error_lsb: float
    noise_lsb: float  # the largest standard deviation of a single point's conversions
    overrange: int
    points: list  # [(dac_code, mean_adc_code), ...]
    noise_pooled_lsb: float = None  # the standard deviation pooled over every point of the sweep
    noise_dof: int = None  # its degrees of freedom, sum(n_i - 1)
    samples: int = None  # conversions per point


@dataclass
class IrqResult:
    delivered: int
    requested: int
    latency_min_ns: float = None
    latency_max_ns: float = None


@dataclass
class Report:
    """Everything the BRINGUP lines of one run said."""

    begun: bool = False
    base: int = None
    irq_line: int = None
    probe: str = None  # "ok" or "absent"
    board_id: int = None
    revision: int = None
    firmware_version: str = None
    firmware_revision: str = None
    dio: list = field(default_factory=list)
    adc: list = field(default_factory=list)
    irq: IrqResult = None
    ended: bool = False
    controller_failures: int = None
    garbled: list = field(default_factory=list)  # (line, reason)
    lines: list = field(default_factory=list)  # every BRINGUP line, in order


@dataclass
class Failure:
    kind: str  # "probe", "dio", "adc", "irq", "report"
    message: str
    channel: int = None
    gain: int = None
    bit: int = None
    metric: str = None
    value: float = None
    limit: float = None


@dataclass
class Judgement:
    verdict: str  # "pass", "fail", "board-absent", "incomplete", "interrupted"
    failures: list
    warnings: list
    adc_pass: dict  # (channel, gain) -> bool
    noise_bound: dict = field(default_factory=dict)  # (channel, gain) -> lower confidence bound on sigma, LSB

    @property
    def exit_code(self):
        return VERDICT_EXIT[self.verdict]


# -- statistics ----------------------------------------------------------------


def _regularized_lower_gamma(a, x):
    """P(a, x), the regularized lower incomplete gamma function, for a > 0 and x >= 0.

    The series converges quickly below a + 1, the continued fraction (modified
    Lentz) above; both to double precision (Numerical Recipes, 6.2).
    """
    if x <= 0.0:
        return 0.0
    log_prefix = -x + a * math.log(x) - math.lgamma(a)
    if x < a + 1.0:
        term = 1.0 / a
        total = term
        denominator = a
        for _ in range(100_000):
            denominator += 1.0
            term *= x / denominator
            total += term
            if term < total * 1e-16:
                break
        return min(1.0, total * math.exp(log_prefix))
    tiny = 1e-300
    b = x + 1.0 - a
    c = 1.0 / tiny
    d = 1.0 / b
    h = d
    for i in range(1, 100_000):
        an = -i * (i - a)
        b += 2.0
        d = an * d + b
        d = tiny if abs(d) < tiny else d
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        d = 1.0 / d
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-16:
            break
    return max(0.0, 1.0 - math.exp(log_prefix) * h)


@functools.lru_cache(maxsize=1024)
def chi_square_quantile(probability, dof):
    """x with P(chi-square(dof) <= x) = probability, for 0 < probability < 1 and dof >= 1.

    Exact (bisection on the distribution function) up to 2000 degrees of
    freedom; beyond, the Wilson-Hilferty approximation, whose relative error
    there is below 1e-5. Cached: a report has few distinct degrees of freedom.
    """
    if not 0.0 < probability < 1.0 or dof < 1:
        raise ValueError("chi_square_quantile needs 0 < probability < 1 and dof >= 1")
    if dof > 2000:
        z = statistics.NormalDist().inv_cdf(probability)
        ratio = 2.0 / (9.0 * dof)
        return dof * (1.0 - ratio + z * math.sqrt(ratio)) ** 3
    low, high = 0.0, dof + 10.0 * math.sqrt(2.0 * dof) + 40.0
    while _regularized_lower_gamma(dof / 2.0, high / 2.0) < probability:
        high *= 2.0
    for _ in range(200):
        middle = (low + high) / 2.0
        if _regularized_lower_gamma(dof / 2.0, middle / 2.0) < probability:
            low = middle
        else:
            high = middle
        if high - low <= 1e-12 * high:
            break
    return (low + high) / 2.0


def noise_lower_bound(deviation, dof, confidence):
    """The one-sided lower confidence bound on sigma from a sample standard deviation with dof degrees of freedom.

    dof * s^2 / sigma^2 follows chi-square(dof) for Gaussian noise, so sigma
    is at least s * sqrt(dof / chi2_confidence(dof)) with the given confidence.
    """
    return deviation * math.sqrt(dof / chi_square_quantile(confidence, dof))


# -- parsing -------------------------------------------------------------------

KEY_VALUE = re.compile(r"([a-z_]+)=(\S+)")
DECIMAL_INTEGER = re.compile(r"[0-9]{1,12}")
HEX_INTEGER = re.compile(r"0[xX][0-9a-fA-F]{1,8}")
BARE_HEX = re.compile(r"(?:0[xX])?([0-9a-fA-F]{1,8})")
DECIMAL_NUMBER = re.compile(r"[+-]?[0-9]{1,16}(?:\.[0-9]{1,9})?")
IDENTIFIER = re.compile(r"[A-Za-z0-9._+-]{1,64}")


def _quote(text, length=24):
    """text for a message: repr'd, and cut short when long."""
    return repr(text) if len(text) <= length else repr(text[:length]) + f"... ({len(text)} characters)"


def _fields(text):
    """Splits 'a=1 b=2' into a dict; raises ValueError on a word that is not key=value or a key given twice."""
    result = {}
    for word in text.split():
        match = KEY_VALUE.fullmatch(word)
        if not match:
            raise ValueError(f"{_quote(word)} is not key=value")
        if match.group(1) in result:
            raise ValueError(f"{match.group(1)} given twice")
        result[match.group(1)] = match.group(2)
    return result


def _integer(text, what, low, high):
    """An integer in decimal, or in hex with a 0x prefix, from low to high."""
    if HEX_INTEGER.fullmatch(text):
        value = int(text, 16)
    elif DECIMAL_INTEGER.fullmatch(text):
        value = int(text, 10)
    else:
        raise ValueError(f"{what} {_quote(text)} is not a whole number")
    if not low <= value <= high:
        raise ValueError(f"{what} {value} is not from {low} to {high}")
    return value


def _hex(text, what, high=0xFFFF):
    """A hex number with or without 0x, from 0 to high."""
    match = BARE_HEX.fullmatch(text)
    if not match:
        raise ValueError(f"{what} {_quote(text)} is not a hex number")
    value = int(match.group(1), 16)
    if value > high:
        raise ValueError(f"{what} 0x{value:x} is above 0x{high:x}")
    return value


def _number(text, what, low, high):
    """A decimal number (the controller prints fixed-point), from low to high."""
    if not DECIMAL_NUMBER.fullmatch(text):
        raise ValueError(f"{what} {_quote(text)} is not a decimal number")
    value = float(text)
    if not low <= value <= high:
        raise ValueError(f"{what} {text} is not from {format_number(low)} to {format_number(high)}")
    return value


def _require(fields, *names):
    missing = [name for name in names if name not in fields]
    if missing:
        raise ValueError("missing " + ", ".join(missing))


def _parse_points(text):
    points = []
    for pair in text.split(","):
        if not pair:
            continue
        if len(points) == MAX_POINTS:
            raise ValueError(f"more than {MAX_POINTS} points")
        out_text, sep, in_text = pair.partition(":")
        if not sep:
            raise ValueError(f"point {_quote(pair)} is not <out>:<in>")
        points.append((_integer(out_text, "DAC code", 0, ADC_FULL_SCALE),
                       _number(in_text, "mean ADC code", 0.0, float(ADC_FULL_SCALE))))
    return points


def _parse_adc(fields):
    _require(fields, "channel", "gain", "offset_lsb", "gain_error_pct", "max_error_lsb", "noise_lsb", "points")
    channel = _integer(fields["channel"], "channel", 0, CHANNELS - 1)
    gain = _integer(fields["gain"], "gain", 0, max(GAINS))
    if gain not in GAINS:
        raise ValueError(f"gain {gain} is not one of 1, 10, 100, 1000")
    pooled = [name for name in ("noise_pooled_lsb", "noise_dof", "samples") if name in fields]
    if pooled and len(pooled) != 3:
        # Half a pooled estimate cannot be judged; the firmware prints all three or none.
        raise ValueError("noise_pooled_lsb, noise_dof and samples go together; missing "
                         + ", ".join(name for name in ("noise_pooled_lsb", "noise_dof", "samples")
                                     if name not in fields))
    result = AdcResult(
        channel, gain,
        _number(fields["offset_lsb"], "offset_lsb", -MAX_METRIC, MAX_METRIC),
        _number(fields["gain_error_pct"], "gain_error_pct", -MAX_METRIC, MAX_METRIC),
        _number(fields["max_error_lsb"], "max_error_lsb", 0.0, MAX_METRIC),
        _number(fields["noise_lsb"], "noise_lsb", 0.0, MAX_NOISE_LSB),
        _integer(fields.get("overrange", "0"), "overrange", 0, MAX_OVERRANGE),
        _parse_points(fields["points"]),
    )
    if pooled:
        result.noise_pooled_lsb = _number(fields["noise_pooled_lsb"], "noise_pooled_lsb", 0.0, MAX_NOISE_LSB)
        result.noise_dof = _integer(fields["noise_dof"], "noise_dof", 0, MAX_COUNT)
        result.samples = _integer(fields["samples"], "samples", 0, MAX_COUNT)
    return result


def _parse_line(report, keyword, rest):
    if keyword == "BEGIN":
        fields = _fields(rest)
        report.begun = True
        if "base" in fields:
            report.base = _integer(fields["base"], "base", 0, 0xFFFF)
        if "irq" in fields:
            report.irq_line = _integer(fields["irq"], "irq", 0, 15)
    elif keyword == "FIRMWARE":
        fields = _fields(rest)
        _require(fields, "version", "revision")
        for name in ("version", "revision"):
            if not IDENTIFIER.fullmatch(fields[name]):
                raise ValueError(f"firmware {name} {_quote(fields[name])} is not letters, digits and ._+-")
        report.firmware_version, report.firmware_revision = fields["version"], fields["revision"]
    elif keyword == "PROBE":
        words = rest.split()
        if not words or words[0] not in ("ok", "absent"):
            raise ValueError("PROBE is neither ok nor absent")
        fields = _fields(" ".join(words[1:]))
        board_id = _hex(fields["id"], "id") if "id" in fields else None
        revision = _hex(fields["revision"], "revision") if "revision" in fields else None
        report.probe, report.board_id, report.revision = words[0], board_id, revision
    elif keyword == "DIO":
        words = rest.split()
        if len(words) < 2 or words[0] not in ("walking-ones", "walking-zeros") or words[1] not in ("ok", "fail"):
            raise ValueError("DIO needs walking-ones|walking-zeros and ok|fail")
        if words[1] == "ok":
            report.dio.append(DioResult(words[0], True))
        else:
            fields = _fields(" ".join(words[2:]))
            _require(fields, "bits", "wrote", "read")
            report.dio.append(DioResult(words[0], False, _integer(fields["bits"], "bits", 0, 0xFFFF),
                                        _integer(fields["wrote"], "wrote", 0, 0xFFFF),
                                        _integer(fields["read"], "read", 0, 0xFFFF)))
    elif keyword == "ADC":
        report.adc.append(_parse_adc(_fields(rest)))
    elif keyword == "IRQ":
        fields = _fields(rest)
        _require(fields, "delivered", "requested")
        delivered = _integer(fields["delivered"], "delivered", 0, MAX_COUNT)
        requested = _integer(fields["requested"], "requested", 0, MAX_COUNT)
        if delivered > requested:
            raise ValueError(f"delivered {delivered} exceeds requested {requested}")
        low = _number(fields["latency_min_ns"], "latency_min_ns", 0.0, MAX_LATENCY_NS) \
            if "latency_min_ns" in fields else None
        high = _number(fields["latency_max_ns"], "latency_max_ns", 0.0, MAX_LATENCY_NS) \
            if "latency_max_ns" in fields else None
        if low is not None and high is not None and low > high:
            raise ValueError(f"latency_min_ns {format_number(low)} exceeds latency_max_ns {format_number(high)}")
        report.irq = IrqResult(delivered, requested, low, high)
    elif keyword == "END":
        fields = _fields(rest)
        failures = _integer(fields["failures"], "failures", 0, MAX_COUNT) if "failures" in fields else None
        report.ended = True
        report.controller_failures = failures
    else:
        raise ValueError(f"unknown result {_quote(keyword)}")


def parse_transcript(text):
    """Parses a console transcript (any other console output is ignored).

    Lines that start with BRINGUP but do not follow the format are kept in
    report.garbled with the reason; they never raise. A line longer than
    MAX_LINE_LENGTH is garbled without being split, so a transcript of any
    size is read in time proportional to its length.
    """
    report = Report()
    for raw in text.replace("\r", "\n").split("\n"):
        line = raw.strip()
        if not line.startswith("BRINGUP"):
            continue
        if len(line) > MAX_LINE_LENGTH:
            shown = line[:80] + f"... ({len(line)} characters)"
            report.lines.append(shown)
            report.garbled.append((shown, f"line longer than {MAX_LINE_LENGTH} characters"))
            continue
        words = line.split(None, 2)
        if words[0] != "BRINGUP" or len(words) < 2:
            continue
        report.lines.append(line)
        try:
            _parse_line(report, words[1], words[2] if len(words) == 3 else "")
        except ValueError as error:
            report.garbled.append((line, str(error)))
    return report


# -- judging -------------------------------------------------------------------


def ideal_adc_code(dac_code, gain):
    """The ADC code a perfect board reads with DAC n wired to ADC n at this gain."""
    return min(max(ADC_MID_SCALE + gain * (dac_code - ADC_MID_SCALE), 0), ADC_FULL_SCALE)


def format_number(value):
    """A number for a message: whole large numbers in full, others with one or two decimals."""
    if isinstance(value, int) or (abs(value) >= 1e5 and value == int(value)):
        return str(int(value))
    return f"{value:.1f}" if value == round(value, 1) else f"{value:.2f}"


def format_limit(value):
    """A limit as the user would type it: 2.0 as 2.0, 0.999 as 0.999 (format_number rounds to two decimals)."""
    if isinstance(value, int):
        return str(value)
    return format_number(value) if value == round(value, 2) else f"{value:.10g}"


def _stuck_level(result, bit):
    return (result.read >> bit) & 1


def _is_dead(results):
    """True when every sweep of a channel reads a constant although the ideal moves."""
    moving = [r for r in results if len(r.points) >= 2]
    if not moving:
        return False
    for result in moving:
        ideal = [ideal_adc_code(code, result.gain) for code, _ in result.points]
        measured = [value for _, value in result.points]
        if max(ideal) - min(ideal) < 8 or max(measured) - min(measured) >= 1.0:
            return False
    return True


def _judge_noise(result, limits, failures, warnings, bounds):
    """Judges one sweep's noise; returns False when it fails.

    The controller pools the variance of every point's repeated conversions
    into one estimate with sum(n_i - 1) degrees of freedom. The sweep fails
    only when the chi-square lower confidence bound on sigma is above the
    limit: the largest of many small-sample deviations, which the older
    report carried alone, exceeds a limit by chance on a healthy board.
    """
    channel, gain = result.channel, result.gain
    if result.noise_pooled_lsb is None:
        # A report from firmware before the pooled estimate: only the largest
        # per-point deviation is known, judged as before (see the warning).
        if result.noise_lsb > limits.max_noise_lsb:
            failures.append(Failure(
                "adc", f"ADC channel {channel} gain {gain}: noise {format_number(result.noise_lsb)} LSB "
                       f"> limit {format_number(limits.max_noise_lsb)}",
                channel=channel, gain=gain, metric="noise_lsb", value=result.noise_lsb, limit=limits.max_noise_lsb))
            return False
        return True
    if result.noise_dof < 1:
        failures.append(Failure(
            "adc", f"ADC channel {channel} gain {gain}: noise not measured: {result.samples} conversion(s) per "
                   f"point give no degrees of freedom", channel=channel, gain=gain, metric="noise_dof",
            value=result.noise_dof, limit=1))
        return False
    bound = noise_lower_bound(result.noise_pooled_lsb, result.noise_dof, limits.noise_confidence)
    bounds[(channel, gain)] = bound
    if bound > limits.max_noise_lsb:
        failures.append(Failure(
            "adc", f"ADC channel {channel} gain {gain}: noise {result.noise_pooled_lsb:.2f} LSB over "
                   f"{result.noise_dof} degrees of freedom, at least {bound:.2f} with "
                   f"{limits.noise_confidence * 100:g} % confidence > limit {format_number(limits.max_noise_lsb)}",
            channel=channel, gain=gain, metric="noise_pooled_lsb", value=result.noise_pooled_lsb,
            limit=limits.max_noise_lsb))
        return False
    return True


def judge(report, limits, expected_base=None, expected_irq=None):
    """Applies the limits (which validate_limits accepts) to a parsed report and lists every failure."""
    failures = []
    warnings = []
    adc_pass = {}
    bounds = {}

    for line, reason in report.garbled[:MAX_GARBLED_LISTED]:
        failures.append(Failure("report", f"unreadable report line ({reason}): {line}"))
    if len(report.garbled) > MAX_GARBLED_LISTED:
        failures.append(Failure("report", f"{len(report.garbled) - MAX_GARBLED_LISTED} more unreadable report lines"))

    if not report.begun and not report.lines:
        return Judgement("incomplete", [Failure("report", "no BRINGUP output from the controller")] + failures,
                         warnings, adc_pass)
    if report.probe == "absent":
        base = f"0x{report.base:x}" if report.base is not None else "the base port"
        return Judgement("board-absent",
                         [Failure("probe", f"board absent: no I/O board answers at {base}")] + failures,
                         warnings, adc_pass)

    if expected_base is not None and report.base is not None and report.base != expected_base:
        failures.append(Failure("report", f"controller used base 0x{report.base:x}, not 0x{expected_base:x}"))
    if expected_irq is not None and report.irq_line is not None and report.irq_line != expected_irq:
        failures.append(Failure("report", f"controller used IRQ {report.irq_line}, not {expected_irq}"))

    if report.probe is None and report.ended and not report.dio and not report.adc and report.irq is None:
        # The controller ended before probing: it could not install the driver at that base and IRQ.
        where = f" at 0x{report.base:x} IRQ {report.irq_line}" if report.base is not None else ""
        failures.append(Failure("probe", f"probe: not run: the controller could not install the board driver{where} "
                                         f"(see its console for the reason)"))
        return Judgement("fail", failures, warnings, adc_pass)
    if report.probe is None:
        failures.append(Failure("probe", "probe: not reported"))
    elif report.board_id is not None and report.board_id != 0x4D46:
        failures.append(Failure("probe", f"probe: identification 0x{report.board_id:04x}, expected 0x4d46"))

    # Digital inputs: one failure per DI bit and pattern, with the first pattern that showed it.
    seen_patterns = {result.pattern for result in report.dio}
    for pattern in ("walking-ones", "walking-zeros"):
        if pattern not in seen_patterns:
            failures.append(Failure("dio", f"DIO {pattern}: not reported"))
    # One failure per DI bit: the first pattern that showed it, with the other pattern's evidence appended.
    by_bit = {}
    for result in report.dio:
        if result.ok:
            continue
        words = result.pattern.replace("-", " ")
        if result.bits == 0:
            failures.append(Failure("dio", f"DIO {words}: failed without naming a bit: wrote 0x{result.wrote:04x} "
                                           f"read 0x{result.read:04x}"))
        for bit in range(DIGITAL_BITS):
            if not result.bits >> bit & 1:
                continue
            evidence = f"{words} wrote 0x{result.wrote:04x} read 0x{result.read:04x}"
            failure = by_bit.get(bit)
            if failure is None:
                by_bit[bit] = Failure("dio", f"DI bit {bit} stuck: {evidence}", bit=bit,
                                      value=_stuck_level(result, bit))
            elif words not in failure.message:
                failure.message += f"; {evidence}"
    failures += [by_bit[bit] for bit in sorted(by_bit)]

    # Analog inputs: every channel at every gain, each metric against its limit.
    by_key = {}
    for result in report.adc:
        by_key.setdefault((result.channel, result.gain), result)
    if any(result.noise_pooled_lsb is None for result in by_key.values()):
        warnings.append("the report has no pooled noise estimate (firmware before noise_pooled_lsb): noise is judged "
                        "on the largest single point's standard deviation, which can fail a healthy board by chance")
    for channel in range(CHANNELS):
        results = [by_key[(channel, gain)] for gain in GAINS if (channel, gain) in by_key]
        if len(results) == len(GAINS) and _is_dead(results):
            level = next(result.points[0][1] for result in results if result.points)
            failures.append(Failure("adc", f"ADC channel {channel} dead: reads {level:.1f} at every DAC code "
                                           f"at every gain", channel=channel, metric="dead"))
        for gain in GAINS:
            result = by_key.get((channel, gain))
            if result is None:
                failures.append(Failure("adc", f"ADC channel {channel} gain {gain}: not reported",
                                        channel=channel, gain=gain))
                adc_pass[(channel, gain)] = False
                continue
            ok = True
            checks = (
                ("offset", "offset_lsb", abs(result.offset_lsb), result.offset_lsb, limits.max_offset_lsb, "LSB"),
                ("gain error", "gain_error_pct", abs(result.gain_error_pct), result.gain_error_pct,
                 limits.max_gain_error_pct, "%"),
                ("max error", "max_error_lsb", result.max_error_lsb, result.max_error_lsb, limits.max_error_lsb, "LSB"),
            )
            for label, metric, magnitude, value, limit, unit in checks:
                if magnitude > limit:
                    ok = False
                    unit_text = " %" if unit == "%" else f" {unit}"
                    failures.append(Failure(
                        "adc", f"ADC channel {channel} gain {gain}: {label} {format_number(value)}{unit_text} "
                               f"> limit {format_number(limit)}",
                        channel=channel, gain=gain, metric=metric, value=value, limit=limit,
                    ))
            if not _judge_noise(result, limits, failures, warnings, bounds):
                ok = False
            if not result.points:
                # No point at all is never a measurement, whatever --min-points says.
                ok = False
                failures.append(Failure("adc", f"ADC channel {channel} gain {gain}: sweep empty: no points measured",
                                        channel=channel, gain=gain, metric="points", value=0,
                                        limit=limits.min_points))
            elif len(result.points) < limits.min_points:
                ok = False
                failures.append(Failure("adc", f"ADC channel {channel} gain {gain}: sweep incomplete: "
                                               f"{len(result.points)} of at least {limits.min_points} points measured",
                                        channel=channel, gain=gain, metric="points", value=len(result.points),
                                        limit=limits.min_points))
            if result.overrange:
                warnings.append(f"ADC channel {channel} gain {gain}: overrange during the sweep")
            adc_pass[(channel, gain)] = ok

    # Interrupts.
    irq = report.irq
    if irq is None:
        failures.append(Failure("irq", "interrupt: not reported"))
    elif irq.requested <= 0:
        failures.append(Failure("irq", "interrupt: no conversions requested"))
    else:
        needed = math.ceil(irq.requested * limits.min_irq_delivered_pct / 100.0 - 1e-9)
        if irq.delivered < needed:
            failures.append(Failure("irq", f"interrupt: {irq.delivered} of {irq.requested} delivered "
                                           f"(minimum {needed})", metric="delivered",
                                    value=irq.delivered, limit=needed))
        if irq.delivered > 0 and irq.latency_max_ns is not None and irq.latency_max_ns > limits.max_irq_latency_ns:
            failures.append(Failure("irq", f"interrupt: max latency {irq.latency_max_ns:.0f} ns "
                                           f"> limit {limits.max_irq_latency_ns:.0f}",
                                    metric="latency_max_ns", value=irq.latency_max_ns,
                                    limit=limits.max_irq_latency_ns))

    # The controller counts the steps it could not run or that found a stuck or absent signal.
    # When the measurements it printed pass the user's limits, its count alone is only a warning:
    # a step that could not run shows up above as a result that was not reported.
    if report.controller_failures and not [f for f in failures if f.kind in ("probe", "dio", "adc", "irq")]:
        warnings.append(f"controller counted {report.controller_failures} failed steps that pass the limits here")

    if not report.ended:
        failures.append(Failure("report", "report incomplete: no BRINGUP END line (time-out or lost connection)"))
        return Judgement("incomplete", failures, warnings, adc_pass, bounds)
    return Judgement("fail" if failures else "pass", failures, warnings, adc_pass, bounds)


# -- the text report and the result document ------------------------------------------


def board_identity(report):
    """The board's identity as words: base, IRQ, id and revision, as far as the report gives them."""
    board = []
    if report.base is not None:
        board.append(f"base 0x{report.base:x}")
    if report.irq_line is not None:
        board.append(f"IRQ {report.irq_line}")
    if report.board_id is not None:
        board.append(f"id 0x{report.board_id:04x}")
    if report.revision is not None:
        board.append(f"revision {report.revision >> 8}.{report.revision & 0xFF}")
    return board


def firmware_identity(report):
    if report.firmware_version is None:
        return None
    return f"DCOS {report.firmware_version} (revision {report.firmware_revision})"


SUMMARIES = {
    "pass": "PASS: every check within its limits",
    "fail": "FAILED: {count} failure(s)",
    "board-absent": "BOARD ABSENT",
    "incomplete": "INCOMPLETE: the bring-up did not finish",
    "interrupted": "INTERRUPTED: the bring-up was stopped before it finished",
}


def format_report(report, judgement, limits):
    """The human-readable pass/fail report, as text."""
    lines = []
    board = board_identity(report)
    lines.append("I/O board bring-up" + (": " + ", ".join(board) if board else ""))
    if firmware_identity(report):
        lines.append(f"firmware: {firmware_identity(report)}")
    lines.append("limits: " + ", ".join(f"{name} {format_limit(value)}" for name, value in asdict(limits).items()))
    if report.probe:
        lines.append(f"  probe            {report.probe}")
    for result in report.dio:
        lines.append(f"  DIO {result.pattern:13s} {'pass' if result.ok else 'FAIL'}")
    if report.adc:
        lines.append("  ADC  ch gain  offset  gain%   maxerr  noise  pooled  dof  result")
        for result in sorted(report.adc, key=lambda r: (r.channel, r.gain)):
            ok = judgement.adc_pass.get((result.channel, result.gain), False)
            pooled = f"{result.noise_pooled_lsb:6.2f} {result.noise_dof:5d}" if result.noise_pooled_lsb is not None \
                else f"{'-':>6s} {'-':>5s}"
            lines.append(f"       {result.channel:2d} {result.gain:4d} {result.offset_lsb:7.2f} {result.gain_error_pct:7.2f} "
                         f"{result.max_error_lsb:7.2f} {result.noise_lsb:6.2f} {pooled}  {'pass' if ok else 'FAIL'}")
    if report.irq is not None:
        irq = report.irq
        latency = ""
        if irq.latency_min_ns is not None and irq.latency_max_ns is not None:
            latency = f", latency {irq.latency_min_ns:g}..{irq.latency_max_ns:g} ns"
        lines.append(f"  IRQ              {irq.delivered} of {irq.requested} delivered{latency}")
    for warning in judgement.warnings:
        lines.append(f"warning: {warning}")
    for failure in judgement.failures:
        lines.append(f"FAIL: {failure.message}")
    lines.append(SUMMARIES[judgement.verdict].format(count=len(judgement.failures)))
    return "\n".join(lines) + "\n"


def result_document(report, judgement, limits, extra=None, timestamp=None):
    """The machine-readable result, as a JSON-serialisable dict of finite numbers.

    timestamp is the time of the run (ISO 8601, UTC); the caller takes it
    when the run starts, so that the result says when the board was measured.
    """
    document = {
        "format": RESULT_FORMAT,
        "version": RESULT_VERSION,
        "timestamp": timestamp,
        "verdict": judgement.verdict,
        "exit_code": judgement.exit_code,
        "board": {
            "base": report.base,
            "irq": report.irq_line,
            "probe": report.probe,
            "id": report.board_id,
            "revision": report.revision,
        },
        "firmware": ({"version": report.firmware_version, "revision": report.firmware_revision}
                     if report.firmware_version is not None else None),
        "limits": asdict(limits),
        "dio": [asdict(result) for result in report.dio],
        "adc": [
            dict(asdict(result), points=[list(point) for point in result.points],
                 ideal=[ideal_adc_code(code, result.gain) for code, _ in result.points],
                 noise_lower_bound_lsb=(round(judgement.noise_bound[(result.channel, result.gain)], 4)
                                        if (result.channel, result.gain) in judgement.noise_bound else None),
                 passed=judgement.adc_pass.get((result.channel, result.gain), False))
            for result in sorted(report.adc, key=lambda r: (r.channel, r.gain))
        ],
        "irq": asdict(report.irq) if report.irq is not None else None,
        "controller_failures": report.controller_failures,
        "failures": [{key: value for key, value in asdict(failure).items() if value is not None}
                     for failure in judgement.failures],
        "warnings": list(judgement.warnings),
        "report_lines": list(report.lines),
    }
    if extra:
        document.update(extra)
    return document


def atomic_write(path, data):
    """Writes bytes to path through a temporary file in the same directory and a rename.

    A reader sees the old file or the whole new one, never a part; a failure
    leaves no temporary file behind. The file gets the usual mode (0666 less
    the umask), not the temporary file's private 0600.
    """
    directory = os.path.dirname(os.path.abspath(path))
    handle, temporary = tempfile.mkstemp(dir=directory, prefix=f".{os.path.basename(path)}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(temporary, 0o666 & ~mask)
        os.replace(temporary, path)
    except BaseException:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        raise


def encode_json(document):
    """The document as JSON text; raises ValueError on a non-finite number instead of writing one."""
    return json.dumps(document, indent=2, sort_keys=False, allow_nan=False) + "\n"


def write_json(path, document):
    """Encodes first, then writes atomically, so a document that cannot be encoded leaves no partial file."""
    atomic_write(path, encode_json(document).encode("utf-8"))


# -- the picture ---------------------------------------------------------------

RED = "#c00000"
GREEN = "#2e8b3c"
GREY = "0.55"


def _mark(axis, label, title, ok):
    """Titles a panel and marks a failing one: red title and a thick red frame."""
    axis.set_label(label)
    axis.set_title(title, fontsize=8, color="black" if ok else RED, fontweight="normal" if ok else "bold")
    if not ok:
        for spine in axis.spines.values():
            spine.set_edgecolor(RED)
            spine.set_linewidth(2.0)


def _draw_header(axis, report, judgement, limits, timestamp):
    axis.set_axis_off()
    verdict = SUMMARIES[judgement.verdict].format(count=len(judgement.failures))
    axis.text(0.0, 1.0, verdict, fontsize=12, fontweight="bold", va="top", transform=axis.transAxes,
              color=GREEN if judgement.verdict == "pass" else RED)
    lines = ["board: " + (", ".join(board_identity(report)) or "not identified"),
             "firmware: " + (firmware_identity(report) or "not reported"),
             f"measured: {timestamp or 'unknown time'}",
             f"limits: offset {format_number(limits.max_offset_lsb)} LSB, gain {format_number(limits.max_gain_error_pct)} %, "
             f"error {format_number(limits.max_error_lsb)} LSB,",
             f"  noise {format_number(limits.max_noise_lsb)} LSB at {limits.noise_confidence * 100:g} %, "
             f"IRQ {format_number(limits.min_irq_delivered_pct)} %, {format_number(limits.max_irq_latency_ns)} ns"]
    shown = [failure.message for failure in judgement.failures[:6]]
    if len(judgement.failures) > 6:
        shown.append(f"... and {len(judgement.failures) - 6} more (see the JSON)")
    axis.text(0.0, 0.80, "\n".join(lines), fontsize=7, va="top", family="monospace", transform=axis.transAxes)
    axis.text(0.0, 0.30, "\n".join(shown), fontsize=6.5, va="top", color=RED, transform=axis.transAxes)
    _mark(axis, "header", "", judgement.verdict == "pass")
    for spine in axis.spines.values():
        spine.set_visible(False)


def _draw_dio(axis, report, judgement):
    """A 2 x 16 grid, one cell per pattern and DI bit: green followed, red stuck, grey not reported."""
    from matplotlib.patches import Rectangle

    failing = {failure.bit for failure in judgement.failures if failure.kind == "dio" and failure.bit is not None}
    broken = [failure for failure in judgement.failures if failure.kind == "dio"]
    by_pattern = {result.pattern: result for result in report.dio}
    for row, pattern in enumerate(("walking-ones", "walking-zeros")):
        result = by_pattern.get(pattern)
        for bit in range(DIGITAL_BITS):
            if result is None:
                colour = "0.85"
            elif not result.ok and (result.bits >> bit & 1 or result.bits == 0):
                colour = RED
            else:
                colour = GREEN
            axis.add_patch(Rectangle((DIGITAL_BITS - 1 - bit, 1 - row), 0.9, 0.9, facecolor=colour,
                                     edgecolor="white"))
    axis.set_xlim(0, DIGITAL_BITS)
    axis.set_ylim(0, 2)
    axis.set_xticks([i + 0.45 for i in range(DIGITAL_BITS)])
    axis.set_xticklabels([str(DIGITAL_BITS - 1 - i) for i in range(DIGITAL_BITS)], fontsize=6)
    axis.set_yticks([1.45, 0.45])
    axis.set_yticklabels(["walking ones", "walking zeros"], fontsize=6)
    axis.set_xlabel("DI bit (green followed DO, red stuck, grey not reported)", fontsize=6)
    axis.tick_params(length=0)
    ok = not broken and report.probe == "ok"
    if ok:
        title = "digital inputs: pass"
    elif failing:
        title = "digital inputs: FAIL: bit " + ", ".join(str(bit) for bit in sorted(failing)) + " stuck"
    else:
        title = "digital inputs: FAIL" if broken else "digital inputs: not measured"
    _mark(axis, "dio", title, ok)


def _draw_irq(axis, report, judgement, limits):
    """Delivered against requested interrupts, and the largest latency against its limit."""
    irq = report.irq
    problems = [failure for failure in judgement.failures if failure.kind == "irq"]
    if irq is None or irq.requested <= 0:
        axis.set_axis_off()
        _mark(axis, "irq", "interrupts: not measured", False)
        return
    needed = math.ceil(irq.requested * limits.min_irq_delivered_pct / 100.0 - 1e-9)
    delivered_ok = irq.delivered >= needed
    axis.barh([1], [irq.requested], color="0.85", height=0.6)
    axis.barh([1], [irq.delivered], color=GREEN if delivered_ok else RED, height=0.6)
    axis.axvline(needed, color="black", linestyle="--", linewidth=1)
    axis.text(irq.requested, 1, f" {irq.delivered} of {irq.requested}", va="center", fontsize=7)
    if irq.latency_max_ns is not None and irq.delivered > 0:
        share = min(irq.latency_max_ns / limits.max_irq_latency_ns, 2.0) if limits.max_irq_latency_ns > 0 else 2.0
        latency_ok = irq.latency_max_ns <= limits.max_irq_latency_ns
        axis.barh([0], [share * irq.requested], color=GREEN if latency_ok else RED, height=0.6)
        axis.axvline(irq.requested, color="black", linewidth=0.5)
        axis.text(share * irq.requested, 0, f" max {irq.latency_max_ns:.0f} ns "
                                            f"(limit {limits.max_irq_latency_ns:.0f})", va="center", fontsize=7)
    axis.set_yticks([1, 0])
    axis.set_yticklabels(["delivered", "latency"], fontsize=6)
    axis.set_xlim(0, irq.requested * 2.6)
    axis.set_xticks([])
    axis.set_xlabel("dashed: the minimum to deliver; thin line: the latency limit", fontsize=6)
    ok = not problems
    title = "interrupts: pass" if ok else "interrupts: FAIL: " + "; ".join(
        failure.message.replace("interrupt: ", "") for failure in problems)
    _mark(axis, "irq", title, ok)


def _draw_adc(axis, channel, gain, result, judgement, limits):
    """Error in LSB against DAC code, with the error limit band and +-1 sigma noise bars."""
    from matplotlib.ticker import MaxNLocator

    if result is None or not result.points:
        axis.set_xticks([])
        axis.set_yticks([])
        _mark(axis, f"adc-{channel}-{gain}", f"ch {channel} gain {gain}: FAIL: not measured", False)
        return
    codes = [code for code, _ in result.points]
    errors = [value - ideal_adc_code(code, gain) for code, value in result.points]
    sigma = result.noise_pooled_lsb if result.noise_pooled_lsb is not None else result.noise_lsb
    limit = limits.max_error_lsb
    axis.axhspan(-limit, limit, color=GREEN, alpha=0.12, linewidth=0)
    axis.axhline(limit, color=GREEN, linewidth=0.6, linestyle="--")
    axis.axhline(-limit, color=GREEN, linewidth=0.6, linestyle="--")
    axis.axhline(0.0, color=GREY, linewidth=0.5)
    axis.vlines(codes, [error - sigma for error in errors], [error + sigma for error in errors], colors="0.4",
                linewidth=0.8)
    inside = [(code, error) for code, error in zip(codes, errors) if abs(error) <= limit]
    outside = [(code, error) for code, error in zip(codes, errors) if abs(error) > limit]
    for points, colour in ((inside, "tab:blue"), (outside, RED)):
        if points:
            axis.plot([code for code, _ in points], [error for _, error in points], "o", markersize=3, color=colour,
                      zorder=3)
    largest = max([abs(error) + sigma for error in errors] + [limit])
    axis.set_ylim(-1.25 * max(largest, 0.5), 1.25 * max(largest, 0.5))
    if len(set(codes)) == 1:
        axis.set_xlim(codes[0] - 1, codes[0] + 1)
    axis.xaxis.set_major_locator(MaxNLocator(nbins=6, integer=True))
    axis.tick_params(labelsize=6)
    ok = judgement.adc_pass.get((channel, gain), False)
    reasons = sorted({failure.metric.replace("_lsb", "").replace("_pct", "").replace("_", " ")
                      for failure in judgement.failures
                      if failure.kind == "adc" and failure.channel == channel and failure.gain in (gain, None)
                      and failure.metric})
    title = f"ch {channel} gain {gain}: " + ("pass" if ok else "FAIL: " + ", ".join(reasons))
    _mark(axis, f"adc-{channel}-{gain}", title, ok)
    noise = (f"noise {result.noise_pooled_lsb:.2f} (dof {result.noise_dof})" if result.noise_pooled_lsb is not None
             else f"noise {result.noise_lsb:.2f} (largest point)")
    axis.text(0.02, 0.04, f"offset {result.offset_lsb:.2f}  gain {result.gain_error_pct:.2f} %  {noise}",
              fontsize=5.5, transform=axis.transAxes, color="0.2")


def bringup_figure(report, judgement, limits, timestamp=None):
    """The bring-up sheet as a matplotlib figure (Agg backend).

    One sheet holds what an engineer looks for: the verdict and the board's
    identity; the DI bits of both walks; the interrupts delivered and their
    latency; and for every channel and gain the error of each point in LSB
    against the DAC code, inside the band of --max-error-lsb, with bars of
    +-1 sigma of one conversion (the pooled noise). Every panel is labelled
    (Axes.get_label(): header, dio, irq, adc-<channel>-<gain>); a failing
    panel has a red bold title saying why and a red frame.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    figure = pyplot.figure(figsize=(4 * len(GAINS), 3.2 + 2.2 * CHANNELS))
    grid = figure.add_gridspec(CHANNELS + 1, len(GAINS), height_ratios=[1.5] + [1.0] * CHANNELS,
                               hspace=0.55, wspace=0.25)
    _draw_header(figure.add_subplot(grid[0, 0:2]), report, judgement, limits, timestamp)
    _draw_dio(figure.add_subplot(grid[0, 2]), report, judgement)
    _draw_irq(figure.add_subplot(grid[0, 3]), report, judgement, limits)
    by_key = {(r.channel, r.gain): r for r in reversed(report.adc)}
    for channel in range(CHANNELS):
        for column, gain in enumerate(GAINS):
            axis = figure.add_subplot(grid[channel + 1, column])
            _draw_adc(axis, channel, gain, by_key.get((channel, gain)), judgement, limits)
            if channel == CHANNELS - 1:
                axis.set_xlabel("DAC code", fontsize=7)
            if column == 0:
                axis.set_ylabel("error, LSB", fontsize=7)
    figure.suptitle("I/O board bring-up: error against the ideal transfer (band: error limit, bars: noise)",
                    fontsize=10)
    figure.subplots_adjust(left=0.05, right=0.98, top=0.965, bottom=0.03)
    return figure


def render_png(report, judgement, limits, timestamp=None):
    """The bring-up sheet as PNG bytes; equal inputs give equal bytes."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    figure = bringup_figure(report, judgement, limits, timestamp)
    try:
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=72, metadata={"Software": None})
        return buffer.getvalue()
    finally:
        pyplot.close(figure)


def plot_transfer_curves(report, judgement, path, limits=None, timestamp=None):
    """Writes the bring-up sheet to a PNG file, atomically. Returns the number of ADC panels with points."""
    atomic_write(path, render_png(report, judgement, limits or Limits(), timestamp))
    return len({(r.channel, r.gain) for r in report.adc if r.points})
