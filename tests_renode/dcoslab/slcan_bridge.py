"""A bridge from the lab VM's slcan serial socket to one bus of the lab's CAN bus hub.

Inside the lab VM (tests_renode/labvm, docs/guide/lab-vm.md), slcand drives
the kernel's slcan line discipline on ttyS1, whose other end is a unix socket
on the host (`LabVM.slcan_socket_path`). The kernel is the *host* side of a
Lawicel serial adapter there; this bridge plays the *adapter*, and its CAN
side is a "host" participant of the hub (docs/protocols/labbus.md, "Joining
from a host tool" and "The lab VM through slcan"). So Linux's own CAN stack
(can-raw, can-isotp, python-can, can-utils) shares a bus with the emulated
controllers.

    bridge = SlcanBridge(vm.slcan_socket_path, hub_socket_path, "can0")
    bridge.start()        # connect to the VM's socket first: right after QEMU starts, so C/S/O are seen
    ...
    bridge.stop()

Contract:

- The VM side: ASCII lines ended by CR (LF and BEL also end a line; empty
  lines are ignored, a line over 64 characters or not ASCII is malformed).
  From the VM:
  `C` closes the channel, `S<n>` sets the bit rate code (labvm BITRATE_CODES:
  S6 is 500 kbit/s), `O` opens it; each is answered CR, or BEL when refused.
  `S<n>` for another bit rate than the hub bus's is refused and logged, and
  `O` after it is refused too: the channel stays closed. `O` without any
  `S<n>` opens at the bus's bit rate. Any other line is answered BEL and
  counted as malformed.
  Frames `t<iii><l><dd..>`, `T<iiiiiiii><l><dd..>`, `r<iii><l>`, `R<iiiiiiii><l>`
  (hex in either case) go to the hub as `TX <port> - <frame> -` while the
  channel is open, in the order they came; the bridge sends no `z`/`Z` reply.
  Like a chip's, a frame nobody acknowledges is retransmitted by the hub.
  Frames while closed are dropped and counted (`dropped_closed`); malformed
  lines are dropped and counted (`malformed`), never raised.
- The hub side: the bridge joins as `HELLO 1 <name> host` and attaches port 0
  to the bus (default name `linux`, so its port is `linux.0`); it is on the
  bus from ATTACH and acknowledges frames like any node, whether the VM's
  channel is open or not (as an adapter's controller does once powered).
  Every `RX` event for its port becomes one Lawicel line to the VM while the
  channel is open (identifiers and data in upper-case hex, as the kernel
  writes them; a DLC of 9-15 is sent as 8, Lawicel's one digit); the VM's
  own frames are not echoed back (the kernel loops
  them back to its local sockets itself). `TXOK` is counted (`sent`); `ERR tx
  ... final`, `LOST ... final` and `ABORTED` are counted (`failed`).
- Every socket operation has a time-out; the thread ends on `stop()`, when
  either side closes (the VM's side closes when QEMU powers off), or on a hub
  `ERROR`; `error` then says why (None after `stop()` alone). `log` keeps the last lines in both directions for a test's
  failure report (`log_text()`).
"""

import collections
import os
import selectors
import socket
import threading
import time

from .canbus import PROTOCOL_VERSION, Frame

# Lawicel "S<n>" codes and the bit rates they select (as labvm.slcan.BITRATE_CODES).
BITRATE_CODES = {10000: 0, 20000: 1, 50000: 2, 100000: 3, 125000: 4, 250000: 5, 500000: 6, 800000: 7, 1000000: 8}
CODE_BITRATES = {code: rate for rate, code in BITRATE_CODES.items()}

OK = b"\r"
REFUSED = b"\a"
MAX_LINE = 64  # the longest Lawicel frame line is 27 characters
DEFAULT_TIMEOUT = 30.0


class BridgeError(RuntimeError):
    """The bridge could not connect, or the hub refused it."""


def parse_lawicel(line):
    """A Lawicel frame line (without its CR) as a hub Frame; ValueError if malformed."""
    if not line or line[0] not in "tTrR":
        raise ValueError(f"{line!r} is not a frame line")
    extended = line[0] in "TR"
    remote = line[0] in "rR"
    width = 8 if extended else 3
    head = line[1:1 + width]
    if len(head) != width or len(line) < 2 + width or not _is_hex(head) or not line[1 + width].isdigit():
        raise ValueError(f"{line!r}: no {width}-digit identifier and length code")
    dlc = int(line[1 + width])
    payload = line[2 + width:]
    if dlc > 8:
        raise ValueError(f"{line!r}: length code {dlc} is not 0-8")
    if remote:
        if payload:
            raise ValueError(f"{line!r}: a remote frame carries no data")
        data = b""
    else:
        if len(payload) != 2 * dlc or (payload and not _is_hex(payload)):
            raise ValueError(f"{line!r}: length code {dlc} needs {2 * dlc} hex digits of data")
        data = bytes.fromhex(payload)
    return Frame(int(head, 16), extended, remote, dlc, data)  # raises ValueError for an id out of range


def to_lawicel(frame):
    """A hub Frame as a Lawicel line, with its CR (upper-case hex, as the kernel writes them)."""
    letter = ("R" if frame.remote else "T") if frame.extended else ("r" if frame.remote else "t")
    identifier = f"{frame.id:08X}" if frame.extended else f"{frame.id:03X}"
    dlc = min(frame.dlc, 8)  # Lawicel has one digit 0-8; a DLC 9-15 frame carries 8 bytes
    return f"{letter}{identifier}{dlc}{'' if frame.remote else frame.data.hex().upper()}\r"


def _is_hex(text):
    return bool(text) and all(c in "0123456789abcdefABCDEF" for c in text)


class SlcanBridge:
    """The adapter end of the VM's slcan socket, joined to one hub bus; see the module docstring."""

    def __init__(self, vm_socket_path, hub_socket_path, bus, name="linux", timeout=DEFAULT_TIMEOUT, log_size=4000):
        self.vm_socket_path = vm_socket_path
        self.hub_socket_path = hub_socket_path
        self.bus = bus
        self.name = name
        self.timeout = timeout
        self.bitrate = None  # the hub bus's, from ATTACHED
        self.port_name = None
        self.is_open = False
        self.requested_bitrate = None  # from the VM's last S<n>
        self.rate_refused = False
        self.commands = []  # the adapter commands the VM sent, in order (C, S6, O, ...)
        self.counts = collections.Counter()  # from_vm, to_vm, sent, failed, malformed, dropped_closed, refused
        self.error = None
        self._log = collections.deque(maxlen=log_size)
        self._lock = threading.Condition()
        self._vm = None
        self._hub = None
        self._thread = None
        self._stop = False
        self._wake_r = self._wake_w = None

    # -- life cycle ---------------------------------------------------------

    def start(self):
        """Connects to the VM's socket (waiting for QEMU to make it), joins the hub, starts the thread."""
        self._vm = self._connect_vm()
        try:
            self._hub = self._join_hub()
        except BaseException:
            self._vm.close()
            raise
        self._wake_r, self._wake_w = os.pipe()
        self._thread = threading.Thread(target=self._run, name="slcan-bridge", daemon=True)
        self._thread.start()
        return self

    def stop(self, timeout=10.0):
        """Leaves the hub, closes the VM's socket and ends the thread."""
        with self._lock:
            self._stop = True
        if self._wake_w is not None:
            try:
                os.write(self._wake_w, b"x")
            except OSError:
                pass
        if self._thread is not None:
            self._thread.join(timeout)
        self._close()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()

    def _connect_vm(self):
        deadline = time.monotonic() + self.timeout
        while True:
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.connect(self.vm_socket_path)
                sock.settimeout(self.timeout)
                self._note(f"# connected to the VM's slcan socket {self.vm_socket_path}")
                return sock
            except (FileNotFoundError, ConnectionRefusedError):
                sock.close()
                if time.monotonic() > deadline:
                    raise BridgeError(f"no slcan socket at {self.vm_socket_path} after {self.timeout:.0f} s") from None
                time.sleep(0.02)

    def _join_hub(self):
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.settimeout(self.timeout)
        self._hub_buffer = b""
        try:
            sock.connect(self.hub_socket_path)
            sock.sendall(f"HELLO {PROTOCOL_VERSION} {self.name} host\n".encode("ascii"))
            welcome = self._answer(sock).split()
            if len(welcome) != 4 or welcome[0] != "WELCOME":
                raise BridgeError(f"the hub answered HELLO with {' '.join(welcome)!r}")
            sock.sendall(f"ATTACH 0 {self.bus}\n".encode("ascii"))
            attached = self._answer(sock).split()
            if len(attached) != 5 or attached[0] != "ATTACHED":
                raise BridgeError(f"the hub answered ATTACH 0 {self.bus} with {' '.join(attached)!r}")
        except OSError as error:
            sock.close()
            raise BridgeError(f"cannot join the hub at {self.hub_socket_path}: {error}") from None
        except BaseException:
            sock.close()
            raise
        self.bitrate = round(1e9 / int(attached[3]))
        self.port_name = attached[4]
        self._note(f"# joined the hub as {self.port_name} on {self.bus} at {self.bitrate} bit/s")
        return sock

    def _answer(self, sock):
        """One line from the hub during the handshake (what follows it stays in _hub_buffer)."""
        while b"\n" not in self._hub_buffer:
            data = sock.recv(4096)  # the socket's time-out bounds this
            if not data:
                raise BridgeError("the hub closed the connection during the handshake")
            self._hub_buffer += data
        line, self._hub_buffer = self._hub_buffer.split(b"\n", 1)
        return line.decode("ascii", "replace")

    def _close(self):
        for sock in (self._hub, self._vm):
            if sock is not None:
                try:
                    if sock is self._hub:
                        sock.sendall(b"BYE\n")
                except OSError:
                    pass
                try:
                    sock.close()
                except OSError:
                    pass
        self._hub = self._vm = None
        for fd in (self._wake_r, self._wake_w):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._wake_r = self._wake_w = None

    # -- observation (thread-safe) ------------------------------------------

    def log_lines(self):
        with self._lock:
            return list(self._log)

    def log_text(self):
        return "".join(line + "\n" for line in self.log_lines())

    def wait_for(self, condition, timeout, what):
        """Waits until condition(self) is true; AssertionError with the bridge's log on time-out."""
        deadline = time.monotonic() + timeout
        with self._lock:
            while not condition(self):
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise AssertionError(f"slcan bridge: timed out after {timeout:.0f} s waiting for {what}; "
                                         f"error {self.error}, counts {dict(self.counts)}\n{self.log_text_locked()}")
                self._lock.wait(min(remaining, 0.5))

    def log_text_locked(self):
        return "".join(line + "\n" for line in self._log)

    def _note(self, line):
        with self._lock:
            self._log.append(f"{time.monotonic():.3f} {line}")
            self._lock.notify_all()

    # -- the thread -----------------------------------------------------------

    def _run(self):
        selector = selectors.DefaultSelector()
        selector.register(self._vm, selectors.EVENT_READ, "vm")
        selector.register(self._hub, selectors.EVENT_READ, "hub")
        selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        vm_buffer = b""
        why = None
        try:
            self._hub_lines(b"")  # anything that came with ATTACHED
            while True:
                with self._lock:
                    if self._stop:
                        break
                for key, _ in selector.select(0.5):
                    if key.data == "wake":
                        os.read(self._wake_r, 64)
                        continue
                    data = key.fileobj.recv(4096)
                    if not data:
                        raise _Ended(f"the {'VM' if key.data == 'vm' else 'hub'} closed the connection")
                    if key.data == "vm":
                        vm_buffer = self._vm_lines(vm_buffer + data)
                    else:
                        self._hub_lines(data)
        except _Ended as ended:
            why = str(ended)
        except OSError as error:
            why = f"{type(error).__name__}: {error}"
        except Exception as error:  # a bug here: make it visible, never hang the test
            why = f"bridge failure: {type(error).__name__}: {error}"
        finally:
            selector.close()
            with self._lock:
                self.error = why
                if why:
                    self._log.append(f"{time.monotonic():.3f} # stopped: {why}")
                self._lock.notify_all()

    # The VM's side: Lawicel lines ended by CR (LF and BEL also end a line).

    def _vm_lines(self, buffer):
        while True:
            ends = [i for i in (buffer.find(b"\r"), buffer.find(b"\n"), buffer.find(b"\a")) if i >= 0]
            if not ends:
                if len(buffer) > MAX_LINE:  # no line end in sight: garbage
                    self._malformed(buffer[:40], "no line end")
                    return b""
                return buffer
            end = min(ends)
            raw, buffer = buffer[:end], buffer[end + 1:]
            if raw:
                try:
                    line = raw.decode("ascii")
                except UnicodeDecodeError:
                    self._malformed(raw[:40], "not ASCII")
                    continue
                self._vm_line(line)

    def _vm_line(self, line):
        self._note(f"vm> {line}")
        with self._lock:
            self.counts["lines_from_vm"] += 1
        head = line[0]
        if head in "tTrR":
            try:
                frame = parse_lawicel(line)
            except ValueError as error:
                self._malformed(line, str(error))
                return
            if not self.is_open:
                self._count("dropped_closed", f"# dropped {line!r}: the channel is not open")
                return
            self._hub.sendall(f"TX 0 - {frame} -\n".encode("ascii"))
            self._count("from_vm")
            return
        if line == "C":
            self._command(line, True, "closed")
            self.is_open = False
        elif head == "S" and len(line) == 2 and line[1].isdigit() and int(line[1]) in CODE_BITRATES:
            self.requested_bitrate = CODE_BITRATES[int(line[1])]
            self.rate_refused = self.requested_bitrate != self.bitrate
            self._command(line, not self.rate_refused,
                          f"refused: {self.requested_bitrate} bit/s, but {self.bus} runs at {self.bitrate} bit/s"
                          if self.rate_refused else f"bit rate {self.requested_bitrate} bit/s")
        elif line == "O":
            if self.rate_refused:
                self._command(line, False, "refused to open: the bit rate asked for is not the bus's")
            else:
                self._command(line, True, f"open on {self.bus}")
                self.is_open = True
        else:
            self._malformed(line, "not a frame or a command this adapter knows")
            self._vm.sendall(REFUSED)

    def _command(self, line, accepted, what):
        with self._lock:
            self.commands.append(line)
            if not accepted:
                self.counts["refused"] += 1
        self._note(f"# {line}: {what}")
        self._vm.sendall(OK if accepted else REFUSED)

    def _malformed(self, line, why):
        self._count("malformed", f"# dropped malformed {line!r}: {why}")

    def _count(self, key, note=None):
        with self._lock:
            self.counts[key] += 1
        if note:
            self._note(note)

    # The hub's side: events for port 0.

    def _hub_lines(self, data):
        self._hub_buffer += data
        while b"\n" in self._hub_buffer:
            raw, self._hub_buffer = self._hub_buffer.split(b"\n", 1)
            words = raw.decode("ascii", "replace").split()
            if not words:
                continue
            verb = words[0]
            if verb == "ERROR":
                raise _Ended(f"the hub refused the bridge: {' '.join(words[1:])}")
            if len(words) < 4 or words[1] != "0":
                continue
            if verb == "RX" and len(words) >= 9:
                frame = Frame.from_words(words[4:8])
                if not self.is_open:
                    self._count("not_forwarded", f"hub> {' '.join(words[4:8])} (not forwarded: the channel is closed)")
                    continue
                line = to_lawicel(frame)
                self._vm.sendall(line.encode("ascii"))
                self._count("to_vm", f"hub> {' '.join(words[4:8])} -> {line[:-1]}")
            elif verb == "TXOK":
                self._count("sent", f"hub> TXOK at {words[3]} ns")
            elif (verb == "ERR" and len(words) >= 7 and words[4] == "tx" and "final" in words[6].split(",")) or \
                    (verb == "LOST" and len(words) >= 6 and words[5] == "1") or verb == "ABORTED":
                self._count("failed", f"hub> {' '.join(words)} (a frame from the VM given up)")


class _Ended(Exception):
    """The bridge's thread ends: a side closed or the hub refused it."""
