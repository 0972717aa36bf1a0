#!/usr/bin/env python3
"""The bench's flash figures (docs/performance.md, "Flashing over CAN").

One emulated 486 board boots from its card (the production image in slot A,
the development key) on the lab's CAN bus at 1 Mbit/s in exact time
(-icount), with its CAN channel attached as node 3. dcos-flash, joined to
the same bus, puts the production image, signed as a newer version, into
the inactive slot while the node runs (--no-restart). From the hub's log
of the session's frames (message type Flashing):

- the payload bytes per bus byte: the image's payload over the bits every
  frame of the session took on the wire (arbitration, stuffing, CRC,
  acknowledge, end of frame and intermission), counted as bytes;
- the session's emulated time, from its first frame's start to its last
  frame's end, and the payload rate it gives;
- what 256 KiB take at that rate, beside the bus's own limit: the time the
  payload would take in back-to-back ISO-TP consecutive frames (7 bytes in
  an 8-byte extended frame) with no flow control, no reply and no pause.

These are measurements, not budgets: the bus's bit time sets most of them.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests_renode, for dcoslab

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.canbus import frame_bits  # noqa: E402
from dcoslab.canlab import CanLab  # noqa: E402
from dcoslab.cards import BIN, DEVELOPMENT_KEY, new_card, signed  # noqa: E402
from dcoslab.emulator import EmulatorError  # noqa: E402
from dcoslab.remote import attach_node  # noqa: E402
from dcoslab.vmworld import World  # noqa: E402

BIT_RATE = 1_000_000
NODE = 3
FLASHING = 0x50
REFERENCE_BYTES = 256 * 1024


def flashing(record):
    return record.frame.extended and (record.frame.id >> 16) & 0xFF == FLASHING and record.outcome == "ok"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default=os.path.join(REPOSITORY, "build", "bench", "flash.json"))
    parser.add_argument("--timeout", type=float, default=900.0, help="seconds for each wait")
    arguments = parser.parse_args()

    world = World()
    directory = tempfile.TemporaryDirectory(prefix="dcos-flash-bench-")
    try:
        card = new_card(directory.name, ("A", signed(directory.name, "1.0.0"), False))
        image = signed(directory.name, "1.1.0")
        payload = os.path.getsize(image) - 256
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BIT_RATE},
                           {"board1": {"bus0": "can0", "card": card}}, timeout=arguments.timeout)
        board = world.lab.board("board1")
        attach_node(board, NODE, [], BIT_RATE, arguments.timeout)
        done = subprocess.run([os.path.join(BIN, "dcos-flash"), "-i", f"lab:{world.lab.socket_path}:can0",
                               "-n", str(NODE), "-k", DEVELOPMENT_KEY, "--no-restart", "--json", image],
                              capture_output=True, text=True, timeout=arguments.timeout)
        if done.returncode != 0:
            raise AssertionError(f"dcos-flash failed ({done.returncode}): {done.stderr}")
        records = [record for record in world.lab.hub.frames() if flashing(record)]
    except (EmulatorError, AssertionError, subprocess.TimeoutExpired) as error:
        print(f"flash_bench.py: the run failed.\n{error}", file=sys.stderr)
        return 1
    finally:
        world.close()
        directory.cleanup()

    bus_bits = sum(frame_bits(record.frame) for record in records)
    span_ns = records[-1].end - records[0].start
    rate = payload / (span_ns / 1e9)
    consecutive = [record for record in records if record.frame.dlc == 8 and record.frame.data[0] >> 4 == 2]
    bits_per_consecutive = sum(frame_bits(record.frame) for record in consecutive) / len(consecutive)
    limit_rate = 7 * BIT_RATE / bits_per_consecutive
    report = {
        "bit_rate": BIT_RATE,
        "payload_bytes": payload,
        "frames": len(records),
        "bus_bytes": bus_bits / 8,
        "payload_per_bus_byte": payload / (bus_bits / 8),
        "session_ms": span_ns / 1e6,
        "payload_bytes_per_s": rate,
        "reference_bytes": REFERENCE_BYTES,
        "reference_s": REFERENCE_BYTES / rate,
        "bus_limit_bytes_per_s": limit_rate,
        "bus_limit_reference_s": REFERENCE_BYTES / limit_rate,
        "bits_per_consecutive_frame": bits_per_consecutive,
    }
    print(f"Flashing over CAN at {BIT_RATE // 1000} kbit/s, the production image ({payload} payload bytes) into a "
          f"running node (emulated time, -icount)")
    print(f"  {len(records)} frames, {report['bus_bytes']:.0f} bytes on the bus: "
          f"{report['payload_per_bus_byte']:.3f} payload bytes per bus byte")
    print(f"  the session: {report['session_ms'] / 1000:.2f} s, {rate / 1024:.1f} KiB/s")
    print(f"  256 KiB: {report['reference_s']:.2f} s at that rate; the bus's own limit "
          f"({bits_per_consecutive:.0f}-bit consecutive frames back to back, {limit_rate / 1024:.1f} KiB/s): "
          f"{report['bus_limit_reference_s']:.2f} s")
    os.makedirs(os.path.dirname(os.path.abspath(arguments.output)), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump(report, handle, indent=2)
        handle.write("\n")
    print(f"wrote {arguments.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
