"""A card that loses its power after exactly N writes (docs/boot.md, "Power
cuts").

QEMU's blkdebug filter sits between the board's IDE disk and the card's
file. It counts the disk's writes with its state machine (each write moves
it one state on) and fails the write after the Nth; the drive's
werror=stop then stops the whole board at that write, before any of it
reaches the file: the card holds exactly the first N writes, as after a
power cut. The harness sees the stop on QEMU's QMP socket, kills the
emulator, and starts the board again on the same file.

A write torn by the cut (half old, half new) is not something QEMU's disk
can do; the host tests tear every write instead
(firmware/flash/unit_tests/PowerCutTest.cpp).
"""
import json
import os
import socket
import time


def drive(card, writes, directory):
    """The -drive value of the card @p card behind a filter that cuts the power after @p writes writes."""
    config = os.path.join(directory, "powercut.conf")
    rules = []
    # blkdebug starts in state 1; write k (1-based) happens in state k.
    for state in range(1, writes + 1):
        rules.append(f'[set-state]\nstate = "{state}"\nevent = "pwritev"\nnew_state = "{state + 1}"\n')
    rules.append(f'[inject-error]\nstate = "{writes + 1}"\nevent = "pwritev"\nerrno = "5"\nonce = "off"\n')
    with open(config, "w", encoding="ascii") as handle:
        handle.write("\n".join(rules))
    return (f"driver=blkdebug,config={config},image.driver=raw,image.file.filename={card},"
            "if=ide,index=0,werror=stop,rerror=stop")


def wait_stopped(path, timeout):
    """True once the emulator at QMP socket @p path has stopped for an I/O error, within @p timeout s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as sock:
                sock.settimeout(max(0.1, deadline - time.monotonic()))
                sock.connect(path)
                reader = sock.makefile("r", encoding="utf-8")
                reader.readline()  # the greeting
                sock.sendall(b'{"execute": "qmp_capabilities"}\n')
                _answer(reader)
                while time.monotonic() < deadline:
                    sock.sendall(b'{"execute": "query-status"}\n')
                    status = _answer(reader)
                    if status.get("status") == "io-error" or (status.get("running") is False
                                                               and status.get("status") != "prelaunch"):
                        return True
                    time.sleep(0.05)
        except (FileNotFoundError, ConnectionRefusedError, socket.timeout, OSError):
            time.sleep(0.05)
    return False


def _answer(reader):
    """The "return" value of the next reply on @p reader, skipping events."""
    while True:
        line = reader.readline()
        if not line:
            raise OSError("QMP closed")
        message = json.loads(line)
        if "return" in message:
            return message["return"]
        if "error" in message:
            raise OSError(message["error"].get("desc", "QMP error"))
