"""The controller's Modbus master polling its application's slaves on the
board's second RS-485 port (COM3), in emulated time.

The application (tests_renode/modbus/polling_app) declares a polling
schedule against slave 17, which the test plays with pymodbus (Debian's
python3-pymodbus, an implementation we did not write): its RTU framer takes
the controller's requests off COM3's Unix socket, its datastore, with the
tables of tests_renode/modbus/pymodbus_slave.py, executes them, and its
framer builds the answers. The test plays it in-process rather than as
pymodbus's serial server so that it can keep a real slave's turnaround:
QEMU's 16550 hands the controller's request over at once rather than at the
baud rate, and an answer that came back before the controller's own frame
had left its shift register would be one no real line can carry (the
controller rightly ignores a frame that starts within t3.5 of its own).

dcos-modbus-sim as the polled slave is tested with the modbus_drive
example (docs/examples/modbus_drive/tests).
"""

import re
import threading
import time

import pytest

pytest.importorskip("pymodbus")
from pymodbus.datastore import ModbusSequentialDataBlock, ModbusSlaveContext  # noqa: E402
from pymodbus.factory import ServerDecoder  # noqa: E402
from pymodbus.framer.rtu_framer import ModbusRtuFramer  # noqa: E402

from dcoslab.serial_line import SerialLine  # noqa: E402
from dcoslab.waiting import wait_until  # noqa: E402
from modbus.pymodbus_slave import COILS, DISCRETE_INPUTS, HOLDING_REGISTERS, INPUT_REGISTERS  # noqa: E402
from test_modbus_application import build_application  # noqa: E402

UNIT = 17
ABSENT = 99
WAIT = 60.0
# A real slave's time from a request's end to its answer, in the host's time.
TURNAROUND_S = 0.003
ENTRIES = ("coils", "inputs", "holding", "input-regs", "w-holding", "w-coils", "r-holding", "r-coils", "ghost",
           "beyond")


class PymodbusSlave(threading.Thread):
    """Slave 17 on the line: pymodbus's framer and datastore, answering after TURNAROUND_S."""

    def __init__(self, line):
        super().__init__(daemon=True)
        self.line = line
        self.store = ModbusSlaveContext(
            co=ModbusSequentialDataBlock(0, list(COILS)), di=ModbusSequentialDataBlock(0, list(DISCRETE_INPUTS)),
            hr=ModbusSequentialDataBlock(0, list(HOLDING_REGISTERS)),
            ir=ModbusSequentialDataBlock(0, list(INPUT_REGISTERS)), zero_mode=True)
        self.framer = ModbusRtuFramer(ServerDecoder())
        self.requests = []
        self.unanswered = 0
        # Function codes answered with a bad CRC, and with another request's data.
        self.corrupt = set()
        self.wrong = set()
        self.stopping = threading.Event()

    def run(self):
        while not self.stopping.is_set():
            chunk = self.line.read(1, 0.05)
            if chunk:
                self.framer.processIncomingPacket(chunk, self.answer, unit=[UNIT, ABSENT], single=False)

    def answer(self, request):
        if request.unit_id == ABSENT:
            # Seen on the line, never answered: slave 99 is not there.
            self.unanswered += 1
            return
        time.sleep(TURNAROUND_S)
        function = request.function_code
        if function in self.wrong:
            # The answer to another request: one register more than asked for.
            request.count += 1
        response = request.execute(self.store)
        response.unit_id = request.unit_id
        response.transaction_id = request.transaction_id
        self.requests.append(function)
        frame = self.framer.buildPacket(response)
        if function in self.corrupt:
            frame = frame[:-1] + bytes([frame[-1] ^ 0xFF])
        self.line.write(frame)

    def stop(self):
        self.stopping.set()
        self.join(timeout=5)


@pytest.fixture(scope="session")
def polling_image(tmp_path_factory):
    return build_application(tmp_path_factory, "polling_app")


@pytest.fixture
def polled(boot, isa486, polling_image):
    emulator = boot(isa486, polling_image, icount=True, serial_sockets=["rs485b"])
    emulator.expect(r"application 'polling' started: 1 task, 4 publishers")
    emulator.expect("dcos> ")
    line = SerialLine(emulator.serial_socket_path("rs485b"), bridge=False)
    slave = PymodbusSlave(line)
    slave.start()
    yield emulator, slave
    slave.stop()
    line.close()


def poll_table(emulator):
    """`modbus poll` as {entry: {"done", "ok", "exceptions", "timeouts", "errors", "last"}} and the line's counters."""
    output = emulator.command("modbus poll")
    entries = {}
    line = {}
    for text in output.splitlines():
        words = text.split()
        if text.startswith("line:"):
            line = {name: int(value) for name, value in zip(words[1::2], words[2::2]) if value.isdigit()}
        elif len(words) >= 13 and words[0] in ENTRIES:
            entries[words[0]] = {"done": int(words[6]), "ok": int(words[7]), "exceptions": int(words[8]),
                                 "timeouts": int(words[9]), "errors": int(words[10]), "last": " ".join(words[12:])}
    assert len(entries) == len(ENTRIES), f"unexpected `modbus poll` output {output!r}"
    return entries, line, output


def wait_polled(emulator, predicate, what):
    """Runs `modbus poll` until predicate(entries) holds; returns the entries, the line's counters and the output."""
    return wait_until(lambda: poll_table(emulator), lambda seen: predicate(seen[0]), what, emulator, timeout=WAIT)


def pages(emulator):
    output = emulator.command("pages")
    result = {}
    for name in ("read", "echo", "ghost"):
        match = re.search(rf"^{name}:((?: [0-9a-f]{{2}}){{16}})", output, re.MULTILINE)
        assert match, f"unexpected `pages` output {output!r}"
        result[name] = bytes.fromhex(match.group(1))
    cycles = re.search(r"app: cycles (\d+) failures (\d+)", output)
    return result, int(cycles.group(1)), int(cycles.group(2))


def packed(bits):
    return bytes(sum(1 << i for i, on in enumerate(bits[k:k + 8]) if on) for k in range(0, len(bits), 8))


def test_every_table_of_a_pymodbus_slave_is_polled_into_the_applications_pages(polled):
    emulator, slave = polled
    entries, _, output = wait_polled(emulator, lambda e: all(e[name]["ok"] >= 2 for name in ENTRIES[:8]),
                                     "every entry of slave 17 answered twice")
    assert "poll: 10 entries of application 'polling' on COM3 (0x3e8, irq 9) at 19200 baud 8E1, time-out 1000 ms, " \
           "2 retries" in output, output
    read, _, failures = pages(emulator)
    # 01 and 02: sixteen bits each, packed from bit 0 of their byte.
    assert read["read"][0:2] == packed(COILS[:16]), read
    assert read["read"][2:4] == packed(DISCRETE_INPUTS[:16]), read
    # 03 and 04: registers high byte first.
    assert read["read"][4:8] == b"".join(value.to_bytes(2, "big") for value in HOLDING_REGISTERS[10:12]), read
    assert read["read"][8:12] == b"".join(value.to_bytes(2, "big") for value in INPUT_REGISTERS[3:5]), read
    # 10 and 0F took the application's "out" page to the slave, where 03 and 01 read it back.
    assert slave.store.getValues(3, 50, 2) == [0x1234, 0x5678]
    assert slave.store.getValues(1, 60, 4) == [True, True, False, True]
    assert read["echo"][0:5] == bytes([0x12, 0x34, 0x56, 0x78, 0x0B]), read
    assert {0x01, 0x02, 0x03, 0x04, 0x0F, 0x10} <= set(slave.requests)
    assert failures == 0


def test_a_slave_that_does_not_answer_times_out_after_its_retries_and_the_application_goes_on(polled):
    emulator, slave = polled
    entries, line, output = wait_polled(emulator, lambda e: e["ghost"]["timeouts"] >= 2, "two time-outs of slave 99")
    unanswered = slave.unanswered
    assert entries["ghost"]["last"] == "error: response time-out", output
    assert entries["ghost"]["ok"] == 0 and entries["ghost"]["errors"] == 0, output
    # Every other entry goes on being served meanwhile.
    assert all(entries[name]["ok"] >= 1 for name in ENTRIES[:8]), output
    # Each time-out is three transmissions (1 + 2 retries) of the same
    # request, as the line shows: three per ended transaction, and up to
    # two more of the transaction still waiting, if any.
    ended = entries["ghost"]["timeouts"]
    assert 3 * ended <= unanswered <= 3 * ended + 2, (unanswered, output)
    assert line["timeouts"] >= 3 * ended, output
    # The page the absent slave would fill stays as it was, and the application runs on.
    read, cycles, failures = pages(emulator)
    assert read["ghost"][0:2] == b"\0\0" and failures == 0
    wait_until(lambda: pages(emulator)[1], lambda now: now > cycles + 5, "more cycles of the application", emulator)


def test_an_exception_answer_is_counted_and_named(polled):
    emulator, _ = polled
    entries, _, output = wait_polled(emulator, lambda e: e["beyond"]["exceptions"] >= 1, "slave 17's exception")
    assert entries["beyond"]["last"] == "exception 02 illegal data address", output
    assert entries["beyond"]["ok"] == 0 and entries["beyond"]["timeouts"] == 0, output
    # An exception is the slave's answer: it is not retried, and the page is left alone.
    assert pages(emulator)[0]["ghost"][2:4] == b"\0\0"


def test_the_application_is_refused_at_boot_without_the_second_port(boot, isa486, polling_image):
    # Only the node knows whether COM3 is there: the loader refuses the
    # whole application, naming its master and the port's status.
    emulator = boot(isa486, polling_image, icount=True, without_devices=["isa-serial"])
    emulator.expect(r"application 'polling' not started: Modbus master 'polling' was refused by its agent "
                    r"\(not found\)")
    emulator.expect("dcos> ")
    assert "app" not in emulator.command("tasks").split()
    assert "no schedule runs" in emulator.command("modbus poll")


def test_answers_with_a_bad_crc_or_another_requests_data_are_retried_then_counted(polled):
    emulator, slave = polled
    before, line_before, _ = wait_polled(emulator, lambda e: e["holding"]["ok"] >= 1 and e["input-regs"]["ok"] >= 1,
                                         "good answers first")
    slave.corrupt.add(0x04)
    slave.wrong.add(0x03)
    entries, line, output = wait_polled(
        emulator, lambda e: e["input-regs"]["timeouts"] >= 1 and e["holding"]["errors"] >= 1,
        "a time-out of the corrupted answers and an error of the wrong ones")
    # A frame with a bad CRC is dropped by the receiver, so the request is
    # sent again and, never answered well, ends in a time-out.
    assert entries["input-regs"]["last"] == "error: response time-out", output
    assert line["crc-errors"] - line_before["crc-errors"] >= 3, output
    # An answer that does not match the request (three registers for two) is
    # malformed: retried, then the transaction ends with the error, named.
    assert entries["holding"]["last"] == "error: invalid response", output
    # The other entries and the application go on.
    assert entries["coils"]["ok"] > before["coils"]["ok"], output
    read, _, failures = pages(emulator)
    assert failures == 0
    # The pages keep the last good values.
    assert read["read"][4:8] == b"".join(value.to_bytes(2, "big") for value in HOLDING_REGISTERS[10:12]), read
    assert read["read"][8:12] == b"".join(value.to_bytes(2, "big") for value in INPUT_REGISTERS[3:5]), read
