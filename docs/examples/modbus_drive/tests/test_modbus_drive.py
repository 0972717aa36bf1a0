"""The modbus_drive application on the emulated ISA 486 board, between a
plant master and a simulated drive.

The board boots the application with exact emulated time (-icount). Its
first RS-485 port (COM2, the controller's slave 1) and its second (COM3,
where its master polls the drive) are each bridged to a pseudo-terminal:
the plant master is dcos-modbus (libmodbus) on COM2's, the drive is
dcos-modbus-sim with share/dcos/modbus/drive.toml (slave 17) on COM3's.
Both tools come with DCOS (bin/), found next to the lab's own Python
package, so these tests run the same against the source tree's staged SDK
and an installed DCOS.

Emulated time runs faster than the host's while the controller idles, so
every wait here is for an emulated event (a counter on the console), and the
real-time bounds only fail a test that hangs.
"""

import json
import pathlib
import re
import subprocess

import dcoslab
import pytest
from dcoslab.serial_line import SerialLine
from dcoslab.waiting import wait_until

SHARE = pathlib.Path(dcoslab.__file__).resolve().parents[2]
BIN = SHARE.parents[1] / "bin"
DRIVE_TOML = SHARE / "modbus" / "drive.toml"
WAIT = 60.0
# The drive answers a few milliseconds after a request, as a real one does.
# The emulated 16550 hands the controller's request over at once rather than
# at 19200 baud, so an instant answer could arrive before the controller's
# own frame has left its shift register, where no real answer can be.
TURNAROUND_MS = 3

DRIVE = re.compile(r"drive: request (?P<requested>\d+) rpm run (?P<run>\d), setpoint (?P<setpoint>\d+) rpm; "
                   r"speed (?P<speed>\d+) rpm, temperature (?P<temperature>\d+)\.\d C, at speed (?P<at_speed>\d), "
                   r"answering (?P<answering>\d)")
CONTROL = re.compile(r"control: cycles (?P<cycles>\d+), drive pages (?P<pages>\d+), losses (?P<losses>\d+), "
                     r"failures (?P<failures>\d+)")


def drive_state(emulator):
    output = emulator.command("drive")
    drive, control = DRIVE.search(output), CONTROL.search(output)
    assert drive and control, f"unexpected `drive` output {output!r}"
    return {key: int(value) for key, value in {**drive.groupdict(), **control.groupdict()}.items()}


def wait_drive(emulator, predicate, what):
    """Runs `drive` until predicate holds: an event in the controller's time."""
    return wait_until(lambda: drive_state(emulator), predicate, what, emulator, timeout=WAIT)


def poll_lines(emulator):
    """`modbus poll` as {entry: (done, ok, timeouts, last)}."""
    output = emulator.command("modbus poll")
    entries = {}
    for line in output.splitlines():
        words = line.split()
        if len(words) >= 13 and words[0] in ("drive-values", "at-speed", "setpoint", "run"):
            entries[words[0]] = {"done": int(words[6]), "ok": int(words[7]), "timeouts": int(words[9]),
                                 "last": " ".join(words[12:])}
    assert len(entries) == 4, f"unexpected `modbus poll` output {output!r}"
    return entries


class Drive:
    """dcos-modbus-sim playing the drive on COM3's pseudo-terminal."""

    def __init__(self, line):
        self.process = subprocess.Popen([str(BIN / "dcos-modbus-sim"), "-d", line.pty_path, "-b", "19200",
                                         "--turnaround", str(TURNAROUND_MS), "--json", str(DRIVE_TOML)],
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        ready = json.loads(self.process.stdout.readline() or "{}")
        assert ready.get("event") == "ready" or "ready" in json.dumps(ready), (ready, self.process.stderr.read())

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            self.process.wait(timeout=10)


@pytest.fixture
def plant(boot, dcos_board, dcos_image):
    """The application booted, COM2 and COM3 bridged, the drive answering on COM3."""
    emulator = boot(dcos_board, dcos_image, icount=True, serial_sockets=["rs485", "rs485b"])
    emulator.expect(r"application 'modbus_drive' started: 1 task, 4 publishers")
    emulator.expect("dcos> ")
    master_line = SerialLine(emulator.serial_socket_path("rs485"), bridge=True)
    drive_line = SerialLine(emulator.serial_socket_path("rs485b"), bridge=True)
    drive = Drive(drive_line)
    yield emulator, master_line, drive_line, drive
    drive.stop()
    master_line.close()
    drive_line.close()


def plant_master(emulator, line, *arguments):
    """One dcos-modbus (libmodbus) transaction with the controller's slave 1."""
    wait_until(lambda: emulator.command("modbus state"), lambda state: "receiver idle" in state,
               "COM2's receiver idle", emulator, timeout=WAIT, pause=0)
    result = subprocess.run([str(BIN / "dcos-modbus"), "-d", line.pty_path, "-b", "19200", "-a", "1", "-r", "0",
                             "--json", *arguments], capture_output=True, text=True, timeout=WAIT)
    assert result.returncode == 0, (arguments, result.stdout, result.stderr, emulator.transcript)
    return json.loads(result.stdout)


def test_the_plant_master_runs_the_drive_through_the_controller(plant):
    emulator, master_line, _, _ = plant
    wait_drive(emulator, lambda s: s["answering"] == 1, "the drive answering")
    plant_master(emulator, master_line, "write-registers", "0=1500")
    plant_master(emulator, master_line, "write-coil", "0", "1")
    # The drive ramps at 500 rpm/s (in the host's time: it is a host program).
    state = wait_drive(emulator, lambda s: abs(s["speed"] - 1500) <= 5 and s["at_speed"] == 1, "the drive at speed")
    assert (state["requested"], state["run"], state["setpoint"]) == (1500, 1, 1500), state
    assert abs(state["speed"] - 1500) <= 5 and 44 <= state["temperature"] <= 46, state
    values = plant_master(emulator, master_line, "read-input-registers", "0", "3")["values"]
    assert abs(values[0] - 1500) <= 5 and 440 <= values[1] <= 460 and values[2] == 1500, values
    assert plant_master(emulator, master_line, "read-discrete-inputs", "0", "2")["values"] == [True, True]
    # Every entry's latest exchange succeeded. The drive is a wall-clock
    # program: under load it may miss a request now and then, which the
    # next round of the schedule retries, so this waits for a round in
    # which every entry's last answer is ok rather than reading one moment.
    wait_until(lambda: poll_lines(emulator),
               lambda e: all(entry["last"] == "ok" and entry["ok"] > 0 for entry in e.values()),
               "every entry answered", emulator, timeout=WAIT)
    assert drive_state(emulator)["failures"] == 0


def test_a_request_above_the_drives_limit_is_clamped(plant):
    emulator, master_line, _, _ = plant
    plant_master(emulator, master_line, "write-registers", "0=5000")
    state = wait_drive(emulator, lambda s: s["requested"] == 5000, "the request read")
    assert state["setpoint"] == 3000, state
    assert plant_master(emulator, master_line, "read-input-registers", "2", "1")["values"] == [3000]


def test_a_drive_that_stops_answering_is_noticed_and_the_controller_goes_on(plant):
    emulator, master_line, _, drive = plant
    wait_drive(emulator, lambda s: s["answering"] == 1, "the drive answering")
    # Time-outs counted before the stop (a host simulator that missed a
    # request under load) are not the ones this test waits for.
    earlier = poll_lines(emulator)["drive-values"]["timeouts"]
    drive.stop()
    state = wait_drive(emulator, lambda s: s["answering"] == 0, "the drive lost")
    assert state["losses"] == 1, state
    # Each entry now takes two transmissions of a 1 s time-out, so the
    # schedule comes round to the drive's values only seconds later.
    entries = wait_until(lambda: poll_lines(emulator), lambda e: e["drive-values"]["timeouts"] > earlier,
                         "a time-out of the drive's values", emulator, timeout=WAIT)
    assert entries["drive-values"]["last"] == "error: response time-out", entries
    # The controller goes on: its control task runs, and the plant master
    # reads the drive's loss in the status it serves.
    cycles = state["cycles"]
    assert plant_master(emulator, master_line, "read-discrete-inputs", "0", "2")["values"] == [False, False]
    wait_drive(emulator, lambda s: s["cycles"] > cycles + 10, "more control cycles")
