"""A minimal client of QEMU's GDB remote stub, for fault injection before a board's kernel runs.

A test boots a board paused (-S) with the stub on a Unix socket, stops it at
the kernel's entry with a hardware breakpoint (the BIOS has built its
tables by then), changes memory, and lets it run: the way to give a kernel
firmware tables it must refuse (a corrupt MP table) without a BIOS of our
own. Only the few packets of the GDB Remote Serial Protocol that needs are
spoken ("Remote Protocol" in the GDB manual): m, M, Z1, z1, c, D and ?.
"""

import os
import socket
import time

from .emulator import EmulatorError

ELF_ENTRY_OFFSET = 24  # e_entry in a 32-bit ELF header


def elf_entry(path):
    """The entry address of a 32-bit ELF image."""
    with open(path, "rb") as handle:
        header = handle.read(28)
    if header[:4] != b"\x7fELF" or header[4] != 1:
        raise ValueError(f"{path} is not a 32-bit ELF image")
    return int.from_bytes(header[ELF_ENTRY_OFFSET:ELF_ENTRY_OFFSET + 4], "little")


class GdbStub:
    """One connection to the stub at a Unix socket path; every wait is bounded."""

    def __init__(self, path, timeout=30.0):
        self.timeout = timeout
        deadline = time.monotonic() + timeout
        while True:
            self._socket = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                self._socket.connect(path)
                break
            except (FileNotFoundError, ConnectionRefusedError):
                self._socket.close()
                if time.monotonic() > deadline:
                    raise EmulatorError(f"the GDB stub at {path} never answered") from None
                time.sleep(0.02)
        self._socket.settimeout(timeout)
        self._pending = b""

    def close(self):
        self._socket.close()

    def _read_byte(self):
        if not self._pending:
            data = self._socket.recv(4096)
            if not data:
                raise EmulatorError("the GDB stub closed the connection")
            self._pending = data
        byte, self._pending = self._pending[:1], self._pending[1:]
        return byte

    def _send(self, payload):
        checksum = sum(payload.encode()) & 0xFF
        self._socket.sendall(f"${payload}#{checksum:02x}".encode())
        if self._read_byte() != b"+":
            raise EmulatorError(f"the GDB stub did not acknowledge {payload[:20]!r}")

    def _receive(self):
        while self._read_byte() != b"$":
            pass
        payload = bytearray()
        while (byte := self._read_byte()) != b"#":
            payload += byte
        self._read_byte()
        self._read_byte()  # The checksum: the stream is a local socket.
        self._socket.sendall(b"+")
        return payload.decode("latin-1")

    def request(self, payload):
        """Sends one packet and returns the stub's answer."""
        self._send(payload)
        return self._receive()

    def read_memory(self, address, length):
        data = bytearray()
        while len(data) < length:
            chunk = min(1024, length - len(data))
            answer = self.request(f"m{address + len(data):x},{chunk:x}")
            if answer.startswith("E") or len(answer) != 2 * chunk:
                raise EmulatorError(f"the GDB stub cannot read 0x{address + len(data):x}: {answer}")
            data += bytes.fromhex(answer)
        return bytes(data)

    def write_memory(self, address, data):
        answer = self.request(f"M{address:x},{len(data):x}:{data.hex()}")
        if answer != "OK":
            raise EmulatorError(f"the GDB stub cannot write 0x{address:x}: {answer}")

    def run_to(self, address):
        """Runs the machine until it reaches address (a hardware breakpoint), then clears the breakpoint."""
        if self.request(f"Z1,{address:x},1") != "OK":
            raise EmulatorError(f"the GDB stub refused a breakpoint at 0x{address:x}")
        self._send("c")
        stop = self._receive()
        if not stop.startswith(("T05", "S05")):
            raise EmulatorError(f"the machine stopped for another reason than the breakpoint: {stop}")
        if self.request(f"z1,{address:x},1") != "OK":
            raise EmulatorError(f"the GDB stub kept the breakpoint at 0x{address:x}")

    def detach(self):
        """Lets the machine run on without the debugger."""
        self.request("D")
        self.close()


def paused_boot_args(path):
    """Emulator arguments that start a board paused, its GDB stub at path."""
    return ["-S", "-gdb", f"unix:{os.fspath(path)},server=on,wait=off"]
