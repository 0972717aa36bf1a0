"""The I/O board driver (drivers/iobus) and its console command on the emulated 486 board.

The on-target tests in tests_renode/target/IobusDriverTest.cpp exercise the
driver through the system agent; most run on the board as wired (isa-mfio at
0x300, IRQ 5, loopback), the others on a machine without the board or with
one of the model's faults. The console tests drive `iobus` on the production
image, including the bring-up report of docs/iobus/bringup-protocol.md.
Register-level behaviour of the model itself is tested in test_isa_mfio_model.py.
"""

import re

import pytest

from dcoslab.target import run_target_test

MFIO = "isa-mfio"

IOBUS_TARGET_TESTS = [
    "iobusprobe",     # probe finds the board at 0x300, and an empty slot is NotFound
    "iobusabsent",    # without the board: Probe and Open fail with NotFound, nothing is written
    "iobusconflict",  # ports over COM1, COM1's IRQ, two boards overlapping: refused, both claimants named
    "iobusirq",       # interrupt-driven conversions, every channel: exact loopback codes, one interrupt each
    "iobuspoll",      # polled conversions: results at once, no interrupts
    "iobusfallback",  # with the no-irq fault: the result still arrives, one missed interrupt, then polled mode
    "iobusgain",      # gain switching per channel: 2049 reads 2049, 2058, 2148, 3048
    "iobusoverrange",  # saturation at x1000 and x100 with the overrange flag, none at x1
    "iobususer",      # a user task opens, writes AO and DO, reads DI, AO and AI, closes; cannot install
]

# How each test's machine is booted; the default is the board as wired.
BOOT_OPTIONS = {
    "iobusabsent": {"without_devices": [MFIO]},
    "iobusfallback": {"device_properties": {MFIO: {"no-irq": "on"}}},
}


@pytest.mark.parametrize("name", IOBUS_TARGET_TESTS)
def test_iobus_driver(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True, **BOOT_OPTIONS.get(name, {})), name)


def test_iobus_tests_pass_again_in_the_same_boot(boot, isa486):
    """A board installed again starts its counters afresh, so a test run twice passes twice."""
    emulator = boot(isa486, "test", icount=True)
    for name in ("iobusoverrange", "iobusirq", "iobusoverrange"):
        emulator.expect(r"dcos> ")
        emulator.send(f"test {name}\r")
        verdict = emulator.expect(rf"TEST {name}: (PASS|FAIL)").group(1)
        assert verdict == b"PASS", f"{name} failed when run again:\n{emulator.transcript}"


BRINGUP_LINE = re.compile(r"^BRINGUP .*$", re.MULTILINE)
ADC_LINE = re.compile(
    r"^BRINGUP ADC channel=(\d) gain=(\d+) offset_lsb=(-?\d+\.\d\d) gain_error_pct=(-?\d+\.\d\d) "
    r"max_error_lsb=(\d+\.\d\d) noise_lsb=(\d+\.\d\d) noise_pooled_lsb=(\d+\.\d\d) noise_dof=(\d+) "
    r"samples=(\d+) overrange=(\d+) points=((?:\d+:\d+\.\d,?)+)$"
)


def bringup(emulator, arguments=""):
    emulator.expect(r"dcos> ")
    emulator.send(f"iobus bringup{arguments}\r")
    emulator.expect(r"BRINGUP END failures=\d+", timeout=300)
    emulator.expect(r"dcos> ")
    return BRINGUP_LINE.findall(emulator.transcript.replace("\r", ""))


def test_bringup_on_a_healthy_board_reports_every_step_and_no_failure(boot, isa486):
    lines = bringup(boot(isa486, icount=True))
    assert lines[0] == "BRINGUP BEGIN base=0x300 irq=5", lines
    assert lines[1] == "BRINGUP PROBE ok id=4d46 revision=0100", lines
    assert re.fullmatch(r"BRINGUP FIRMWARE version=\d+\.\d+\.\d+ revision=\S+", lines[2]), lines
    assert lines[3] == "BRINGUP DIO walking-ones ok", lines
    assert lines[4] == "BRINGUP DIO walking-zeros ok", lines
    adc = [ADC_LINE.match(line) for line in lines[5:-2]]
    assert all(adc), lines
    assert [(int(m.group(1)), int(m.group(2))) for m in adc] == [
        (channel, gain) for channel in range(8) for gain in (1, 10, 100, 1000)
    ]
    for match in adc:
        gain = int(match.group(2))
        assert match.group(3, 4, 5, 6, 7, 10) == ("0.00", "0.00", "0.00", "0.00", "0.00", "0"), match.group(0)
        points = match.group(11).split(",")
        samples = int(match.group(9))
        assert int(match.group(8)) == len(points) * (samples - 1), match.group(0)
        for point in points:
            output, mean = point.split(":")
            ideal = 2048 + (int(output) - 2048) * gain
            assert float(mean) == ideal, match.group(0)
    assert re.fullmatch(r"BRINGUP IRQ delivered=64 requested=64 latency_min_ns=\d+ latency_max_ns=\d+", lines[-2])
    assert lines[-1] == "BRINGUP END failures=0"


def test_bringup_without_a_board_reports_it_absent(boot, isa486):
    lines = bringup(boot(isa486, icount=True, without_devices=[MFIO]))
    assert lines == ["BRINGUP BEGIN base=0x300 irq=5", "BRINGUP PROBE absent", "BRINGUP END failures=1"]


@pytest.mark.parametrize(
    "properties, expected",
    [
        ({"stuck-di-bit": "4", "stuck-di-value": "0"},
         ["BRINGUP DIO walking-ones fail bits=0x0010 wrote=0x0010 read=0x0000",
          "BRINGUP DIO walking-zeros fail bits=0x0010 wrote=0xfffe read=0xffee"]),
        ({"no-irq": "on"}, ["BRINGUP IRQ delivered=0 requested=64 latency_min_ns=0 latency_max_ns=0"]),
    ],
    ids=["stuck-di-bit", "no-irq"],
)
def test_bringup_names_the_injected_fault(boot, isa486, properties, expected):
    lines = bringup(boot(isa486, icount=True, device_properties={MFIO: properties}))
    for line in expected:
        assert line in lines, lines
    failures = int(lines[-1].split("=")[1])
    assert failures == (2 if "stuck-di-bit" in properties else 1), lines


def test_bringup_counts_a_dead_channel_at_every_gain(boot, isa486):
    lines = bringup(boot(isa486, icount=True, device_properties={MFIO: {"dead-adc-channel": "3"}}))
    dead = [line for line in lines if line.startswith("BRINGUP ADC channel=3 ")]
    assert len(dead) == 4
    for line in dead:
        assert "gain_error_pct=-100.00" in line, line
    assert lines[-1] == "BRINGUP END failures=4"


def test_bringup_reports_a_resource_conflict(boot, isa486):
    emulator = boot(isa486, icount=True)
    lines = bringup(emulator, " 0x3f8 4")
    assert lines == ["BRINGUP BEGIN base=0x3f8 irq=4", "BRINGUP END failures=1"], lines
    assert "error: ports 0x3f8-0x437 wanted by mfio0 are held by com1 (0x3f8-0x3ff)" in emulator.transcript


def test_iobus_console_commands(boot, isa486):
    emulator = boot(isa486, icount=True)
    emulator.expect(r"dcos> ")
    assert "mfio0 at 0x300 irq 5: present, id 0x4d46 revision 1.0" in emulator.command("iobus probe")
    assert "ao2 code=3072 value=+5.000000 V" in emulator.command("iobus write ao2 3072")
    assert "ai2 code=3072 gain=1 value=+5.000000 V overrange=0" in emulator.command("iobus read 2")
    assert "ai2 gain=10" in emulator.command("iobus gain 2 10")
    assert "ai2 code=4095 gain=10 value=+0.999512 V overrange=1" in emulator.command("iobus read ai2")
    assert "do=0x1234" in emulator.command("iobus write 17 0x1234")
    assert "di=0x1234" in emulator.command("iobus read di")
    resources = emulator.command("iobus resources")
    assert re.search(r"mfio0 +0x300-0x33f +5", resources), resources
    assert re.search(r"com1 +0x3f8-0x3ff +4", resources), resources
    assert "error: IRQ 4 wanted by mfio0 is held by com1" in emulator.command("iobus probe 0x300 4")
    # A bad argument is named with what would have been right, instead of
    # the usage of every subcommand.
    assert "usage: iobus probe [base] [irq] | read <channel>" in emulator.command("iobus")
    for bad, error in (
            ("iobus read", "error: read takes one channel\r\nusage: iobus read <channel>"),
            ("iobus read 18", "error: unknown channel '18': the channels are ai0-ai7, ao0-ao7, di and do, or 0-17"),
            ("iobus read ai9", "error: unknown channel 'ai9'"),
            ("iobus write ai0 1", "error: ai0 is an input; write takes an analog output ao0-ao7 or do"),
            ("iobus write di 1", "error: di is an input"),
            ("iobus write ao0 4096", "error: value '4096' is out of range for ao0: 0 to 4095 (0xfff)"),
            ("iobus write do 0x10000", "error: value '0x10000' is out of range for do: 0 to 65535 (0xffff)"),
            ("iobus write ao0 volts", "error: value 'volts' is out of range for ao0"),
            ("iobus gain 0 20", "error: gain '20' is not one of 1, 10, 100 and 1000"),
            ("iobus gain ao0 10", "error: ao0 has no gain; the programmable gain is on the analog inputs ai0-ai7"),
            ("iobus probe 0x301", "error: base '0x301' is not an even port from 0x000 to 0xffc0\r\n"
                                  "usage: iobus probe [base] [irq]"),
            ("iobus probe 0x300 16", "error: irq '16' is not an interrupt line from 0 to 15"),
            ("iobus bringup 0x300 5 7", "error: too many arguments"),
            ("iobus stats now", "error: stats takes no arguments"),
            ("iobus frobnicate", "error: unknown subcommand 'frobnicate': the subcommands are probe read write "
                                 "gain bringup resources stats")):
        answer = emulator.command(bad)
        assert error in answer, (bad, answer)
        assert "| read <channel>" not in answer, (bad, answer)


def test_iobus_without_a_board(boot, isa486):
    emulator = boot(isa486, icount=True, without_devices=[MFIO])
    emulator.expect(r"dcos> ")
    assert "mfio0 at 0x300 irq 5: absent (not found)" in emulator.command("iobus probe")
    assert "error: no I/O board at 0x300: not found" in emulator.command("iobus read 0")
