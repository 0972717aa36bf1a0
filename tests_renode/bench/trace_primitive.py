#!/usr/bin/python3
"""Prints the instruction trace of one benchmark's measured call, by function.

A developer's tool for the instruction budgets (docs/performance.md): it
boots the bench image as `make bench` does (-cpu pentium, -icount shift=0),
with QEMU logging every instruction it executes (-singlestep -d exec,nochain),
runs `bench run <name> --repeat 1`, and takes the last call of the benchmark's
measure function from the log: the instructions from its first instruction to
its return, each named by the function it lies in (from the image's symbols).
It prints how many instructions each function retired in that call, in the
order they ran, and with --listing every instruction with its disassembly.

  tests_renode/bench/trace_primitive.py Semaphore.Acquire
  tests_renode/bench/trace_primitive.py Semaphore.Acquire --measure acquire --listing

Under the per-function counts it prints the bench's own figure for the same
call, which must be the trace's count less one (tests_renode/test_bench_framework.py).

The measure function is found from the DCOS_BENCHMARK line that registers the
benchmark in tests_renode/bench/*.cpp; --measure names it where that fails.
Exit codes: 0 traced, 1 the benchmark or its call was not found, 2 usage.
"""

import argparse
import bisect
import collections
import glob
import os
import re
import socket
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.emulator import Emulator  # noqa: E402

TRACE_LINE = re.compile(rb"^Trace \d+: 0x[0-9a-f]+ \[[0-9a-f]+/([0-9a-f]+)/")


def measure_function_of(name):
    """The measure function's identifier in the DCOS_BENCHMARK registering name."""
    for path in glob.glob(os.path.join(HERE, "*.cpp")):
        text = open(path, encoding="utf-8").read()
        match = re.search(r"DCOS_BENCHMARK\(\s*\w+,\s*\"" + re.escape(name) + r"\",\s*\w+,\s*(\w+)", text)
        if match:
            return match.group(1), os.path.basename(path)
    return None, None


def monitor(path, command):
    """Runs one command on QEMU's human monitor and waits for its next prompt."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as connection:
        connection.settimeout(60)
        connection.connect(path)
        received = b""
        while not received.endswith(b"(qemu) "):
            received += connection.recv(4096)
        connection.sendall(command.encode("ascii") + b"\n")
        received = b""
        while b"(qemu) " not in received:
            chunk = connection.recv(4096)
            if not chunk:
                break
            received += chunk


def source_file(image, address):
    """The source file name (no directory) of the code at address."""
    output = subprocess.run(["addr2line", "-e", image, f"{address:#x}"], check=True, capture_output=True,
                            text=True).stdout
    return os.path.basename(output.split(":")[0])


def symbols(image):
    """Sorted (address, size, demangled name) of the image's functions."""
    output = subprocess.run(["nm", "-C", "-S", "--defined-only", image], check=True, capture_output=True,
                            text=True).stdout
    table = []
    for line in output.splitlines():
        parts = line.split(" ", 3)
        if len(parts) == 4 and len(parts[2]) == 1 and parts[2] in "tTwW":
            table.append((int(parts[0], 16), int(parts[1], 16), parts[3]))
        elif len(parts) >= 3 and len(parts[1]) == 1 and parts[1] in "tT":
            # An assembly label has no size: it reaches to the next symbol.
            table.append((int(parts[0], 16), 0, " ".join(parts[2:])))
    table.sort()
    return [(address, size or ((table[i + 1][0] - address) if i + 1 < len(table) else 1), name)
            for i, (address, size, name) in enumerate(table)]


def disassembly(image):
    output = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", image], check=True,
                            capture_output=True, text=True).stdout
    lines = {}
    for line in output.splitlines():
        match = re.match(r"^\s+([0-9a-f]+):\s+(.*)$", line)
        if match:
            lines[int(match.group(1), 16)] = match.group(2)
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("benchmark", help='a bench name, e.g. "Semaphore.Acquire"')
    parser.add_argument("--measure", help="the measure function's name (default: from DCOS_BENCHMARK)")
    parser.add_argument("--objects", type=int, default=8, choices=(8, 4096),
                        help="trace the call made with this many objects (default 8)")
    parser.add_argument("--listing", action="store_true", help="print every instruction")
    parser.add_argument("--board", default="isa486")
    args = parser.parse_args()

    measure, source = measure_function_of(args.benchmark)
    measure = args.measure or measure
    if measure is None:
        print(f"trace_primitive: no DCOS_BENCHMARK registers {args.benchmark!r}; give --measure", file=sys.stderr)
        return 1
    board = load_board(args.board)
    image = board.image("benchmark")
    table = symbols(image)
    starts = [entry[0] for entry in table]
    candidates = [entry for entry in table if re.search(r"(^|::)" + re.escape(measure) + r"\(\)$", entry[2])]
    if len(candidates) > 1 and source:  # Several files' own helpers may share a name.
        candidates = [entry for entry in candidates if source_file(image, entry[0]) == source]
    if len(candidates) != 1:
        print(f"trace_primitive: {len(candidates)} functions named {measure}() in {image}", file=sys.stderr)
        return 1
    entry_address = candidates[0][0]

    with tempfile.TemporaryDirectory(prefix="dcos-trace-") as directory:
        log = os.path.join(directory, "exec.log")
        monitor_path = os.path.join(directory, "monitor.sock")
        emulator = Emulator(board, image, icount=True, cpu=board.benchmark_cpu or None,
                            memory_mib=board.benchmark_memory(),
                            extra_args=["-singlestep", "-D", log,
                                        "-monitor", f"unix:{monitor_path},server=on,wait=off"])
        try:
            emulator.start(timeout=600)
            emulator.expect(r"dcos> ", timeout=600)
            # Log only while the benchmark runs: the boot would be millions of lines.
            monitor(monitor_path, "log exec,nochain")
            output = emulator.command(f"bench run {args.benchmark} --repeat 1", timeout=1200)
            monitor(monitor_path, "log none")
        finally:
            emulator.close()
        if f"BENCH {args.benchmark} " not in output:
            print(f"trace_primitive: the bench image did not run {args.benchmark}:\n{output}", file=sys.stderr)
            return 1
        with open(log, "rb") as handle:
            pcs = [int(match.group(1), 16) for match in map(TRACE_LINE.match, handle) if match]

    # The calls of measure(): from each entry to the instruction after the
    # call (the return address is the entry's caller's next instruction, the
    # first PC seen again at a shallower call depth: find the ret by depth).
    entries = [index for index, pc in enumerate(pcs) if pc == entry_address]
    per_count = len(entries) // 2
    if not entries:
        print(f"trace_primitive: {measure}() never ran", file=sys.stderr)
        return 1
    # bench run runs the 8-object count first, then 4096.
    chosen = entries[per_count - 1] if args.objects == 8 and per_count else entries[-1]
    caller_next = None
    listing = disassembly(image)
    # The return address is the instruction after the call that preceded the entry.
    call_site = pcs[chosen - 1]
    text = listing.get(call_site, "")
    if not text.startswith("call"):
        print(f"trace_primitive: {measure}() was not entered by a call ({text})", file=sys.stderr)
        return 1
    caller_next = min(address for address in listing if address > call_site)
    end = chosen
    while end < len(pcs) and pcs[end] != caller_next:
        end += 1
    path = pcs[chosen:end]

    def function_of(pc):
        index = bisect.bisect_right(starts, pc) - 1
        if index >= 0 and pc < table[index][0] + max(table[index][1], 1):
            return table[index][2]
        return f"?{pc:#x}"

    runs = []
    for pc in path:
        name = function_of(pc)
        if runs and runs[-1][0] == name:
            runs[-1][1] += 1
        else:
            runs.append([name, 1])
        if args.listing:
            print(f"{pc:08x}  {listing.get(pc, '?'):<48} {name}")
    totals = collections.Counter()
    for name, count in runs:
        totals[name] += count
    # The bench's figure for the same object count: the call less an empty
    # call, whose function is a lone ret, so it is the trace less one.
    figure = re.search(rf"^BENCH {re.escape(args.benchmark)} objects={args.objects} min=(\d+)", output, re.MULTILINE)
    print(f"{args.benchmark}: {len(path)} instructions from {measure}() to its return "
          f"({args.objects} objects; includes the call's own overhead)")
    print(f"bench figure: {figure.group(1) if figure else '-'} (the trace less an empty function's ret)")
    for name, count in totals.most_common():
        print(f"  {count:6d}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
