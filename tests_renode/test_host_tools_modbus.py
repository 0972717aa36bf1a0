"""dcos-modbus and dcos-modbus-sim against Modbus implementations we did not write.

The ends are joined by a pseudo-terminal pair (tests_renode/modbus/ptylink.py),
a null-modem cable in software, so every byte crosses a real tty as it would
a USB-RS485 adapter:

- pymodbus (Debian's python3-pymodbus) as the slave, dcos-modbus as the
  master: every function code dcos-modbus offers (01, 02, 03, 04, 05, 06,
  0F, 10, 17, 2B/0E) reads what pymodbus holds or writes what pymodbus then
  holds;
- pymodbus as the master against dcos-modbus-sim, every function code;
- dcos-modbus against dcos-modbus-sim: the simulated drive's ramp and its
  "at speed" bit in time, the sensor's sine;
- the failures: a slave that does not answer (time-out, retries, exit 4),
  exceptions named, bad arguments (exit 2), ports that are not there (exit
  3), configuration files that are not valid (exit 6, file and line).

pymodbus runs with parity N: pyserial sets a port's modes again whenever a
setting changes, and this machine's kernel refuses a pseudo-terminal's
second tcsetattr() with parity bits set (EINVAL). Parity means nothing on a
pseudo-terminal, so nothing is lost; libmodbus ends use even parity, the
default of [SL] 2.5.1, among themselves.

No test needs the emulator. Every wait has a time-out.
"""

import json
import os
import queue
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
import tty

import pytest

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(REPOSITORY, "build", "host_tools", "bin")
DCOS_MODBUS = os.path.join(BIN, "dcos-modbus")
DCOS_MODBUS_SIM = os.path.join(BIN, "dcos-modbus-sim")
EXAMPLES = os.path.join(REPOSITORY, "host_tools", "modbus", "examples")
HELPERS = os.path.join(REPOSITORY, "tests_renode", "modbus")
PYMODBUS_SLAVE = os.path.join(HELPERS, "pymodbus_slave.py")
sys.path.insert(0, HELPERS)

import pymodbus_slave  # noqa: E402  (the values the pymodbus slave holds)
from ptylink import PtyLink  # noqa: E402

# The longest any one step may take on a loaded machine; the tools' own
# time-outs are far shorter.
TIMEOUT = 30
SLAVE = 17


class LineReader:
    """A process's stdout read by a thread, so a test can wait for a line with a time-out."""

    def __init__(self, process):
        self.process = process
        self.lines = queue.Queue()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        for line in self.process.stdout:
            self.lines.put(line)
        self.lines.put(None)

    def line(self, timeout=TIMEOUT):
        try:
            line = self.lines.get(timeout=timeout)
        except queue.Empty:
            pytest.fail(f"no line from {self.process.args[0]} within {timeout} s")
        if line is None:
            pytest.fail(f"{self.process.args[0]} ended: {self.process.stderr.read()}")
        return line

    def rest(self, timeout=TIMEOUT):
        """Every line up to the end of the output."""
        lines = []
        deadline = time.monotonic() + timeout
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                pytest.fail(f"{self.process.args[0]} did not end within {timeout} s")
            if line is None:
                return lines
            lines.append(line)


def stop(process):
    if process.poll() is None:
        process.kill()
    process.wait(timeout=TIMEOUT)


@pytest.fixture
def link():
    joined = PtyLink()
    yield joined
    joined.close()


@pytest.fixture
def pymodbus(link):
    """pymodbus answering as slave 17 on the link's second end."""
    process = subprocess.Popen([sys.executable, PYMODBUS_SLAVE, link.paths[1], "--slave", str(SLAVE), "--parity",
                                "N", "--seconds", "120"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    reader = LineReader(process)
    assert reader.line().strip() == "ready"
    yield process
    stop(process)


# A request is asked again twice, with a second to answer each time: the
# simulators are Python processes on a machine that may be busy, and these
# tests are about what is exchanged, not how fast. The tests of time-outs
# give their own.
def tool(port, *arguments, slave=SLAVE, parity="N", timeout_ms=1000, retries=2, json_output=False):
    command = [DCOS_MODBUS, "-d", port, "-a", str(slave), "--parity", parity, "-t", str(timeout_ms), "-r",
               str(retries)]
    command += ["--json"] if json_output else []
    return subprocess.run(command + list(arguments), capture_output=True, text=True, timeout=TIMEOUT)


def tool_json(port, *arguments, **options):
    result = tool(port, *arguments, json_output=True, **options)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


def values(result):
    """The "address value" lines of dcos-modbus's text output, as a dict."""
    assert result.returncode == 0, result.stderr
    return {int(a): int(v) for a, v in (line.split() for line in result.stdout.splitlines())}


# --- dcos-modbus against pymodbus -------------------------------------------


def test_reads_every_table_of_pymodbus(link, pymodbus):
    port = link.paths[0]
    coils = values(tool(port, "read-coils", "0", "20"))
    assert coils == {i: int(pymodbus_slave.COILS[i]) for i in range(20)}
    inputs = values(tool(port, "read-discrete-inputs", "3", "13"))
    assert inputs == {i: int(pymodbus_slave.DISCRETE_INPUTS[i]) for i in range(3, 16)}
    holding = values(tool(port, "read-holding-registers", "0x10", "5"))
    assert holding == {i: pymodbus_slave.HOLDING_REGISTERS[i] for i in range(16, 21)}
    # The largest read [AP] 6.4 allows, 125 registers, across the table's end.
    answer = tool_json(port, "read-input-registers", "0", "100")
    assert answer["function"] == 4 and answer["slave"] == SLAVE and answer["address"] == 0
    assert answer["values"] == pymodbus_slave.INPUT_REGISTERS


def test_writes_reach_pymodbus(link, pymodbus):
    port = link.paths[0]
    assert tool(port, "write-coil", "1", "on").returncode == 0                  # 05
    assert tool(port, "write-register", "5", "-2").returncode == 0              # 06
    assert tool(port, "write-coils", "40=1,1,0,1,0,0,1,1,1").returncode == 0    # 0F, two bytes of bits
    written = tool_json(port, "write-registers", "20=7,0x8,65535")               # 10
    assert (written["function"], written["address"], written["count"]) == (16, 20, 3)
    assert values(tool(port, "read-coils", "0", "2")) == {0: 1, 1: 1}
    assert values(tool(port, "read-coils", "40", "9")) == dict(enumerate([1, 1, 0, 1, 0, 0, 1, 1, 1], start=40))
    assert values(tool(port, "read-holding-registers", "5", "1")) == {5: 65534}
    # 17 writes first, then reads, in one request.
    both = tool_json(port, "write-read", "30=1,2", "19:13")
    assert both["function"] == 23
    assert both["values"] == [1019, 7, 8, 65535] + [1000 + i for i in range(23, 30)] + [1, 2]


def test_device_identification_of_pymodbus(link, pymodbus):
    port = link.paths[0]
    regular = tool_json(port, "identify")
    assert {o["name"]: o["value"] for o in regular["objects"]} == pymodbus_slave.IDENTITY
    basic = tool(port, "identify", "--code", "basic")
    assert basic.returncode == 0, basic.stderr
    assert basic.stdout.splitlines() == ["VendorName: pymodbus", "ProductCode: PM-SLAVE", "MajorMinorRevision: 3.0.0"]
    one = tool_json(port, "identify", "--code", "individual", "--object", "4")
    assert one["objects"] == [{"id": 4, "name": "ProductName", "value": "pymodbus test slave"}]


def test_exception_from_pymodbus_is_named(link, pymodbus):
    result = tool(link.paths[0], "read-holding-registers", "99", "2", json_output=True)
    assert result.returncode == 1
    assert "exception 02 (Illegal data address)" in result.stderr
    answer = json.loads(result.stdout)
    assert (answer["exception"], answer["exception_name"], answer["exit_status"]) == (2, "Illegal data address", 1)


def test_slave_that_does_not_answer_times_out_after_its_retries(link, pymodbus):
    # pymodbus ignores requests for slaves it does not have: slave 18 is silent.
    started = time.monotonic()
    result = tool(link.paths[0], "read-holding-registers", "0", "1", slave=18, timeout_ms=200, retries=2,
                  json_output=True)
    elapsed = time.monotonic() - started
    assert result.returncode == 4, result.stderr
    assert "no answer from slave 18" in result.stderr and "3 attempts" in result.stderr
    assert json.loads(result.stdout)["exit_status"] == 4
    assert elapsed >= 0.6
    requests = [data for side, data in link.log if side == 0]
    assert b"".join(requests).count(bytes([18, 3, 0, 0, 0, 1])) == 3


def test_nothing_on_the_line_times_out(link):
    result = tool(link.paths[0], "write-register", "0", "1", timeout_ms=100, retries=0)
    assert result.returncode == 4
    assert "no answer from slave 17 to write-register (06) at 0 within 100 ms (1 attempt)" in result.stderr


@pytest.mark.parametrize("arguments, message", [
    (["-a", "0", "read-coils", "0"], "is not a slave address"),
    (["-a", "248", "read-coils", "0"], "is not a slave address"),
    (["--parity", "X", "read-coils", "0"], "is not a parity"),
    (["-b", "12345", "read-coils", "0"], "12345 baud is not a rate"),
    (["read-holding-registers", "0", "126"], "a count of 126 is out of range: 1 to 125"),
    (["read-coils", "65535", "2"], "run past the last address"),
    (["read-coils", "0x1G"], "is not a data address"),
    (["write-coil", "1", "2"], "is not a coil value"),
    (["write-register", "1", "65536"], "is not a register value"),
    (["write-registers", "100=1,,2"], "is not a register value"),
    (["write-registers", "100"], "is not a register list"),
    (["write-coils", "0=" + ",".join(["1"] * 1969)], "more than 1968 coils"),
    (["write-read", "0=1", "5"], "is not a range"),
    (["identify", "--object", "256"], "object id 256 is out of range"),
    (["read-coils"], "address is required"),
    (["frobnicate"], "A subcommand is required"),
])
def test_bad_arguments_are_refused_before_the_port_is_opened(arguments, message):
    # The port does not exist: a bad argument must be reported as one (2),
    # not as the missing port (3).
    command = [DCOS_MODBUS, "-d", "/nonexistent/tty", "-a", "17", *arguments]
    if "-a" in arguments[:1]:
        command = [DCOS_MODBUS, "-d", "/nonexistent/tty", *arguments]
    result = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr


def test_port_that_is_not_there_or_has_no_rs485_mode(link):
    missing = subprocess.run([DCOS_MODBUS, "-d", "/nonexistent/tty", "-a", "1", "read-coils", "0"],
                             capture_output=True, text=True, timeout=TIMEOUT)
    assert missing.returncode == 3
    assert "cannot open /nonexistent/tty" in missing.stderr
    # A pseudo-terminal has no kernel RS-485 mode, as many USB adapters have none.
    rs485 = tool(link.paths[0], "--rs485", "read-coils", "0")
    assert rs485.returncode == 3
    assert "has no RS-485 mode" in rs485.stderr and "--rts" in rs485.stderr


def test_rts_driver_enable_keeps_the_exchange_intact(link, pymodbus):
    # libmodbus drains the port and waits around each request when it drives
    # RTS; a pseudo-terminal has no RTS line, but the exchange must come
    # through that path whole, in both polarities.
    for polarity in ("up", "down"):
        answer = tool_json(link.paths[0], "--rts", polarity, "read-holding-registers", "0", "3")
        assert answer["values"] == pymodbus_slave.HOLDING_REGISTERS[:3]


def test_help_and_version():
    for program in (DCOS_MODBUS, DCOS_MODBUS_SIM):
        helped = subprocess.run([program, "--help"], capture_output=True, text=True, timeout=TIMEOUT)
        assert helped.returncode == 0 and "exit status" in helped.stdout
        version = subprocess.run([program, "--version"], capture_output=True, text=True, timeout=TIMEOUT)
        assert version.returncode == 0 and version.stdout.startswith(os.path.basename(program) + " ")


# --- dcos-modbus-sim --------------------------------------------------------


class Simulator:
    """dcos-modbus-sim on one end of a link, with its JSON status lines."""

    def __init__(self, config, port, *arguments):
        self.process = subprocess.Popen([DCOS_MODBUS_SIM, "-d", port, "--json", "--seconds", "120", *arguments,
                                         config], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.reader = LineReader(self.process)
        self.ready = json.loads(self.reader.line())
        assert self.ready["event"] == "ready", self.ready

    def stop(self):
        """Stops it as an operator would (SIGTERM); returns the request lines and the final status."""
        self.process.send_signal(signal.SIGTERM)
        lines = [json.loads(line) for line in self.reader.rest()]
        assert self.process.wait(timeout=TIMEOUT) == 0, self.process.stderr.read()
        assert lines[-1]["event"] == "stopped"
        return lines[:-1], lines[-1]


@pytest.fixture
def drive(link):
    simulator = Simulator(os.path.join(EXAMPLES, "drive.toml"), link.paths[1])
    yield simulator
    stop(simulator.process)


def wait_until(condition, timeout, what):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.05)
    pytest.fail(f"{what} not within {timeout} s")


def test_pymodbus_master_against_the_simulated_drive(link, drive):
    from pymodbus.client import ModbusSerialClient
    from pymodbus.mei_message import ReadDeviceInformationRequest

    client = ModbusSerialClient(link.paths[0], baudrate=19200, parity="N", timeout=2, broadcast_enable=True)
    assert client.connect()
    try:
        assert not client.write_register(0, 600, slave=SLAVE).isError()                         # 06
        assert not client.write_coil(0, True, slave=SLAVE).isError()                            # 05
        assert client.read_coils(0, 1, slave=SLAVE).bits[0] is True                             # 01
        assert client.read_holding_registers(0, 2, slave=SLAVE).registers == [600, 500]          # 03
        assert not client.write_registers(10, [1, 2, 3], slave=SLAVE).isError()                 # 10
        # pymodbus 3.0's readwrite_registers() takes the slave as "unit", unlike the others.
        both = client.readwrite_registers(read_address=10, read_count=5, write_address=14,      # 17
                                          write_registers=[9], unit=SLAVE)
        assert both.registers == [1, 2, 3, 0, 9]
        # The speed ramps at 500 rpm/s towards 600: at speed within two seconds.
        wait_until(lambda: client.read_discrete_inputs(0, 1, slave=SLAVE).bits[0], 10, "at speed")   # 02
        # At speed means within the tolerance of 5; the ramp ends on the setpoint itself.
        speed, temperature = client.read_input_registers(0, 2, slave=SLAVE).registers              # 04
        assert 595 <= speed <= 600 and 447 <= temperature <= 453
        wait_until(lambda: client.read_input_registers(0, 1, slave=SLAVE).registers[0] == 600, 5, "600 rpm")
        assert not client.write_coils(0, [False], slave=SLAVE).isError()                       # 0F
        wait_until(lambda: client.read_input_registers(0, 1, slave=SLAVE).registers[0] == 0, 10, "stopped")
        information = client.execute(ReadDeviceInformationRequest(read_code=0x02, object_id=0, unit=SLAVE))
        assert information.information[0] == b"DCOS" and information.information[1] == b"SIM-DRIVE"
        assert information.information[4] == b"Simulated drive"
        # A broadcast write is carried out and never answered ([SL] 2.1).
        answered_before = len([data for side, data in link.log if side == 1])
        client.write_register(1, 321, slave=0)
        time.sleep(0.3)
        assert len([data for side, data in link.log if side == 1]) == answered_before
        assert client.read_holding_registers(1, 1, slave=SLAVE).registers == [321]
        refused = client.read_holding_registers(2, 1, slave=SLAVE)     # address 2 is not declared
        assert refused.isError() and refused.exception_code == 2
        refused = client.read_coils(0, 2, slave=SLAVE)                 # only coil 0 is
        assert refused.isError() and refused.exception_code == 2
    finally:
        client.close()
    requests, status = drive.stop()
    assert {r["function"] for r in requests} == {1, 2, 3, 4, 5, 6, 15, 16, 23, 43}
    assert status["exceptions"] == 2 and status["bad_frames"] == 0
    assert status["values"]["holding_register_10"] == 1 and status["values"]["run"] == 0


def test_dcos_modbus_drives_the_simulated_drive_through_its_ramp(link, drive):
    port = link.paths[0]
    assert values(tool(port, "read-input-registers", "0", parity="E")) == {0: 0}
    assert tool(port, "write-register", "0", "1000", parity="E").returncode == 0
    # Off: the speed stays at 0 whatever the setpoint.
    time.sleep(0.3)
    assert values(tool(port, "read-input-registers", "0", parity="E")) == {0: 0}
    # The clock starts before the request that starts the ramp, so the
    # elapsed time measured is never shorter than the ramp's own.
    started = time.monotonic()
    assert tool(port, "write-coil", "0", "1", parity="E").returncode == 0
    samples = []
    # The drive ramps in wall time; the loop bounds a hung drive.
    while time.monotonic() - started < 30:
        speed = values(tool(port, "read-input-registers", "0", parity="E"))[0]
        at_speed = values(tool(port, "read-discrete-inputs", "0", parity="E"))[0]
        samples.append((time.monotonic() - started, speed, at_speed))
        if speed == 1000 and at_speed:
            break
        time.sleep(0.1)
    speeds = [s for _, s, _ in samples]
    assert speeds == sorted(speeds), samples          # the ramp only rises
    assert speeds[-1] == 1000 and samples[-1][2] == 1, samples
    # 500 rpm/s: never ahead of the clock, so full speed no sooner than 2 s
    # (how much later depends on how busy the machine is: not asserted).
    assert all(speed <= 500 * t + 50 for t, speed, _ in samples), samples
    assert samples[-1][0] >= 1.9, samples
    # "At speed" is read just after the speed, while the ramp goes on: on
    # from 995 at the latest, and not long before (100 rpm is 200 ms).
    assert all(at for _, speed, at in samples if speed >= 995), samples
    assert not any(at for _, speed, at in samples if speed < 900), samples
    identity = tool_json(port, "identify", "--code", "basic", parity="E")
    assert [o["value"] for o in identity["objects"]] == ["DCOS", "SIM-DRIVE", "1.0"]
    refused = tool(port, "write-coils", "0=1,1", parity="E")
    assert refused.returncode == 1 and "Illegal data address" in refused.stderr
    _, status = drive.stop()
    assert status["values"]["speed"] == 1000 and status["values"]["at_speed"] == 1


def crc16(frame):
    """The RTU CRC ([SL] 6.2.2), appended low byte first."""
    crc = 0xFFFF
    for byte in frame:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return bytes(frame) + bytes([crc & 0xFF, crc >> 8])


def test_simulator_drops_noise_and_refuses_unknown_functions(link, drive):
    line = os.open(link.paths[0], os.O_RDWR | os.O_NOCTTY)
    try:
        tty.setraw(line)
        os.write(line, b"\x41" * 300)                       # longer than any frame, no silence
        time.sleep(0.1)
        os.write(line, bytes([SLAVE, 3, 0, 0, 0, 1, 0, 0]))  # a wrong CRC
        time.sleep(0.1)
        os.write(line, crc16([SLAVE, 0x41, 0x22]))            # a function the simulator does not serve
        answer = b""
        deadline = time.monotonic() + TIMEOUT
        while len(answer) < 5 and time.monotonic() < deadline:
            if select.select([line], [], [], 0.5)[0]:
                answer += os.read(line, 64)
        assert answer == crc16([SLAVE, 0xC1, 0x01]), answer.hex()   # exception 01, illegal function
    finally:
        os.close(line)
    assert values(tool(link.paths[0], "read-holding-registers", "1", parity="E")) == {1: 500}
    requests, status = drive.stop()
    # The noise is one bad frame, or two if a loaded machine delays its second half past the frame gap.
    assert status["bad_frames"] in (2, 3) and status["exceptions"] == 1 and status["requests"] == 2
    assert [r["function"] for r in requests] == [0x41, 3]


def test_simulated_sensor_follows_its_sine(link, tmp_path):
    config = tmp_path / "sensor.toml"
    config.write_text(
        '[device]\nvendor_name = "DCOS"\nproduct_code = "S"\nrevision = "1"\n'
        '[[input_register]]\nname = "level"\naddress = 7\nsine = { offset = 1000, amplitude = 100, period_s = 2 }\n'
        '[[input_register]]\nname = "supply"\naddress = 8\nconstant = { value = 24000, noise = 20 }\n')
    simulator = Simulator(str(config), link.paths[1], "-a", "5")
    try:
        samples = []
        started = time.monotonic()
        while time.monotonic() - started < 2.5:
            samples.append(tool_json(link.paths[0], "read-input-registers", "7", "2", slave=5)["values"])
            time.sleep(0.05)
        levels = [level for level, _ in samples]
        assert all(900 <= level <= 1100 for level in levels), levels
        assert max(levels) >= 1080 and min(levels) <= 920, levels   # a whole period was seen
        assert all(23980 <= supply <= 24020 for _, supply in samples), samples
        assert len({supply for _, supply in samples}) > 1, samples  # the noise is there
    finally:
        requests, status = simulator.stop()
    assert status["requests"] == len(samples) and status["exceptions"] == 0


BAD_CONFIGS = [
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\nrevision = "1"\n[[coil]\naddress = 0\n', ":5:", "not TOML"),
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\nrevision = "1"\n[[coil]]\nadress = 0\n', ":6:",
     "unknown key 'adress'"),
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\n[[coil]]\naddress = 0\n', ":1:", "'revision' is required"),
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\nrevision = "1"\n[[input_register]]\nname = "speed"\n'
     'address = 0\nramp = { follows = "setpont", per_second = 10 }\n', ":8:", "names 'setpont', which no entry"),
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\nrevision = "1"\n[[holding_register]]\naddress = 0\n'
     'count = 4\n[[holding_register]]\naddress = 3\n', ":8:", "overlap 'holding_register_0' on line 5"),
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\nrevision = "1"\n[[coil]]\naddress = 70000\n', ":6:",
     "'address' must be an integer from 0 to 65535"),
    ('[device]\nvendor_name = "A"\nproduct_code = "B"\nrevision = "1"\n[[coil]]\naddress = 0\n'
     'sine = { period_s = 1 }\n', ":7:", "a coil cannot have a sine"),
]


@pytest.mark.parametrize("text, line, message", BAD_CONFIGS)
def test_configuration_errors_name_file_and_line(tmp_path, text, line, message):
    config = tmp_path / "bad.toml"
    config.write_text(text)
    for arguments in (["--check"], ["-d", "/nonexistent/tty"]):
        result = subprocess.run([DCOS_MODBUS_SIM, *arguments, str(config)], capture_output=True, text=True,
                                timeout=TIMEOUT)
        assert result.returncode == 6, result.stderr
        assert f"{config}{line}" in result.stderr and message in result.stderr, result.stderr


def test_simulator_arguments_and_ports(tmp_path):
    drive = os.path.join(EXAMPLES, "drive.toml")
    checked = subprocess.run([DCOS_MODBUS_SIM, "--check", "--json", drive], capture_output=True, text=True,
                             timeout=TIMEOUT)
    assert checked.returncode == 0 and json.loads(checked.stdout)["points"] == 7
    for arguments, status, message in [
        ([drive], 2, "say which port"),
        (["-d", "/dev/null", "-b", "1234", drive], 2, "1234 baud is not a rate"),
        (["-d", "/dev/null", "-a", "300", drive], 2, "is not a slave address"),
        (["-d", "/nonexistent/tty", drive], 3, "cannot open /nonexistent/tty"),
        (["-d", "/dev/null", str(tmp_path / "missing.toml")], 6, "missing.toml: cannot be read"),
    ]:
        result = subprocess.run([DCOS_MODBUS_SIM, *arguments], capture_output=True, text=True, timeout=TIMEOUT)
        assert result.returncode == status, (arguments, result.stderr)
        assert message in result.stderr, result.stderr


def test_simulator_answers_after_its_turnaround(link):
    # A slave that takes 300 ms: a master waiting 1 s gets its answer no
    # sooner than that, and one waiting 100 ms times out, as against a late
    # device.
    simulator = Simulator(os.path.join(EXAMPLES, "drive.toml"), link.paths[1], "--turnaround", "300")
    try:
        port = link.paths[0]
        started = time.monotonic()
        assert values(tool(port, "read-holding-registers", "1", parity="E", timeout_ms=1000)) == {1: 500}
        assert time.monotonic() - started >= 0.3
        late = tool(port, "read-holding-registers", "1", parity="E", timeout_ms=100, retries=0)
        assert late.returncode != 0 and "no answer" in late.stderr, late.stderr
    finally:
        stop(simulator.process)
    bad = subprocess.run([DCOS_MODBUS_SIM, "--turnaround", "-1", "--check", os.path.join(EXAMPLES, "drive.toml")],
                         capture_output=True, text=True, timeout=TIMEOUT)
    assert bad.returncode == 2 and "turnaround" in bad.stderr, bad.stderr
