"""The host end of the lab VM's slcan serial port: Lawicel ASCII on a unix socket.

The VM's second serial port (ttyS1) is a QEMU `-chardev socket` server on a
unix socket (`LabVM.slcan_socket_path`). Inside the VM, `slcand` attaches the
kernel's slcan line discipline to ttyS1, so SocketCAN `can0` and this socket
are two ends of one serial line speaking the Lawicel (CAN232/CANUSB) protocol.
Any host program joins the VM's CAN bus by connecting to the socket; this
module is a small one for tests, and the contract for a replacement (such as
the lab CAN bus hub's slcan bridge) is just:

- The stream is ASCII lines, each ended by CR ("\\r"); there is no LF.
- Frames in either direction (ids and data in upper-case hex, as the kernel
  writes them; the kernel also reads lower case):
    t<iii><l><dd...>        standard data frame, e.g. t123411223344
    T<iiiiiiii><l><dd...>   extended data frame, e.g. T1ABCDEF020102
    r<iii><l> / R<iiiiiiii><l>   remote frames (no data)
  <l> is the length code 0-8.
- The guest also sends adapter commands when slcand starts: "C" (close),
  "S<n>" (bit rate code, see `BITRATE_CODES`) and "O" (open). They need no
  answer (the kernel ignores a CR or BEL reply). They are sent only once, so a
  host program that wants to see them must connect before the guest runs
  slcand; `LabVM` connects its `SlcanPort` right after QEMU starts.
- QEMU's socket is `server=on,wait=off`: while nobody is connected, what the
  guest sends is dropped; a new connection may be made at any time.
"""

import socket
import threading
import time

# Lawicel "S<n>" codes and the bit rates they select.
BITRATE_CODES = {10000: 0, 20000: 1, 50000: 2, 100000: 3, 125000: 4, 250000: 5, 500000: 6, 800000: 7, 1000000: 8}

DEFAULT_TIMEOUT = 30.0


class SlcanError(AssertionError):
    """A Lawicel line or frame that did not come, or could not be parsed."""


class CanFrame:
    """A classic CAN frame: identifier, data (0-8 bytes), extended or standard, data or remote."""

    __slots__ = ("can_id", "data", "extended", "remote", "dlc")

    def __init__(self, can_id, data=b"", extended=None, remote=False, dlc=None):
        data = bytes(data)
        if extended is None:
            extended = can_id > 0x7FF
        limit = 0x1FFFFFFF if extended else 0x7FF
        if not 0 <= can_id <= limit:
            raise ValueError(f"CAN id {can_id:#x} does not fit a {'n extended' if extended else ' standard'} frame")
        if len(data) > 8 or (remote and data):
            raise ValueError("a classic CAN frame carries 0 to 8 data bytes, a remote frame none")
        self.can_id = can_id
        self.data = data
        self.extended = extended
        self.remote = remote
        self.dlc = len(data) if dlc is None else dlc
        if not 0 <= self.dlc <= 8:
            raise ValueError(f"length code {self.dlc} is not 0-8")

    def __eq__(self, other):
        return isinstance(other, CanFrame) and (self.can_id, self.data, self.extended, self.remote, self.dlc) == (
            other.can_id, other.data, other.extended, other.remote, other.dlc)

    def __hash__(self):
        return hash((self.can_id, self.data, self.extended, self.remote, self.dlc))

    def __repr__(self):
        kind = "extended" if self.extended else "standard"
        if self.remote:
            return f"CanFrame({self.can_id:#x}, remote, dlc={self.dlc}, {kind})"
        return f"CanFrame({self.can_id:#x}, {self.data.hex()!r}, {kind})"

    def lawicel(self):
        """The frame as one Lawicel line, with its CR."""
        letter = ("R" if self.remote else "T") if self.extended else ("r" if self.remote else "t")
        identifier = f"{self.can_id:08X}" if self.extended else f"{self.can_id:03X}"
        return f"{letter}{identifier}{self.dlc}{'' if self.remote else self.data.hex().upper()}\r"

    @classmethod
    def from_lawicel(cls, line):
        """Parses one Lawicel frame line (with or without its CR)."""
        text = line.rstrip("\r")
        if not text or text[0] not in "tTrR":
            raise SlcanError(f"{line!r} is not a Lawicel frame line")
        extended = text[0] in "TR"
        remote = text[0] in "rR"
        width = 8 if extended else 3
        try:
            can_id = int(text[1:1 + width], 16)
            dlc = int(text[1 + width], 10)
            payload = text[2 + width:]
            data = b"" if remote else bytes.fromhex(payload)
        except (ValueError, IndexError):
            raise SlcanError(f"{line!r} is not a well-formed Lawicel frame") from None
        if len(text) < 2 + width or (not remote and len(data) != dlc) or (remote and payload):
            raise SlcanError(f"{line!r}: the length code and the data do not agree")
        return cls(can_id, data, extended=extended, remote=remote, dlc=dlc)


class SlcanPort:
    """A host-side connection to the VM's slcan socket, for tests.

    port = SlcanPort(path)          # connects (waits for QEMU to create the socket)
    port.send(CanFrame(0x123, b"\\x11\\x22"))   # or port.send_line("t1232 1122")
    frame = port.receive_frame()    # next frame the guest sent
    line = port.receive_line()      # next line of any kind (frames and commands)
    port.lines                      # every line received so far, in order
    """

    def __init__(self, path, connect_timeout=DEFAULT_TIMEOUT):
        self.path = path
        self.lines = []  # every complete line received, without CR
        self._pending = bytearray()
        self._cursor = 0  # index in self.lines of the next line receive_line returns
        self._condition = threading.Condition()
        self._closed = False
        deadline = time.monotonic() + connect_timeout
        while True:
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.connect(path)
                break
            except (FileNotFoundError, ConnectionRefusedError):
                sock.close()
                if time.monotonic() > deadline:
                    raise SlcanError(f"no slcan socket at {path} after {connect_timeout:.0f} s") from None
                time.sleep(0.02)
        self._socket = sock
        self._reader = threading.Thread(target=self._read, name="slcan-reader", daemon=True)
        self._reader.start()

    def _read(self):
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
                self._pending += data
                while True:
                    ends = [i for i in (self._pending.find(b"\r"), self._pending.find(b"\a")) if i >= 0]
                    if not ends:
                        break
                    end = min(ends)
                    line = self._pending[:end].decode("ascii", "replace").lstrip("\n")
                    del self._pending[:end + 1]
                    if line:
                        self.lines.append(line)
                self._condition.notify_all()

    def send_line(self, text):
        """Writes one Lawicel line; a CR is added if text has none."""
        if not text.endswith("\r"):
            text += "\r"
        self._socket.sendall(text.encode("ascii"))

    def send(self, frame):
        """Writes a CanFrame as its Lawicel line."""
        self._socket.sendall(frame.lawicel().encode("ascii"))

    def receive_line(self, timeout=DEFAULT_TIMEOUT):
        """The next complete line (without CR) after the previous one returned."""
        deadline = time.monotonic() + timeout
        with self._condition:
            while self._cursor >= len(self.lines):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise SlcanError(f"no Lawicel line on {self.path} within {timeout:.0f} s; "
                                     f"lines so far: {self.lines}, unfinished: {bytes(self._pending)!r}")
                if self._closed:
                    raise SlcanError(f"the slcan socket {self.path} closed; lines so far: {self.lines}")
                self._condition.wait(min(remaining, 0.5))
            line = self.lines[self._cursor]
            self._cursor += 1
            return line

    def receive_frame(self, timeout=DEFAULT_TIMEOUT):
        """The next frame line, parsed; command lines (C, S6, O, ...) before it are skipped."""
        deadline = time.monotonic() + timeout
        while True:
            line = self.receive_line(max(0.0, deadline - time.monotonic()))
            if line[:1] in ("t", "T", "r", "R"):
                return CanFrame.from_lawicel(line)

    def wait_for_line(self, wanted, timeout=DEFAULT_TIMEOUT):
        """Waits until a line equal to wanted has arrived (at any time since connecting)."""
        deadline = time.monotonic() + timeout
        with self._condition:
            while wanted not in self.lines:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise SlcanError(f"no line {wanted!r} on {self.path} within {timeout:.0f} s; "
                                     f"lines so far: {self.lines}")
                if self._closed:
                    raise SlcanError(f"the slcan socket {self.path} closed before {wanted!r}; lines: {self.lines}")
                self._condition.wait(min(remaining, 0.5))

    def close(self):
        try:
            self._socket.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._socket.close()
        self._reader.join(timeout=5)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
