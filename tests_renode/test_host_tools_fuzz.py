"""Property-based fuzzing of the host tools' parsers (Debian's python3-hypothesis).

Each parser reads what another program or a person wrote: the bring-up
report from a serial line, the plant protocol from the emulator, the
compiler's messages. Whatever they are given, they must answer with their
documented error and never raise anything else, never hang, and never put a
non-finite number in their output. The strategies mix well-formed lines with
the hostile values that once broke them (a 401-digit number, a 4,000-digit
base, 1e308, NaN, an over-long time) and with arbitrary text.

Every test is bounded: derandomize=True makes each run draw the same
examples (repeatable in CI), deadline=None tolerates a loaded machine, and
max_examples keeps each test to a few seconds. No example database is
written.
"""

import json
import math
import os
import subprocess
import sys
import tempfile

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for folder in ("bringup", "plant_simulator", "app_build"):
    sys.path.insert(0, os.path.join(REPOSITORY, "host_tools", folder))

import bringup_report as br  # noqa: E402
import explain_configuration_error as explainer  # noqa: E402
import plant_simulator as plant  # noqa: E402

FUZZ = settings(max_examples=250, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.filter_too_much])

# -- building blocks ----------------------------------------------------------------

HOSTILE_NUMBERS = ["nan", "-nan", "inf", "-inf", "1e999", "-1e999", "1e308", "1" * 401, "9" * 4000,
                   "0x" + "f" * 4000, "0x", "", "-0", "+5", "1_000", "\u0663", "0.5.5", "1e-400", "  7", "0x1g",
                   "4096", "65536", "-1", "18446744073709551616"]


def two_decimals(value):
    return f"{value:.2f}"


def six_decimals(value):
    return f"{value:.6f}"


def four_hex_digits(value):
    return f"{value:04x}"


def nines(count):
    return "9" * count


# Strategies are built once: hypothesis describes each new one by its source, which costs far more than drawing.
NUMBERS = st.one_of(
    st.integers(-5000, 5000).map(str),
    st.integers().map(str),
    st.integers(0, 0xFFFF).map(hex),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-5000, 5000).map(two_decimals),
    st.sampled_from(HOSTILE_NUMBERS),
    st.text(max_size=12),
)


def numbers():
    """Number-like text: plausible values, huge and non-finite ones, and junk."""
    return NUMBERS


KEYS = ["base", "irq", "id", "revision", "version", "channel", "gain", "offset_lsb", "gain_error_pct",
        "max_error_lsb", "noise_lsb", "noise_pooled_lsb", "noise_dof", "samples", "overrange", "points",
        "bits", "wrote", "read", "delivered", "requested", "latency_min_ns", "latency_max_ns", "failures"]


KEYWORDS = st.sampled_from(["BEGIN", "FIRMWARE", "PROBE", "DIO", "ADC", "IRQ", "END"]) | st.text(max_size=8)


@st.composite
def points(draw):
    pairs = draw(st.lists(st.tuples(numbers(), numbers()), max_size=80))
    return ",".join(f"{out}:{value}" for out, value in pairs) + draw(st.sampled_from(["", ",", ",,x", ":"]))


@st.composite
def bringup_lines(draw):
    """One BRINGUP line: a known result with fuzzed fields, or anything."""
    keyword = draw(KEYWORDS)
    words = []
    if keyword == "PROBE":
        words.append(draw(st.sampled_from(["ok", "absent", "maybe"])))
    if keyword == "DIO":
        words += [draw(st.sampled_from(["walking-ones", "walking-zeros", "walking"])),
                  draw(st.sampled_from(["ok", "fail", "?"]))]
    for key in draw(st.lists(st.sampled_from(KEYS), max_size=14)):
        value = draw(points()) if key == "points" else draw(numbers())
        words.append(f"{key}={value}")
    if draw(st.booleans()):
        words.append(draw(st.text(max_size=30)))
    return f"BRINGUP {keyword} " + " ".join(words)


def healthy_transcript():
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from test_host_tools_bringup import transcript
    return transcript()


HEALTHY = healthy_transcript()


@st.composite
def transcripts(draw):
    """A healthy transcript with lines replaced, added or dropped, or fuzzed lines alone, or any text."""
    kind = draw(st.sampled_from(["mutated", "fuzzed", "text"]))
    if kind == "text":
        return draw(st.text(max_size=2000))
    if kind == "fuzzed":
        return "\r\n".join(draw(st.lists(bringup_lines(), max_size=40)))
    lines = HEALTHY.split("\r\n")
    for _ in range(draw(st.integers(1, 6))):
        index = draw(st.integers(0, len(lines) - 1))
        action = draw(st.sampled_from(["replace", "insert", "drop"]))
        if action == "drop":
            del lines[index]
        else:
            line = draw(bringup_lines())
            lines[index:index + (action == "replace")] = [line]
    return draw(st.sampled_from(["\r\n", "\n", "\r"])).join(lines)


def limits():
    """Any limits the tool accepts."""
    def bounded(name):
        low, high = br.LIMIT_RANGES[name]
        if isinstance(low, int):
            return st.integers(low, high)
        return st.floats(low, high, allow_nan=False, allow_infinity=False)
    return st.builds(br.Limits, **{name: bounded(name) for name in br.LIMIT_RANGES})


def assert_finite(value, where="document"):
    """Every number in a JSON-like value is finite."""
    if isinstance(value, float):
        assert math.isfinite(value), where
    elif isinstance(value, dict):
        for key, item in value.items():
            assert_finite(item, f"{where}.{key}")
    elif isinstance(value, (list, tuple)):
        for index, item in enumerate(value):
            assert_finite(item, f"{where}[{index}]")


# -- the bring-up report parser ----------------------------------------------------------


@FUZZ
@given(transcripts(), limits())
@example(HEALTHY.replace("requested=64", "requested=" + "1" * 401), br.Limits())
@example(HEALTHY.replace("base=0x300", "base=0x" + "f" * 4000), br.Limits())
@example(HEALTHY.replace("offset_lsb=0.25", "offset_lsb=nan"), br.Limits())
@example(HEALTHY.replace(":48.0", ":1e999"), br.Limits())
@example("BRINGUP ADC channel=0 gain=1 offset_lsb=0 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=,",
         br.Limits(min_points=1))
def test_the_bringup_report_parser_never_raises_and_writes_only_finite_numbers(text, chosen):
    report = br.parse_transcript(text)
    judgement = br.judge(report, chosen, expected_base=0x300, expected_irq=5)
    assert judgement.verdict in br.VERDICT_EXIT
    for result in report.adc:
        assert 0 <= result.channel < br.CHANNELS and result.gain in br.GAINS
        assert 0 < len(result.points) + 1 <= br.MAX_POINTS + 1
        for code, mean in result.points:
            assert 0 <= code <= br.ADC_FULL_SCALE and 0.0 <= mean <= br.ADC_FULL_SCALE
    assert isinstance(br.format_report(report, judgement, chosen), str)
    document = br.result_document(report, judgement, chosen, {"connection": {"kind": "transcript"}},
                                  timestamp="2025-01-31T14:05:09Z")
    # encode_json refuses NaN and the infinities, and Python's int-to-text limit for huge integers.
    encoded = br.encode_json(document)
    assert_finite(json.loads(encoded))
    # Every garbled line is a failure that says why; a report that parsed whole has none of those.
    assert len([f for f in judgement.failures if f.message.startswith("unreadable report line")]) == \
        min(len(report.garbled), br.MAX_GARBLED_LISTED)


@FUZZ
@given(st.lists(bringup_lines(), min_size=1, max_size=3))
def test_a_bringup_line_either_parses_into_ranges_or_is_garbled_with_a_reason(lines):
    report = br.parse_transcript("\n".join(lines))
    for line, reason in report.garbled:
        assert reason and len(line) <= br.MAX_LINE_LENGTH
    if report.base is not None:
        assert 0 <= report.base <= 0xFFFF
    if report.irq is not None:
        assert 0 <= report.irq.delivered <= report.irq.requested <= br.MAX_COUNT


# -- the plant simulator's line parser ------------------------------------------------------


VOLTS_TEXT = st.one_of(st.floats(-10, 10).map(six_decimals),
                       st.floats(allow_nan=True, allow_infinity=True).map(repr),
                       st.sampled_from(["1e308", "-1e308", "nan", "inf", "10.000001", "1" * 401, "0x10"]),
                       st.text(max_size=8))
TIME_TEXT = st.one_of(st.integers(0, 2**64).map(str), st.integers().map(str),
                      st.sampled_from(["9" * 400, "-5", "1e3", "0" * 30 + "7", "18446744073709551616"]))
DO_TEXT = st.one_of(st.integers(0, 0xFFFF).map(four_hex_digits), st.text(max_size=6))


@st.composite
def sample_lines(draw):
    kind = draw(st.sampled_from(["sample", "sample", "text"]))
    if kind == "text":
        return draw(st.text(max_size=200))
    volts = [draw(VOLTS_TEXT) for _ in range(draw(st.integers(6, 9)))]
    return " ".join(["SAMPLE", draw(TIME_TEXT)] + volts + [draw(DO_TEXT)])


def finite_sample(volts):
    return all(math.isfinite(value) and abs(value) <= plant.DAC_LIMIT_V for value in volts)


@FUZZ
@given(sample_lines())
@example("SAMPLE 1000 1e308 0 0 0 0 0 0 0 0000")
@example("SAMPLE " + "9" * 400 + " 1 0 0 0 0 0 0 0 0000")
@example("SAMPLE 100 " + "0 " * 8 + "0000" + " " * 5000)
def test_the_sample_parser_returns_values_in_range_or_a_protocol_error(line):
    try:
        time_ns, volts, do_word = plant.parse_sample(line)
    except plant.ProtocolError as error:
        assert str(error)
        return
    assert 0 <= time_ns <= plant.MAX_TIME_NS
    assert len(volts) == plant.CHANNELS and finite_sample(volts)
    assert 0 <= do_word <= 0xFFFF


def _plant_options():
    """Any options the simulator accepts, as command-line words."""
    def number(low, high):
        return st.floats(low, high, allow_nan=False, allow_infinity=False).map(repr)
    return st.fixed_dictionaries({
        "--gain": number(-plant.MAX_GAIN, plant.MAX_GAIN),
        "--tau": st.one_of(st.just("0"), number(0, plant.MAX_SECONDS)),
        "--dead-time": st.one_of(st.just("0"), number(0, 1e-3), number(0, plant.MAX_SECONDS)),
        "--offset": number(-plant.MAX_VOLTS, plant.MAX_VOLTS),
        "--initial": number(-plant.MAX_VOLTS, plant.MAX_VOLTS),
        "--disturbance": number(-plant.MAX_VOLTS, plant.MAX_VOLTS),
        "--disturbance-at": number(0, 10),
        "--noise": number(0, plant.MAX_VOLTS),
        "--other-inputs": st.sampled_from(["zero", "loopback"]),
    })


PLANT_OPTIONS = _plant_options()


@FUZZ
@given(PLANT_OPTIONS, st.lists(sample_lines(), min_size=1, max_size=25))
@example({"--gain": "2", "--tau": "1"}, ["SAMPLE 0 1 0 0 0 0 0 0 0 0000", "SAMPLE 1000 1e308 0 0 0 0 0 0 0 0000",
                                         "SAMPLE 2000 1 0 0 0 0 0 0 0 0000"])
@example({"--gain": "1", "--tau": "1"}, ["SAMPLE 0 1 0 0 0 0 0 0 0 0000",
                                         "SAMPLE " + "9" * 400 + " 1 0 0 0 0 0 0 0 0000",
                                         "SAMPLE 2000 1 0 0 0 0 0 0 0 0000"])
@example({"--gain": "1e6", "--tau": "1e-300"}, ["SAMPLE 0 10 0 0 0 0 0 0 0 0000",
                                                 "SAMPLE 9223372036854775807 -10 0 0 0 0 0 0 0 0000"])
def test_the_plant_simulator_answers_every_line_with_finite_inputs_and_keeps_its_state_finite(options, lines):
    # option=value: argparse would take a value such as -1e+300 for an option of its own.
    arguments = [f"{option}={value}" for option, value in options.items()]
    with open(os.devnull, "w") as log:
        simulator = plant.PlantSimulator(plant.build_parser().parse_args(arguments), log=log)
        for number, line in enumerate(lines, 1):
            reply = simulator.handle_line(line + "\n", number)
            fields = reply.split()
            assert fields[0] == "INPUT" and len(fields) == 10, reply
            assert all(math.isfinite(float(value)) for value in fields[1:9]), reply
            assert len(fields[9]) == 4 and 0 <= int(fields[9], 16) <= 0xFFFF
            assert math.isfinite(simulator.process.y) and math.isfinite(simulator.process.delayed_input)
        assert simulator.samples + simulator.errors == len(lines)


# -- the configuration-error explainer --------------------------------------------------------


DIGITS = st.one_of(st.integers(0, 10**6).map(str), st.integers(4300, 6000).map(nines),
                   st.text(alphabet="0123456789", min_size=1, max_size=30))
KINDS = st.sampled_from(["Task", "Heap", "X"]) | st.text(max_size=5)
RULES = st.sampled_from(["NameMissing", "PriorityOutOfRange"]) | st.text(max_size=8)


@st.composite
def compiler_messages(draw):
    rejected = (f"ConfigurationRejected<dcos::app::ObjectKind::{draw(KINDS)}, "
                f"dcos::internal::ObjectName{{\"{draw(st.text(max_size=40))}\"}}, "
                f"dcos::app::ConfigurationRule::{draw(RULES)}, {draw(DIGITS)}, {draw(DIGITS)}>")
    parts = [draw(st.text(max_size=200)), rejected, draw(st.text(max_size=100))]
    if draw(st.booleans()):
        parts.append("static assertion failed: " + draw(st.text(max_size=100)))
    return "\n".join(parts) if draw(st.booleans()) else draw(st.text(max_size=500))


@FUZZ
@given(compiler_messages())
@example("ConfigurationRejected<dcos::app::ObjectKind::Task, dcos::internal::ObjectName{\"\"}, "
         "dcos::app::ConfigurationRule::NameMissing, " + "9" * 5000 + ", 0>")
def test_the_explainer_returns_one_line_or_nothing(messages):
    summary = explainer.explain(messages)
    assert summary is None or (summary.startswith("configuration error: ") and "\n" not in summary)


@FUZZ
@given(st.binary(max_size=3000))
def test_the_explainer_reads_any_file(data):
    with tempfile.NamedTemporaryFile("wb", suffix=".messages") as handle:
        handle.write(data)
        handle.flush()
        with open(os.devnull, "w") as sink:
            saved, sys.stderr = sys.stderr, sink
            try:
                assert explainer.main([handle.name]) == explainer.EXIT_OK
            finally:
                sys.stderr = saved


def test_the_explainer_says_why_it_cannot_read_a_file(tmp_path):
    script = os.path.join(REPOSITORY, "host_tools", "app_build", "explain_configuration_error.py")
    result = subprocess.run([sys.executable, script, str(tmp_path / "missing.messages")], capture_output=True,
                            text=True, timeout=60)
    assert result.returncode == explainer.EXIT_USAGE
    assert "Traceback" not in result.stderr
    assert f"cannot read the compiler's messages from {tmp_path / 'missing.messages'}: No such file or directory" \
        in result.stderr
    result = subprocess.run([sys.executable, script, "--help"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and "exit status: 0" in result.stdout and "2 bad usage" in result.stdout
