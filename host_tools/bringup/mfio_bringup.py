#!/usr/bin/python3
"""Host bring-up tool for the multi-function ISA I/O board.

It drives the controller's `iobus bringup [base] [irq]` console command,
collects the BRINGUP lines (docs/iobus/bringup-protocol.md), judges them
against limits the user can set, prints a pass/fail report that names every
failing channel and gain, DI bit or interrupt, writes a JSON result and a
PNG of measured against ideal transfer curves, and exits with a status that
says what happened:

    0  every check passed
    1  failures found
    2  bad options
    3  board absent (the probe found no board)
    4  no connection, time-out, or the report did not finish

The controller is reached over a serial device (pyserial), a Unix socket
(the emulator's console socket), a launched program's stdin and stdout
(--exec), or an emulated board booted here through tests_renode/dcoslab
(--emulator, for lab use, with optional fault properties of the isa-mfio
model). --transcript judges a saved console transcript instead.

The parsing and judging live in bringup_report.py; this file is the console
plumbing and the command line.
"""

import argparse
import os
import re
import select
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bringup_report as br  # noqa: E402

REPOSITORY = os.path.dirname(os.path.dirname(HERE))
LAB = os.path.join(REPOSITORY, "tests_renode")
DEFAULT_PROMPT = r"dcos> "


class ConnectionFailed(Exception):
    """The console could not be reached or went away."""


# -- consoles ---------------------------------------------------------------
#
# Each console offers write(bytes), read(timeout) -> bytes ('' on time-out,
# None when closed) and close().


class FdConsole:
    """A console over a pair of file descriptors (a socket, a serial port, pipes)."""

    def __init__(self, read_fd, write):
        self.read_fd = read_fd
        self._write = write

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
            return None
        return data if data else None

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
        except (serial.SerialException, OSError) as error:
            raise ConnectionFailed(f"cannot open serial device {device}: {error}") from None
        super().__init__(self.port.fileno(), self.port.write)

    def close(self):
        self.port.close()


class ProcessConsole(FdConsole):
    """A launched program whose stdin and stdout are the console."""

    def __init__(self, command):
        try:
            self.process = subprocess.Popen(command, shell=True, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                            stderr=subprocess.DEVNULL)
        except OSError as error:
            raise ConnectionFailed(f"cannot start {command!r}: {error}") from None

        def write(data):
            self.process.stdin.write(data)
            self.process.stdin.flush()

        super().__init__(self.process.stdout.fileno(), write)

    def close(self):
        if self.process.poll() is None:
            self.process.kill()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pass


class EmulatorConsole:
    """An emulated board booted through tests_renode/dcoslab, its console socket read through dcoslab."""

    def __init__(self, options):
        sys.path.insert(0, LAB)
        try:
            from dcoslab.board import load_board
            from dcoslab.emulator import Emulator, EmulatorError
        except ImportError as error:
            raise ConnectionFailed(f"cannot load the emulator lab from {LAB}: {error}") from None
        self.error_type = EmulatorError
        try:
            board = load_board(options.board)
        except SystemExit as error:
            raise ConnectionFailed(str(error)) from None
        properties = dict(options.model_property or [])
        if options.model not in board.device_drivers():
            raise ConnectionFailed(f"board {options.board} has no {options.model} device; its devices are: "
                                   f"{', '.join(board.device_drivers())}")
        image = options.image or board.image(options.image_kind)
        self.emulator = Emulator(
            board, image, icount=options.icount,
            device_properties={options.model: properties} if properties else None,
            without_devices=[options.model] if options.without_model else (),
            extra_args=options.emulator_arg or (),
        )
        try:
            self.emulator.start(timeout=options.connect_timeout)
        except (EmulatorError, ValueError, RuntimeError) as error:
            self.emulator.close()
            raise ConnectionFailed(f"the emulator did not start: {error}") from None
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

    def close(self):
        self.emulator.close()


# -- the session ------------------------------------------------------------


class Session:
    """Reads the console into a transcript and waits for patterns with time-outs."""

    def __init__(self, console, echo=None):
        self.console = console
        self.text = ""
        self.cursor = 0
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


def bringup_command(options):
    words = ["iobus", "bringup"]
    if options.base is not None:
        words.append(f"0x{options.base:x}")
    if options.irq is not None:
        if options.base is None:
            words.append("0x300")
        words.append(str(options.irq))
    return " ".join(words)


def run_on_console(console, options, prompt):
    """Runs the command and returns (transcript of the command's output, why it stopped or None)."""
    echo = sys.stdout if options.verbose else None
    session = Session(console, echo)
    # Wake the shell and wait for a prompt; a console that shows none may still work.
    if options.wait_prompt:
        session.send("\r")
        if session.wait_for(prompt, options.connect_timeout) is None and session.closed:
            return session.text, "the console closed before the first prompt"
    start = len(session.text)
    session.cursor = start
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
            return session.text[start:], f"the controller printed no BRINGUP report for '{command}'"
        if session.closed:
            return session.text[start:], "the console closed before the report began"
        if remaining <= 0:
            return session.text[start:], f"no BRINGUP report within {options.timeout:g} s (--timeout)"
    end = session.wait_for(r"BRINGUP END[^\n]*\n|BRINGUP PROBE absent[^\n]*\n", max(deadline - time.monotonic(), 0))
    if end is None:
        why = "the console closed" if session.closed else f"no BRINGUP END within {options.timeout:g} s (--timeout)"
        return session.text[start:], why
    if "absent" in end.group(0):
        # The sequence ends after an absent probe; take an END line if it follows promptly.
        session.wait_for(r"BRINGUP END[^\n]*\n", 2.0)
    return session.text[start:], None


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


def key_value(text):
    key, sep, value = text.partition("=")
    if not sep or not key:
        raise argparse.ArgumentTypeError(f"{text!r} is not KEY=VALUE")
    return key, value


def integer(text):
    try:
        return int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number (decimal or 0x hex)") from None


def build_parser():
    limits = br.Limits()
    table = "\n".join(f"  --{name.replace('_', '-'):24s} {br.format_number(getattr(limits, name)):>10s}  {text}"
                      for name, text in br.LIMIT_DESCRIPTIONS.items())
    parser = argparse.ArgumentParser(
        prog="mfio_bringup.py",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        description=(
            "Bring-up of the multi-function ISA I/O board: runs 'iobus bringup [base] [irq]' on a DCOS\n"
            "controller's console, judges the BRINGUP report against limits, prints a pass/fail report\n"
            "naming each failing channel/gain, DI bit or interrupt, and writes a JSON result and a PNG of\n"
            "measured against ideal transfer curves."
        ),
        epilog=(
            "limits (option, default, meaning):\n" + table + "\n\n"
            "exit status:\n"
            "  0  every check passed\n"
            "  1  failures found (named in the report and in the JSON)\n"
            "  2  bad options\n"
            "  3  board absent: the probe found no board at the base port\n"
            "  4  no connection, time-out, or an incomplete report\n"
        ),
    )
    where = parser.add_argument_group("console (exactly one)")
    group = where.add_mutually_exclusive_group(required=True)
    group.add_argument("--serial", metavar="DEVICE", help="a serial device, e.g. /dev/ttyUSB0 (needs python3-serial)")
    group.add_argument("--socket", metavar="PATH", help="a Unix socket serving the console, e.g. the emulator's "
                                                         "-chardev socket,server=on")
    group.add_argument("--exec", dest="exec_command", metavar="COMMAND",
                       help="launch COMMAND (through the shell) and use its stdin and stdout as the console, "
                            "e.g. an emulator with -serial stdio")
    group.add_argument("--emulator", action="store_true",
                       help="boot the emulated board (--board) through tests_renode/dcoslab and use its console")
    group.add_argument("--transcript", metavar="FILE",
                       help="judge a saved console transcript instead of talking to a controller ('-' = stdin)")
    where.add_argument("--baud", type=int, default=115200, help="serial speed (default 115200)")
    where.add_argument("--prompt", default=DEFAULT_PROMPT, help=f"regex of the shell prompt (default {DEFAULT_PROMPT!r})")
    where.add_argument("--no-wait-prompt", dest="wait_prompt", action="store_false",
                       help="send the command at once instead of first pressing Enter and waiting for a prompt")
    lab = parser.add_argument_group("emulator (with --emulator)")
    lab.add_argument("--board", default="isa486", help="board definition in tests_renode/boards (default isa486)")
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
    run.add_argument("--base", type=integer, help="base port passed to the command (default: the controller's, 0x300)")
    run.add_argument("--irq", type=integer, help="IRQ passed to the command (default: the controller's, 5)")
    run.add_argument("--timeout", type=float, default=300.0,
                     help="seconds from sending the command to the END line (default 300)")
    run.add_argument("--connect-timeout", type=float, default=60.0,
                     help="seconds to connect, boot the emulator and see the first prompt (default 60)")
    limit_group = parser.add_argument_group("limits (see the table below)")
    for name, text in br.LIMIT_DESCRIPTIONS.items():
        kind = type(getattr(limits, name))
        limit_group.add_argument(f"--{name.replace('_', '-')}", type=kind, default=getattr(limits, name),
                                 help=f"{text} (default {br.format_number(getattr(limits, name))})")
    output = parser.add_argument_group("output")
    output.add_argument("--json", default="bringup-result.json", metavar="PATH",
                        help="JSON result file (default bringup-result.json); '' for none")
    output.add_argument("--png", default="bringup-curves.png", metavar="PATH",
                        help="PNG of the transfer curves (default bringup-curves.png); '' for none")
    output.add_argument("--save-transcript", metavar="PATH", help="also save the raw console output")
    output.add_argument("--verbose", "-v", action="store_true", help="echo the console while it runs")
    return parser


def main(argv=None):
    parser = build_parser()
    options = parser.parse_args(argv)
    if (options.model_property or options.without_model or options.emulator_arg) and not options.emulator:
        parser.error("--model-property, --without-model and --emulator-arg need --emulator")
    limits = br.Limits(**{name: getattr(options, name) for name in br.LIMIT_DESCRIPTIONS})
    connection = {}
    problem = None
    if options.transcript:
        connection["kind"] = "transcript"
        try:
            if options.transcript == "-":
                text = sys.stdin.read()
            else:
                with open(options.transcript, encoding="latin-1") as handle:
                    text = handle.read()
        except OSError as error:
            print(f"error: cannot read {options.transcript}: {error}", file=sys.stderr)
            return br.EXIT_NO_CONNECTION
    else:
        connection["kind"] = ("serial" if options.serial else "socket" if options.socket
                              else "exec" if options.exec_command else "emulator")
        connection["command"] = bringup_command(options)
        try:
            console = open_console(options)
        except ConnectionFailed as error:
            print(f"error: {error}", file=sys.stderr)
            document = br.result_document(br.Report(), br.Judgement("incomplete", [br.Failure("report", str(error))],
                                                                   [], {}), limits,
                                          {"connection": connection})
            if options.json:
                br.write_json(options.json, document)
            return br.EXIT_NO_CONNECTION
        try:
            if isinstance(console, EmulatorConsole):
                connection["emulator"] = console.argv
            text, problem = run_on_console(console, options, options.prompt)
        except ConnectionFailed as error:
            text, problem = "", str(error)
        finally:
            console.close()
    if options.save_transcript:
        with open(options.save_transcript, "w", encoding="latin-1") as handle:
            handle.write(text)
    report = br.parse_transcript(text)
    judgement = br.judge(report, limits, expected_base=options.base, expected_irq=options.irq)
    if problem:
        connection["problem"] = problem
        if judgement.verdict in ("pass", "fail") and not report.ended:
            judgement.verdict = "incomplete"
        print(f"error: {problem}", file=sys.stderr)
    sys.stdout.write(br.format_report(report, judgement, limits))
    if options.png and report.adc:
        try:
            br.plot_transfer_curves(report, judgement, options.png)
            print(f"transfer curves: {options.png}")
        except Exception as error:  # A plot failure must not hide the verdict.
            print(f"warning: no PNG written: {error}", file=sys.stderr)
    if options.json:
        br.write_json(options.json, br.result_document(report, judgement, limits, {"connection": connection}))
        print(f"result: {options.json}")
    return judgement.exit_code


if __name__ == "__main__":
    sys.exit(main())
