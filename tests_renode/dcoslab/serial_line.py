"""A board's serial port (e.g. the isa486's RS-485 port, COM2) in a test's hands.

The emulator serves the port on a Unix socket (Emulator(serial_sockets=
["rs485"])). With bridge=False the test writes and reads the line's bytes
itself (write, read): tests_renode/test_modbus_rs485.py does, under exact
emulated time, one frame per write. With bridge=True the bytes are copied
both ways to the master side of a pseudo-terminal, so that a host program
that expects a serial device (pymodbus's serial client, libmodbus) opens
`pty_path` as it would /dev/ttyUSB0. Such a program's timing between
characters is the host's, not the emulated line's: one that writes each
frame in one write(), as libmodbus does, reaches the controller as one
frame (test_libmodbus_master_reads_and_writes_the_controllers_slave), but
nothing at the emulated line's exact timing comes through the bridge. For
exact timing the port goes on the lab's RS-485 line instead
(dcoslab/rs485.py, docs/protocols/labbus.md "The RS-485 line"), where a
host program joins through rs485.LinePty and its bytes are paced at the
line's baud rate in emulated time.
"""

import os
import select
import socket
import threading
import time
import tty


class SerialLine:
    def __init__(self, socket_path, timeout=30.0, bridge=True):
        """bridge=False: no pty; the test writes and reads the line itself (write, read)."""
        deadline = time.monotonic() + timeout
        while True:
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.connect(socket_path)
                break
            except (FileNotFoundError, ConnectionRefusedError):
                sock.close()
                if time.monotonic() > deadline:
                    raise AssertionError(f"serial socket {socket_path} never appeared") from None
                time.sleep(0.02)
        self._socket = sock
        self._stop = threading.Event()
        self._thread = None
        self._master = self._slave = None
        self.pty_path = None
        if not bridge:
            return
        self._master, slave = os.openpty()
        tty.setraw(slave)
        self.pty_path = os.ttyname(slave)
        # Kept open so that the pty does not hang up between a program's closes.
        self._slave = slave
        self._thread = threading.Thread(target=self._copy, daemon=True)
        self._thread.start()

    def _copy(self):
        while not self._stop.is_set():
            ready, _, _ = select.select([self._socket, self._master], [], [], 0.1)
            try:
                if self._socket in ready:
                    data = self._socket.recv(4096)
                    if not data:
                        return
                    os.write(self._master, data)
                if self._master in ready:
                    self._socket.sendall(os.read(self._master, 4096))
            except OSError:
                return

    def write(self, data):
        """Puts bytes on the line at once (no bridge)."""
        self._socket.sendall(data)

    def read(self, count, timeout):
        """Up to count bytes the controller sends within timeout seconds (no bridge)."""
        data = b""
        deadline = time.monotonic() + timeout
        while len(data) < count:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                break
            ready, _, _ = select.select([self._socket], [], [], remaining)
            if not ready:
                break
            chunk = self._socket.recv(count - len(data))
            if not chunk:
                break
            data += chunk
        return data

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
        self._socket.close()
        for fd in (self._master, self._slave):
            if fd is not None:
                os.close(fd)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
