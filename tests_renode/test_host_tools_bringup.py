"""Tests of the host bring-up tool (host_tools/bringup) on canned transcripts.

No emulator and no driver are needed: the transcripts follow
docs/iobus/bringup-protocol.md, and a fake controller console on a Unix
socket (and behind --exec) stands in for the controller where the console
plumbing is tested.
"""

import datetime
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

import pytest

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BRINGUP_DIRECTORY = os.path.join(REPOSITORY, "host_tools", "bringup")
TOOL = os.path.join(BRINGUP_DIRECTORY, "mfio_bringup.py")
sys.path.insert(0, BRINGUP_DIRECTORY)

import bringup_report as br  # noqa: E402

TIMEOUT = 60
GAINS = (1, 10, 100, 1000)


def transcript(stuck_bit=None, stuck_level=0, dead_channel=None, delivered=64, absent=False, end=True,
               max_error=None, noise=0.0, latency_max=5000, pooled=True, dof=63, samples=8):
    """A console transcript as the controller prints it, with the chosen faults.

    noise is both the largest per-point deviation and the pooled one; with
    pooled=False the ADC lines are those of firmware before the pooled noise.
    """
    out = ["DCOS 0.1.0 - Distributed Controller Operating System", "dcos> iobus bringup",
           "BRINGUP BEGIN base=0x300 irq=5"]
    if absent:
        return "\r\n".join(out + ["BRINGUP PROBE absent", "BRINGUP END failures=1", "dcos> "])
    failures = 0
    out.append("BRINGUP PROBE ok id=4d46 revision=0100")
    out.append("BRINGUP FIRMWARE version=0.1.0 revision=c7f45ba-dirty")
    noise_fields = f"noise_lsb={noise:.2f}" + (f" noise_pooled_lsb={noise:.2f} noise_dof={dof} samples={samples}"
                                               if pooled else "")
    for pattern in ("walking-ones", "walking-zeros"):
        # As the controller walks: the first pattern in which the stuck bit differs is reported.
        failed = None
        for bit in range(16):
            wrote = (1 << bit) if pattern == "walking-ones" else 0xFFFF & ~(1 << bit)
            read = wrote
            if stuck_bit is not None:
                read = (wrote & ~(1 << stuck_bit)) | (stuck_level << stuck_bit)
            if read != wrote:
                failed = (wrote, read)
                break
        if failed:
            failures += 1
            out.append(f"BRINGUP DIO {pattern} fail bits=0x{1 << stuck_bit:04x} wrote=0x{failed[0]:04x} "
                       f"read=0x{failed[1]:04x}")
        else:
            out.append(f"BRINGUP DIO {pattern} ok")
    for channel in range(8):
        for gain in GAINS:
            span = 2000 // gain
            codes = [2048 - span + i * span // 4 for i in range(9)]
            if channel == dead_channel:
                failures += 1
                points = ",".join(f"{code}:2048.0" for code in codes)
                dead_noise = "noise_lsb=0.00" + (f" noise_pooled_lsb=0.00 noise_dof={dof} samples={samples}"
                                                 if pooled else "")
                out.append(f"BRINGUP ADC channel={channel} gain={gain} offset_lsb=0.00 gain_error_pct=-100.00 "
                           f"max_error_lsb={gain * span:.2f} {dead_noise} overrange=0 points={points}")
                continue
            error = 0.5
            if max_error and (channel, gain) in max_error:
                error = max_error[(channel, gain)]
            points = ",".join(f"{code}:{2048 + gain * (code - 2048):.1f}" for code in codes)
            out.append(f"BRINGUP ADC channel={channel} gain={gain} offset_lsb=0.25 gain_error_pct=-0.02 "
                       f"max_error_lsb={error:.2f} {noise_fields} overrange=0 points={points}")
    if delivered < 64:
        failures += 1
    out.append(f"BRINGUP IRQ delivered={delivered} requested=64 latency_min_ns=1200 latency_max_ns={latency_max}")
    if end:
        out += [f"BRINGUP END failures={failures}", "dcos> "]
    return "\r\n".join(out) + "\r\n"


def judged(text, **limits):
    report = br.parse_transcript(text)
    return report, br.judge(report, br.Limits(**limits))


def messages(judgement):
    return [failure.message for failure in judgement.failures]


# -- parsing and judging ----------------------------------------------------


def test_a_healthy_board_passes_with_every_result_parsed():
    report, judgement = judged(transcript())
    assert judgement.verdict == "pass" and judgement.exit_code == br.EXIT_PASS
    assert messages(judgement) == []
    assert (report.base, report.irq_line, report.board_id, report.revision) == (0x300, 5, 0x4D46, 0x0100)
    assert (report.firmware_version, report.firmware_revision) == ("0.1.0", "c7f45ba-dirty")
    assert len(report.adc) == 32 and all(judgement.adc_pass.values()) and len(judgement.adc_pass) == 32
    assert report.adc[0].points[0] == (48, 48.0) and len(report.adc[0].points) == 9
    assert (report.adc[0].noise_pooled_lsb, report.adc[0].noise_dof, report.adc[0].samples) == (0.0, 63, 8)
    assert judgement.warnings == []
    assert report.irq == br.IrqResult(64, 64, 1200.0, 5000.0)
    assert report.controller_failures == 0 and report.ended


def test_a_stuck_di_bit_is_named_exactly():
    _, judgement = judged(transcript(stuck_bit=4))
    assert judgement.verdict == "fail" and judgement.exit_code == br.EXIT_FAILURES
    # Stuck low, the bit fails its own pattern in walking ones and every other pattern in walking zeros.
    assert messages(judgement) == ["DI bit 4 stuck: walking ones wrote 0x0010 read 0x0000; "
                                   "walking zeros wrote 0xfffe read 0xffee"]
    assert judgement.failures[0].bit == 4 and judgement.failures[0].value == 0


def test_a_di_bit_stuck_high_is_named_in_walking_zeros():
    _, judgement = judged(transcript(stuck_bit=11, stuck_level=1))
    assert messages(judgement) == ["DI bit 11 stuck: walking ones wrote 0x0001 read 0x0801; "
                                   "walking zeros wrote 0xf7ff read 0xffff"]
    assert judgement.failures[0].value == 1


def test_several_bits_in_one_line_are_each_named():
    text = transcript().replace("BRINGUP DIO walking-ones ok",
                                "BRINGUP DIO walking-ones fail bits=0x8001 wrote=0x0001 read=0x0000")
    _, judgement = judged(text)
    assert messages(judgement) == ["DI bit 0 stuck: walking ones wrote 0x0001 read 0x0000",
                                   "DI bit 15 stuck: walking ones wrote 0x0001 read 0x0000"]


def test_a_dead_adc_channel_is_named_and_only_that_channel():
    _, judgement = judged(transcript(dead_channel=3))
    assert judgement.verdict == "fail"
    assert messages(judgement)[0] == "ADC channel 3 dead: reads 2048.0 at every DAC code at every gain"
    assert "ADC channel 3 gain 100: max error 2000.0 LSB > limit 2.0" in messages(judgement)
    assert {failure.channel for failure in judgement.failures} == {3}
    assert [key for key, ok in judgement.adc_pass.items() if not ok] == [(3, gain) for gain in GAINS]


def test_a_channel_over_its_error_limit_is_named_with_channel_gain_value_and_limit():
    _, judgement = judged(transcript(max_error={(3, 100): 12.5}))
    assert messages(judgement) == ["ADC channel 3 gain 100: max error 12.5 LSB > limit 2.0"]
    failure = judgement.failures[0]
    assert (failure.channel, failure.gain, failure.metric, failure.value, failure.limit) == \
        (3, 100, "max_error_lsb", 12.5, 2.0)


def test_a_missing_interrupt_is_named():
    _, judgement = judged(transcript(delivered=0))
    assert messages(judgement) == ["interrupt: 0 of 64 delivered (minimum 64)"]
    assert judgement.exit_code == br.EXIT_FAILURES


def test_an_absent_board_gives_its_own_verdict():
    report, judgement = judged(transcript(absent=True))
    assert judgement.verdict == "board-absent" and judgement.exit_code == br.EXIT_BOARD_ABSENT
    assert messages(judgement) == ["board absent: no I/O board answers at 0x300"]
    assert report.probe == "absent"


def test_a_truncated_report_is_incomplete():
    text = transcript()
    cut = text[:text.index("BRINGUP ADC channel=5 gain=10")]
    report, judgement = judged(cut)
    assert judgement.verdict == "incomplete" and judgement.exit_code == br.EXIT_NO_CONNECTION
    assert "report incomplete: no BRINGUP END line (time-out or lost connection)" in messages(judgement)
    assert "ADC channel 5 gain 10: not reported" in messages(judgement)
    assert "interrupt: not reported" in messages(judgement)


def test_no_report_at_all_is_incomplete():
    _, judgement = judged("dcos> iobus bringup\r\nunknown command: iobus\r\ndcos> ")
    assert judgement.verdict == "incomplete"
    assert messages(judgement) == ["no BRINGUP output from the controller"]


@pytest.mark.parametrize("bad, reason", [
    ("BRINGUP ADC channel=2 gain=10 offset_lsb=0.2", "missing gain_error_pct"),
    ("BRINGUP ADC channel=2 gain=10 offset_lsb=zz gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:1",
     "offset_lsb 'zz' is not a decimal number"),
    ("BRINGUP ADC channel=9 gain=10 offset_lsb=0 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:1",
     "channel 9 is not from 0 to 7"),
    ("BRINGUP ADC channel=2 gain=10 offset_lsb=0 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 noise_dof=7 "
     "points=1:1", "noise_pooled_lsb, noise_dof and samples go together; missing noise_pooled_lsb, samples"),
    ("BRINGUP ADC channel=2 gain=10 offset_lsb=0 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:5000.0",
     "mean ADC code 5000.0 is not from 0.0 to 4095.0"),
    ("BRINGUP ADC channel=2 gain=10 offset_lsb=nan gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:1",
     "offset_lsb 'nan' is not a decimal number"),
    ("BRINGUP ADC channel=2 gain=10 offset_lsb=1e400 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:1",
     "offset_lsb '1e400' is not a decimal number"),
    ("BRINGUP DIO walking-ones fail bits=0x10000 wrote=0x0001 read=0x0000", "bits 65536 is not from 0 to 65535"),
    ("BRINGUP IRQ delivered=65 requested=64", "delivered 65 exceeds requested 64"),
    ("BRINGUP FIRMWARE version=0.1.0", "missing revision"),
    ("BRINGUP FIRMWARE version=0.1.0 revision=a;b", "is not letters, digits and ._+-"),
    ("BRINGUP ADC channel=2 gain=7 offset_lsb=0 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:1",
     "gain 7 is not one of"),
    ("BRINGUP DIO walking-sideways ok", "DIO needs"),
    ("BRINGUP IRQ delivered=64", "missing requested"),
    ("BRINGUP FROB x=1", "unknown result 'FROB'"),
    ("BRINGUP ADC channel=2 gain=10 garbage", "is not key=value"),
])
def test_a_garbled_line_is_a_named_failure(bad, reason):
    text = transcript().replace("BRINGUP IRQ", bad + "\r\nBRINGUP IRQ")
    _, judgement = judged(text)
    assert judgement.verdict == "fail"
    assert len(judgement.failures) == 1
    assert judgement.failures[0].kind == "report"
    assert reason in judgement.failures[0].message and bad in judgement.failures[0].message


def test_a_garbled_line_replacing_a_result_names_the_missing_result():
    text = transcript().replace("BRINGUP ADC channel=6 gain=1000 ", "BRINGUP ADC chan\x00nel=6 gain=1000 ")
    _, judgement = judged(text)
    assert "ADC channel 6 gain 1000: not reported" in messages(judgement)
    assert any(m.startswith("unreadable report line") for m in messages(judgement))


def test_a_sweep_with_no_points_fails_whatever_the_minimum():
    text = transcript()
    line = next(l for l in text.split("\r\n") if l.startswith("BRINGUP ADC channel=4 gain=10 "))
    empty = line[:line.index("points=")] + "points=,"
    for minimum in (1, 3):
        _, judgement = judged(text.replace(line, empty), min_points=minimum)
        assert judgement.verdict == "fail"
        assert messages(judgement) == ["ADC channel 4 gain 10: sweep empty: no points measured"]


def test_a_sweep_with_too_few_points_is_named():
    text = transcript()
    line = next(l for l in text.split("\r\n") if l.startswith("BRINGUP ADC channel=4 gain=10 "))
    cut = line[:line.index("points=")] + "points=1848:1848.0"
    _, judgement = judged(text.replace(line, cut))
    assert messages(judgement) == ["ADC channel 4 gain 10: sweep incomplete: 1 of at least 3 points measured"]
    assert judged(text.replace(line, cut), min_points=1)[1].verdict == "pass"


def test_an_end_without_a_probe_says_the_driver_could_not_be_installed():
    text = "dcos> iobus bringup 0x2f8 3\r\nBRINGUP BEGIN base=0x2f8 irq=3\r\nerror: ports taken\r\n" \
           "BRINGUP END failures=1\r\ndcos> "
    _, judgement = judged(text)
    assert judgement.verdict == "fail"
    assert messages(judgement) == ["probe: not run: the controller could not install the board driver at 0x2f8 "
                                   "IRQ 3 (see its console for the reason)"]


def test_a_controller_failure_count_the_limits_do_not_confirm_is_a_warning():
    _, judgement = judged(transcript().replace("BRINGUP END failures=0", "BRINGUP END failures=2"))
    assert judgement.verdict == "pass"
    assert judgement.warnings == ["controller counted 2 failed steps that pass the limits here"]


def test_limits_can_be_tightened_and_relaxed():
    # Pooled noise 0.8 LSB over 63 degrees of freedom passes the default 1.0 limit; against a tightened 0.5 one
    # its 99.9 % lower bound (0.8 x sqrt(63 / 103.44) = 0.62) is above, on every channel and gain.
    _, default = judged(transcript(noise=0.8))
    assert default.verdict == "pass"
    _, tight = judged(transcript(noise=0.8), max_noise_lsb=0.5)
    assert len(tight.failures) == 32
    assert "ADC channel 0 gain 1: noise 0.80 LSB over 63 degrees of freedom, at least 0.62 with 99.9 % confidence " \
           "> limit 0.5" in messages(tight)
    # A lower confidence asks for less evidence: 0.56 LSB is not shown above 0.5 at 99.9 % but is at 60 %.
    assert judged(transcript(noise=0.56), max_noise_lsb=0.5)[1].verdict == "pass"
    assert judged(transcript(noise=0.56), max_noise_lsb=0.5, noise_confidence=0.6)[1].verdict == "fail"
    # The injected 12.5 LSB error passes a relaxed limit.
    _, relaxed = judged(transcript(max_error={(3, 100): 12.5}), max_error_lsb=20.0)
    assert relaxed.verdict == "pass"
    # 60 of 64 interrupts pass a 90 % minimum but not the default 100 %.
    assert judged(transcript(delivered=60), min_irq_delivered_pct=90)[1].verdict == "pass"
    assert messages(judged(transcript(delivered=60))[1]) == ["interrupt: 60 of 64 delivered (minimum 64)"]
    # Latency against its limit.
    _, slow = judged(transcript(latency_max=2_000_000))
    assert messages(slow) == ["interrupt: max latency 2000000 ns > limit 1000000"]
    # Offset and gain error.
    _, strict = judged(transcript(), max_offset_lsb=0.1, max_gain_error_pct=0.01)
    assert "ADC channel 7 gain 1000: offset 0.25 LSB > limit 0.1" in messages(strict)
    assert "ADC channel 7 gain 1000: gain error -0.02 % > limit 0.01" in messages(strict)


def test_the_ideal_transfer_saturates_at_full_scale():
    assert br.ideal_adc_code(2048, 1000) == 2048
    assert br.ideal_adc_code(2050, 1000) == 4048
    assert br.ideal_adc_code(2051, 1000) == 4095
    assert br.ideal_adc_code(0, 1) == 0 and br.ideal_adc_code(4095, 1) == 4095
    assert br.ideal_adc_code(2000, 10) == 1568


# -- the command-line tool on transcripts ------------------------------------


def png_size(path):
    """Decodes the PNG signature and IHDR chunk; returns (width, height)."""
    with open(path, "rb") as handle:
        data = handle.read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    length, kind = struct.unpack(">I4s", data[8:16])
    assert kind == b"IHDR" and length == 13
    width, height = struct.unpack(">II", data[16:24])
    (crc,) = struct.unpack(">I", data[29:33])
    assert crc == zlib.crc32(data[12:29])
    assert data.endswith(b"IEND\xaeB`\x82")
    return width, height


def run_tool(*args, stdin=None, cwd=None):
    return subprocess.run([sys.executable, TOOL] + list(args), input=stdin, capture_output=True, text=True,
                          timeout=TIMEOUT, cwd=cwd)


@pytest.fixture
def workdir():
    with tempfile.TemporaryDirectory(prefix="bringup-test-") as directory:
        yield directory


def run_on_transcript(workdir, text, *args):
    path = os.path.join(workdir, "console.txt")
    with open(path, "w", encoding="latin-1") as handle:
        handle.write(text)
    result = run_tool("--transcript", path, "--json", os.path.join(workdir, "result.json"),
                      "--png", os.path.join(workdir, "curves.png"), *args)
    document = None
    if os.path.exists(os.path.join(workdir, "result.json")):
        with open(os.path.join(workdir, "result.json"), encoding="utf-8") as handle:
            document = json.load(handle)
    return result, document


def test_tool_healthy_exit_0_json_and_png(workdir):
    result, document = run_on_transcript(workdir, transcript())
    assert result.returncode == 0, result.stdout + result.stderr
    assert "PASS: every check within its limits" in result.stdout
    assert document["format"] == "dcos-iobus-bringup-result" and document["version"] == 2
    assert document["verdict"] == "pass" and document["exit_code"] == 0
    assert document["board"] == {"base": 0x300, "irq": 5, "probe": "ok", "id": 0x4D46, "revision": 0x100}
    assert document["firmware"] == {"version": "0.1.0", "revision": "c7f45ba-dirty"}
    measured = datetime.datetime.strptime(document["timestamp"], "%Y-%m-%dT%H:%M:%SZ").replace(
        tzinfo=datetime.timezone.utc)
    assert abs((datetime.datetime.now(datetime.timezone.utc) - measured).total_seconds()) < 120
    assert document["limits"]["max_error_lsb"] == 2.0
    assert len(document["adc"]) == 32 and all(entry["passed"] for entry in document["adc"])
    first = document["adc"][0]
    assert (first["channel"], first["gain"], first["points"][0], first["ideal"][0]) == (0, 1, [48, 48.0], 48)
    assert (first["noise_pooled_lsb"], first["noise_dof"], first["samples"], first["noise_lower_bound_lsb"]) == \
        (0.0, 63, 8, 0.0)
    assert document["irq"]["delivered"] == 64 and document["failures"] == []
    assert len(document["report_lines"]) == 3 + 2 + 32 + 2
    # Written through a temporary file and a rename: nothing else is left in the directory.
    assert sorted(os.listdir(workdir)) == ["console.txt", "curves.png", "result.json"]
    width, height = png_size(os.path.join(workdir, "curves.png"))
    assert width > 400 and height > 400
    assert os.path.getsize(os.path.join(workdir, "curves.png")) > 10_000


@pytest.mark.parametrize("faults, code, expected", [
    (dict(stuck_bit=4), 1, "FAIL: DI bit 4 stuck: walking ones wrote 0x0010 read 0x0000; "
                           "walking zeros wrote 0xfffe read 0xffee"),
    (dict(dead_channel=3), 1, "FAIL: ADC channel 3 dead: reads 2048.0 at every DAC code at every gain"),
    (dict(delivered=0), 1, "FAIL: interrupt: 0 of 64 delivered (minimum 64)"),
    (dict(absent=True), 3, "FAIL: board absent: no I/O board answers at 0x300"),
    (dict(end=False), 4, "INCOMPLETE: the bring-up did not finish"),
])
def test_tool_names_the_fault_and_exits_with_its_status(workdir, faults, code, expected):
    result, document = run_on_transcript(workdir, transcript(**faults))
    assert result.returncode == code, result.stdout + result.stderr
    assert expected in result.stdout.splitlines()
    assert document["exit_code"] == code
    assert document["verdict"] == {1: "fail", 3: "board-absent", 4: "incomplete"}[code]
    assert document["failures"]


def test_tool_json_names_the_failing_channel_and_gain(workdir):
    result, document = run_on_transcript(workdir, transcript(max_error={(3, 100): 12.5}))
    assert result.returncode == 1
    assert "FAIL: ADC channel 3 gain 100: max error 12.5 LSB > limit 2.0" in result.stdout
    assert document["failures"] == [{"kind": "adc", "message": "ADC channel 3 gain 100: max error 12.5 LSB > limit 2.0",
                                     "channel": 3, "gain": 100, "metric": "max_error_lsb", "value": 12.5,
                                     "limit": 2.0}]
    failing = [(entry["channel"], entry["gain"]) for entry in document["adc"] if not entry["passed"]]
    assert failing == [(3, 100)]
    png_size(os.path.join(workdir, "curves.png"))


def test_tool_limit_options_override_the_defaults(workdir):
    result, document = run_on_transcript(workdir, transcript(max_error={(3, 100): 12.5}), "--max-error-lsb", "15",
                                         "--max-noise-lsb", "0.2", "--min-irq-delivered-pct", "50",
                                         "--max-irq-latency-ns", "3000", "--max-offset-lsb", "1",
                                         "--max-gain-error-pct", "0.5", "--noise-confidence", "0.99")
    assert result.returncode == 1
    assert document["limits"] == {"max_offset_lsb": 1.0, "max_gain_error_pct": 0.5, "max_error_lsb": 15.0,
                                  "max_noise_lsb": 0.2, "noise_confidence": 0.99, "min_irq_delivered_pct": 50.0,
                                  "max_irq_latency_ns": 3000.0, "min_points": 3}
    assert [f["message"] for f in document["failures"]] == ["interrupt: max latency 5000 ns > limit 3000"]


def test_tool_reads_a_transcript_from_stdin_and_can_skip_outputs(workdir):
    result = run_tool("--transcript", "-", "--json", "", "--png", "", stdin=transcript(stuck_bit=2), cwd=workdir)
    assert result.returncode == 1
    assert "FAIL: DI bit 2 stuck: walking ones wrote 0x0004 read 0x0000; walking zeros wrote 0xfffe read 0xfffa" \
        in result.stdout
    assert os.listdir(workdir) == []


def test_tool_help_lists_every_option_limit_and_exit_status():
    result = run_tool("--help")
    assert result.returncode == 0
    for option in ("--serial", "--socket", "--exec", "--emulator", "--transcript", "--baud", "--base", "--irq",
                    "--timeout", "--connect-timeout", "--json", "--png", "--model-property", "--icount"):
        assert option in result.stdout
    for name in br.LIMIT_DESCRIPTIONS:
        assert "--" + name.replace("_", "-") in result.stdout
    for line in ("0    every check passed", "1    failures found", "2    bad options", "3    board absent",
                 "4    no connection", "5    a result file", "130  interrupted"):
        assert line in result.stdout
    # The README documents the same statuses.
    with open(os.path.join(BRINGUP_DIRECTORY, "README.md"), encoding="utf-8") as handle:
        readme = handle.read()
    for status in ("| 0 |", "| 1 |", "| 2 |", "| 3 |", "| 4 |", "| 5 |", "| 130 |"):
        assert status in readme


def test_tool_bad_options_exit_2():
    assert run_tool().returncode == 2
    assert run_tool("--transcript", "x", "--socket", "y").returncode == 2
    assert run_tool("--transcript", "x", "--model-property", "no-irq=on").returncode == 2


# -- the console plumbing against a fake controller --------------------------


class FakeController:
    """A console on a Unix socket: echoes what is typed, answers 'iobus bringup' with a transcript."""

    def __init__(self, path, report, stall_after=None):
        self.path = path
        self.report = report
        self.stall_after = stall_after
        self.commands = []
        self.stop = threading.Event()
        self.server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.server.bind(path)
        self.server.listen(1)
        self.server.settimeout(TIMEOUT)
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        try:
            connection, _ = self.server.accept()
        except OSError:
            return
        connection.settimeout(TIMEOUT)
        with connection:
            connection.sendall(b"DCOS 0.1.0\r\ndcos> ")
            line = b""
            while True:
                try:
                    data = connection.recv(1)
                except OSError:
                    return
                if not data:
                    return
                if data != b"\r":
                    line += data
                    continue
                command, line = line.decode(), b""
                self.commands.append(command)
                connection.sendall(command.encode() + b"\r\n")
                if command.startswith("iobus bringup"):
                    body = self.report.replace("dcos> iobus bringup\r\n", "")
                    if self.stall_after:
                        connection.sendall(body[:body.index(self.stall_after)].encode())
                        self.stop.wait(TIMEOUT)
                        return
                    for piece in body.split("\r\n"):
                        connection.sendall(piece.encode() + b"\r\n")
                elif command:
                    connection.sendall(b"unknown command: " + command.encode() + b"\r\ndcos> ")
                else:
                    connection.sendall(b"dcos> ")

    def close(self):
        self.stop.set()
        self.server.close()
        self.thread.join(timeout=5)


def test_tool_drives_the_command_over_a_socket(workdir):
    path = os.path.join(workdir, "console.sock")
    controller = FakeController(path, transcript(dead_channel=6))
    try:
        result = run_tool("--socket", path, "--base", "0x300", "--irq", "5", "--timeout", "20",
                          "--json", os.path.join(workdir, "r.json"), "--png", os.path.join(workdir, "r.png"),
                          "--save-transcript", os.path.join(workdir, "console.txt"))
    finally:
        controller.close()
    assert result.returncode == 1, result.stdout + result.stderr
    assert controller.commands == ["", "iobus bringup 0x300 5"]
    assert "FAIL: ADC channel 6 dead: reads 2048.0 at every DAC code at every gain" in result.stdout
    with open(os.path.join(workdir, "r.json"), encoding="utf-8") as handle:
        document = json.load(handle)
    assert document["connection"] == {"kind": "socket", "command": "iobus bringup 0x300 5"}
    png_size(os.path.join(workdir, "r.png"))
    with open(os.path.join(workdir, "console.txt"), encoding="latin-1") as handle:
        assert "BRINGUP END failures=4" in handle.read()


def test_tool_reports_a_time_out_when_the_report_stalls(workdir):
    path = os.path.join(workdir, "console.sock")
    controller = FakeController(path, transcript(), stall_after="BRINGUP ADC channel=2 gain=1 ")
    started = time.monotonic()
    try:
        result = run_tool("--socket", path, "--timeout", "2", "--json", os.path.join(workdir, "r.json"),
                          "--png", "")
    finally:
        controller.close()
    assert result.returncode == 4, result.stdout + result.stderr
    assert time.monotonic() - started < 20
    assert "no BRINGUP END within 2 s (--timeout)" in result.stderr
    assert "ADC channel 2 gain 1: not reported" in result.stdout


FAKE_CONSOLE_PROGRAM = r"""
import os, sys
mode, report_path = sys.argv[1], sys.argv[2]
def write(text):
    os.write(1, text.encode())
write("DCOS 0.1.0\r\ndcos> ")
line = b""
while True:
    data = os.read(0, 1)
    if not data:
        break
    if data != b"\r":
        line += data
        continue
    command, line = line.decode(), b""
    write(command + "\r\n")
    if command.startswith("iobus bringup") and mode == "report":
        write(open(report_path).read().replace("dcos> iobus bringup\r\n", ""))
    elif command:
        write("unknown command: " + command + "\r\ndcos> ")
    else:
        write("dcos> ")
"""


def fake_console_command(workdir, mode, report):
    program = os.path.join(workdir, "fake_console.py")
    with open(program, "w", encoding="utf-8") as handle:
        handle.write(FAKE_CONSOLE_PROGRAM)
    report_path = os.path.join(workdir, "report.txt")
    with open(report_path, "w", encoding="latin-1") as handle:
        handle.write(report)
    return f"{sys.executable} {program} {mode} {report_path}"


def test_tool_drives_a_launched_program_over_stdin_and_stdout(workdir):
    result = run_tool("--exec", fake_console_command(workdir, "report", transcript(stuck_bit=9)), "--timeout", "20",
                      "--json", os.path.join(workdir, "r.json"), "--png", os.path.join(workdir, "r.png"))
    assert result.returncode == 1, result.stdout + result.stderr
    assert "FAIL: DI bit 9 stuck: walking ones wrote 0x0200 read 0x0000; walking zeros wrote 0xfffe read 0xfdfe" \
        in result.stdout
    png_size(os.path.join(workdir, "r.png"))


def test_tool_stops_when_the_controller_has_no_bringup_command(workdir):
    started = time.monotonic()
    result = run_tool("--exec", fake_console_command(workdir, "unknown", ""), "--timeout", "30",
                      "--json", os.path.join(workdir, "r.json"), "--png", "")
    assert result.returncode == 4, result.stdout + result.stderr
    assert time.monotonic() - started < 15
    assert "printed no BRINGUP report for 'iobus bringup'" in result.stderr
    assert "no BRINGUP output from the controller" in result.stdout


def test_tool_exits_4_without_a_connection(workdir):
    result = run_tool("--socket", os.path.join(workdir, "nobody.sock"), "--connect-timeout", "0.5",
                      "--json", os.path.join(workdir, "r.json"), "--png", "")
    assert result.returncode == 4
    assert "cannot connect to console socket" in result.stderr
    with open(os.path.join(workdir, "r.json"), encoding="utf-8") as handle:
        document = json.load(handle)
    assert document["verdict"] == "incomplete" and document["exit_code"] == 4
    assert document["failures"][0]["message"].startswith("cannot connect to console socket")


def test_a_report_from_firmware_before_the_pooled_noise_is_judged_as_before_with_a_warning():
    _, judgement = judged(transcript(noise=0.8, pooled=False), max_noise_lsb=0.5)
    assert "ADC channel 0 gain 1: noise 0.8 LSB > limit 0.5" in messages(judgement)
    assert any("no pooled noise estimate" in warning for warning in judgement.warnings)
    assert judged(transcript(noise=0.8, pooled=False))[1].verdict == "pass"


def test_a_sweep_without_repeated_conversions_has_no_noise_measurement():
    _, judgement = judged(transcript(dof=0, samples=1))
    assert judgement.verdict == "fail"
    assert "ADC channel 5 gain 10: noise not measured: 1 conversion(s) per point give no degrees of freedom" \
        in messages(judgement)


# -- hostile input: the tool answers with a named failure and a documented status, never a traceback ----


def replace_line(text, prefix, new):
    line = next(l for l in text.split("\r\n") if l.startswith(prefix))
    return text.replace(line, new(line))


UNREADABLE = "FAIL: unreadable report line ("
HOSTILE_TRANSCRIPTS = {
    "a 401-digit number": (lambda t: t.replace("requested=64", "requested=" + "1" * 401), UNREADABLE),
    "a 4,000-digit base": (lambda t: t.replace("base=0x300", "base=0x" + "f" * 4000), UNREADABLE),
    "a 4,000-digit decimal base": (lambda t: t.replace("base=0x300", "base=" + "9" * 4000), UNREADABLE),
    "a sweep with no points": (lambda t: replace_line(t, "BRINGUP ADC channel=4 gain=10 ",
                                                      lambda l: l[:l.index("points=")] + "points=,"),
                               "FAIL: ADC channel 4 gain 10: sweep empty: no points measured"),
    "a NaN offset": (lambda t: t.replace("offset_lsb=0.25", "offset_lsb=nan", 1), UNREADABLE),
    "an infinite mean": (lambda t: replace_line(t, "BRINGUP ADC channel=1 gain=1 ",
                                                lambda l: l.replace(":48.0", ":1e999")), UNREADABLE),
    "a 100,000-character line": (lambda t: t.replace("BRINGUP IRQ", "BRINGUP DIO " + "x" * 100_000
                                                     + "\r\nBRINGUP IRQ"), UNREADABLE),
    "a NUL and non-ASCII bytes": (lambda t: t.replace("BRINGUP END", "BRINGUP \x00\xff\u00e9 z=1\r\nBRINGUP END"),
                                  UNREADABLE),
}


@pytest.mark.parametrize("name", sorted(HOSTILE_TRANSCRIPTS))
def test_tool_answers_hostile_reports_with_a_named_failure(workdir, name):
    change, expected = HOSTILE_TRANSCRIPTS[name]
    result, document = run_on_transcript(workdir, change(transcript()))
    assert "Traceback" not in result.stderr, result.stderr
    assert result.returncode == 1, result.stdout + result.stderr
    assert any(line.startswith(expected) for line in result.stdout.splitlines()), result.stdout
    # The whole document was written: it parses, it names the failure, and nothing else is left behind.
    assert document["verdict"] == "fail" and document["exit_code"] == 1
    assert any(f"FAIL: {failure['message']}".startswith(expected) for failure in document["failures"])
    assert sorted(os.listdir(workdir)) == ["console.txt", "curves.png", "result.json"]


def test_tool_checks_output_paths_before_it_runs(workdir):
    missing = os.path.join(workdir, "missing", "x")
    text = transcript()
    for option in ("--json", "--png", "--save-transcript"):
        arguments = {"--json": os.path.join(workdir, "r.json"), "--png": os.path.join(workdir, "r.png"),
                     "--save-transcript": os.path.join(workdir, "t.txt")}
        arguments[option] = missing
        result = run_tool("--transcript", "-", *[word for pair in arguments.items() for word in pair], stdin=text)
        assert result.returncode == 2, result.stdout + result.stderr
        # Nothing ran: no verdict printed, nothing written, and the error names the option and the directory.
        assert result.stdout == ""
        assert f"{option} {missing}: directory {os.path.dirname(missing)} does not exist" in result.stderr
        assert os.listdir(workdir) == []
    result = run_tool("--transcript", "-", "--json", workdir, "--png", "", stdin=text)
    assert result.returncode == 2 and "is a directory" in result.stderr
    same = os.path.join(workdir, "same")
    result = run_tool("--transcript", "-", "--json", same, "--png", same, stdin=text)
    assert result.returncode == 2 and "name the same file" in result.stderr


FLOAT_OPTIONS = ["--max-offset-lsb", "--max-gain-error-pct", "--max-error-lsb", "--max-noise-lsb",
                 "--noise-confidence", "--min-irq-delivered-pct", "--max-irq-latency-ns", "--timeout",
                 "--connect-timeout"]


def refused(capsys, *arguments):
    """Runs the tool's main() in this process on options it must refuse; returns its error output."""
    import mfio_bringup

    with pytest.raises(SystemExit) as stop:
        mfio_bringup.main(["--transcript", "-", "--json", "", "--png", ""] + list(arguments))
    captured = capsys.readouterr()
    assert stop.value.code == 2 and captured.out == "", captured.out
    return captured.err


@pytest.mark.parametrize("option", FLOAT_OPTIONS)
def test_tool_refuses_nan_infinite_and_negative_numbers(capsys, option):
    for value in ("nan", "inf", "-inf", "-1", "1e999", "x", "1" * 5000):
        assert f"argument {option}:" in refused(capsys, f"{option}={value}"), value


@pytest.mark.parametrize("option, value", [("--min-points", "0"), ("--min-points", "-3"), ("--min-points", "2.5"),
                                           ("--noise-confidence", "1"), ("--min-irq-delivered-pct", "101"),
                                           ("--baud", "0"), ("--base", "0x10000"), ("--base", "-2"),
                                           ("--base", "0x301"), ("--base", "9" * 5000), ("--irq", "16"),
                                           ("--prompt", "(")])
def test_tool_refuses_other_values_out_of_range(capsys, option, value):
    assert option in refused(capsys, f"{option}={value}")


def test_tool_does_not_hang_on_a_nan_connect_timeout(workdir):
    started = time.monotonic()
    result = run_tool("--socket", os.path.join(workdir, "nobody.sock"), "--connect-timeout", "nan",
                      "--json", os.path.join(workdir, "r.json"))
    assert result.returncode == 2 and time.monotonic() - started < 20


def test_a_run_without_a_picture_removes_an_older_one(workdir):
    png, json_path = os.path.join(workdir, "curves.png"), os.path.join(workdir, "result.json")
    result, _ = run_on_transcript(workdir, transcript())
    assert result.returncode == 0 and os.path.exists(png)
    # The next run gets no report, so it draws nothing: the older picture must not pass for this run's.
    result, document = run_on_transcript(workdir, "dcos> iobus bringup\r\nunknown command: iobus\r\ndcos> ")
    assert result.returncode == 4
    assert not os.path.exists(png)
    assert f"removed the older {png}" in result.stderr
    assert document["verdict"] == "incomplete"
    assert sorted(os.listdir(workdir)) == ["console.txt", "result.json"]


# -- the picture -----------------------------------------------------------------


TIMESTAMP = "2025-01-31T14:05:09Z"


def sheet(text, **limits):
    report, judgement = judged(text, **limits)
    return report, judgement, br.Limits(**limits)


def panel(figure, label):
    (axis,) = [axis for axis in figure.axes if axis.get_label() == label]
    return axis


def failing_mark(axis):
    """The panel's title says FAIL in red, and its frame is red."""
    title = axis.title
    return "FAIL" in title.get_text() and title.get_color() == br.RED


def test_the_pictures_of_a_passing_a_stuck_di_and_a_no_irq_board_differ():
    pictures = {name: br.render_png(*sheet(text), TIMESTAMP) for name, text in
                (("pass", transcript()), ("stuck", transcript(stuck_bit=4)), ("no-irq", transcript(delivered=0)))}
    assert len(set(pictures.values())) == 3
    # Equal inputs draw equal bytes, so the differences come from what the boards did.
    assert br.render_png(*sheet(transcript()), TIMESTAMP) == pictures["pass"]
    for data in pictures.values():
        assert data.startswith(b"\x89PNG\r\n\x1a\n")


def test_failing_panels_and_sections_are_marked():
    import matplotlib.pyplot as pyplot

    cases = {
        "pass": (transcript(), set()),
        "stuck": (transcript(stuck_bit=4), {"dio", "header"}),
        "no-irq": (transcript(delivered=0), {"irq", "header"}),
        "error": (transcript(max_error={(3, 100): 12.5}), {"adc-3-100", "header"}),
        "dead": (transcript(dead_channel=6), {"adc-6-1", "adc-6-10", "adc-6-100", "adc-6-1000", "header"}),
    }
    for name, (text, failing) in cases.items():
        report, judgement, limits = sheet(text)
        figure = br.bringup_figure(report, judgement, limits, TIMESTAMP)
        try:
            labels = {axis.get_label() for axis in figure.axes}
            assert {"header", "dio", "irq"} | {f"adc-{c}-{g}" for c in range(8) for g in GAINS} <= labels
            marked = {label for label in labels if label != "header" and failing_mark(panel(figure, label))}
            assert marked == failing - {"header"}, name
            header = panel(figure, "header")
            verdict = header.texts[0]
            assert verdict.get_text() == ("PASS: every check within its limits" if not failing
                                          else f"FAILED: {len(judgement.failures)} failure(s)"), name
            assert (verdict.get_color() == br.RED) == bool(failing), name
            if name == "stuck":
                assert "bit 4 stuck" in panel(figure, "dio").title.get_text()
            if name == "error":
                assert "max error" in panel(figure, "adc-3-100").title.get_text()
        finally:
            pyplot.close(figure)


# -- what --exec starts, it ends -------------------------------------------------


FAKE_EMULATOR = r"""
import os, signal, sys, time
mode, report_path, pid_path = sys.argv[1:4]
if mode == "stubborn":
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
with open(pid_path + ".tmp", "w") as handle:
    handle.write(str(os.getpid()))
os.rename(pid_path + ".tmp", pid_path)
def write(text):
    os.write(1, text.encode())
report = open(report_path).read().replace("dcos> iobus bringup\r\n", "")
write("DCOS 0.1.0\r\ndcos> ")
line = b""
while True:
    data = os.read(0, 1)
    if not data:
        break
    if data != b"\r":
        line += data
        continue
    command, line = line.decode(), b""
    write(command + "\r\n")
    if command.startswith("iobus bringup"):
        write(report if mode == "report" else report[:report.index("BRINGUP ADC channel=2")])
    else:
        write("dcos> ")
# Like an emulator, it does not end when its input does.
time.sleep(60)
"""


def alive(pid):
    """True while the process exists and is not a zombie (an orphan's zombie may wait for a busy init)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="latin-1") as handle:
            state = handle.read().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return False
    return state not in ("Z", "X")


def fake_emulator(workdir, mode, report):
    program = os.path.join(workdir, "fake_emulator.py")
    with open(program, "w", encoding="utf-8") as handle:
        handle.write(FAKE_EMULATOR)
    report_path = os.path.join(workdir, "report.txt")
    with open(report_path, "w", encoding="latin-1") as handle:
        handle.write(report)
    pid_path = os.path.join(workdir, "emulator.pid")
    # "; true" keeps the shell alive as the emulator's parent, as any command with a redirection or a pipe does.
    return f"{sys.executable} {program} {mode} {report_path} {pid_path}; true", pid_path


def emulator_pid(pid_path):
    with open(pid_path, encoding="utf-8") as handle:
        return int(handle.read())


def assert_ended(pid):
    deadline = time.monotonic() + 5
    while alive(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not alive(pid), f"the emulator (pid {pid}) is still running after the tool ended"


@pytest.mark.parametrize("mode, report, arguments, code", [
    ("report", transcript(), [], 0),
    ("report", transcript(stuck_bit=9), [], 1),
    ("stall", transcript(), ["--timeout", "2"], 4),
    ("stubborn", transcript(), ["--timeout", "2"], 4),
], ids=["success", "failure", "time-out", "time-out, SIGTERM ignored"])
def test_tool_ends_the_program_it_started(workdir, mode, report, arguments, code):
    command, pid_path = fake_emulator(workdir, mode, report)
    result = run_tool("--exec", command, "--json", os.path.join(workdir, "r.json"), "--png", "", *arguments)
    assert result.returncode == code, result.stdout + result.stderr
    assert_ended(emulator_pid(pid_path))


def test_tool_ends_the_program_it_started_on_ctrl_c(workdir):
    command, pid_path = fake_emulator(workdir, "stall", transcript())
    json_path = os.path.join(workdir, "r.json")
    tool = subprocess.Popen([sys.executable, TOOL, "--exec", command, "--json", json_path, "--png", "",
                             "--timeout", "60"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + TIMEOUT
        while not os.path.exists(pid_path):
            assert tool.poll() is None and time.monotonic() < deadline, "the program was not started"
            time.sleep(0.05)
        time.sleep(1.0)  # The command is sent and the report has begun.
        tool.send_signal(signal.SIGINT)
        stdout, stderr = tool.communicate(timeout=TIMEOUT)
    finally:
        if tool.poll() is None:
            tool.kill()
            tool.wait()
    assert tool.returncode == 130, stdout + stderr
    assert "Traceback" not in stderr and "interrupted" in stderr
    assert "INTERRUPTED: the bring-up was stopped before it finished" in stdout
    with open(json_path, encoding="utf-8") as handle:
        document = json.load(handle)
    assert document["verdict"] == "interrupted" and document["exit_code"] == 130
    assert_ended(emulator_pid(pid_path))


# The second program closes its output a while before it exits, as an
# emulator tearing down does: the console ends before the exit status exists.
@pytest.mark.parametrize("exit_delay_s", [0, 0.5])
def test_tool_shows_the_error_of_a_program_that_does_not_start(workdir, exit_delay_s):
    program = os.path.join(workdir, "broken_emulator.py")
    with open(program, "w", encoding="utf-8") as handle:
        handle.write("import os, sys, time\n"
                     "sys.stderr.write('qemu-system-i386: -kernel nope.elf: could not load kernel\\n')\n"
                     f"os.close(1)\ntime.sleep({exit_delay_s})\nsys.exit(1)\n")
    started = time.monotonic()
    # exec: the program itself holds the console, not a shell waiting for it.
    result = run_tool("--exec", f"exec {sys.executable} {program}", "--json", os.path.join(workdir, "r.json"),
                      "--png", "", "--connect-timeout", "30")
    assert result.returncode == 4, result.stdout + result.stderr
    assert time.monotonic() - started < 20
    assert "the program exited with status 1" in result.stderr
    assert "qemu-system-i386: -kernel nope.elf: could not load kernel" in result.stderr
    with open(os.path.join(workdir, "r.json"), encoding="utf-8") as handle:
        assert "could not load kernel" in json.load(handle)["connection"]["problem"]
