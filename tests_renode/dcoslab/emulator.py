"""Runs one emulated board and talks to its console.

The console is a Unix socket the emulator serves and waits on, so not a byte
of early output is lost. Every wait has a time-out; when one expires the error
carries the whole console transcript, which pytest prints with the failure.
"""

import os
import re
import socket
import subprocess
import tempfile
import threading
import time

from . import powercut
from .board import EXIT_PANIC, EXIT_FAIL, EXIT_PASS
from .symbolize import explain

# Generous limits: these bound a hung emulator, they do not measure speed.
DEFAULT_TIMEOUT = 60.0


class EmulatorError(AssertionError):
    """A console expectation or emulator exit that did not happen."""


class Emulator:
    def __init__(self, board, image, append="", icount=False, cpu=None, memory_mib=None, accel=None,
                 device_properties=None, without_devices=(), extra_args=(), name=None, serial_sockets=(),
                 line_ports=None, card=False, power_cut_after=None):
        self.board = board
        # What failures call this emulator, e.g. "board2" among several boards.
        self.name = name or board.name
        self.image = image
        self.append = append
        self.icount = icount
        self.cpu = cpu  # None: the board's own CPU model
        self.memory_mib = memory_mib  # None: the board's memory
        self.accel = accel  # None: QEMU's default accelerator (TCG)
        # Per-run changes to the board's devices (see Board.emulator_command).
        self.device_properties = device_properties or {}
        self.without_devices = tuple(without_devices)
        self.extra_args = tuple(extra_args)
        # Serial ports of the board (names in its serial_ports, e.g. "rs485")
        # joined to a Unix socket each, which a test connects to
        # (serial_socket_path); the other ports but the console go nowhere.
        self.serial_sockets = tuple(serial_sockets)
        # Serial ports joined to a lab line instead (Board.emulator_command).
        self.line_ports = dict(line_ports or {})
        # image is a CompactFlash card the board boots from (Board.emulator_command).
        self.card = card
        # The card loses its power after this many writes (dcoslab/powercut.py).
        self.power_cut_after = power_cut_after
        self._workdir = tempfile.TemporaryDirectory(prefix="dcos-emulator-")
        self._socket_path = os.path.join(self._workdir.name, "console.sock")
        self._stderr_path = os.path.join(self._workdir.name, "emulator.stderr")
        self._qmp_path = os.path.join(self._workdir.name, "qmp.sock") if power_cut_after is not None else None
        self._buffer = bytearray()
        self._cursor = 0
        self._condition = threading.Condition()
        self._closed = False
        self._process = None
        self._socket = None
        self._reader = None
        self.argv = []

    # -- life cycle ---------------------------------------------------------

    def start(self, timeout=DEFAULT_TIMEOUT):
        if not os.path.exists(self.image):
            raise EmulatorError(f"firmware image {self.image} does not exist; run 'make firmware'")
        backend = f"socket,id=console,path={self._socket_path},server=on,wait=on"
        backends = {"console": "chardev:console"}
        chardevs = []
        for port in self.serial_sockets:
            if port not in self.board.serial_ports or port == "console":
                raise EmulatorError(f"board {self.board.name} has no serial port '{port}' besides the console; "
                                    f"its ports are: {', '.join(self.board.serial_ports)}")
            # wait=off: the board runs before the test connects; what it sends
            # until then is lost, as on an unconnected line.
            chardevs += ["-chardev", f"socket,id={port},path={self.serial_socket_path(port)},server=on,wait=off"]
            backends[port] = f"chardev:{port}"
        card_drive = None
        extra_args = self.extra_args
        if self.power_cut_after is not None:
            card_drive = powercut.drive(self.image, self.power_cut_after, self._workdir.name)
            extra_args = tuple(extra_args) + ("-qmp", f"unix:{self._qmp_path},server=on,wait=off")
        command = self.board.emulator_command(
            self.image, backends, append=self.append, icount=self.icount, cpu=self.cpu,
            memory_mib=self.memory_mib, accel=self.accel, device_properties=self.device_properties,
            without_devices=self.without_devices, extra_args=extra_args, line_ports=self.line_ports,
            card=self.card, card_drive=card_drive,
        )
        command[1:1] = ["-chardev", backend] + chardevs
        self.argv = command
        with open(self._stderr_path, "wb") as stderr:
            self._process = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=stderr, stderr=stderr)
        self._connect_console(timeout)
        return self

    def _connect_console(self, timeout):
        deadline = time.monotonic() + timeout
        while True:
            if self._process.poll() is not None:
                raise EmulatorError(f"emulator exited with status {self._process.returncode}:\n"
                                    + self.emulator_messages())
            try:
                sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
                sock.connect(self._socket_path)
                break
            except (FileNotFoundError, ConnectionRefusedError):
                sock.close()
                if time.monotonic() > deadline:
                    raise EmulatorError("emulator console socket never appeared") from None
                time.sleep(0.02)
        with self._condition:
            self._closed = False
        self._socket = sock
        self._reader = threading.Thread(target=self._read_console, daemon=True)
        self._reader.start()

    @property
    def console_socket_path(self):
        """The Unix socket the board's console (COM1) is served on."""
        return self._socket_path

    def release_console(self):
        """Lets another program have the console: the harness disconnects.

        The emulator serves the console socket again for the next client (a
        host tool such as dcos-flash, then reattach_console()); what the
        board prints while nobody is connected is lost.
        """
        self._socket.shutdown(socket.SHUT_RDWR)
        self._socket.close()
        self._reader.join(timeout=5)
        self._socket = None
        self._reader = None

    def wait_power_cut(self, timeout=DEFAULT_TIMEOUT):
        """Waits until the card's power cut stopped the board (power_cut_after)."""
        if self._qmp_path is None:
            raise EmulatorError("this emulator's card has no power cut")
        if not powercut.wait_stopped(self._qmp_path, timeout):
            raise self._failure(f"the board did not stop at the card's write {self.power_cut_after + 1} "
                                f"within {timeout} s")

    def reattach_console(self, timeout=DEFAULT_TIMEOUT):
        """Connects the harness to the console again after release_console()."""
        self._connect_console(timeout)

    def serial_socket_path(self, port):
        """The Unix socket the emulator serves serial port @p port on (see serial_sockets)."""
        return os.path.join(self._workdir.name, f"{port}.sock")

    def _read_console(self):
        while True:
            try:
                data = self._socket.recv(4096)
            except OSError:
                data = b""
            with self._condition:
                if not data:
                    self._closed = True
                    self._condition.notify_all()
                    return
                self._buffer += data
                self._condition.notify_all()

    def close(self):
        if self._process is not None and self._process.poll() is None:
            self._process.kill()
            self._process.wait(timeout=DEFAULT_TIMEOUT)
        if self._socket is not None:
            self._socket.close()
        if self._reader is not None:
            self._reader.join(timeout=5)
        self._workdir.cleanup()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.close()

    # -- console ------------------------------------------------------------

    @property
    def transcript(self):
        """Everything the console has printed so far."""
        with self._condition:
            return self._buffer.decode("latin-1")

    def emulator_messages(self):
        try:
            with open(self._stderr_path, encoding="utf-8", errors="replace") as handle:
                return handle.read()
        except FileNotFoundError:
            return ""

    def _failure(self, what):
        transcript = self.transcript
        code = explain(transcript, self.image)
        return EmulatorError(
            f"{self.name}: {what}\n----- console transcript -----\n{transcript}\n----- end of transcript -----\n"
            + (f"----- code addresses in the transcript ({self.image}) -----\n{code}" if code else "")
            + (f"emulator said: {self.emulator_messages()}" if self.emulator_messages() else "")
        )

    def expect(self, pattern, timeout=DEFAULT_TIMEOUT):
        """Waits for pattern (a regex) in the output after the previous match.

        Returns the match object; its text is consumed, so the next expect
        looks only at later output.
        """
        regex = re.compile(pattern.encode("latin-1") if isinstance(pattern, str) else pattern)
        deadline = time.monotonic() + timeout
        with self._condition:
            while True:
                match = regex.search(self._buffer, self._cursor)
                if match:
                    self._cursor = match.end()
                    return match
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise self._failure(f"timed out after {timeout:.0f} s waiting for {pattern!r}")
                if self._closed:
                    raise self._failure(f"console closed while waiting for {pattern!r}")
                self._condition.wait(min(remaining, 0.5))

    def output_since_mark(self):
        """The output after the last match that has not been consumed yet."""
        with self._condition:
            return self._buffer[self._cursor:].decode("latin-1")

    def send(self, text):
        """Types text on the console."""
        self._socket.sendall(text.encode("latin-1"))

    def command(self, line, prompt=r"dcos> ", timeout=DEFAULT_TIMEOUT):
        """Runs one shell command and returns its output (without echo and prompt)."""
        self.send(line + "\r")
        self.expect(re.escape(line) + r"\r\n", timeout)
        start = self._cursor
        match = self.expect(prompt, timeout)
        with self._condition:
            return self._buffer[start:match.start()].decode("latin-1")

    # -- exit ---------------------------------------------------------------

    def wait_exit(self, timeout=DEFAULT_TIMEOUT):
        """Waits for the emulator to end and returns its exit status."""
        try:
            return self._process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            raise self._failure(f"emulator still running after {timeout:.0f} s") from None

    def expect_exit(self, status, timeout=DEFAULT_TIMEOUT):
        names = {EXIT_PASS: "pass", EXIT_FAIL: "fail", EXIT_PANIC: "panic"}
        actual = self.wait_exit(timeout)
        if actual != status:
            raise self._failure(
                f"emulator exit status {actual} ({names.get(actual, 'not a test result')}), "
                f"expected {status} ({names.get(status, '?')})"
            )
