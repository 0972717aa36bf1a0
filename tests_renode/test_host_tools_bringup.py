"""Tests of the host bring-up tool (host_tools/bringup) on canned transcripts.

No emulator and no driver are needed: the transcripts follow
docs/iobus/bringup-protocol.md, and a fake controller console on a Unix
socket (and behind --exec) stands in for the controller where the console
plumbing is tested.
"""

import json
import os
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
               max_error=None, noise=0.0, latency_max=5000):
    """A console transcript as the controller prints it, with the chosen faults."""
    out = ["DCOS 0.1.0 - Distributed Controller Operating System", "dcos> iobus bringup",
           "BRINGUP BEGIN base=0x300 irq=5"]
    if absent:
        return "\r\n".join(out + ["BRINGUP PROBE absent", "BRINGUP END failures=1", "dcos> "])
    failures = 0
    out.append("BRINGUP PROBE ok id=4d46 revision=0100")
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
                out.append(f"BRINGUP ADC channel={channel} gain={gain} offset_lsb=0.00 gain_error_pct=-100.00 "
                           f"max_error_lsb={gain * span:.2f} noise_lsb=0.00 overrange=0 points={points}")
                continue
            error = 0.5
            if max_error and (channel, gain) in max_error:
                error = max_error[(channel, gain)]
            points = ",".join(f"{code}:{2048 + gain * (code - 2048):.1f}" for code in codes)
            out.append(f"BRINGUP ADC channel={channel} gain={gain} offset_lsb=0.25 gain_error_pct=-0.02 "
                       f"max_error_lsb={error:.2f} noise_lsb={noise:.2f} overrange=0 points={points}")
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
    assert len(report.adc) == 32 and all(judgement.adc_pass.values()) and len(judgement.adc_pass) == 32
    assert report.adc[0].points[0] == (48, 48.0) and len(report.adc[0].points) == 9
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
     "could not convert"),
    ("BRINGUP ADC channel=9 gain=10 offset_lsb=0 gain_error_pct=0 max_error_lsb=0 noise_lsb=0 points=1:1",
     "channel 9 is not 0..7"),
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
    # Noise 0.8 LSB passes the default 1.0 limit and fails a tightened 0.5 one, on every channel and gain.
    _, default = judged(transcript(noise=0.8))
    assert default.verdict == "pass"
    _, tight = judged(transcript(noise=0.8), max_noise_lsb=0.5)
    assert len(tight.failures) == 32
    assert "ADC channel 0 gain 1: noise 0.8 LSB > limit 0.5" in messages(tight)
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


def run_tool(*args, stdin=None):
    return subprocess.run([sys.executable, TOOL] + list(args), input=stdin, capture_output=True, text=True,
                          timeout=TIMEOUT)


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
    assert document["format"] == "dcos-iobus-bringup-result" and document["version"] == 1
    assert document["verdict"] == "pass" and document["exit_code"] == 0
    assert document["board"] == {"base": 0x300, "irq": 5, "probe": "ok", "id": 0x4D46, "revision": 0x100}
    assert document["limits"]["max_error_lsb"] == 2.0
    assert len(document["adc"]) == 32 and all(entry["passed"] for entry in document["adc"])
    first = document["adc"][0]
    assert (first["channel"], first["gain"], first["points"][0], first["ideal"][0]) == (0, 1, [48, 48.0], 48)
    assert document["irq"]["delivered"] == 64 and document["failures"] == []
    assert len(document["report_lines"]) == 2 + 2 + 32 + 2
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
                                         "--max-gain-error-pct", "0.5")
    assert result.returncode == 1
    assert document["limits"] == {"max_offset_lsb": 1.0, "max_gain_error_pct": 0.5, "max_error_lsb": 15.0,
                                  "max_noise_lsb": 0.2, "min_irq_delivered_pct": 50.0, "max_irq_latency_ns": 3000.0,
                                  "min_points": 3}
    assert [f["message"] for f in document["failures"]] == ["interrupt: max latency 5000 ns > limit 3000"]


def test_tool_reads_a_transcript_from_stdin_and_can_skip_outputs(workdir):
    os.chdir(workdir)
    result = run_tool("--transcript", "-", "--json", "", "--png", "", stdin=transcript(stuck_bit=2))
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
    for line in ("0  every check passed", "1  failures found", "3  board absent", "4  no connection"):
        assert line in result.stdout


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
                      "--json", os.path.join(workdir, "r.json"))
    assert result.returncode == 4
    assert "cannot connect to console socket" in result.stderr
    with open(os.path.join(workdir, "r.json"), encoding="utf-8") as handle:
        document = json.load(handle)
    assert document["verdict"] == "incomplete" and document["exit_code"] == 4
    assert document["failures"][0]["message"].startswith("cannot connect to console socket")
