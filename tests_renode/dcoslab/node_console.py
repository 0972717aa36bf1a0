"""A second node's console on one of its board's serial ports, used as the main console is.

The dual-Pentium board's node 3 has its own console (COM4, the board's
"node3" serial port); a test reaches it through the emulator's socket for
that port (Emulator(serial_sockets=["node3"])). The port is not waited
for, so what node 3 printed before the test connected is gone: a test
starts by asking for a prompt.
"""

import re
import time

from .emulator import DEFAULT_TIMEOUT, EmulatorError
from .serial_line import SerialLine


class NodeConsole:
    def __init__(self, emulator, port, timeout=DEFAULT_TIMEOUT):
        self.emulator = emulator
        self.port = port
        self._line = SerialLine(emulator.serial_socket_path(port), timeout=timeout, bridge=False)
        self._buffer = bytearray()
        self._cursor = 0

    def close(self):
        self._line.close()

    @property
    def transcript(self):
        return self._buffer.decode("latin-1")

    def send(self, text):
        self._line.write(text.encode("latin-1"))

    def expect(self, pattern, timeout=DEFAULT_TIMEOUT):
        """Waits for pattern after what the previous expect matched; raises with both consoles' transcripts."""
        regex = re.compile(pattern.encode("latin-1") if isinstance(pattern, str) else pattern)
        deadline = time.monotonic() + timeout
        while True:
            match = regex.search(self._buffer, self._cursor)
            if match:
                self._cursor = match.end()
                return match
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise EmulatorError(f"{self.port}: timed out after {timeout} s waiting for {pattern!r}\n"
                                    f"----- {self.port} console transcript -----\n{self.transcript}\n"
                                    f"----- main console transcript -----\n{self.emulator.transcript}")
            self._buffer += self._line.read(4096, min(remaining, 0.5))

    def prompt(self, timeout=DEFAULT_TIMEOUT):
        """Asks for a fresh prompt (an empty line) and waits for it."""
        self.send("\r")
        self.expect(r"dcos> ", timeout)

    def command(self, line, timeout=DEFAULT_TIMEOUT):
        """Runs one shell command and returns its output (without echo and prompt)."""
        self.send(line + "\r")
        self.expect(re.escape(line) + r"\r\n", timeout)
        start = self._cursor
        match = self.expect(r"dcos> ", timeout)
        return self._buffer[start:match.start()].decode("latin-1")
