"""The controller's Modbus RTU line on the RS-485 port (COM2), in emulated
time, against frames built and checked by an implementation we did not
write: pymodbus (Debian's python3-pymodbus 3.0), its RTU framer and its PDU
classes.

The board runs under the harness's exact emulated time (-icount
shift=0,align=off,sleep=off) with a 10 kHz tick, and the test holds COM2's
Unix socket. Each request is written in one write. QEMU's 16550 takes a
received byte without baud pacing, one per main-loop round at the receive
trigger level of 1 the line uses; while the controller idles between two
bytes, emulated time can only leap to the next timer deadline, which the
10 kHz tick puts at most 100 us ahead, far below t1.5 (859 us at 19200
baud). So a frame always arrives whole, and the controller's t3.5 silence
after it, and its answer, follow in emulated time.

A station must not start a frame before the line has been silent for t3.5
([SL] 2.5.1.1); the controller's receiver ignores one that does. Before the
test puts a frame on the line it therefore asks the controller, on its
console, for the receiver's state and waits for "idle": that wait is in the
controller's own time. Silence is proven in the same terms: after a frame
that must get no answer, the test waits for the controller to count the
frame, then sends a request that must be answered and checks that the first
bytes on the line are exactly that answer.

libmodbus, through our dcos-modbus on a pseudo-terminal bridged to the
socket, is a master of the controller's slave too: it writes each request
in one write(), so its frames arrive whole as well.

What these tests cannot show is the exact timing of a real line (a silence
just over t1.5 inside a frame, a frame started just before t3.5): QEMU's
stock UART does not pace received bytes at the baud rate. The host unit
tests of fieldbus/modbus's receiver and of drivers/modbus's LineRunner
prove that with a simulated clock, and tests_renode/test_modbus_line.py
with the board's COM2 on the lab's RS-485 line (the isa-rs485-uart model,
characters at their exact emulated times, collisions), against pymodbus,
libmodbus and a second board.
"""

import json
import os
import re
import struct
import subprocess
import time

import pytest

pytest.importorskip("pymodbus")
from pymodbus.bit_read_message import (  # noqa: E402
    ReadCoilsRequest,
    ReadCoilsResponse,
    ReadDiscreteInputsRequest,
)
from pymodbus.bit_write_message import WriteMultipleCoilsRequest, WriteSingleCoilRequest, WriteSingleCoilResponse  # noqa: E402
from pymodbus.factory import ClientDecoder, ServerDecoder  # noqa: E402
from pymodbus.framer.rtu_framer import ModbusRtuFramer  # noqa: E402
from pymodbus.mei_message import ReadDeviceInformationRequest  # noqa: E402
from pymodbus.pdu import ExceptionResponse  # noqa: E402
from pymodbus.register_read_message import (  # noqa: E402
    ReadHoldingRegistersRequest,
    ReadHoldingRegistersResponse,
    ReadInputRegistersRequest,
    ReadWriteMultipleRegistersRequest,
)
from pymodbus.register_write_message import WriteMultipleRegistersRequest, WriteSingleRegisterRequest  # noqa: E402
from pymodbus.utilities import computeCRC  # noqa: E402

from dcoslab.board import REPOSITORY  # noqa: E402
from dcoslab.modbus_console import modbus_state, wait_for_state  # noqa: E402
from dcoslab.serial_line import SerialLine  # noqa: E402

UNIT = 17
# 19200 baud 8E1, the default line of [SL] 2.5.1.
BAUD = 19200
# A 1 ms tick would let emulated time leap 1 ms while the controller idles
# between two received bytes, more than t1.5 at 19200 baud; 10 kHz bounds it at 100 us.
APPEND = "tick_hz=10000"
# Real-time bounds for waits that end on an emulated event; emulated time
# runs faster than real time while the controller idles, so these are only
# there to fail a test that hangs.
WAIT = 20.0


def client_framer():
    return ModbusRtuFramer(ClientDecoder())


def server_framer():
    return ModbusRtuFramer(ServerDecoder())


def request_bytes(request):
    """The RTU frame of a pymodbus request (its unit set), CRC included."""
    return client_framer().buildPacket(request)


def response_bytes(response):
    return server_framer().buildPacket(response)


def raw_frame(unit, pdu):
    """A frame for a PDU pymodbus has no class for, with pymodbus's CRC."""
    body = bytes([unit]) + pdu
    return body + struct.pack(">H", computeCRC(body))


def read_message(line, framer, what, timeout=WAIT):
    """Reads the line until framer decodes one message for UNIT; returns it and the bytes read."""
    messages = []
    data = b""
    deadline = time.monotonic() + timeout
    while not messages:
        remaining = deadline - time.monotonic()
        chunk = line.read(1, max(remaining, 0)) if remaining > 0 else b""
        if not chunk:
            raise AssertionError(f"no complete {what} within {timeout:.0f} s; the line carried {data.hex() or 'nothing'}")
        data += chunk
        try:
            framer.processIncomingPacket(chunk, messages.append, unit=UNIT, single=True)
        except struct.error:
            # pymodbus 3.0 sizes a 2B/0E answer from its object headers and
            # raises struct.error, where it means "not all here yet", when a
            # header is cut off; the framer has kept the bytes, so reading on
            # completes the frame.
            pass
    return messages[0], data


def state(emulator):
    """The `modbus state` counters as {"frames.crc-errors": 0, ..., "frames.receiver": "idle"}."""
    return modbus_state(emulator)


def wait_for(emulator, predicate, what):
    """Runs `modbus state` until predicate(state) holds: a wait in the controller's time."""
    return wait_for_state(emulator, predicate, what, WAIT, pause=0)


def wait_line_idle(emulator):
    """Waits until the controller's receiver has seen t3.5 of silence."""
    return wait_for(emulator, lambda s: s["frames.receiver"] == "idle", "receiver idle")


@pytest.fixture
def slave_line(boot, isa486):
    """The controller as slave 17 at 19200 8E1, and the line's bytes in the test's hands."""
    emulator = boot(isa486, icount=True, append=APPEND, serial_sockets=["rs485"])
    emulator.expect("dcos> ")
    line = SerialLine(emulator.serial_socket_path("rs485"), bridge=False)
    assert f"slave {UNIT} on COM2 at {BAUD} baud 8E1" in emulator.command(f"modbus slave {UNIT} {BAUD}")
    yield emulator, line
    line.close()


def exchange(emulator, line, request):
    """Puts one request frame (bytes or a pymodbus request) on the idle line; returns the decoded answer and its bytes."""
    frame = request if isinstance(request, bytes) else request_bytes(request)
    wait_line_idle(emulator)
    line.write(frame)
    return read_message(line, client_framer(), f"answer to {frame.hex()}")


def test_slave_serves_every_function_code(slave_line):
    emulator, line = slave_line
    # 02 and 04: the console slave's pattern (discrete input n on for
    # multiples of 3, input register n = 0x1000 + n).
    answer, _ = exchange(emulator, line, ReadDiscreteInputsRequest(0, 10, unit=UNIT))
    assert not answer.isError(), answer
    assert answer.bits[:10] == [i % 3 == 0 for i in range(10)]
    answer, _ = exchange(emulator, line, ReadInputRegistersRequest(5, 3, unit=UNIT))
    assert answer.registers == [0x1005, 0x1006, 0x1007]
    # 05, then 01 reads it back; the answer to 05 echoes the request, byte for byte.
    answer, data = exchange(emulator, line, WriteSingleCoilRequest(7, True, unit=UNIT))
    assert data == response_bytes(WriteSingleCoilResponse(7, True, unit=UNIT))
    answer, data = exchange(emulator, line, ReadCoilsRequest(0, 9, unit=UNIT))
    assert answer.bits[:9] == [False] * 7 + [True, False]
    assert data == response_bytes(ReadCoilsResponse([False] * 7 + [True, False], unit=UNIT))
    # 0F.
    answer, _ = exchange(emulator, line, WriteMultipleCoilsRequest(20, [True, False, True, True], unit=UNIT))
    assert (answer.function_code, answer.address, answer.count) == (0x0F, 20, 4)
    answer, _ = exchange(emulator, line, ReadCoilsRequest(20, 4, unit=UNIT))
    assert answer.bits[:4] == [True, False, True, True]
    # 06 and 03.
    answer, _ = exchange(emulator, line, WriteSingleRegisterRequest(3, 4321, unit=UNIT))
    assert (answer.function_code, answer.address, answer.value) == (0x06, 3, 4321)
    answer, data = exchange(emulator, line, ReadHoldingRegistersRequest(3, 1, unit=UNIT))
    assert data == response_bytes(ReadHoldingRegistersResponse([4321], unit=UNIT))
    # 10.
    answer, _ = exchange(emulator, line, WriteMultipleRegistersRequest(10, [1, 2, 3, 65535], unit=UNIT))
    assert (answer.function_code, answer.address, answer.count) == (0x10, 10, 4)
    answer, _ = exchange(emulator, line, ReadHoldingRegistersRequest(10, 4, unit=UNIT))
    assert answer.registers == [1, 2, 3, 65535]
    # 17: the write lands before the read ([AP] 6.17).
    answer, _ = exchange(emulator, line, ReadWriteMultipleRegistersRequest(
        read_address=10, read_count=3, write_address=11, write_registers=[77, 88], unit=UNIT))
    assert answer.registers == [1, 77, 88]
    # What the master wrote is where the controller reads it.
    assert "data: 1 77 88 65535" in emulator.command("modbus data holding 10 4")
    assert "data: 1 0 1 1" in emulator.command("modbus data coils 20 4")
    # 2B / 0E: basic device identification, stream access from object 0.
    answer, _ = exchange(emulator, line, ReadDeviceInformationRequest(read_code=1, object_id=0, unit=UNIT))
    assert not answer.isError(), answer
    assert answer.information == {0: b"DCOS", 1: b"DCOS-486", 2: b"0.1"}
    seen = state(emulator)
    assert seen["slave.messages"] == 12 and seen["slave.exceptions"] == 0
    assert seen["frames.crc-errors"] == 0 and seen["frames.gap-errors"] == 0
    assert seen["frames.ignored-characters"] == 0
    assert seen["line.frames-sent"] == 12


def exception_of(answer):
    assert isinstance(answer, ExceptionResponse), answer
    return answer.original_code, answer.exception_code


def test_slave_exceptions_01_02_03(slave_line):
    emulator, line = slave_line
    # 01: a function the slave does not serve; the answer is exactly the exception frame.
    answer, data = exchange(emulator, line, raw_frame(UNIT, bytes([0x41, 0x00])))
    assert exception_of(answer) == (0x41, 1)
    assert data == raw_frame(UNIT, bytes([0xC1, 0x01]))
    answer, _ = exchange(emulator, line, raw_frame(UNIT, bytes([0x08, 0x00, 0x00, 0x12, 0x34])))
    assert exception_of(answer) == (0x08, 1)
    # 02: past the 256 entries of each of the console slave's tables.
    assert exception_of(exchange(emulator, line, ReadHoldingRegistersRequest(250, 10, unit=UNIT))[0]) == (3, 2)
    assert exception_of(exchange(emulator, line, ReadCoilsRequest(300, 1, unit=UNIT))[0]) == (1, 2)
    assert exception_of(exchange(emulator, line, WriteSingleRegisterRequest(256, 1, unit=UNIT))[0]) == (6, 2)
    # 03: quantity 0 and the maximum plus one for each read.
    for request, function in ((ReadCoilsRequest, 1), (ReadDiscreteInputsRequest, 2),
                              (ReadHoldingRegistersRequest, 3), (ReadInputRegistersRequest, 4)):
        most = 2000 if function <= 2 else 125
        assert exception_of(exchange(emulator, line, request(0, 0, unit=UNIT))[0]) == (function, 3)
        assert exception_of(exchange(emulator, line, request(0, most + 1, unit=UNIT))[0]) == (function, 3)
        # The maximum itself is served where the table holds it.
        if most <= 125:
            answer, _ = exchange(emulator, line, request(0, most, unit=UNIT))
            assert not answer.isError() and len(answer.registers) == most
    seen = state(emulator)
    assert seen["slave.exceptions"] == 13
    assert seen["slave.messages"] == 15


def test_slave_stays_silent_for_a_bad_crc_another_slave_and_a_broadcast(slave_line):
    emulator, line = slave_line
    probe = ReadHoldingRegistersRequest(5, 1, unit=UNIT)

    def silent_then_answers(frame, counter, expected_value):
        """frame gets no answer: the controller counts it, and the next answer is the first thing on the line."""
        before = state(emulator)
        wait_line_idle(emulator)
        line.write(frame)
        wait_for(emulator, lambda s: s["frames.seen"] == before["frames.seen"] + 1, f"frame {frame.hex()} counted")
        answer, data = exchange(emulator, line, probe)
        assert data == response_bytes(ReadHoldingRegistersResponse([expected_value], unit=UNIT)), \
            f"after {frame.hex()} the line carried {data.hex()}"
        after = state(emulator)
        assert after[counter] == before[counter] + 1, (counter, before, after)

    good = request_bytes(ReadHoldingRegistersRequest(0, 1, unit=UNIT))
    silent_then_answers(good[:-1] + bytes([good[-1] ^ 0x01]), "frames.crc-errors", 0)
    silent_then_answers(request_bytes(ReadHoldingRegistersRequest(0, 1, unit=UNIT + 1)), "slave.other-addresses", 0)
    # A broadcast write is executed without an answer: the register the probe reads changes.
    silent_then_answers(request_bytes(WriteSingleRegisterRequest(5, 0x1234, unit=0)), "slave.no-responses", 0x1234)
    assert "data: 4660" in emulator.command("modbus data holding 5 1")
    # A broadcast read is ignored.
    silent_then_answers(request_bytes(ReadHoldingRegistersRequest(5, 1, unit=0)), "slave.no-responses", 0x1234)
    seen = state(emulator)
    assert seen["frames.crc-errors"] == 1
    assert seen["slave.other-addresses"] == 1
    assert seen["slave.no-responses"] == 2
    assert seen["line.frames-sent"] == 4  # the four probes, nothing else


# -- the controller as master; the test plays slave 17 -----------------------

@pytest.fixture
def master_line(boot, isa486):
    emulator = boot(isa486, icount=True, append=APPEND, serial_sockets=["rs485"])
    emulator.expect("dcos> ")
    line = SerialLine(emulator.serial_socket_path("rs485"), bridge=False)
    yield emulator, line
    line.close()


def start_master(emulator, timeout_ms, retries):
    out = emulator.command(f"modbus master {BAUD} e {timeout_ms} {retries}")
    assert f"master on COM2 at {BAUD} baud 8E1, time-out {timeout_ms} ms, {retries} retries" in out, out


def submit(emulator, command):
    out = emulator.command(f"modbus submit {command}")
    assert re.search(r"submitted [0-9a-f]{2} to 17", out), out


def take_request(line):
    """The controller's next request, decoded by pymodbus's server framer."""
    return read_message(line, server_framer(), "request from the controller")


def test_master_takes_correct_answers(master_line):
    emulator, line = master_line
    start_master(emulator, 5000, 2)
    submit(emulator, f"read {UNIT} holding 0 2")
    request, data = take_request(line)
    assert isinstance(request, ReadHoldingRegistersRequest) and (request.address, request.count) == (0, 2)
    assert data == request_bytes(ReadHoldingRegistersRequest(0, 2, unit=UNIT))
    wait_line_idle(emulator)
    line.write(response_bytes(ReadHoldingRegistersResponse([0x1234, 0xABCD], unit=UNIT)))
    assert "ok 03: 4660 43981" in emulator.command("modbus result")
    # A write: 05 with its echo.
    submit(emulator, f"write {UNIT} coils 7 1")
    request, _ = take_request(line)
    assert isinstance(request, WriteSingleCoilRequest) and (request.address, request.value) == (7, True)
    wait_line_idle(emulator)
    line.write(response_bytes(WriteSingleCoilResponse(7, True, unit=UNIT)))
    assert "ok 05: 00 07 ff 00" in emulator.command("modbus result")
    seen = state(emulator)
    assert (seen["master.transactions"], seen["master.transmissions"], seen["master.responses"]) == (2, 2, 2)
    assert seen["master.timeouts"] == 0 and seen["master.state"] == "idle"
    # Each end is shown once: a second result has no transaction to wait for.
    assert "error: no transaction was submitted" in emulator.command("modbus result")


def test_master_times_out_and_retries_when_no_answer_comes(master_line):
    emulator, line = master_line
    start_master(emulator, 100, 2)
    submit(emulator, f"read {UNIT} holding 0 2")
    # The first transmission and two retries of the same frame.
    expected = request_bytes(ReadHoldingRegistersRequest(0, 2, unit=UNIT))
    for attempt in range(3):
        _, data = take_request(line)
        assert data == expected, f"attempt {attempt + 1}: {data.hex()}"
    assert "error: response time-out after 3 transmissions" in emulator.command("modbus result")
    seen = state(emulator)
    assert (seen["master.transmissions"], seen["master.timeouts"], seen["master.failures"]) == (3, 3, 1)
    assert seen["line.frames-sent"] == 3


def test_master_retries_after_an_answer_with_a_bad_crc(master_line):
    emulator, line = master_line
    start_master(emulator, 1000, 1)
    submit(emulator, f"read {UNIT} holding 0 2")
    take_request(line)
    wait_line_idle(emulator)
    good = response_bytes(ReadHoldingRegistersResponse([1, 2], unit=UNIT))
    line.write(good[:-2] + bytes([good[-2] ^ 0xFF, good[-1]]))
    # The damaged answer is dropped; the master's time-out runs out and it sends the request again.
    _, data = take_request(line)
    assert data == request_bytes(ReadHoldingRegistersRequest(0, 2, unit=UNIT))
    wait_line_idle(emulator)
    line.write(good)
    assert "ok 03: 1 2" in emulator.command("modbus result")
    seen = state(emulator)
    assert seen["frames.crc-errors"] == 1
    assert (seen["master.transmissions"], seen["master.timeouts"], seen["master.responses"]) == (2, 1, 1)


def test_master_ignores_an_answer_after_its_time_out(master_line):
    emulator, line = master_line
    start_master(emulator, 100, 0)
    submit(emulator, f"read {UNIT} holding 0 2")
    take_request(line)
    assert "error: response time-out after 1 transmissions" in emulator.command("modbus result")
    # The answer comes now, after the transaction ended: counted as a frame
    # no one waited for, not taken as an answer.
    wait_line_idle(emulator)
    before = state(emulator)
    line.write(response_bytes(ReadHoldingRegistersResponse([1, 2], unit=UNIT)))
    seen = wait_for(emulator, lambda s: s["frames.delivered"] == before["frames.delivered"] + 1, "late answer received")
    assert seen["master.foreign"] == before["master.foreign"] + 1
    assert seen["master.responses"] == 0 and seen["master.timeouts"] == 1
    # A second transaction that times out reports its own transmissions, not the line's total.
    submit(emulator, f"read {UNIT} holding 0 2")
    take_request(line)
    assert "error: response time-out after 1 transmissions" in emulator.command("modbus result")


# -- libmodbus as master against the controller ------------------------------------

DCOS_MODBUS = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-modbus")


@pytest.fixture
def bridged_slave(boot, isa486):
    """The controller as slave 17, its line on a pseudo-terminal for a host program that wants a serial device."""
    emulator = boot(isa486, icount=True, append=APPEND, serial_sockets=["rs485"])
    emulator.expect("dcos> ")
    line = SerialLine(emulator.serial_socket_path("rs485"), bridge=True)
    assert f"slave {UNIT} on COM2 at {BAUD} baud 8E1" in emulator.command(f"modbus slave {UNIT} {BAUD}")
    yield emulator, line
    line.close()


def dcos_modbus(emulator, line, *arguments):
    """One dcos-modbus run (libmodbus) on the bridged line, started once the controller's receiver is idle.

    libmodbus writes a request in one write(), which the bridge passes on
    whole, so it reaches the controller as one frame (see the module's
    docstring); the next request waits for the receiver's t3.5 in the
    controller's own time.
    """
    wait_line_idle(emulator)
    result = subprocess.run([DCOS_MODBUS, "-d", line.pty_path, "-b", str(BAUD), "-a", str(UNIT), "-r", "0",
                             "--json", *arguments], capture_output=True, text=True, timeout=WAIT)
    return result.returncode, (json.loads(result.stdout) if result.stdout.strip() else None), result.stderr


def test_libmodbus_master_reads_and_writes_the_controllers_slave(bridged_slave):
    emulator, line = bridged_slave
    status, answer, errors = dcos_modbus(emulator, line, "read-input-registers", "5", "3")
    assert status == 0, (answer, errors, emulator.transcript)
    assert answer["values"] == [0x1005, 0x1006, 0x1007], answer
    status, answer, errors = dcos_modbus(emulator, line, "write-registers", "40=7,8,65535")
    assert status == 0, (answer, errors)
    status, answer, errors = dcos_modbus(emulator, line, "read-holding-registers", "40", "3")
    assert status == 0 and answer["values"] == [7, 8, 65535], (answer, errors)
    assert "data: 7 8 65535" in emulator.command("modbus data holding 40 3"), emulator.transcript
    status, answer, errors = dcos_modbus(emulator, line, "write-coil", "3", "1")
    assert status == 0, (answer, errors)
    status, answer, errors = dcos_modbus(emulator, line, "read-coils", "0", "5")
    assert status == 0 and answer["values"] == [False, False, False, True, False], (answer, errors)
    # 02: the console slave's pattern, discrete input n on for multiples of 3.
    status, answer, errors = dcos_modbus(emulator, line, "read-discrete-inputs", "0", "7")
    assert status == 0 and answer["values"] == [i % 3 == 0 for i in range(7)], (answer, errors)
    # 06 and 0F, each read back by the controller's own console.
    status, answer, errors = dcos_modbus(emulator, line, "write-register", "3", "4321")
    assert status == 0, (answer, errors)
    assert "data: 4321" in emulator.command("modbus data holding 3 1"), emulator.transcript
    status, answer, errors = dcos_modbus(emulator, line, "write-coils", "20=1,0,1,1")
    assert status == 0, (answer, errors)
    assert "data: 1 0 1 1" in emulator.command("modbus data coils 20 4"), emulator.transcript
    # 17: the write lands before the read ([AP] 6.17).
    status, answer, errors = dcos_modbus(emulator, line, "write-read", "41=77,88", "40:3")
    assert status == 0 and answer["values"] == [7, 77, 88], (answer, errors)
    assert "data: 7 77 88" in emulator.command("modbus data holding 40 3"), emulator.transcript
    # Device identification (2B/0E), which libmodbus cannot frame: dcos-modbus frames it itself.
    status, answer, errors = dcos_modbus(emulator, line, "identify", "--code", "basic")
    assert status == 0, (answer, errors)
    assert "DCOS-486" in json.dumps(answer) and "0.1" in json.dumps(answer), answer
    # An address past the table: libmodbus names the controller's exception 02.
    status, answer, errors = dcos_modbus(emulator, line, "read-holding-registers", "1000", "1")
    assert status == 1 and "02" in json.dumps(answer), (answer, errors)
