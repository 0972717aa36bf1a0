"""Tests of the plant simulator (host_tools/plant_simulator) without the emulator.

The simulator's answers are checked against the analytical solution of the
first-order-plus-dead-time process at several sample times, with irregular
timestamps, across the dead time, with a disturbance step and a down step;
malformed lines must be answered with the previous inputs and counted; the
socket mode is exercised with a client that plays the emulator's model.
"""

import csv
import math
import os
import socket
import subprocess
import sys
import tempfile
import time

import pytest

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLANT_DIRECTORY = os.path.join(REPOSITORY, "host_tools", "plant_simulator")
PLANT = os.path.join(PLANT_DIRECTORY, "plant_simulator.py")
sys.path.insert(0, PLANT_DIRECTORY)

import plant_simulator  # noqa: E402

TIMEOUT = 30


def sample(time_ns, dacs=None, do_word=0):
    dacs = list(dacs or [0.0] * 8)
    return f"SAMPLE {time_ns} " + " ".join(f"{v:.6f}" for v in dacs) + f" {do_word:04x}"


def dacs_with(channel, value):
    dacs = [0.0] * 8
    dacs[channel] = value
    return dacs


def parse_input(line):
    fields = line.split()
    assert fields[0] == "INPUT" and len(fields) == 10, line
    return [float(v) for v in fields[1:9]], int(fields[9], 16)


def make_simulator(*args):
    return plant_simulator.PlantSimulator(plant_simulator.build_parser().parse_args(list(args)), log=open(os.devnull, "w"))


def fopdt_step(t, k, tau, theta, step, y0=0.0, t_step=0.0):
    """y(t) of tau*dy/dt = -y + k*u(t-theta) with u stepping from 0 to step at t_step and y(0) = y0."""
    free = y0 * math.exp(-t / tau)
    if t <= t_step + theta:
        return free
    return free + k * step * (1.0 - math.exp(-(t - t_step - theta) / tau))


def test_step_response_matches_the_analytical_solution_at_irregular_times():
    k, tau, theta = 2.5, 0.4, 0.15
    simulator = make_simulator("--gain", str(k), "--tau", str(tau), "--dead-time", str(theta),
                               "--input-channel", "2", "--output-channel", "5", "--initial", "0.5")
    # The step is applied at the first sample (t = 0); the samples then come at
    # irregular times before, at, just after and long after the dead time.
    times_s = [0.0, 0.013, 0.1, 0.149999, 0.15, 0.150001, 0.2, 0.37, 0.55, 1.0, 1.7, 4.0]
    for t in times_s:
        volts, _ = parse_input(simulator.handle_line(sample(int(round(t * 1e9)), dacs_with(2, 1.2))))
        expected = fopdt_step(round(t * 1e9) / 1e9, k, tau, theta, 1.2, y0=0.5)
        assert volts[5] == pytest.approx(expected, abs=2e-6), f"at t = {t} s"
        assert volts[0] == 0.0 and volts[2] == 0.0  # the other inputs read 0 V by default
    assert simulator.errors == 0 and simulator.samples == len(times_s)


def test_the_result_does_not_depend_on_how_often_the_model_samples():
    args = ("--gain", "1.5", "--tau", "0.3", "--dead-time", "0.07")
    sparse, dense = make_simulator(*args), make_simulator(*args)
    u = 2.0
    sparse.handle_line(sample(0, dacs_with(0, u)))
    for step in range(1, 1000):
        dense.handle_line(sample(step * 1_000_000 - 1_000_000, dacs_with(0, u)))
    last_dense = dense.handle_line(sample(999_000_000, dacs_with(0, u)))
    last_sparse = sparse.handle_line(sample(999_000_000, dacs_with(0, u)))
    assert parse_input(last_dense)[0][0] == pytest.approx(parse_input(last_sparse)[0][0], abs=2e-6)
    assert parse_input(last_sparse)[0][0] == pytest.approx(fopdt_step(0.999, 1.5, 0.3, 0.07, u), abs=2e-6)


def test_a_step_down_and_a_disturbance_follow_superposition():
    k, tau, theta = 1.0, 0.5, 0.2
    simulator = make_simulator("--gain", "1", "--tau", "0.5", "--dead-time", "0.2",
                               "--disturbance", "-0.8", "--disturbance-at", "1.3")
    simulator.handle_line(sample(0, dacs_with(0, 3.0)))          # step up at 0
    simulator.handle_line(sample(600_000_000, dacs_with(0, 1.0)))  # step down by 2 at 0.6 s
    for t in (0.7, 0.8, 0.85, 1.25, 1.3, 1.31, 2.0, 3.5):
        volts, _ = parse_input(simulator.handle_line(sample(int(round(t * 1e9)), dacs_with(0, 1.0))))
        expected = fopdt_step(t, k, tau, theta, 3.0) + fopdt_step(t, k, tau, theta, -2.0, t_step=0.6)
        if t > 1.3:
            expected += -0.8 * (1.0 - math.exp(-(t - 1.3) / tau))
        assert volts[0] == pytest.approx(expected, abs=2e-6), f"at t = {t} s"


def test_zero_time_constant_is_a_pure_gain_with_dead_time():
    simulator = make_simulator("--gain", "-2", "--tau", "0", "--dead-time", "0.01", "--offset", "0.25")
    assert parse_input(simulator.handle_line(sample(0, dacs_with(0, 1.0))))[0][0] == pytest.approx(0.25)
    assert parse_input(simulator.handle_line(sample(9_999_999, dacs_with(0, 1.0))))[0][0] == pytest.approx(0.25)
    assert parse_input(simulator.handle_line(sample(10_000_000, dacs_with(0, 1.0))))[0][0] == pytest.approx(-1.75)


def test_noise_is_deterministic_from_the_seed_and_leaves_the_state_alone():
    def run(seed):
        simulator = make_simulator("--tau", "0.1", "--noise", "0.01", "--seed", str(seed))
        return [parse_input(simulator.handle_line(sample(t * 10_000_000, dacs_with(0, 1.0))))[0][0]
                for t in range(200)]
    first, again, other = run(3), run(3), run(4)
    assert first == again
    assert first != other
    # The mean error of the late (settled) samples is small: noise is zero-mean around the true output.
    settled = [value - 1.0 for value in first[150:]]
    assert abs(sum(settled) / len(settled)) < 0.005
    assert 0.005 < math.sqrt(sum(e * e for e in settled) / len(settled)) < 0.02


def test_digital_inputs_copy_the_outputs_or_follow_a_mapping():
    plain = make_simulator()
    assert parse_input(plain.handle_line(sample(0, do_word=0xA5C3)))[1] == 0xA5C3
    mapped = make_simulator("--di-map", "0=1,1=0,15=15", "--di-fixed", "0f00", "--di-invert", "8000")
    # DO 0x0001: DI bit 1 = 1, DI bit 0 = DO bit 1 = 0, bit 15 = 0 inverted to 1, fixed 0x0f00.
    assert parse_input(mapped.handle_line(sample(0, do_word=0x0001)))[1] == 0x8F02


def test_other_inputs_can_loop_back_or_be_constant():
    simulator = make_simulator("--output-channel", "1", "--other-inputs", "loopback", "--ai-constant", "7=-3.5",
                               "--tau", "0")
    dacs = [0.5, 9.0, 1.5, 2.5, 3.5, 4.5, 5.5, 6.5]
    volts, _ = parse_input(simulator.handle_line(sample(0, dacs)))
    assert volts[0] == 0.5 and volts[2:7] == dacs[2:7]
    assert volts[1] == pytest.approx(0.5)  # the process output, from DAC 0
    assert volts[7] == -3.5


@pytest.mark.parametrize("line, reason", [
    ("", "empty line"),
    ("HELLO 1 2 3", "keyword SAMPLE"),
    ("SAMPLE 100 1 2 3 0000", "expected 11 fields"),
    ("SAMPLE 1e3 0 0 0 0 0 0 0 0 0000", "whole number"),
    ("SAMPLE 100 0 0 x 0 0 0 0 0 0000", "DAC2 value"),
    ("SAMPLE 100 0 0 0 0 nan 0 0 0 0000", "not finite"),
    ("SAMPLE 100 0 0 0 0 0 0 0 0 12345", "4 hex digits"),
    ("SAMPLE 100 0 0 0 0 0 0 0 0 00g0", "4 hex digits"),
    ("SAMPLE -5 0 0 0 0 0 0 0 0 0000", "negative"),
    ("SAMPLE 10 0 0 0 0 0 0 0 0 0000", "went backwards"),
])
def test_a_malformed_line_is_answered_with_the_previous_inputs_and_counted(line, reason):
    messages = tempfile.TemporaryFile("w+")
    simulator = plant_simulator.PlantSimulator(
        plant_simulator.build_parser().parse_args(["--tau", "0", "--gain", "3"]), log=messages)
    good = simulator.handle_line(sample(1000, dacs_with(0, 1.0), 0x0042))
    assert simulator.handle_line(line, 2) == good
    assert simulator.errors == 1 and simulator.samples == 1
    messages.seek(0)
    assert reason in messages.read()
    # The next good line is answered normally.
    assert parse_input(simulator.handle_line(sample(2000, dacs_with(0, 2.0), 0x0001)))[0][0] == pytest.approx(6.0)


def test_before_the_first_sample_a_malformed_line_gets_the_initial_inputs():
    simulator = make_simulator("--initial", "1.25", "--output-channel", "3", "--di-fixed", "00ff", "--di-map", "0=0")
    volts, di = parse_input(simulator.handle_line("garbage"))
    assert volts[3] == 1.25 and di == 0x00FE


def run_stdio(args, text):
    return subprocess.run([sys.executable, PLANT] + args, input=text, capture_output=True, text=True,
                          timeout=TIMEOUT)


def test_stdio_mode_answers_every_line_and_logs_a_csv():
    with tempfile.TemporaryDirectory() as directory:
        log = os.path.join(directory, "trajectory.csv")
        lines = [sample(0, dacs_with(0, 1.0), 0x00FF), "not a sample", sample(500_000_000, dacs_with(0, 1.0), 0x0003)]
        result = run_stdio(["--gain", "2", "--tau", "0.5", "--dead-time", "0.05", "--csv", log],
                           "\n".join(lines) + "\n")
        assert result.returncode == 0, result.stderr
        replies = result.stdout.splitlines()
        assert len(replies) == 3
        assert replies[1] == replies[0]
        assert parse_input(replies[2])[0][0] == pytest.approx(fopdt_step(0.5, 2, 0.5, 0.05, 1.0), abs=2e-6)
        assert parse_input(replies[2])[1] == 0x0003
        assert "line 2: expected the keyword SAMPLE" in result.stderr
        assert "plant: 2 samples, 1 malformed lines" in result.stderr
        with open(log, newline="") as handle:
            rows = list(csv.DictReader(handle))
        assert [row["time_ns"] for row in rows] == ["0", "500000000"]
        assert float(rows[1]["process_output"]) == pytest.approx(fopdt_step(0.5, 2, 0.5, 0.05, 1.0), abs=2e-6)
        assert rows[1]["di"] == "0003" and rows[0]["do"] == "00ff"


def test_help_documents_every_option():
    result = subprocess.run([sys.executable, PLANT, "--help"], capture_output=True, text=True, timeout=TIMEOUT)
    assert result.returncode == 0
    with open(os.path.join(PLANT_DIRECTORY, "README.md"), encoding="utf-8") as handle:
        readme = handle.read()
    for action in plant_simulator.build_parser()._actions:
        for option in action.option_strings:
            if option in ("-h", "--help"):
                continue
            assert option in result.stdout
            assert f"`{option}" in readme or f"{option}`" in readme, f"{option} is not in README.md"
            assert action.help


def test_bad_options_exit_with_status_2():
    assert run_stdio(["--input-channel", "8"], "").returncode == 2
    assert run_stdio(["--tau", "-1"], "").returncode == 2
    assert run_stdio(["--di-map", "0-1"], "").returncode == 2


def connect_with_retry(path, deadline):
    while True:
        client = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            client.connect(path)
            return client
        except (FileNotFoundError, ConnectionRefusedError):
            client.close()
            if time.monotonic() > deadline:
                raise
            time.sleep(0.02)


def test_socket_mode_serves_a_client_like_the_model():
    with tempfile.TemporaryDirectory() as directory:
        path = os.path.join(directory, "plant.sock")
        process = subprocess.Popen([sys.executable, PLANT, "--socket", path, "--gain", "4", "--tau", "0.2",
                                    "--output-channel", "6", "--accept-timeout", "20"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            client = connect_with_retry(path, time.monotonic() + TIMEOUT)
            client.settimeout(TIMEOUT)
            reader = client.makefile("r", encoding="latin-1")
            # Lines may arrive in pieces, like bytes from a chardev.
            for part in ("SAMPLE 0 0.5 0 0 0 0 0 0 0 ", "0011\nSAMPLE 100000000 0.5 0 0 0 0 0 0 0 0022\n"):
                client.sendall(part.encode())
            first, second = reader.readline(), reader.readline()
            client.sendall(b"SAMPLE oops\n")
            third = reader.readline()
            assert parse_input(first) == ([0.0] * 8, 0x0011)
            volts, di = parse_input(second)
            assert volts[6] == pytest.approx(4 * 0.5 * (1 - math.exp(-0.1 / 0.2)), abs=2e-6) and di == 0x0022
            assert third == second
            reader.close()
            client.close()
            _, stderr = process.communicate(timeout=TIMEOUT)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait(timeout=TIMEOUT)
        assert process.returncode == 0, stderr
        assert "plant: 2 samples, 1 malformed lines" in stderr
        assert not os.path.exists(path)


def test_socket_mode_gives_up_when_no_client_comes():
    with tempfile.TemporaryDirectory() as directory:
        result = subprocess.run([sys.executable, PLANT, "--socket", os.path.join(directory, "plant.sock"),
                                 "--accept-timeout", "0.3"], capture_output=True, text=True, timeout=TIMEOUT)
        assert result.returncode == 3
        assert "no client connected within 0.3 s" in result.stderr


# -- hostile input: every line is checked, none is fatal, the state stays finite --------------


def test_one_huge_input_does_not_poison_the_simulation():
    # 1e308 V times the gain 2 would be infinite, and every later answer with it: the line is refused instead.
    messages = tempfile.TemporaryFile("w+")
    simulator = plant_simulator.PlantSimulator(
        plant_simulator.build_parser().parse_args(["--tau", "0.5", "--gain", "2"]), log=messages)
    simulator.handle_line(sample(0, dacs_with(0, 1.0)))
    previous = simulator.handle_line(sample(100_000_000, dacs_with(0, 1.0)))
    assert simulator.handle_line("SAMPLE 200000000 1e308 0 0 0 0 0 0 0 0000", 3) == previous
    for text in ("nan", "inf", "-1e308", "10.5"):
        assert simulator.handle_line(f"SAMPLE 200000000 {text} 0 0 0 0 0 0 0 0000", 4) == previous
    volts, _ = parse_input(simulator.handle_line(sample(300_000_000, dacs_with(0, 1.0))))
    assert volts[0] == pytest.approx(fopdt_step(0.3, 2, 0.5, 0.0, 1.0), abs=2e-6)
    assert simulator.errors == 5 and math.isfinite(simulator.process.y)
    messages.seek(0)
    text = messages.read()
    assert "DAC0 value '1e308' is outside the DAC's -10..+10 V" in text
    assert "DAC0 value 'nan' is not finite" in text


@pytest.mark.parametrize("time_text, reason", [
    ("9" * 400, "is beyond 2^63 - 1 ns, the model's clock"),
    ("9223372036854775808", "is beyond 2^63 - 1 ns"),
    ("1" * 5000, "line longer than 4096 characters"),
])
def test_an_over_long_time_is_answered_not_fatal(time_text, reason):
    with tempfile.TemporaryDirectory() as directory:
        lines = [sample(0, dacs_with(0, 1.0)), f"SAMPLE {time_text} 1 0 0 0 0 0 0 0 0000",
                 sample(1_000_000_000, dacs_with(0, 1.0))]
        result = run_stdio(["--tau", "1", "--csv", os.path.join(directory, "log.csv")], "\n".join(lines) + "\n")
    assert result.returncode == 0 and "Traceback" not in result.stderr, result.stderr
    replies = result.stdout.splitlines()
    assert len(replies) == 3 and replies[1] == replies[0]
    assert parse_input(replies[2])[0][0] == pytest.approx(fopdt_step(1.0, 1, 1, 0, 1.0), abs=2e-6)
    assert reason in result.stderr and "plant: 2 samples, 1 malformed lines" in result.stderr


def test_a_line_without_end_is_not_buffered_without_limit():
    # A megabyte without a newline is dropped as it arrives; the lines around it are answered.
    text = sample(0, dacs_with(0, 1.0)) + "\n" + "x" * 1_000_000 + "\n" + sample(10, dacs_with(0, 1.0)) + "\n"
    result = run_stdio(["--tau", "0"], text)
    assert result.returncode == 0, result.stderr
    assert len(result.stdout.splitlines()) == 3
    assert "line 2: line longer than 4096 characters" in result.stderr


PLANT_FLOAT_OPTIONS = ["--gain", "--tau", "--dead-time", "--initial", "--initial-input", "--offset", "--disturbance",
                       "--disturbance-at", "--noise", "--accept-timeout", "--idle-timeout"]


@pytest.mark.parametrize("option", PLANT_FLOAT_OPTIONS)
def test_number_options_must_be_finite_and_in_range(capsys, option):
    for value in ("nan", "inf", "-inf", "1e999", "1e300", "x"):
        with pytest.raises(SystemExit) as stop:
            plant_simulator.main([f"{option}={value}"])
        assert stop.value.code == 2, (option, value)
        assert f"argument {option}" in capsys.readouterr().err


def test_other_options_are_checked_too(capsys, tmp_path):
    for arguments in (["--ai-constant", "3=nan"], ["--ai-constant", "3=1e999"], ["--max-error-messages", "-1"],
                      ["--seed", "9" * 5000], ["--output-channel", "9" * 5000], ["--initial-input", "11"],
                      ["--csv", str(tmp_path / "missing" / "log.csv")]):
        with pytest.raises(SystemExit) as stop:
            plant_simulator.main(arguments)
        assert stop.value.code == 2, arguments
        error = capsys.readouterr().err
        assert "Traceback" not in error and arguments[0] in error, error


def test_the_answers_stop_quietly_when_their_reader_goes():
    process = subprocess.Popen([sys.executable, PLANT, "--tau", "0"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        process.stdin.write(sample(0) + "\n")
        process.stdin.flush()
        assert process.stdout.readline().startswith("INPUT ")
        process.stdout.close()
        for step in range(1, 200):
            process.stdin.write(sample(step) + "\n")
        process.stdin.close()
    except BrokenPipeError:
        pass
    finally:
        stderr = process.stderr.read()
        process.wait(timeout=TIMEOUT)
    assert process.returncode == 0 and "Traceback" not in stderr, stderr


# -- several boards (--boards): redundant controllers wired to one plant ---------------------------


def test_several_boards_drive_the_process_with_the_highest_output():
    simulator = make_simulator("--boards", "3", "--tau", "0", "--gain", "1", "--input-channel", "1",
                               "--output-channel", "0")
    # Board 0 only measures (0 V); boards 1 and 2 are controllers with slightly different outputs.
    simulator.handle_line(sample(0, dacs_with(1, 0.0)), 1, 0)
    simulator.handle_line(sample(1_000, dacs_with(1, 2.0)), 1, 1)
    simulator.handle_line(sample(2_000, dacs_with(1, 2.1)), 1, 2)
    volts, _ = parse_input(simulator.handle_line(sample(3_000, dacs_with(1, 0.0)), 2, 0))
    assert volts[0] == pytest.approx(2.1, abs=1e-6)
    # Board 2 dies: board 1's output drives from that moment on.
    simulator.disconnect(2)
    volts, _ = parse_input(simulator.handle_line(sample(4_000, dacs_with(1, 0.0)), 3, 0))
    assert volts[0] == pytest.approx(2.0, abs=1e-6)
    # The last controller dies too: nothing drives the process but the measuring board's 0 V.
    simulator.disconnect(1)
    volts, _ = parse_input(simulator.handle_line(sample(5_000, dacs_with(1, 0.0)), 4, 0))
    assert volts[0] == pytest.approx(0.0, abs=1e-6)
    assert simulator.errors == 0


def test_a_board_slightly_behind_is_taken_at_the_simulations_time_and_one_far_behind_is_refused():
    simulator = make_simulator("--boards", "2", "--tau", "0.2", "--max-skew", "1")
    first = simulator.handle_line(sample(10_000_000, dacs_with(0, 1.0)), 1, 0)
    behind = simulator.handle_line(sample(9_500_000, dacs_with(0, 1.0)), 1, 1)
    assert simulator.errors == 0 and simulator.process.time_ns == 10_000_000
    assert parse_input(behind)[0][0] == pytest.approx(parse_input(first)[0][0], abs=1e-9)
    # 2 ms behind is beyond the skew: malformed, answered with that board's previous answer.
    assert simulator.handle_line(sample(8_000_000, dacs_with(0, 5.0)), 2, 1) == behind
    assert simulator.errors == 1
    # Board 0's malformed line gets board 0's previous answer, not board 1's.
    assert simulator.handle_line("SAMPLE oops", 2, 0) == first
    # A board that never sent a good line gets the initial inputs.
    assert simulator.handle_line("SAMPLE oops", 1, 2) == simulator.initial_reply
    with_one_board = make_simulator("--tau", "0.2")
    with_one_board.handle_line(sample(10_000_000), 1)
    with_one_board.handle_line(sample(9_999_999), 2)
    assert with_one_board.errors == 1, "one board's time never goes backwards"


def test_several_boards_need_a_socket():
    result = subprocess.run([sys.executable, PLANT, "--boards", "2"], capture_output=True, text=True,
                            timeout=TIMEOUT, input="")
    assert result.returncode == 2 and "--boards" in result.stderr


def test_socket_mode_serves_several_boards_and_ends_when_the_last_has_gone():
    with tempfile.TemporaryDirectory() as directory:
        path = os.path.join(directory, "plant.sock")
        log = os.path.join(directory, "plant.csv")
        process = subprocess.Popen([sys.executable, PLANT, "--socket", path, "--boards", "2", "--tau", "0",
                                    "--input-channel", "1", "--accept-timeout", "20", "--csv", log],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            controller = connect_with_retry(path, time.monotonic() + TIMEOUT)
            sensor = connect_with_retry(path, time.monotonic() + TIMEOUT)
            for client in (controller, sensor):
                client.settimeout(TIMEOUT)
            controller_lines = controller.makefile("r", encoding="latin-1")
            sensor_lines = sensor.makefile("r", encoding="latin-1")
            controller.sendall((sample(1_000, dacs_with(1, 3.0)) + "\n").encode())
            assert parse_input(controller_lines.readline())[0][0] == pytest.approx(3.0, abs=1e-6)
            sensor.sendall((sample(2_000) + "\n").encode())
            assert parse_input(sensor_lines.readline())[0][0] == pytest.approx(3.0, abs=1e-6)
            # The controller's emulator stops: the sensor goes on and sees the process fall back to 0 V.
            controller_lines.close()
            controller.close()
            # The simulator learns of it when it reads the end of the connection, a moment later.
            deadline = time.monotonic() + TIMEOUT
            for number in range(10_000):
                sensor.sendall((sample(3_000 + number) + "\n").encode())
                volts, _ = parse_input(sensor_lines.readline())
                if volts[0] == pytest.approx(0.0, abs=1e-6) or time.monotonic() > deadline:
                    break
                time.sleep(0.02)
            assert volts[0] == pytest.approx(0.0, abs=1e-6)
            sensor_lines.close()
            sensor.close()
            _, stderr = process.communicate(timeout=TIMEOUT)
        finally:
            if process.poll() is None:
                process.kill()
                process.wait(timeout=TIMEOUT)
        assert process.returncode == 0, stderr
        assert "board 0 connected" in stderr and "board 1 connected" in stderr
        assert "board 0 gone" in stderr and "board 1 gone" in stderr
        with open(log, newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(handle))
        assert [row["board"] for row in rows[:2]] == ["0", "1"]
