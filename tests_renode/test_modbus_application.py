"""The controller's slave serving an application's Modbus register map, on
the RS-485 port (COM2), in emulated time.

The application (tests_renode/modbus/mapped_app) declares its map and its
slave (address 17, 19200 baud 8E1), so the line starts at boot and serves
the map before any of its tasks runs; it is built with the staged SDK like
any application outside the tree. The test holds COM2's Unix socket and
builds and checks every frame with pymodbus's RTU framer, as
test_modbus_rs485.py does (its module docstring says why a frame written in
one write arrives whole under -icount, and why the test waits for the
controller's receiver to be idle before each frame); libmodbus, through our
dcos-modbus on a pseudo-terminal bridged to the socket, is a master too.

What the map binds: holding registers 0-3 and coils 0-7 to the "command"
publisher, which the line writes and the application's "control" task
reads; input registers 0-3 and discrete inputs 0-7 to "process", which the
task publishes from what it read (register 0 + 1000, register 1 x 2, its
cycle count, the coils echoed); input registers 10-13 to "command" again,
read only; input registers 100-101 to the I/O board's analog inputs 0-1 and
coils 100-103 to its digital outputs 0-3. The `mbmap` command prints what
the task read last.
"""

import os
import re
import shutil
import subprocess

import pytest

pytest.importorskip("pymodbus")
from pymodbus.bit_read_message import ReadCoilsRequest, ReadDiscreteInputsRequest  # noqa: E402
from pymodbus.bit_write_message import WriteMultipleCoilsRequest, WriteSingleCoilRequest  # noqa: E402
from pymodbus.register_read_message import (  # noqa: E402
    ReadHoldingRegistersRequest,
    ReadInputRegistersRequest,
    ReadWriteMultipleRegistersRequest,
)
from pymodbus.register_write_message import WriteMultipleRegistersRequest, WriteSingleRegisterRequest  # noqa: E402

from dcoslab.board import REPOSITORY  # noqa: E402
from dcoslab.serial_line import SerialLine  # noqa: E402
from dcoslab.waiting import wait_until  # noqa: E402
from test_modbus_rs485 import BAUD, UNIT, dcos_modbus, exception_of, exchange, state  # noqa: E402

APPLICATION_MAKEFILE = os.path.join(REPOSITORY, "build", "sdk", "share", "dcos", "application.mk")
MBMAP = re.compile(r"mbmap: command (?P<command0>\d+) (?P<command1>\d+) enable 0x(?P<enable>[0-9a-f]{2}) "
                   r"updates (?P<updates>\d+) cycles (?P<cycles>\d+) errors (?P<errors>\d+)")


def build_application(tmp_path_factory, name):
    """tests_renode/modbus/<name> built against the staged SDK (`make sdk`); returns its image."""
    directory = tmp_path_factory.mktemp("apps") / name
    shutil.copytree(os.path.join(REPOSITORY, "tests_renode", "modbus", name), directory)
    result = subprocess.run(["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={directory}", "app"],
                            capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    return str(directory / "build" / f"{name}-486.elf")


@pytest.fixture(scope="session")
def mapped_image(tmp_path_factory):
    """The mapped application (tests_renode/modbus/mapped_app)."""
    return build_application(tmp_path_factory, "mapped_app")


@pytest.fixture(params=[False], ids=["socket"])
def mapped_line(request, boot, isa486, mapped_image):
    """The mapped application booted, COM2's bytes in the test's hands (param True: bridged to a pty)."""
    emulator = boot(isa486, mapped_image, icount=True, serial_sockets=["rs485"])
    emulator.expect(r"application 'mbmap' started: 1 task, 2 publishers")
    emulator.expect("dcos> ")
    line = SerialLine(emulator.serial_socket_path("rs485"), bridge=request.param)
    yield emulator, line
    line.close()


def seen(emulator):
    """What the application's control task read last, from `mbmap`."""
    output = emulator.command("mbmap")
    match = MBMAP.search(output)
    assert match, f"unexpected mbmap output {output!r}\n{emulator.transcript}"
    return {key: int(value, 16 if key == "enable" else 10) for key, value in match.groupdict().items()}


def wait_seen(emulator, predicate, what):
    """Runs `mbmap` until predicate holds: the application has read the master's write."""
    return wait_until(lambda: seen(emulator), predicate, what, emulator)


def test_the_line_serves_the_map_from_boot(mapped_line):
    emulator, _ = mapped_line
    out = emulator.command("modbus state")
    assert f"modbus: slave {UNIT} on COM2" in out and f"at {BAUD} baud 8E1" in out, out
    assert "serving: the register map of application 'mbmap', 7 entries, backend failures 0" in out, out
    out = emulator.command("app")
    assert f"modbus map, 7 entries, checked; served by slave {UNIT} on the RS-485 port at {BAUD} baud 8E1" in out, out


def test_every_table_is_read_and_written_where_the_application_reads_it(mapped_line):
    emulator, line = mapped_line
    # 10 and 06: the command publisher, which the application's task reads.
    answer, _ = exchange(emulator, line, WriteMultipleRegistersRequest(0, [1234, 4321, 7, 8], unit=UNIT))
    assert (answer.function_code, answer.address, answer.count) == (0x10, 0, 4), answer
    wait_seen(emulator, lambda s: (s["command0"], s["command1"]) == (1234, 4321), "registers 1234 4321")
    answer, _ = exchange(emulator, line, WriteSingleRegisterRequest(1, 500, unit=UNIT))
    assert (answer.function_code, answer.address, answer.value) == (0x06, 1, 500), answer
    wait_seen(emulator, lambda s: (s["command0"], s["command1"]) == (1234, 500), "register 1 at 500")
    # 03: what was written, the other bytes of the page kept.
    answer, _ = exchange(emulator, line, ReadHoldingRegistersRequest(0, 4, unit=UNIT))
    assert answer.registers == [1234, 500, 7, 8], answer
    # 0F and 05: the coils are bits of the same page, byte 8.
    answer, _ = exchange(emulator, line, WriteMultipleCoilsRequest(0, [True, False, True], unit=UNIT))
    assert (answer.function_code, answer.address, answer.count) == (0x0F, 0, 3), answer
    answer, _ = exchange(emulator, line, WriteSingleCoilRequest(7, True, unit=UNIT))
    assert (answer.function_code, answer.address, answer.value) == (0x05, 7, True), answer
    wait_seen(emulator, lambda s: s["enable"] == 0x85, "coils 0, 2 and 7")
    # The registers survived the coil writes: a page write keeps the bytes the request does not name.
    assert seen(emulator)["command0"] == 1234
    # 01.
    answer, _ = exchange(emulator, line, ReadCoilsRequest(0, 8, unit=UNIT))
    assert answer.bits[:8] == [True, False, True, False, False, False, False, True], answer
    # 04 and 02: what the application publishes from what it read.
    answer, _ = exchange(emulator, line, ReadInputRegistersRequest(0, 4, unit=UNIT))
    assert answer.registers[:2] == [2234, 1000], answer
    cycles = answer.registers[2] << 16 | answer.registers[3]
    assert cycles > 0
    answer, _ = exchange(emulator, line, ReadDiscreteInputsRequest(0, 8, unit=UNIT))
    assert answer.bits[:8] == [True, False, True, False, False, False, False, True], answer
    # The publication moves on: the cycle count is the application's, not a copy the line keeps.
    answer, _ = exchange(emulator, line, ReadInputRegistersRequest(2, 2, unit=UNIT))
    assert answer.registers[0] << 16 | answer.registers[1] > cycles, answer
    # 04 on the command page, read only, and 17 writing it and reading it back in one transaction.
    answer, _ = exchange(emulator, line, ReadInputRegistersRequest(10, 4, unit=UNIT))
    assert answer.registers == [1234, 500, 7, 8], answer
    answer, _ = exchange(emulator, line, ReadWriteMultipleRegistersRequest(
        read_address=0, read_count=4, write_address=2, write_registers=[70, 80], unit=UNIT))
    assert answer.registers == [1234, 500, 70, 80], answer
    # The I/O board: analog inputs as 12-bit codes, digital outputs written and read back.
    answer, _ = exchange(emulator, line, ReadInputRegistersRequest(100, 2, unit=UNIT))
    assert not answer.isError() and all(0 <= value <= 4095 for value in answer.registers), answer
    answer, _ = exchange(emulator, line, WriteMultipleCoilsRequest(100, [True, True, False, True], unit=UNIT))
    assert not answer.isError(), answer
    answer, _ = exchange(emulator, line, ReadCoilsRequest(100, 4, unit=UNIT))
    assert answer.bits[:4] == [True, True, False, True], answer
    values = seen(emulator)
    assert values["errors"] == 0, values
    counters = state(emulator)
    assert counters["slave.exceptions"] == 0, counters
    assert counters["frames.crc-errors"] == 0, counters


def test_unmapped_addresses_and_read_only_bindings_are_refused(mapped_line):
    emulator, line = mapped_line
    before = seen(emulator)["updates"]
    # 02: holding register 4 is past the command entry; a range reaching into it is refused whole.
    assert exception_of(exchange(emulator, line, ReadHoldingRegistersRequest(4, 1, unit=UNIT))[0]) == (3, 2)
    assert exception_of(exchange(emulator, line, WriteMultipleRegistersRequest(2, [9, 9, 9], unit=UNIT))[0]) == (16, 2)
    assert exception_of(exchange(emulator, line, ReadCoilsRequest(8, 1, unit=UNIT))[0]) == (1, 2)
    assert exception_of(exchange(emulator, line, ReadDiscreteInputsRequest(50, 1, unit=UNIT))[0]) == (2, 2)
    # The process page and the analog inputs are input registers only: as holding
    # registers those addresses do not exist, so a write to them is refused.
    assert exception_of(exchange(emulator, line, WriteSingleRegisterRequest(100, 1, unit=UNIT))[0]) == (6, 2)
    assert exception_of(exchange(emulator, line, WriteSingleRegisterRequest(10, 1, unit=UNIT))[0]) == (6, 2)
    # Nothing of a refused request was written: the application never saw a new command page.
    answer, _ = exchange(emulator, line, ReadHoldingRegistersRequest(0, 4, unit=UNIT))
    assert answer.registers == [0, 0, 0, 0], answer
    assert seen(emulator)["updates"] == before
    counters = state(emulator)
    assert counters["slave.exceptions"] == 6, counters


@pytest.mark.parametrize("mapped_line", [True], ids=["pty"], indirect=True)
def test_libmodbus_master_reads_and_writes_the_map(mapped_line):
    emulator, line = mapped_line
    status, answer, errors = dcos_modbus(emulator, line, "write-registers", "0=300,400")
    assert status == 0, (answer, errors, emulator.transcript)
    wait_seen(emulator, lambda s: (s["command0"], s["command1"]) == (300, 400), "registers 300 400")
    status, answer, errors = dcos_modbus(emulator, line, "read-input-registers", "0", "2")
    assert status == 0 and answer["values"] == [1300, 800], (answer, errors)
    status, answer, errors = dcos_modbus(emulator, line, "write-coil", "1", "1")
    assert status == 0, (answer, errors)
    wait_seen(emulator, lambda s: s["enable"] == 0x02, "coil 1")
    status, answer, errors = dcos_modbus(emulator, line, "read-discrete-inputs", "0", "3")
    assert status == 0 and answer["values"] == [False, True, False], (answer, errors)
    status, answer, errors = dcos_modbus(emulator, line, "identify", "--code", "regular")
    assert status == 0 and "mbmap" in str(answer), (answer, errors)
    # An unmapped address: libmodbus names the controller's exception 02.
    status, answer, errors = dcos_modbus(emulator, line, "read-holding-registers", "4", "1")
    assert status == 1 and "02" in str(answer), (answer, errors)


def test_a_map_naming_board_points_is_refused_at_boot_without_the_board(boot, isa486, mapped_image):
    # Only the node knows whether the I/O board is there: the loader refuses
    # the whole application, names the slave and the board's status, and
    # the console comes up with the line off.
    emulator = boot(isa486, mapped_image, icount=True, without_devices=["isa-mfio"])
    match = emulator.expect(r"application 'mbmap' not started: Modbus slave 'mbmap' was refused by its agent "
                            r"\(([a-z -]+)\)")
    emulator.expect("dcos> ")
    assert "control" not in emulator.command("tasks")
    assert "modbus: off" in emulator.command("modbus state"), match.group(0)
