"""The emulator's multi-function I/O board model (isa-mfio), without a driver.

The on-target tests in tests_renode/target/MfioModelTest.cpp poke the
registers from the controller and check every behaviour of the register map
(docs/iobus/mfio-register-map.md) on the board as the board file wires it:
0x300, IRQ 5, loopback. The tests below change the model's properties for
one run (faults, noise, conversion time, the plant wiring) and read what the
`mfiodump` probe prints. All of them run under -icount, so the emulated
times and the noise sequence are exact and repeatable.
"""

import math
import os
import re
import socket
import subprocess
import sys
import tempfile
import threading

import pytest

from dcoslab.board import EXIT_FAIL, EXIT_PASS, REPOSITORY
from dcoslab.built_emulator import EmulatorNotBuilt, built_emulator_path
from dcoslab.emulator import EmulatorError
from dcoslab.logic_analyzer import measure, read_trace
from dcoslab.target import run_target_test

MFIO_MODEL_TARGET_TESTS = [
    "mfioreg",     # ID, REVISION, reset values, read-back, read-only and write-only registers, RESET, 8-bit access
    "mfiodio",     # DO drives DI: walking ones and zeros
    "mfioadc",     # DAC n drives ADC n at gain 1 with the exact code, every channel
    "mfiogain",    # each gain per channel, saturation and the overrange flag
    "mfiotiming",  # BUSY then DONE after 20 us, DONE latched, ADC_START ignored while busy, sample at start
    "mfioirq",     # IRQ_ENABLE raises IRQ 5 and IRQ_PENDING, IRQ_ACK clears them, one interrupt per conversion
    "mfiodump",    # the probe the tests below read, on the board as wired
]

MFIO = "isa-mfio"
# The DAC codes mfiodump drives: channel n at 0x400 + 0x100 n.
DUMP_DAC = [0x400 + 0x100 * channel for channel in range(8)]


@pytest.mark.parametrize("name", MFIO_MODEL_TARGET_TESTS)
def test_mfio_model(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)


def run_dump(boot, isa486, properties=None, extra_args=(), without_devices=(), expect_status=EXIT_PASS):
    """Boots the test image with the given isa-mfio properties and parses `test mfiodump`."""
    emulator = boot(isa486, "test", icount=True, device_properties={MFIO: properties} if properties else None,
                    extra_args=extra_args, without_devices=without_devices)
    emulator.expect(r"dcos> ")
    emulator.send("test mfiodump --exit\r")
    emulator.expect(r"TEST mfiodump: (PASS|FAIL)", timeout=120)
    emulator.expect_exit(expect_status, timeout=120)
    text = emulator.transcript
    result = {
        "emulator": emulator,
        "id": int(re.search(r"MFIO id=([0-9a-f]{4})", text).group(1), 16),
        "adc": {int(ch): int(data, 16) for ch, data in re.findall(r"MFIO adc ch=(\d) data=([0-9a-f]{4})", text)},
        "repeat": [int(data, 16) for data in re.findall(r"MFIO repeat ch=0 data=([0-9a-f]{4})", text)],
        "dio": [(int(do, 16), int(di, 16)) for do, di in re.findall(r"MFIO dio do=([0-9a-f]{4}) di=([0-9a-f]{4})", text)],
    }
    conversion = re.search(r"MFIO conversion ns=(\d+)", text)
    result["conversion_ns"] = int(conversion.group(1)) if conversion else None
    irq = re.search(r"MFIO irq count=(\d+) status=([0-9a-f]{4})", text)
    result["irq_count"], result["irq_status"] = (int(irq.group(1)), int(irq.group(2), 16)) if irq else (None, None)
    return result


def adc_code(volts, gain=1):
    """The map's converter: round((Vin x gain + 10 V) x 4096 / 20 V), clamped, with the overrange flag."""
    code = math.floor((volts * gain + 10.0) * 4096.0 / 20.0 + 0.5)
    if code < 0:
        return 0x8000
    if code > 4095:
        return 0x8000 | 4095
    return code


def dac_volts(code):
    return (code - 2048) * 20.0 / 4096.0


# -- the board as wired, and absent ------------------------------------------------


def test_loopback_dump_is_exact(boot, isa486):
    dump = run_dump(boot, isa486)
    assert dump["id"] == 0x4D46
    assert dump["adc"] == {channel: (channel << 12) | DUMP_DAC[channel] for channel in range(8)}
    assert dump["repeat"] == [DUMP_DAC[0]] * 8
    assert dump["dio"] == [(0x5A3C, 0x5A3C), (0x0000, 0x0000), (0xFFFF, 0xFFFF)]
    assert 19000 <= dump["conversion_ns"] <= 35000
    # One interrupt; the dump does not acknowledge it, so it is still pending.
    assert (dump["irq_count"], dump["irq_status"]) == (1, 0x000A)


def test_board_left_out_reads_as_an_empty_bus(boot, isa486):
    dump = run_dump(boot, isa486, without_devices=[MFIO], expect_status=EXIT_FAIL)
    assert dump["id"] == 0xFFFF
    assert "no I/O board at 0x300: ID reads ffff" in dump["emulator"].transcript


def test_make_run_boots_the_board_wired_in_loopback():
    command = subprocess.run([sys.executable, os.path.join(REPOSITORY, "tests_renode", "launch.py"), "--print-command"],
                             capture_output=True, text=True, timeout=60, check=True).stdout.split()
    assert command[0] == built_emulator_path()
    assert "isa-mfio,iobase=0x300,irq=5" in command
    # The isapc machine would otherwise put an NE2000 on the board's ports.
    assert command[command.index("-nic") + 1] == "none"


def test_only_the_built_emulator_can_be_named_built():
    with pytest.raises(EmulatorNotBuilt, match="the build makes only qemu-system-i386, qemu-system-x86_64"):
        built_emulator_path("qemu-system-arm")


@pytest.mark.parametrize("properties, message", [
    ({"stuck-di-bit": "16"}, "stuck-di-bit 16 is not -1 \\(none\\) or a DI bit 0..15"),
    ({"dead-adc-channel": "8"}, "dead-adc-channel 8 is not -1 \\(none\\) or a channel 0..7"),
    ({"wiring": "plant"}, "wiring=plant needs a plant chardev"),
    ({"wiring": "radio"}, "wiring 'radio' is neither 'loopback' nor 'plant'"),
    ({"noise-lsb": "lots"}, "noise-lsb 'lots' is not a number >= 0"),
    ({"iobase": "0x301"}, "iobase 0x301 must be a multiple of 0x40"),
])
def test_bad_properties_are_refused_at_start(boot, isa486, properties, message):
    # The emulator opens the console socket before it creates devices, so it
    # may refuse the device just after the harness has connected.
    try:
        emulator = boot(isa486, "test", device_properties={MFIO: properties})
    except EmulatorError as error:
        said = str(error)
    else:
        assert emulator.wait_exit(timeout=60) == 1
        said = emulator.emulator_messages()
    assert re.search(message, said), said


# -- fault injection --------------------------------------------------------------


@pytest.mark.parametrize("bit, level", [(4, 0), (0, 1), (15, 1)])
def test_stuck_di_bit(boot, isa486, bit, level):
    dump = run_dump(boot, isa486, {"stuck-di-bit": str(bit), "stuck-di-value": str(level)})
    mask = 1 << bit
    for do, di in dump["dio"]:
        assert di == ((do | mask) if level else (do & ~mask)), f"DO {do:04x} gave DI {di:04x}"
    # Only DI is affected: the analog side is untouched.
    assert dump["adc"][0] == DUMP_DAC[0]


def test_dead_adc_channel(boot, isa486):
    dump = run_dump(boot, isa486, {"dead-adc-channel": "2"})
    for channel in range(8):
        expected = 0x800 if channel == 2 else DUMP_DAC[channel]
        assert dump["adc"][channel] == (channel << 12) | expected, f"channel {channel}"


def test_no_irq_completes_conversions_without_the_interrupt(boot, isa486):
    dump = run_dump(boot, isa486, {"no-irq": "on"})
    assert dump["irq_count"] == 0
    # DONE, but the board is not requesting its interrupt.
    assert dump["irq_status"] == 0x0002
    assert dump["adc"][7] == 0x7000 | DUMP_DAC[7]


def test_conversion_time_is_a_property(boot, isa486):
    dump = run_dump(boot, isa486, {"conversion-ns": "2000000"})
    assert 1999000 <= dump["conversion_ns"] <= 2015000


# -- deterministic noise ------------------------------------------------------------


def codes(dump):
    return [dump["adc"][channel] for channel in range(8)] + dump["repeat"]


def test_noise_is_deterministic_from_the_seed(boot, isa486):
    noisy = {"noise-lsb": "2", "noise-seed": "7"}
    first = codes(run_dump(boot, isa486, noisy))
    second = codes(run_dump(boot, isa486, noisy))
    other_seed = codes(run_dump(boot, isa486, {"noise-lsb": "2", "noise-seed": "8"}))
    clean = [(channel << 12) | DUMP_DAC[channel] for channel in range(8)] + [DUMP_DAC[0]] * 8
    assert first == second, "the same seed gives the same codes"
    assert first != clean, "noise-lsb > 0 changes the codes"
    assert other_seed != first, "another seed gives other codes"
    # Around the right value, with about the right spread.
    errors = [(code & 0xFFF) - (expected & 0xFFF) for code, expected in zip(first, clean)]
    assert max(abs(error) for error in errors) <= 10
    rms = math.sqrt(sum(error * error for error in errors) / len(errors))
    assert 0.8 <= rms <= 4.0, f"noise of 2 LSB gave an RMS error of {rms:.2f} LSB: {errors}"


def test_noise_of_zero_leaves_the_codes_exact_whatever_the_seed(boot, isa486):
    dump = run_dump(boot, isa486, {"noise-lsb": "0", "noise-seed": "12345"})
    assert dump["repeat"] == [DUMP_DAC[0]] * 8


# -- the plant wiring ---------------------------------------------------------------


class PlantStub:
    """A tiny plant simulator: a Unix-socket server answering SAMPLE lines.

    reply(index, fields) returns the line to send back (without the
    newline) or None to stay silent; every SAMPLE line is recorded.
    """

    def __init__(self, reply):
        self.reply = reply
        self.samples = []
        self.errors = []
        self._directory = tempfile.TemporaryDirectory(prefix="dcos-plant-")
        self.path = os.path.join(self._directory.name, "plant.sock")
        self._server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self._server.bind(self.path)
        self._server.listen(1)
        self._server.settimeout(60)
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def chardev_args(self):
        return ["-chardev", f"socket,id=plant,path={self.path}"]

    def _serve(self):
        try:
            connection, _ = self._server.accept()
        except OSError as error:
            self.errors.append(f"no connection: {error}")
            return
        connection.settimeout(120)
        buffer = b""
        with connection:
            while True:
                try:
                    data = connection.recv(4096)
                except OSError:
                    return
                if not data:
                    return
                buffer += data
                while b"\n" in buffer:
                    line, buffer = buffer.split(b"\n", 1)
                    fields = line.decode("ascii").split()
                    if not fields or fields[0] != "SAMPLE":
                        self.errors.append(f"unexpected line {line!r}")
                        continue
                    self.samples.append(fields)
                    answer = self.reply(len(self.samples) - 1, fields)
                    if answer is not None:
                        connection.sendall(answer.encode("ascii") + b"\n")

    def close(self):
        self._server.close()
        self._thread.join(timeout=5)
        self._directory.cleanup()


@pytest.fixture
def plant_stub():
    stubs = []

    def start(reply):
        stub = PlantStub(reply)
        stubs.append(stub)
        return stub

    yield start
    for stub in stubs:
        stub.close()


PLANT_VOLTS = [-4.0 + 1.25 * channel + 0.000123 for channel in range(8)]


def input_line(volts, digital_in):
    return "INPUT " + " ".join(f"{value:.6f}" for value in volts) + f" {digital_in:04x}"


def test_plant_wiring_exchanges_samples_for_inputs(boot, isa486, plant_stub):
    stub = plant_stub(lambda index, fields: input_line(PLANT_VOLTS, 0x1234))
    dump = run_dump(boot, isa486, {"wiring": "plant", "plant": "plant"}, extra_args=stub.chardev_args())
    assert stub.errors == []
    # The inputs are the plant's, through the converter at gain 1.
    assert dump["adc"] == {channel: (channel << 12) | adc_code(PLANT_VOLTS[channel]) for channel in range(8)}
    assert dump["repeat"] == [adc_code(PLANT_VOLTS[0])] * 8
    # DI is the plant's, whatever DO says.
    assert [di for _, di in dump["dio"]] == [0x1234] * 3
    # One SAMPLE per conversion: 8 + 8 repeats + the timed one + the interrupt one.
    assert len(stub.samples) == 18
    first = stub.samples[0]
    assert len(first) == 11
    assert [float(value) for value in first[2:10]] == [dac_volts(code) for code in DUMP_DAC]
    assert first[10] == "5a3c"
    times = [int(sample[1]) for sample in stub.samples]
    assert times == sorted(times) and times[0] > 0
    # Conversions of the repeat loop are a conversion time and a little apart.
    assert 20000 <= times[9] - times[8] <= 60000
    assert "missed" not in dump["emulator"].emulator_messages()


def test_plant_on_write_tells_the_plant_of_each_dac_write(boot, isa486, plant_stub):
    """With plant-on-write every DAC write is an exchange too, carrying the
    new value at the write's time; conversions exchange as before."""
    stub = plant_stub(lambda index, fields: input_line(PLANT_VOLTS, 0x1234))
    dump = run_dump(boot, isa486, {"wiring": "plant", "plant": "plant", "plant-on-write": "on"},
                    extra_args=stub.chardev_args())
    assert stub.errors == []
    # mfiodump writes DAC0 to DAC7 once each, then converts 18 times as without the switch.
    assert len(stub.samples) == 8 + 18
    for channel, fields in enumerate(stub.samples[:8]):
        volts = [float(value) for value in fields[2:10]]
        assert volts == [dac_volts(DUMP_DAC[n]) if n <= channel else 0.0 for n in range(8)], (channel, fields)
    times = [int(sample[1]) for sample in stub.samples]
    assert times == sorted(times)
    # The conversions still read the plant's inputs.
    assert dump["adc"] == {channel: (channel << 12) | adc_code(PLANT_VOLTS[channel]) for channel in range(8)}


def test_plant_silence_and_garbage_keep_the_previous_inputs(boot, isa486, plant_stub):
    before = input_line([1.0] * 8, 0x0001)
    after = input_line([-1.0] * 8, 0x0002)

    def reply(index, fields):
        if index == 1:
            return None  # silent: the model waits 1 s of host time, then goes on
        if index == 2:
            return "INPUT 1 2 3"
        return before if index == 0 else after

    stub = plant_stub(reply)
    dump = run_dump(boot, isa486, {"wiring": "plant", "plant": "plant"}, extra_args=stub.chardev_args())
    assert dump["adc"][0] == adc_code(1.0)
    assert dump["adc"][1] == 0x1000 | adc_code(1.0), "after a silent plant the previous inputs stay"
    assert dump["adc"][2] == 0x2000 | adc_code(1.0), "after a malformed reply the previous inputs stay"
    assert dump["adc"][3] == 0x3000 | adc_code(-1.0)
    assert [di for _, di in dump["dio"]] == [0x0002] * 3
    messages = dump["emulator"].emulator_messages()
    assert "plant exchange 1 missed (no INPUT line within 1 s)" in messages
    assert "plant exchange 2 missed (malformed INPUT line)" in messages
    assert "plant exchange 3 missed" not in messages


def test_plant_saturation_sets_the_overrange_flag(boot, isa486, plant_stub):
    volts = [12.0, -12.0, 9.99, -10.0, 0.0, 0.0, 0.0, 0.0]
    stub = plant_stub(lambda index, fields: input_line(volts, 0))
    dump = run_dump(boot, isa486, {"wiring": "plant", "plant": "plant"}, extra_args=stub.chardev_args())
    assert dump["adc"][0] == 0x8000 | 4095
    assert dump["adc"][1] == 0x9000 | 0
    assert dump["adc"][2] == 0x2000 | adc_code(9.99)
    assert dump["adc"][3] == 0x3000 | 0


# -- the logic analyzer on DO ----------------------------------------------------------

# What the console writes to DO, in order; the repeated value is no change,
# so it must give no trace line.
TRACED_DO_WRITES = [0x0001, 0x0001, 0x8000, 0xA5A5, 0x0000]


@pytest.mark.parametrize("wiring", ["loopback", "plant"])
def test_do_trace_records_every_change_in_emulated_time(boot, isa486, plant_stub, tmp_path, wiring):
    trace = tmp_path / "do.trace"
    properties = {"do-trace": "dotrace"}
    extra_args = ["-chardev", f"file,id=dotrace,path={trace}"]
    if wiring == "plant":
        stub = plant_stub(lambda index, fields: input_line([0.0] * 8, 0))
        properties.update({"wiring": "plant", "plant": "plant"})
        extra_args += stub.chardev_args()
    emulator = boot(isa486, "test", icount=True, device_properties={MFIO: properties}, extra_args=extra_args)
    emulator.expect(r"dcos> ")
    for value in TRACED_DO_WRITES:
        assert f"do=0x{value:04x}" in emulator.command(f"iobus write do 0x{value:04x}")
    # The model writes each line before the guest's OUT instruction completes,
    # so the trace is complete once the last command has printed its prompt.
    samples = read_trace(trace)
    values = [sample.value for sample in samples]
    times = [sample.time_ns for sample in samples]
    # The power-on reset states the level, then one line per change, in order.
    assert values == [0x0000, 0x0001, 0x8000, 0xA5A5, 0x0000], samples
    assert times[0] == 0
    assert times == sorted(times), samples
    assert len(set(times[1:])) == len(times) - 1, "each command runs at a later emulated time"
    # The analyzer sees bit 0 rise, fall and rise again: one cycle, exactly
    # the times of the lines.
    cycle = measure(samples, 0)
    assert cycle.periods_ns == (times[3] - times[1],)
    assert cycle.high_times_ns == (times[2] - times[1],)
    assert "DO trace line" not in emulator.emulator_messages()
    if wiring == "plant":
        assert stub.errors == []
