#!/usr/bin/python3
"""Host bring-up tool for the multi-function ISA I/O board.

It drives the controller's `iobus bringup [base] [irq]` console command,
collects the BRINGUP lines (docs/iobus/bringup-protocol.md), judges them
against limits the user can set, prints a pass/fail report that names every
failing channel and gain, DI bit or interrupt, writes a JSON result and a
PNG sheet of the results, and exits with a status that says what happened:

    0    every check passed
    1    failures found
    2    bad options (checked before anything runs, output paths included)
    3    board absent (the probe found no board)
    4    no connection, time-out, or the report did not finish
    5    a result file could not be written
    130  interrupted (Ctrl-C, SIGTERM or SIGHUP)

The controller is reached over a serial device (pyserial), a Unix socket
(the emulator's console socket), a launched program's stdin and stdout
(--exec), or an emulated board booted here through the emulator lab
(--emulator, for lab use, with optional fault properties of the isa-mfio
model). --transcript judges a saved console transcript instead. Whatever it
started (--exec, --emulator) it ends again, on success, failure, time-out and
interruption alike.

The parsing and judging live in bringup_report.py; this file is the console
plumbing and the command line. It runs from the source tree and from an
installed DCOS (make install: share/dcos/tools/bringup/, started through
bin/mfio_bringup.py), where the emulator lab is share/dcos/python/.
"""

import argparse
import datetime
import importlib.util
import math
import os
import re
import select
import signal
import socket
import subprocess
import sys
import tempfile
import time

# The real location, also when started through a symbolic link such as an installation's bin/.
HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, HERE)

import bringup_report as br  # noqa: E402

DEFAULT_PROMPT = r"dcos> "
# The longest time-out accepted: longer ones overflow select() and are surely typing mistakes.
MAX_TIMEOUT_S = 1e6
# How long the program or emulator that was started gets to end after SIGTERM before SIGKILL.
TERMINATE_GRACE_S = 3.0
# How long a report waits for a program whose console closed to exit.
EXIT_STATUS_WAIT_S = 2.0


def lab_directory():
    """The emulator lab (the dcoslab package): tests_renode/ in the source tree, share/dcos/python/ installed."""
    root = os.path.dirname(os.path.dirname(HERE))
    for candidate in (os.path.join(root, "tests_renode"), os.path.join(root, "python")):
        if os.path.isdir(os.path.join(candidate, "dcoslab")):
            return candidate
    return os.path.join(root, "tests_renode")


class ConnectionFailed(Exception):
    """The console could not be reached or went away."""


class Interrupts:
    """Turns Ctrl-C, SIGTERM and SIGHUP into KeyboardInterrupt while the bring-up runs, and only records
    them while the tool cleans up and writes its results, so that a second Ctrl-C cannot leave a started
    emulator running or a result half written."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

    def __init__(self):
        self.raising = True
        self.seen = False
        for number in self.SIGNALS:
            signal.signal(number, self._handle)

    def _handle(self, number, frame):
        self.seen = True
        if self.raising:
            self.raising = False
            raise KeyboardInterrupt

    def defer(self):
        self.raising = False


# -- consoles ---------------------------------------------------------------
#
# Each console offers write(bytes), read(timeout) -> bytes ('' on time-out,
# None when closed), diagnostics() -> what the far end said about itself
# (for an error message) and close().


class FdConsole:
    """A console over a pair of file descriptors (a socket, a serial port, pipes)."""

    def __init__(self, read_fd, write):
        self.read_fd = read_fd
        self._write = write
        self.ended = False  # the far end closed the console

    def write(self, data):
        try:
            self._write(data)
        except OSError as error:
            raise ConnectionFailed(f"console write failed: {error}") from None

    def read(self, timeout):
        ready, _, _ = select.select([self.read_fd], [], [], max(timeout, 0))
        if not ready:
            return b""
        try:
            data = os.read(self.read_fd, 4096)
        except OSError:
            data = b""
        if not data:
            self.ended = True
            return None
        return data

    def diagnostics(self):
        return ""

    def close(self):
        pass


class SocketConsole(FdConsole):
    def __init__(self, path, timeout):
        deadline = time.monotonic() + timeout
        while True:
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.connect(path)
                break
            except (FileNotFoundError, ConnectionRefusedError) as error:
                sock.close()
                if time.monotonic() > deadline:
                    raise ConnectionFailed(f"cannot connect to console socket {path}: {error}") from None
                time.sleep(0.05)
            except OSError as error:
                sock.close()
                raise ConnectionFailed(f"cannot connect to console socket {path}: {error}") from None
        self.sock = sock
        super().__init__(sock.fileno(), sock.sendall)

    def close(self):
        self.sock.close()


class SerialConsole(FdConsole):
    def __init__(self, device, baud):
        try:
            import serial
        except ImportError:
            raise ConnectionFailed("pyserial is missing: install Debian's python3-serial") from None
        try:
            self.port = serial.Serial(device, baudrate=baud, timeout=0)
        except (serial.SerialException, OSError, ValueError) as error:
            raise ConnectionFailed(f"cannot open serial device {device}: {error}") from None
        super().__init__(self.port.fileno(), self.port.write)

    def close(self):
        self.port.close()


def _tail(data, limit=4000):
    """The end of a program's error output, decoded, for a message."""
    text = data[-limit:].decode("utf-8", errors="replace").strip()
    return ("..." + text) if len(data) > limit else text


class ProcessConsole(FdConsole):
    """A launched program whose stdin and stdout are the console.

    The program runs in a session and process group of its own: the shell
    that runs COMMAND may start the emulator as its child, and ending only
    the shell would leave the emulator running. close() ends the whole group.
    Its standard error goes to a temporary file, so that a program that
    cannot start can say why.
    """

    def __init__(self, command):
        self.errors = tempfile.TemporaryFile()
        try:
            self.process = subprocess.Popen(command, shell=True, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                            stderr=self.errors, start_new_session=True)
        except OSError as error:
            self.errors.close()
            raise ConnectionFailed(f"cannot start {command!r}: {error}") from None
        self.command = command

        def write(data):
            self.process.stdin.write(data)
            self.process.stdin.flush()

        super().__init__(self.process.stdout.fileno(), write)

    def diagnostics(self):
        # The console ends when the program closes its output, a moment
        # before the program itself has exited and can be reaped: give it
        # that moment, so that its exit status is part of the report.
        try:
            status = self.process.wait(EXIT_STATUS_WAIT_S) if self.ended else self.process.poll()
        except subprocess.TimeoutExpired:
            status = None
        parts = []
        if status is not None:
            parts.append(f"the program exited with status {status}" if status >= 0
                         else f"the program was ended by signal {-status}")
        try:
            self.errors.seek(0)
            said = _tail(self.errors.read())
        except (OSError, ValueError):
            said = ""
        if said:
            parts.append("its error output:\n" + "\n".join("  " + line for line in said.splitlines()))
        return "\n".join(parts)

    def _group_alive(self):
        try:
            os.killpg(self.process.pid, 0)
            return True
        except (ProcessLookupError, PermissionError):
            return False

    def close(self):
        # SIGTERM to the whole group first, so that an emulator can end cleanly; SIGKILL after the grace time.
        try:
            os.killpg(self.process.pid, signal.SIGTERM)
        except (ProcessLookupError, PermissionError):
            pass
        deadline = time.monotonic() + TERMINATE_GRACE_S
        while time.monotonic() < deadline:
            self.process.poll()
            if self.process.returncode is not None and not self._group_alive():
                break
            time.sleep(0.02)
        else:
            try:
                os.killpg(self.process.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pass
        for stream in (self.process.stdin, self.process.stdout):
            try:
                stream.close()
            except OSError:
                pass
        self.errors.close()


class EmulatorConsole:
    """An emulated board booted through the emulator lab (dcoslab), its console socket read through dcoslab."""

    def __init__(self, options):
        lab = lab_directory()
        sys.path.insert(0, lab)
        try:
            from dcoslab.board import load_board
            from dcoslab.emulator import Emulator, EmulatorError
        except ImportError as error:
            raise ConnectionFailed(f"cannot load the emulator lab from {lab}: {error}") from None
        try:
            board = load_board(options.board)
        except SystemExit as error:
            raise ConnectionFailed(str(error)) from None
        properties = dict(options.model_property or [])
        if options.model not in board.device_drivers():
            raise ConnectionFailed(f"board {options.board} has no {options.model} device; its devices are: "
                                   f"{', '.join(board.device_drivers())}")
        try:
            image = options.image or board.image(options.image_kind)
        except (KeyError, ValueError, SystemExit) as error:
            raise ConnectionFailed(f"board {options.board} has no {options.image_kind} image; it has: "
                                   f"{', '.join(getattr(board, 'images', {}))}") from None
        self.emulator = Emulator(
            board, image, icount=options.icount,
            device_properties={options.model: properties} if properties else None,
            without_devices=[options.model] if options.without_model else (),
            extra_args=options.emulator_arg or (),
        )
        try:
            self.emulator.start(timeout=options.connect_timeout)
        except (EmulatorError, ValueError, RuntimeError, OSError) as error:
            self.emulator.close()
            raise ConnectionFailed(f"the emulator did not start: {error}") from None
        except BaseException:
            # Interrupted while it starts: the emulator must not outlive the tool.
            self.emulator.close()
            raise
        self.argv = self.emulator.argv
        self.seen = 0

    def write(self, data):
        try:
            self.emulator.send(data.decode("latin-1"))
        except OSError as error:
            raise ConnectionFailed(f"console write failed: {error}") from None

    def read(self, timeout):
        deadline = time.monotonic() + timeout
        while True:
            text = self.emulator.transcript
            if len(text) > self.seen:
                data = text[self.seen:].encode("latin-1")
                self.seen = len(text)
                return data
            if self.emulator._process.poll() is not None:
                return None
            if time.monotonic() >= deadline:
                return b""
            time.sleep(0.01)

    def diagnostics(self):
        status = self.emulator._process.poll()
        said = _tail(self.emulator.emulator_messages().encode("utf-8"))
        parts = []
        if status is not None:
            parts.append(f"the emulator exited with status {status}")
        if said:
            parts.append("its messages:\n" + "\n".join("  " + line for line in said.splitlines()))
        return "\n".join(parts)

    def close(self):
        self.emulator.close()


# -- the session ------------------------------------------------------------


class Session:
    """Reads the console into a transcript and waits for patterns with time-outs."""

    def __init__(self, console, echo=None):
        self.console = console
        self.text = ""
        self.cursor = 0
        self.start = 0  # where the command's output begins
        self.closed = False
        self.echo = echo

    def pump(self, timeout):
        data = self.console.read(timeout)
        if data is None:
            self.closed = True
            return False
        if data:
            chunk = data.decode("latin-1")
            self.text += chunk
            if self.echo:
                self.echo.write(chunk)
                self.echo.flush()
        return bool(data)

    def wait_for(self, regex, timeout):
        """The match of regex after the cursor, or None at time-out or end of the console."""
        pattern = re.compile(regex)
        deadline = time.monotonic() + timeout
        while True:
            match = pattern.search(self.text, self.cursor)
            if match:
                self.cursor = match.end()
                return match
            remaining = deadline - time.monotonic()
            if remaining <= 0 or self.closed:
                return None
            self.pump(min(remaining, 0.2))

    def send(self, text):
        self.console.write(text.encode("latin-1"))

    def output(self):
        """The console output from the command on."""
        return self.text[self.start:]


def bringup_command(options):
    words = ["iobus", "bringup"]
    if options.base is not None:
        words.append(f"0x{options.base:x}")
    if options.irq is not None:
        if options.base is None:
            words.append("0x300")
        words.append(str(options.irq))
    return " ".join(words)


def run_on_console(session, options, prompt):
    """Runs the command; returns why it stopped early, or None. session.output() is the command's output."""
    # Wake the shell and wait for a prompt; a console that shows none may still work.
    if options.wait_prompt:
        session.send("\r")
        if session.wait_for(prompt, options.connect_timeout) is None and session.closed:
            session.start = len(session.text)
            return "the console closed before the first prompt"
    start = len(session.text)
    session.cursor = session.start = start
    command = bringup_command(options)
    session.send(command + "\r")
    deadline = time.monotonic() + options.timeout
    begin = None
    while begin is None:
        remaining = deadline - time.monotonic()
        # Either the report begins, or the prompt comes back without it
        # (for example "unknown command").
        begin = session.wait_for(r"BRINGUP BEGIN|BRINGUP PROBE", min(max(remaining, 0), 0.5))
        if begin is not None:
            break
        after_echo = session.text[start:]
        echoed = after_echo.find(command)
        if echoed >= 0 and re.search(prompt, after_echo[echoed + len(command):]):
            return f"the controller printed no BRINGUP report for '{command}'"
        if session.closed:
            return "the console closed before the report began"
        if remaining <= 0:
            return f"no BRINGUP report within {options.timeout:g} s (--timeout)"
    end = session.wait_for(r"BRINGUP END[^\n]*\n|BRINGUP PROBE absent[^\n]*\n", max(deadline - time.monotonic(), 0))
    if end is None:
        return "the console closed" if session.closed else f"no BRINGUP END within {options.timeout:g} s (--timeout)"
    if "absent" in end.group(0):
        # The sequence ends after an absent probe; take an END line if it follows promptly.
        session.wait_for(r"BRINGUP END[^\n]*\n", 2.0)
    return None


def open_console(options):
    if options.serial:
        return SerialConsole(options.serial, options.baud)
    if options.socket:
        return SocketConsole(options.socket, options.connect_timeout)
    if options.exec_command:
        return ProcessConsole(options.exec_command)
    if options.emulator:
        return EmulatorConsole(options)
    raise ConnectionFailed("no console given")


# -- options ----------------------------------------------------------------


def key_value(text):
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"{text!r} is not KEY=VALUE")
    return key, value


def _short(text):
    return repr(text) if len(text) <= 24 else repr(text[:24]) + "..."


def integer_in(low, high, even=False):
    """An argparse type: a whole number (decimal or 0x hex) from low to high."""
    def parse(text):
        try:
            value = int(text, 0) if len(text) <= 24 else None
        except ValueError:
            value = None
        if value is None or not low <= value <= high or (even and value % 2):
            raise argparse.ArgumentTypeError(
                f"{_short(text)} is not {'an even' if even else 'a'} whole number from {low:#x} to {high:#x}"
                if high > 255 else f"{_short(text)} is not a whole number from {low} to {high}")
        return value
    return parse


def float_in(low, high, low_open=False):
    """An argparse type: a finite number from low to high (NaN and the infinities are refused)."""
    def parse(text):
        try:
            value = float(text) if len(text) <= 40 else math.nan
        except ValueError:
            value = math.nan
        if not math.isfinite(value) or value > high or value < low or (low_open and value == low):
            bound = f"above {low:g}" if low_open else f"from {low:g}"
            raise argparse.ArgumentTypeError(f"{_short(text)} is not a finite number {bound} to {high:g}")
        return value
    return parse


def limit_type(name):
    """An argparse type for a limit: its kind and LIMIT_RANGES."""
    kind = type(getattr(br.Limits(), name))

    def parse(text):
        try:
            value = kind(text) if len(text) <= 40 else None
        except ValueError:
            value = None
        if value is None:
            raise argparse.ArgumentTypeError(f"{_short(text)} is not a {'whole ' if kind is int else ''}number")
        problem = br.check_limit(name, value)
        if problem:
            raise argparse.ArgumentTypeError(problem)
        return value
    return parse


def check_output_paths(parser, options):
    """Refuses output paths that cannot be written, before anything runs: a bring-up takes minutes,
    and its result must not be lost at the end to a typing mistake."""
    try:
        _check_output_paths(parser, options)
    except OSError as error:
        parser.error(f"cannot check the output paths: {error}")


def _check_output_paths(parser, options):
    outputs = [(flag, path) for flag, path in (("--json", options.json), ("--png", options.png),
                                               ("--save-transcript", options.save_transcript)) if path]
    if outputs and any(not os.path.isabs(path) for _, path in outputs):
        try:
            os.getcwd()
        except OSError as error:
            parser.error(f"relative output paths need a current directory, and it is gone: {error.strerror}")
    seen = {}
    for flag, path in outputs:
        directory = os.path.dirname(os.path.abspath(path))
        if os.path.isdir(path):
            parser.error(f"{flag} {path}: is a directory")
        if not os.path.isdir(directory):
            parser.error(f"{flag} {path}: directory {directory} does not exist")
        if not os.access(directory, os.W_OK | os.X_OK):
            parser.error(f"{flag} {path}: directory {directory} is not writable")
        if os.path.exists(path) and not os.access(path, os.W_OK) and not os.path.islink(path):
            # A rename replaces it anyway, but the user protected it.
            parser.error(f"{flag} {path}: the file is write-protected")
        real = os.path.realpath(path)
        if real in seen:
            parser.error(f"{flag} and {seen[real]} name the same file {path}")
        seen[real] = flag
        if options.transcript and options.transcript != "-" and real == os.path.realpath(options.transcript):
            parser.error(f"{flag} {path} is the transcript being judged")
    if options.png and importlib.util.find_spec("matplotlib") is None:
        parser.error("--png needs matplotlib: install Debian's python3-matplotlib (mk/install-deps.sh), "
                     "or pass --png '' for no picture")


def check_options(parser, options):
    if (options.model_property or options.without_model or options.emulator_arg) and not options.emulator:
        parser.error("--model-property, --without-model and --emulator-arg need --emulator")
    try:
        re.compile(options.prompt)
    except re.error as error:
        parser.error(f"--prompt {_short(options.prompt)} is not a regular expression: {error}")
    check_output_paths(parser, options)


EXIT_STATUS_HELP = (
    "exit status:\n"
    "  0    every check passed\n"
    "  1    failures found (named in the report and in the JSON)\n"
    "  2    bad options, checked before anything runs: a value out of range (NaN and infinities\n"
    "       included), an output path whose directory is missing or not writable\n"
    "  3    board absent: the probe found no board at the base port\n"
    "  4    no connection, time-out, or an incomplete report\n"
    "  5    a result file (JSON, PNG, transcript) could not be written\n"
    "  130  interrupted (Ctrl-C, SIGTERM, SIGHUP): what was started is ended, the JSON says so\n"
)


def build_parser():
    limits = br.Limits()
    table = "\n".join(f"  --{name.replace('_', '-'):24s} {br.format_limit(getattr(limits, name)):>10s}  {text}"
                      for name, text in br.LIMIT_DESCRIPTIONS.items())
    parser = argparse.ArgumentParser(
        prog="mfio_bringup.py",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Bring-up of the multi-function ISA I/O board: runs 'iobus bringup [base] [irq]' on a DCOS\n"
            "controller's console, judges the BRINGUP report against limits, prints a pass/fail report\n"
            "naming each failing channel/gain, DI bit or interrupt, and writes a JSON result and a PNG\n"
            "sheet (error against code per channel and gain, digital inputs, interrupts)."
        ),
        epilog=(
            "limits (option, default, meaning):\n" + table + "\n\n"
            "noise: the controller pools each sweep's conversions into one standard deviation with its\n"
            "degrees of freedom; a sweep fails when the chi-square lower confidence bound on sigma (at\n"
            "--noise-confidence) is above --max-noise-lsb.\n\n" + EXIT_STATUS_HELP
        ),
    )
    where = parser.add_argument_group("console (exactly one)")
    group = where.add_mutually_exclusive_group(required=True)
    group.add_argument("--serial", metavar="DEVICE", help="a serial device, e.g. /dev/ttyUSB0 (needs python3-serial)")
    group.add_argument("--socket", metavar="PATH", help="a Unix socket serving the console, e.g. the emulator's "
                                                         "-chardev socket,server=on")
    group.add_argument("--exec", dest="exec_command", metavar="COMMAND",
                       help="launch COMMAND (through the shell, in a process group of its own) and use its stdin "
                            "and stdout as the console, e.g. an emulator with -serial stdio; the whole group is "
                            "ended when the tool ends, and its stderr is shown when it fails")
    group.add_argument("--emulator", action="store_true",
                       help="boot the emulated board (--board) through the emulator lab and use its console")
    group.add_argument("--transcript", metavar="FILE",
                       help="judge a saved console transcript instead of talking to a controller ('-' = stdin)")
    where.add_argument("--baud", type=integer_in(1, 10_000_000), default=115200,
                       help="serial speed (default 115200)")
    where.add_argument("--prompt", default=DEFAULT_PROMPT, help=f"regex of the shell prompt (default {DEFAULT_PROMPT!r})")
    where.add_argument("--no-wait-prompt", dest="wait_prompt", action="store_false",
                       help="send the command at once instead of first pressing Enter and waiting for a prompt")
    lab = parser.add_argument_group("emulator (with --emulator)")
    lab.add_argument("--board", default="isa486", help="board definition of the emulator lab (default isa486)")
    lab.add_argument("--image", help="firmware image (default: the board's image of --image-kind)")
    lab.add_argument("--image-kind", default="production", help="production, test, ... (default production)")
    lab.add_argument("--model", default="isa-mfio", help="the I/O board's device in the board file (default isa-mfio)")
    lab.add_argument("--model-property", type=key_value, action="append", metavar="KEY=VALUE",
                     help="set a property of the I/O board model, e.g. stuck-di-bit=4, dead-adc-channel=3, "
                          "no-irq=on, noise-lsb=0.5; repeatable")
    lab.add_argument("--without-model", action="store_true",
                     help="boot the board without its I/O board model, to see the tool report an absent board")
    lab.add_argument("--emulator-arg", action="append", metavar="ARG",
                     help="one more emulator argument, repeatable; e.g. the plant chardev: "
                          "--emulator-arg=-chardev --emulator-arg=socket,id=plant,path=SOCK with "
                          "--model-property wiring=plant --model-property plant=plant")
    lab.add_argument("--icount", action=argparse.BooleanOptionalAction, default=True,
                     help="exact instruction counting, so emulated time and the interrupt latencies are the same "
                          "every run (default on; --no-icount runs in host real time, where latencies depend on "
                          "the host's load)")
    run = parser.add_argument_group("bring-up")
    run.add_argument("--base", type=integer_in(0, 0xFFFF, even=True),
                     help="base port passed to the command (default: the controller's, 0x300)")
    run.add_argument("--irq", type=integer_in(0, 15), help="IRQ passed to the command (default: the controller's, 5)")
    run.add_argument("--timeout", type=float_in(0.0, MAX_TIMEOUT_S, low_open=True), default=300.0,
                     help="seconds from sending the command to the END line, above 0 to 1000000 (default 300)")
    run.add_argument("--connect-timeout", type=float_in(0.0, MAX_TIMEOUT_S, low_open=True), default=60.0,
                     help="seconds to connect, boot the emulator and see the first prompt, above 0 to 1000000 "
                          "(default 60)")
    limit_group = parser.add_argument_group("limits (see the table below)")
    for name, text in br.LIMIT_DESCRIPTIONS.items():
        low, high = br.LIMIT_RANGES[name]
        limit_group.add_argument(f"--{name.replace('_', '-')}", type=limit_type(name), default=getattr(limits, name),
                                 help=f"{text}; {br.format_limit(low)} to {br.format_limit(high)} "
                                      f"(default {br.format_limit(getattr(limits, name))})")
    output = parser.add_argument_group("output (written atomically; the directories must exist)")
    output.add_argument("--json", default="bringup-result.json", metavar="PATH",
                        help="JSON result file (default bringup-result.json); '' for none")
    output.add_argument("--png", default="bringup-curves.png", metavar="PATH",
                        help="PNG sheet of the results (default bringup-curves.png); '' for none. A run that "
                             "draws no sheet removes an older file of this name")
    output.add_argument("--save-transcript", metavar="PATH", help="also save the raw console output")
    output.add_argument("--verbose", "-v", action="store_true", help="echo the console while it runs")
    return parser


# -- the run ----------------------------------------------------------------


def utc_timestamp():
    """Now, in ISO 8601 UTC to the second, e.g. 2025-01-31T14:05:09Z."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def read_transcript(path):
    """The transcript's text, decoded byte for byte (a console may send anything); raises OSError."""
    if path == "-":
        return sys.stdin.buffer.read().decode("latin-1")
    with open(path, "rb") as handle:
        return handle.read().decode("latin-1")


def converse(options, connection, interrupts):
    """Talks to the controller; returns (console output, why it stopped early or None, interrupted)."""
    console = None
    session = None
    problem = None
    interrupted = False
    details = ""
    try:
        console = open_console(options)
        if isinstance(console, EmulatorConsole):
            connection["emulator"] = console.argv
        session = Session(console, sys.stdout if options.verbose else None)
        problem = run_on_console(session, options, options.prompt)
    except ConnectionFailed as error:
        problem = str(error)
    except KeyboardInterrupt:
        interrupted = True
        problem = "interrupted (Ctrl-C, SIGTERM or SIGHUP) before the report finished"
    finally:
        interrupts.defer()
        if console is not None:
            if problem:
                details = console.diagnostics()
            console.close()
    if details:
        problem += "\n" + details
    return (session.output() if session is not None else ""), problem, interrupted


def remove_stale(path, why):
    """Removes an older file of an output's name that this run does not replace, so it is not taken for this run's."""
    if os.path.lexists(path) and not os.path.isdir(path):
        try:
            os.unlink(path)
            print(f"{why}; removed the older {path}", file=sys.stderr)
        except OSError as error:
            print(f"warning: {why}, and the older {path} could not be removed: {error}", file=sys.stderr)


def main(argv=None):
    parser = build_parser()
    options = parser.parse_args(argv)
    check_options(parser, options)
    limits = br.Limits(**{name: getattr(options, name) for name in br.LIMIT_DESCRIPTIONS})
    timestamp = utc_timestamp()
    interrupts = Interrupts()
    connection = {}
    problem = None
    interrupted = False
    status_override = None
    if options.transcript:
        connection["kind"] = "transcript"
        try:
            text = read_transcript(options.transcript)
        except OSError as error:
            text, problem = "", f"cannot read {options.transcript}: {error.strerror or error}"
        except KeyboardInterrupt:
            text, problem, interrupted = "", "interrupted (Ctrl-C, SIGTERM or SIGHUP) while reading the transcript", True
        interrupts.defer()
    else:
        connection["kind"] = ("serial" if options.serial else "socket" if options.socket
                              else "exec" if options.exec_command else "emulator")
        connection["command"] = bringup_command(options)
        text, problem, interrupted = converse(options, connection, interrupts)

    report = br.parse_transcript(text)
    judgement = br.judge(report, limits, expected_base=options.base, expected_irq=options.irq)
    if problem:
        connection["problem"] = problem
        if judgement.verdict in ("pass", "fail") and not report.ended:
            judgement.verdict = "incomplete"
        if judgement.verdict == "incomplete" and not report.lines:
            judgement.failures.insert(0, br.Failure("report", problem.splitlines()[0]))
        print(f"error: {problem}", file=sys.stderr)
    if interrupted and not report.ended:
        judgement.verdict = "interrupted"
    sys.stdout.write(br.format_report(report, judgement, limits))

    status = judgement.exit_code
    if options.save_transcript:
        try:
            br.atomic_write(options.save_transcript, text.encode("latin-1", errors="replace"))
        except OSError as error:
            print(f"error: cannot write the transcript {options.save_transcript}: {error}", file=sys.stderr)
            status_override = br.EXIT_OUTPUT
    if options.png:
        if report.lines:
            try:
                br.plot_transfer_curves(report, judgement, options.png, limits, timestamp)
                print(f"result sheet: {options.png}")
            except Exception as error:  # A picture that cannot be drawn must not hide the verdict.
                print(f"error: no PNG written: {error}", file=sys.stderr)
                remove_stale(options.png, "no PNG for this run")
                status_override = br.EXIT_OUTPUT
        else:
            remove_stale(options.png, "no PNG for this run (the controller printed no report)")
    if options.json:
        document = br.result_document(report, judgement, limits, {"connection": connection}, timestamp=timestamp)
        if status_override is not None:
            document["exit_code"] = status_override
        try:
            br.write_json(options.json, document)
            print(f"result: {options.json}")
        except (OSError, ValueError) as error:
            print(f"error: cannot write the result {options.json}: {error}", file=sys.stderr)
            status_override = br.EXIT_OUTPUT
    return status if status_override is None else status_override


if __name__ == "__main__":
    sys.exit(main())
