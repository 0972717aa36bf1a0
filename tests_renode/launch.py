#!/usr/bin/env python3
"""Boots a board in the emulator with its console on this terminal (`make run`).

Leave the emulator with Ctrl-A X; Ctrl-A H lists the emulator's other keys.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.board import load_board  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--board", default="isa486", help="board definition in tests_renode/boards/")
    parser.add_argument("--image", help="firmware image (default: the board's production image)")
    parser.add_argument("--append", default="", help="kernel command line, e.g. tick_hz=100")
    parser.add_argument("--print-command", action="store_true", help="print the emulator command and exit")
    arguments = parser.parse_args()

    board = load_board(arguments.board)
    image = arguments.image or board.image("production")
    if not os.path.exists(image):
        sys.exit(f"error: firmware image {image} does not exist; run 'make firmware'")
    command = board.emulator_command(image, {"console": "mon:stdio"}, append=arguments.append)
    if arguments.print_command:
        print(" ".join(command))
        return
    print(f"Booting the {board.name} board: {board.description}.", flush=True)
    print("Console on this terminal; Ctrl-A X leaves the emulator.", flush=True)
    os.execvp(command[0], command)


if __name__ == "__main__":
    main()
