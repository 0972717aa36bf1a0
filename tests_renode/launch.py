#!/usr/bin/env python3
"""Boots a board in the emulator with its console on this terminal (`make run`).

Leave the emulator with Ctrl-A X; Ctrl-A H lists the emulator's other keys.
"""

import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.board import load_board  # noqa: E402
from dcoslab.built_emulator import EmulatorNotBuilt  # noqa: E402
from dcoslab.symbolize import explain  # noqa: E402


def device_property(text):
    """Parses DRIVER.PROPERTY=VALUE, e.g. isa-mfio.no-irq=on."""
    name, equals, value = text.partition("=")
    driver, dot, prop = name.rpartition(".")
    if not equals or not dot or not driver or not prop:
        raise argparse.ArgumentTypeError(f"'{text}' is not DRIVER.PROPERTY=VALUE, e.g. isa-mfio.no-irq=on")
    return driver, prop, value


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--board", default="isa486", help="board definition in tests_renode/boards/")
    parser.add_argument("--image", help="firmware image (default: the board's production image)")
    parser.add_argument("--card", metavar="CARD.IMG",
                        help="boot from this CompactFlash card image through the BIOS and the stage loader "
                             "instead of a firmware image (make card builds build/486/card-486.img; docs/boot.md); "
                             "the card carries its own command line, so --append does not apply")
    parser.add_argument("--append", action="append", default=[], metavar="OPTION",
                        help="add to the kernel command line (repeatable): node=N sets the node id (1-65534, "
                             "default 1), tick_hz=N the system tick rate (19-10000 Hz, default 1000)")
    parser.add_argument("--set", type=device_property, action="append", default=[], metavar="DRIVER.PROPERTY=VALUE",
                        help="set a device property for this run, e.g. isa-mfio.stuck-di-bit=3 (repeatable)")
    parser.add_argument("--without", action="append", default=[], metavar="DRIVER",
                        help="leave a board device out for this run, e.g. isa-mfio (repeatable)")
    parser.add_argument("--emulator-arg", action="append", default=[], metavar="ARG",
                        help="pass an argument to the emulator as it is, e.g. a -chardev (repeatable)")
    parser.add_argument("--serial", action="append", default=[], metavar="PORT=BACKEND",
                        help="connect a serial port of the board other than the console, e.g. rs485=pty "
                             "(QEMU -serial syntax; unconnected ports are null)")
    parser.add_argument("--line", action="append", default=[], metavar="PORT=SOCKET,LINE,NAME",
                        help="put a serial port on a line of a running lab hub (dcoslab/canbus.py --line), e.g. "
                             "rs485=/tmp/lab.sock,line0,board1; the board then runs under -icount, in step "
                             "with the hub (docs/protocols/labbus.md, \"The RS-485 line\")")
    parser.add_argument("--print-command", action="store_true", help="print the emulator command and exit")
    arguments = parser.parse_args()
    properties = {}
    for driver, prop, value in arguments.set:
        properties.setdefault(driver, {})[prop] = value

    backends = {"console": "mon:stdio"}
    for text in arguments.serial:
        port, equals, backend = text.partition("=")
        if not equals or not port or not backend or port == "console":
            sys.exit(f"error: --serial {text}: expected PORT=BACKEND for a port other than the console, e.g. rs485=pty")
        backends[port] = backend
    line_ports = {}
    for text in arguments.line:
        port, equals, rest = text.partition("=")
        fields = rest.split(",")
        if not equals or not port or len(fields) != 3 or not all(fields):
            sys.exit(f"error: --line {text}: expected PORT=SOCKET,LINE,NAME, e.g. rs485=/tmp/lab.sock,line0,board1")
        line_ports[port] = {"hub": fields[0], "line": fields[1], "hub-name": fields[2]}
    board = load_board(arguments.board)
    for port in backends:
        if port not in board.serial_ports:
            sys.exit(f"error: board {board.name} has no serial port '{port}'; its ports are: "
                     f"{', '.join(board.serial_ports)}")
    if arguments.card and (arguments.image or arguments.append):
        sys.exit("error: --card boots the card's own image with its own command line: "
                 "leave out --image and --append (dcos-card create --append sets the line)")
    image = arguments.card or arguments.image or board.image("production")
    if not os.path.exists(image):
        sys.exit(f"error: {'card' if arguments.card else 'firmware'} image {image} does not exist; "
                 f"run 'make {'card' if arguments.card else 'firmware'}'")
    try:
        command = board.emulator_command(image, backends, append=" ".join(arguments.append),
                                         device_properties=properties, without_devices=arguments.without,
                                         extra_args=arguments.emulator_arg, line_ports=line_ports,
                                         icount=bool(line_ports), card=bool(arguments.card))
    except (EmulatorNotBuilt, ValueError) as error:
        sys.exit(f"error: {error}")
    if arguments.print_command:
        print(" ".join(command))
        return
    print(f"Booting the {board.name} board: {board.description}.", flush=True)
    print("Console on this terminal; Ctrl-A X leaves the emulator.", flush=True)
    sys.exit(relay_console(command, image))


def relay_console(command, image):
    """Runs the emulator with its console passed through to this terminal.

    The emulator reads the keyboard itself (it puts the terminal in raw
    mode); its output comes through here, so that below every report that
    names code by address (a panic, a task's fault, a back trace) the
    function and source line of each address appear as well. Returns the
    emulator's exit status.
    """
    process = subprocess.Popen(command, stdout=subprocess.PIPE)
    out = sys.stdout.buffer
    line = bytearray()
    try:
        while True:
            chunk = os.read(process.stdout.fileno(), 4096)
            if not chunk:
                break
            out.write(chunk)
            out.flush()
            line.extend(chunk)
            while b"\n" in line:
                complete, _, rest = line.partition(b"\n")
                line = bytearray(rest)
                text = complete.decode("latin-1")
                if "EIP=" in text or "back trace:" in text:
                    code = explain(text, image)
                    if code:
                        # The terminal is raw while the emulator runs: end lines with CR LF.
                        out.write(code.replace("\n", "\r\n").encode("latin-1"))
                        out.flush()
    except KeyboardInterrupt:
        process.terminate()
    return process.wait()


if __name__ == "__main__":
    main()
