"""Several emulated boards on the lab's CAN buses, for one test.

A CanLab starts the hub (dcoslab/canbus.py) with named buses and bit rates,
boots boards whose `isa-sja1000` channels are wired to those buses, and
drives each channel through the test image's `canlab` console command
(tests_renode/target/Sja1000ModelTest.cpp). The `canlab` fixture of the lab's
pytest plugin makes one per test and stops it afterwards; a failing test
prints every board's console transcript and the bus log.

    def test_two_boards(canlab):
        lab = canlab({"can0": 500_000}, {"board1": {"bus0": "can0"}, "board2": {"bus0": "can0"}})
        board1, board2 = lab.board("board1"), lab.board("board2")
        for board in (board1, board2):
            board.init(0, 500_000)
        board1.send(0, 0x123, b"\\x11\\x22")
        received = board2.wait_log(0, lambda log: log.frames())
        assert lab.hub.frames()[0].outcome == "ok"

Every wait has a time-out; exactness comes from -icount, not from the host.
"""

import os
import re
import tempfile
import time
from dataclasses import dataclass, field

from .canbus import Frame, Hub

# BTR0 and BTR1 for the CiA bit rates with the card's 16 MHz crystal
# (tq = 125 ns * (BRP + 1); sample point 87.5 %, 80 % at 800 kbit/s and
# 75 % at 1 Mbit/s), as CAN tools compute them for an SJA1000.
CIA_BIT_TIMING = {
    1_000_000: (0x00, 0x14),
    800_000: (0x00, 0x16),
    500_000: (0x00, 0x1C),
    250_000: (0x01, 0x1C),
    125_000: (0x03, 0x1C),
    100_000: (0x04, 0x1C),
    50_000: (0x09, 0x1C),
    20_000: (0x18, 0x1C),
    10_000: (0x31, 0x1C),
}

# A fixed real-time clock, so that boards boot alike in every run (the
# kernel reads the time of day at start-up).
RTC_BASE = "2026-01-01T00:00:00"

# Generous: these bound a hung board or hub, they do not measure speed.
DEFAULT_TIMEOUT = 120.0

_LOG_LINE = re.compile(r"CANLOG (\d) (\d+) (\w+)(.*?)\r?\n")
_LOG_END = re.compile(r"CANLOG (\d) end (\d+) dropped=(\d+)\r?\n")
_TX_LINE = re.compile(r"CANTX (\d) (\d+) ([0-9a-f]+)\r?\n")
_REGS_LINE = re.compile(r"CANREGS (\d) (.*?)\r?\n")


@dataclass(frozen=True)
class LogEntry:
    """One event the board's interrupt routine recorded (`canlab log`).

    kind is RX, TI, EI, EPI, ALI, BEI, DOI or WUI; uptime the board's uptime
    in ns when the routine ran. For RX, frame is the frame received; for the
    others, fields holds the printed values (sr, tx, rx, alc, ecc) as ints.
    """

    channel: int
    uptime: int
    kind: str
    frame: Frame = None
    fields: dict = field(default_factory=dict)


class BoardLog(list):
    """The entries of one `canlab log`, with filters."""

    def of(self, kind):
        return [entry for entry in self if entry.kind == kind]

    def frames(self):
        return self.of("RX")


def _parse_entry(channel, uptime, kind, rest):
    words = rest.split()
    if kind == "RX":
        return LogEntry(channel, uptime, kind, Frame.from_words(words))
    values = {}
    for word in words:
        key, _, value = word.partition("=")
        values[key] = int(value, 16 if key in ("sr", "ecc") else 10)
    return LogEntry(channel, uptime, kind, fields=values)


class LabBoard:
    """One booted board of the lab: its emulator and the `canlab` command."""

    def __init__(self, name, emulator, hub=None):
        self.name = name
        self.emulator = emulator
        self.hub = hub

    def command(self, line, timeout=DEFAULT_TIMEOUT):
        return self.emulator.command(line, timeout=timeout)

    def init(self, channel, bitrate=None, btr=None, listen=False, selftest=False, join=True, timeout=DEFAULT_TIMEOUT):
        """Resets the channel, sets PeliCAN mode, the bit rate and every
        interrupt, and starts it; with join, waits until the hub has it on the
        bus. A chip that has just left reset mode counts 11 recessive bits
        before it takes part (1.1 ms at 10 kbit/s), and a frame sent meanwhile
        is neither received nor acknowledged by it: without the wait, a test's
        first frame would depend on how fast the host typed the commands."""
        btr0, btr1 = btr if btr is not None else CIA_BIT_TIMING[bitrate]
        words = [f"canlab init {channel} {btr0:#04x} {btr1:#04x}"]
        if listen:
            words.append("listen")
        if selftest:
            words.append("selftest")
        output = self.command(" ".join(words))
        if f"CANINIT {channel}" not in output:
            raise AssertionError(f"{self.name}: canlab init failed:\n{output}")
        if join and self.hub is not None:
            self.hub.wait_on_bus([f"{self.name}.{channel}"], timeout)

    def send(self, channel, id, data=b"", extended=False, remote=False, dlc=None, once=False, self_rx=False,
             at_ms=None, count=1, timeout=DEFAULT_TIMEOUT):
        """Sends a frame (count times, back to back); returns the uptimes of the requests."""
        return self.begin_send(channel, id, data, extended, remote, dlc, once, self_rx, at_ms, count)(timeout)

    def begin_send(self, channel, id, data=b"", extended=False, remote=False, dlc=None, once=False, self_rx=False,
                   at_ms=None, count=1):
        """Types a send command and returns at once, with a function that
        waits for it and returns the uptimes of the requests: several boards
        can be told to send at the same uptime (at_ms) before any does."""
        words = [f"canlab send {channel} {id:x} {bytes(data).hex() or '-'}"]
        if extended:
            words.append("ext")
        if remote:
            words.append("rtr")
        if dlc is not None:
            words.append(f"dlc={dlc}")
        if once:
            words.append("once")
        if self_rx:
            words.append("self")
        if at_ms is not None:
            words.append(f"at={at_ms}")
        if count != 1:
            words.append(f"count={count}")
        line = " ".join(words)
        self.emulator.send(line + "\r")
        self.emulator.expect(re.escape(line) + r"\r\n")

        def finish(timeout=DEFAULT_TIMEOUT):
            output = self.emulator.expect(r"([\s\S]*?)dcos> ", timeout).group(1).decode("latin-1")
            requests = [int(match.group(2)) for match in _TX_LINE.finditer(output + "\n")]
            if len(requests) != count or "error" in output:
                raise AssertionError(f"{self.name}: canlab send did not request {count} frame(s):\n{output}")
            return requests

        return finish

    def log(self, channel):
        """What the interrupt routine recorded since the last log (and forgets it)."""
        output = self.command(f"canlab log {channel}") + "\n"
        end = _LOG_END.search(output)
        if end is None:
            raise AssertionError(f"{self.name}: no end of log in:\n{output}")
        if int(end.group(3)) != 0:
            raise AssertionError(f"{self.name}: the interrupt routine dropped {end.group(3)} entries")
        return BoardLog(_parse_entry(int(m.group(1)), int(m.group(2)), m.group(3), m.group(4))
                        for m in _LOG_LINE.finditer(output) if m.group(2) != "end")

    def wait_log(self, channel, predicate, timeout=DEFAULT_TIMEOUT, what="the events asked for"):
        """Collects log entries until predicate(entries) is true; returns all of them."""
        collected = BoardLog()
        deadline = time.monotonic() + timeout
        while True:
            collected.extend(self.log(channel))
            if predicate(collected):
                return collected
            if time.monotonic() > deadline:
                raise AssertionError(f"{self.name}: timed out after {timeout:.0f} s waiting for {what}; "
                                     f"the log has {[(e.kind, e.fields or str(e.frame)) for e in collected]}")
            time.sleep(0.05)

    def regs(self, channel):
        """MOD, SR, IER, TXERR, RXERR, EWLR, RMC and the uptime, as ints."""
        output = self.command(f"canlab regs {channel}") + "\n"
        match = _REGS_LINE.search(output)
        if match is None:
            raise AssertionError(f"{self.name}: no register line in:\n{output}")
        values = {}
        for word in match.group(2).split():
            key, _, value = word.partition("=")
            values[key] = int(value, 16 if key in ("mod", "sr", "ier") else 10)
        return values

    def uptime_ms(self, channel=0):
        return self.regs(channel)["uptime"] // 1_000_000

    def echo(self, channel, on=True):
        self.command(f"canlab echo {channel} {'on' if on else 'off'}")

    def reset(self, channel):
        """Enters reset mode; returns the uptime of the write."""
        return self._mode(channel, "reset")

    def start(self, channel):
        """Leaves reset mode (after bus-off: starts the recovery); returns the uptime of the write."""
        return self._mode(channel, "start")

    def _mode(self, channel, verb):
        output = self.command(f"canlab {verb} {channel}")
        match = re.search(rf"CANMODE {channel} (\d+) mod=", output)
        if match is None:
            raise AssertionError(f"{self.name}: canlab {verb} failed:\n{output}")
        return int(match.group(1))

    def abort(self, channel):
        self.command(f"canlab abort {channel}")


class CanLab:
    """A hub with named buses and the boards joined to it."""

    def __init__(self, boot, board_definition, buses, wiring, pace=None, kind="test", timeout=DEFAULT_TIMEOUT,
                 lines=None, append="", cpu=None):
        """buses maps bus names to bit rates; wiring maps board names to the
        card's channel wiring, e.g. {"board1": {"bus0": "can0", "bus1": "can1"}},
        where the key "rs485" names the lab RS-485 line the board's RS-485
        port is on (lines maps line names to a baud rate and format, see
        dcoslab/rs485.py). The hub holds the clock until every board has
        joined, so all boot in step from emulated time 0. append is the
        kernel command line of every board; the key "append" of a board's
        wiring gives that board its own (e.g. "node=2"), the key "devices"
        more device properties ({"isa-mfio": {"wiring": "plant", ...}}) and
        the key "args" more emulator arguments (a -chardev for them), the
        key "board" another board definition than board_definition for that
        board (its CAN card, Board.can_card, is the one wired), the
        key "serial_sockets" serial ports of the board to join to Unix
        sockets (the p5smp's node 3 console, dcoslab/node_console.py), the
        key "card" a CompactFlash card image the board boots from instead of
        the image kind (docs/boot.md), and the key "expect" what its console
        shows once it is up, instead of the shell's prompt. cpu
        replaces the board's CPU model on every board (the remote bench's
        counting image runs on the board's benchmark_cpu, whose time-stamp
        counter counts instructions under -icount)."""
        self._directory = tempfile.TemporaryDirectory(prefix="dcos-canlab-")
        self.socket_path = os.path.join(self._directory.name, "hub.sock")
        self.hub = Hub(self.socket_path, buses, expect=list(wiring), pace=pace, timeout=timeout, lines=lines)
        self.hub.start()
        self.boards = {}
        prompts = {}
        try:
            for name, channels in wiring.items():
                properties = {"hub": self.socket_path, "hub-name": name}
                line_ports = {}
                board_append = append
                devices = {}
                board_args = []
                card = None
                prompt = r"dcos> "
                definition = board_definition
                serial_sockets = ()
                for key, value in channels.items():
                    if key == "board":
                        definition = value
                    elif key == "serial_sockets":
                        serial_sockets = tuple(value)
                    elif key == "append":
                        board_append = value
                    elif key == "card":
                        card = value
                    elif key == "expect":
                        prompt = value
                    elif key == "devices":
                        devices = value
                    elif key == "args":
                        board_args = list(value)
                    elif key == "rs485":
                        line_ports["rs485"] = {"hub": self.socket_path, "hub-name": name, "line": value}
                    else:
                        properties[key] = value
                # Only what is asked for goes to boot: a world's own boot (dcoslab/vmworld.py)
                # knows no kernel command line or line ports.
                options = {"append": board_append} if board_append else {}
                if line_ports:
                    options["line_ports"] = line_ports
                if cpu:
                    options["cpu"] = cpu
                if card:
                    options["card"] = card
                if serial_sockets:
                    options["serial_sockets"] = serial_sockets
                emulator = boot(definition, kind, icount=True, name=name,
                                device_properties={definition.can_card: properties, **devices},
                                extra_args=["-rtc", f"base={RTC_BASE}", *board_args], **options)
                self.boards[name] = LabBoard(name, emulator, self.hub)
                prompts[name] = prompt
            for name, board in self.boards.items():
                board.emulator.expect(prompts[name], timeout=timeout)
        except BaseException:
            self.close()
            raise

    def board(self, name):
        return self.boards[name]

    def bit_ns(self, bus):
        return self.hub.buses[bus].bit_ns

    def close(self):
        self.hub.stop()
        self._directory.cleanup()
