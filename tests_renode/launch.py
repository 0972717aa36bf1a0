#!/usr/bin/env python3
"""Boots a board in the emulator with its console on this terminal (`make run`).

Leave the emulator with Ctrl-A X; Ctrl-A H lists the emulator's other keys.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.board import load_board  # noqa: E402
from dcoslab.built_emulator import EmulatorNotBuilt  # noqa: E402


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
    parser.add_argument("--append", default="", help="kernel command line, e.g. tick_hz=100")
    parser.add_argument("--set", type=device_property, action="append", default=[], metavar="DRIVER.PROPERTY=VALUE",
                        help="set a device property for this run, e.g. isa-mfio.stuck-di-bit=3 (repeatable)")
    parser.add_argument("--without", action="append", default=[], metavar="DRIVER",
                        help="leave a board device out for this run, e.g. isa-mfio (repeatable)")
    parser.add_argument("--emulator-arg", action="append", default=[], metavar="ARG",
                        help="pass an argument to the emulator as it is, e.g. a -chardev (repeatable)")
    parser.add_argument("--print-command", action="store_true", help="print the emulator command and exit")
    arguments = parser.parse_args()
    properties = {}
    for driver, prop, value in arguments.set:
        properties.setdefault(driver, {})[prop] = value

    board = load_board(arguments.board)
    image = arguments.image or board.image("production")
    if not os.path.exists(image):
        sys.exit(f"error: firmware image {image} does not exist; run 'make firmware'")
    try:
        command = board.emulator_command(image, {"console": "mon:stdio"}, append=arguments.append,
                                         device_properties=properties, without_devices=arguments.without,
                                         extra_args=arguments.emulator_arg)
    except (EmulatorNotBuilt, ValueError) as error:
        sys.exit(f"error: {error}")
    if arguments.print_command:
        print(" ".join(command))
        return
    print(f"Booting the {board.name} board: {board.description}.", flush=True)
    print("Console on this terminal; Ctrl-A X leaves the emulator.", flush=True)
    os.execvp(command[0], command)


if __name__ == "__main__":
    main()
