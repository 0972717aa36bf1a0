"""Parsing and judging of the controller's I/O board bring-up report.

The controller's console command `iobus bringup` prints one `BRINGUP` line
per result (docs/iobus/bringup-protocol.md). This module turns a console
transcript into a parsed report, judges it against the user's limits and
describes every failure in one line that names the channel and gain, the DI
bit, or the interrupt exactly. It does no input or output of its own apart
from the optional plot, so it is tested on canned transcripts without an
emulator.
"""

import json
import math
import re
from dataclasses import asdict, dataclass, field

CHANNELS = 8
GAINS = (1, 10, 100, 1000)
DIGITAL_BITS = 16
ADC_FULL_SCALE = 4095
ADC_MID_SCALE = 2048

# Exit statuses of the bring-up tool; the judging decides among the first four.
EXIT_PASS = 0
EXIT_FAILURES = 1
EXIT_USAGE = 2
EXIT_BOARD_ABSENT = 3
EXIT_NO_CONNECTION = 4

VERDICT_EXIT = {
    "pass": EXIT_PASS,
    "fail": EXIT_FAILURES,
    "board-absent": EXIT_BOARD_ABSENT,
    "incomplete": EXIT_NO_CONNECTION,
}


@dataclass
class Limits:
    """The pass/fail limits. Every field has a command-line option of the same name."""

    max_offset_lsb: float = 2.0
    max_gain_error_pct: float = 1.0
    max_error_lsb: float = 2.0
    max_noise_lsb: float = 1.0
    min_irq_delivered_pct: float = 100.0
    max_irq_latency_ns: float = 1_000_000.0
    min_points: int = 3


# (field, option help, unit) for the documented table and the --help text.
LIMIT_DESCRIPTIONS = {
    "max_offset_lsb": "largest |offset| of the fitted line at 0 V, in LSB",
    "max_gain_error_pct": "largest |gain error| of the fitted slope against the ideal, in percent",
    "max_error_lsb": "largest deviation of any point from the ideal transfer, in LSB",
    "max_noise_lsb": "largest standard deviation over a point's repeated conversions, in LSB",
    "min_irq_delivered_pct": "smallest share of requested conversion interrupts that must arrive, in percent",
    "max_irq_latency_ns": "largest interrupt latency (expected completion to handler), in ns",
    "min_points": "smallest number of DAC steps in each channel's and gain's sweep",
}


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
    noise_lsb: float
    overrange: int
    points: list  # [(dac_code, mean_adc_code), ...]


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
    verdict: str  # "pass", "fail", "board-absent", "incomplete"
    failures: list
    warnings: list
    adc_pass: dict  # (channel, gain) -> bool

    @property
    def exit_code(self):
        return VERDICT_EXIT[self.verdict]


LINE = re.compile(r"^\s*BRINGUP\s+(\S+)\s*(.*?)\s*$")
KEY_VALUE = re.compile(r"^([a-z_]+)=(\S+)$")


def _fields(text):
    """Splits 'a=1 b=2' into a dict; raises ValueError on a word that is not key=value."""
    result = {}
    for word in text.split():
        match = KEY_VALUE.match(word)
        if not match:
            raise ValueError(f"{word!r} is not key=value")
        result[match.group(1)] = match.group(2)
    return result


def _integer(text):
    """An integer in decimal, or in hex with a 0x prefix."""
    text = text.strip()
    return int(text, 16) if text.lower().startswith("0x") else int(text, 10)


def _number(text):
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text!r} is not finite")
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
        out_text, sep, in_text = pair.partition(":")
        if not sep:
            raise ValueError(f"point {pair!r} is not <out>:<in>")
        points.append((_integer(out_text), _number(in_text)))
    return points


def _parse_line(report, keyword, rest):
    if keyword == "BEGIN":
        fields = _fields(rest)
        report.begun = True
        if "base" in fields:
            report.base = _integer(fields["base"])
        if "irq" in fields:
            report.irq_line = _integer(fields["irq"])
    elif keyword == "PROBE":
        words = rest.split()
        if not words or words[0] not in ("ok", "absent"):
            raise ValueError("PROBE is neither ok nor absent")
        report.probe = words[0]
        fields = _fields(" ".join(words[1:]))
        if "id" in fields:
            report.board_id = int(fields["id"], 16)
        if "revision" in fields:
            report.revision = int(fields["revision"], 16)
    elif keyword == "DIO":
        words = rest.split()
        if len(words) < 2 or words[0] not in ("walking-ones", "walking-zeros") or words[1] not in ("ok", "fail"):
            raise ValueError("DIO needs walking-ones|walking-zeros and ok|fail")
        if words[1] == "ok":
            report.dio.append(DioResult(words[0], True))
        else:
            fields = _fields(" ".join(words[2:]))
            _require(fields, "bits", "wrote", "read")
            report.dio.append(DioResult(words[0], False, _integer(fields["bits"]) & 0xFFFF,
                                        _integer(fields["wrote"]) & 0xFFFF, _integer(fields["read"]) & 0xFFFF))
    elif keyword == "ADC":
        fields = _fields(rest)
        _require(fields, "channel", "gain", "offset_lsb", "gain_error_pct", "max_error_lsb", "noise_lsb", "points")
        channel, gain = _integer(fields["channel"]), _integer(fields["gain"])
        if not 0 <= channel < CHANNELS:
            raise ValueError(f"channel {channel} is not 0..7")
        if gain not in GAINS:
            raise ValueError(f"gain {gain} is not one of 1, 10, 100, 1000")
        report.adc.append(AdcResult(
            channel, gain, _number(fields["offset_lsb"]), _number(fields["gain_error_pct"]),
            _number(fields["max_error_lsb"]), _number(fields["noise_lsb"]),
            _integer(fields.get("overrange", "0")), _parse_points(fields["points"]),
        ))
    elif keyword == "IRQ":
        fields = _fields(rest)
        _require(fields, "delivered", "requested")
        report.irq = IrqResult(
            _integer(fields["delivered"]), _integer(fields["requested"]),
            _number(fields["latency_min_ns"]) if "latency_min_ns" in fields else None,
            _number(fields["latency_max_ns"]) if "latency_max_ns" in fields else None,
        )
    elif keyword == "END":
        fields = _fields(rest)
        report.ended = True
        if "failures" in fields:
            report.controller_failures = _integer(fields["failures"])
    else:
        raise ValueError(f"unknown result {keyword!r}")


def parse_transcript(text):
    """Parses a console transcript (any other console output is ignored).

    Lines that start with BRINGUP but do not follow the format are kept in
    report.garbled with the reason; they never raise.
    """
    report = Report()
    for raw in text.replace("\r", "\n").split("\n"):
        match = LINE.match(raw)
        if not match:
            continue
        line = raw.strip()
        report.lines.append(line)
        try:
            _parse_line(report, match.group(1), match.group(2))
        except ValueError as error:
            report.garbled.append((line, str(error)))
    return report


def ideal_adc_code(dac_code, gain):
    """The ADC code a perfect board reads with DAC n wired to ADC n at this gain."""
    return min(max(ADC_MID_SCALE + gain * (dac_code - ADC_MID_SCALE), 0), ADC_FULL_SCALE)


def format_number(value):
    """A number for a message: whole large numbers in full, others with one or two decimals."""
    if isinstance(value, int) or (abs(value) >= 1e5 and value == int(value)):
        return str(int(value))
    return f"{value:.1f}" if value == round(value, 1) else f"{value:.2f}"


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


def judge(report, limits, expected_base=None, expected_irq=None):
    """Applies the limits to a parsed report and lists every failure."""
    failures = []
    warnings = []
    adc_pass = {}

    for line, reason in report.garbled:
        failures.append(Failure("report", f"unreadable report line ({reason}): {line}"))

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
    for channel in range(CHANNELS):
        results = [by_key[(channel, gain)] for gain in GAINS if (channel, gain) in by_key]
        if len(results) == len(GAINS) and _is_dead(results):
            level = results[0].points[0][1]
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
                ("noise", "noise_lsb", result.noise_lsb, result.noise_lsb, limits.max_noise_lsb, "LSB"),
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
            if len(result.points) < limits.min_points:
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
        return Judgement("incomplete", failures, warnings, adc_pass)
    return Judgement("fail" if failures else "pass", failures, warnings, adc_pass)


def format_report(report, judgement, limits):
    """The human-readable pass/fail report, as text."""
    lines = []
    board = []
    if report.base is not None:
        board.append(f"base 0x{report.base:x}")
    if report.irq_line is not None:
        board.append(f"IRQ {report.irq_line}")
    if report.board_id is not None:
        board.append(f"id 0x{report.board_id:04x}")
    if report.revision is not None:
        board.append(f"revision {report.revision >> 8}.{report.revision & 0xFF}")
    lines.append("I/O board bring-up" + (": " + ", ".join(board) if board else ""))
    lines.append("limits: " + ", ".join(f"{name} {format_number(value)}" for name, value in asdict(limits).items()))
    if report.probe:
        lines.append(f"  probe            {report.probe}")
    for result in report.dio:
        lines.append(f"  DIO {result.pattern:13s} {'pass' if result.ok else 'FAIL'}")
    if report.adc:
        lines.append("  ADC  ch gain  offset  gain%   maxerr  noise  result")
        for result in sorted(report.adc, key=lambda r: (r.channel, r.gain)):
            ok = judgement.adc_pass.get((result.channel, result.gain), False)
            lines.append(f"       {result.channel:2d} {result.gain:4d} {result.offset_lsb:7.2f} {result.gain_error_pct:7.2f} "
                         f"{result.max_error_lsb:7.2f} {result.noise_lsb:6.2f}  {'pass' if ok else 'FAIL'}")
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
    summary = {
        "pass": "PASS: every check within its limits",
        "fail": f"FAILED: {len(judgement.failures)} failure(s)",
        "board-absent": "BOARD ABSENT",
        "incomplete": "INCOMPLETE: the bring-up did not finish",
    }[judgement.verdict]
    lines.append(summary)
    return "\n".join(lines) + "\n"


def result_document(report, judgement, limits, extra=None):
    """The machine-readable result, as a JSON-serialisable dict."""
    document = {
        "format": "dcos-iobus-bringup-result",
        "version": 1,
        "verdict": judgement.verdict,
        "exit_code": judgement.exit_code,
        "board": {
            "base": report.base,
            "irq": report.irq_line,
            "probe": report.probe,
            "id": report.board_id,
            "revision": report.revision,
        },
        "limits": asdict(limits),
        "dio": [asdict(result) for result in report.dio],
        "adc": [
            dict(asdict(result), points=[list(point) for point in result.points],
                 ideal=[ideal_adc_code(code, result.gain) for code, _ in result.points],
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


def write_json(path, document):
    with open(path, "w", encoding="utf-8") as handle:
        json.dump(document, handle, indent=2, sort_keys=False)
        handle.write("\n")


def plot_transfer_curves(report, judgement, path):
    """Draws measured against ideal transfer curves, one panel per channel and gain, into a PNG.

    Imports matplotlib (Agg backend) only here, so parsing and judging need
    nothing beyond the standard library. Returns the number of panels drawn.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as pyplot

    by_key = {(r.channel, r.gain): r for r in reversed(report.adc)}
    figure, axes = pyplot.subplots(CHANNELS, len(GAINS), figsize=(4 * len(GAINS), 2.6 * CHANNELS), squeeze=False)
    panels = 0
    for channel in range(CHANNELS):
        for column, gain in enumerate(GAINS):
            axis = axes[channel][column]
            result = by_key.get((channel, gain))
            if result is None or not result.points:
                axis.set_title(f"ch {channel} gain {gain}: not measured", fontsize=8, color="red")
                axis.set_axis_off()
                continue
            panels += 1
            codes = [code for code, _ in result.points]
            measured = [value for _, value in result.points]
            low, high = min(codes), max(codes)
            ideal_codes = sorted(set(codes + [low, high]))
            axis.plot(ideal_codes, [ideal_adc_code(c, gain) for c in ideal_codes], "-", color="0.6", label="ideal")
            axis.plot(codes, measured, "o", markersize=3, color="tab:blue", label="measured")
            ok = judgement.adc_pass.get((channel, gain), False)
            axis.set_title(f"ch {channel} gain {gain}: {'pass' if ok else 'FAIL'} "
                           f"(max err {result.max_error_lsb:g} LSB)", fontsize=8,
                           color="black" if ok else "red")
            axis.tick_params(labelsize=6)
            axis.set_ylim(-100, ADC_FULL_SCALE + 100)
            if channel == CHANNELS - 1:
                axis.set_xlabel("DAC code", fontsize=7)
            if column == 0:
                axis.set_ylabel("ADC code", fontsize=7)
            if channel == 0 and column == 0:
                axis.legend(fontsize=6)
    figure.suptitle("I/O board bring-up: measured (points) against ideal (line) transfer curves")
    figure.tight_layout(rect=(0, 0, 1, 0.98))
    figure.savefig(path, format="png", dpi=72)
    pyplot.close(figure)
    return panels
