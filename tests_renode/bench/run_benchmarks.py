#!/usr/bin/python3
"""Runs the on-target benchmarks and reports them: what `make bench` calls.

Boots the board's bench image on its benchmark CPU model with exact
instruction counting (-icount shift=0), runs the console command
`bench run`, parses its BENCH lines (format: tests_renode/bench/BenchmarkRunner.cpp),
prints the seed's Tables 9.2-9.11 for DCOS beside the seed's own figures and
writes two JSON reports:

  primitives.json  every benchmark, keyed "<Agent>.<Primitive>":
      {"instructions_8": n, "instructions_4096": n, "variable": bool,
       "cost": "constant" | "log" | "variable", "seed_table": "9.x",
       "seed_microseconds": x | null,
       "cycles_median_8": n, "cycles_median_4096": n,        (KVM pass only)
       "cycles_min_8": n, "cycles_max_8": n, "cycles_min_4096": n, "cycles_max_4096": n,
       "budget": null | {"instructions": n | null, "flat": bool, "now": n | null,
                         "bound": text | null, "verdict": "within" | "over" | "no count" | "missing",
                         "flat_agrees": bool | null, "offences": [text]}}
  kernel.json      the kernel core's subset (Kernel, Task, Scheduler, Timer,
                   System) with the instruction fields only.
  can.json         instructions per received and per sent CAN frame through
                   the SJA1000 driver and the link layer (the Can.* pieces
                   added up) and the CPU share at 7,407 frames/s.
  modbus.json      instructions per received character and per handled
                   Modbus request (read and write 10 holding registers)
                   through the 16550 driver and the RTU stack, the line's
                   transactions per second at 115200 baud and the CPU share
                   there.

n is the smallest instruction count of one call with that many objects (null
when setup failed). Where /dev/kvm is usable and the bench image runs under
KVM, a second pass boots it with -accel kvm, where rdtsc counts real cycles of
the host CPU, runs every benchmark --kvm-repeat times and reports the median
(and min and max) of each; otherwise it says plainly that no real cycle
figures are reported. Real-time figures are reported, never asserted.

After the tables it prints every benchmark that has a budget in
tests_renode/bench/budgets.toml against that budget, and every fixed-cost
benchmark that is NOT FLAT (budgets.py decides; `make bench STRICT=1` fails
on them, this script only with --strict). See docs/performance.md.
"""

import argparse
import json
import os
import re
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))  # tests_renode, for dcoslab
sys.path.insert(0, HERE)

from dcoslab.board import REPOSITORY, load_board  # noqa: E402
from dcoslab.emulator import Emulator, EmulatorError  # noqa: E402
from seed_figures import SEED_FIGURES, SEED_PROCESSOR, SEED_TABLES, seed_text, table_of  # noqa: E402
import budgets as budget_file  # noqa: E402

OBJECT_COUNTS = (8, 4096)
PROMPT = r"dcos> "

RESULT_LINE = re.compile(
    r"^BENCH (?P<name>\S+) objects=(?P<objects>\d+) min=(?P<min>\d+) max=(?P<max>\d+)"
    r"(?: median=(?P<median>\d+))? variable=(?P<variable>[01]) cost=(?P<cost>constant|log|variable)\r?$",
    re.MULTILINE,
)
ERROR_LINE = re.compile(r"^BENCH (?P<name>\S+) objects=(?P<objects>\d+) error=(?P<code>\d+) (?P<text>.*?)\r?$",
                        re.MULTILINE)
OVERHEAD_LINE = re.compile(r"^BENCH overhead min=(?P<min>\d+) max=(?P<max>\d+) warmup=(?P<warmup>\d+) "
                           r"repeat=(?P<repeat>\d+)\r?$", re.MULTILINE)
LIST_LINE = re.compile(r"^BENCH (?P<name>\S+) cost=(?P<cost>constant|log|variable) variable=(?P<variable>[01]) "
                       r"irq=(?P<irq>on|off)\r?$", re.MULTILINE)


class BenchmarkError(Exception):
    pass


# The agents whose figures go to kernel.json (issue 3: the kernel core).
KERNEL_AGENTS = ("Kernel", "Task", "Scheduler", "Timer", "System")


def parse_run(output):
    """Parses the output of `bench run` into (overhead, {name: entry}).

    entry[objects] is (min, max), or a string when setup or the measured call
    failed; entry["median"][objects] is the median where the target printed one.
    """
    overhead = OVERHEAD_LINE.search(output)
    if overhead is None:
        raise BenchmarkError("no 'BENCH overhead' line in the output of 'bench run'")
    results = {}
    for match in RESULT_LINE.finditer(output):
        entry = results.setdefault(match["name"], {"cost": match["cost"], "variable": match["variable"] == "1"})
        entry[int(match["objects"])] = (int(match["min"]), int(match["max"]))
        if match["median"] is not None:
            entry.setdefault("median", {})[int(match["objects"])] = int(match["median"])
    for match in ERROR_LINE.finditer(output):
        entry = results.setdefault(match["name"], {"cost": "?", "variable": False})
        entry[int(match["objects"])] = f"setup failed: {match['text']}"
    return {key: int(value) for key, value in overhead.groupdict().items()}, results


def run_on_target(board, image, selection, repeat, timeout, accel=None, boot_timeout=None):
    """Boots the bench image and returns the output of `bench run` and the emulator's argv.

    Always on the board's benchmark CPU model (the machine's default model,
    an i486 for isapc, has no time-stamp counter). Without accel: with exact
    instruction counting. With accel="kvm": in real time (no -icount).
    """
    emulator = Emulator(board, image, icount=not accel, cpu=board.benchmark_cpu or None,
                        memory_mib=board.benchmark_memory(), accel=accel)
    try:
        emulator.start(timeout=timeout)
        wait_for_prompt(emulator, boot_timeout or timeout)
        line = "bench run" + (f" {selection}" if selection else "") + (f" --repeat {repeat}" if repeat else "")
        output = emulator.command(line, timeout=timeout)
        if not re.search(r"^BENCH done\r?$", output, re.MULTILINE):
            raise BenchmarkError(f"'{line}' did not end with 'BENCH done':\n"
                                 f"----- console transcript -----\n{emulator.transcript}\n"
                                 "----- end of transcript -----")
        return output, emulator.argv
    finally:
        emulator.close()


def wait_for_prompt(emulator, timeout):
    """Waits for the shell's prompt; gives up at once when KVM reports that it cannot run the guest.

    (QEMU then stops the guest but keeps running, so the console alone would
    only time out.)
    """
    deadline = time.monotonic() + timeout
    while True:
        try:
            emulator.expect(PROMPT, timeout=min(1.0, max(0.1, deadline - time.monotonic())))
            return
        except EmulatorError:
            if "KVM internal error" in emulator.emulator_messages() or time.monotonic() >= deadline:
                raise


def kvm_unusable_reason():
    """None when /dev/kvm can be opened for reading and writing, else why not."""
    try:
        descriptor = os.open("/dev/kvm", os.O_RDWR)
    except OSError as error:
        return f"/dev/kvm: {error.strerror}"
    os.close(descriptor)
    return None


def emulator_failure_summary(error):
    """The emulator's own words from an EmulatorError, shortened to its first telling lines."""
    text = str(error)
    said = text.split("emulator said:", 1)[1] if "emulator said:" in text else ""
    lines = [line.strip() for line in said.splitlines()
             if line.strip() and "waiting for connection" not in line and not line.startswith("extra data")]
    kvm_lines = [line for line in lines if "KVM" in line or "failure" in line]
    if kvm_lines:
        return "; ".join(kvm_lines[:2])
    return lines[0] if lines else text.splitlines()[0]


def run_kvm_pass(board, image, selection, repeat, timeout):
    """Runs every benchmark under KVM. Returns ({name: entry}, argv, None) or (None, None, reason)."""
    reason = kvm_unusable_reason()
    if reason is not None:
        return None, None, reason
    try:
        # A guest that KVM cannot run stops at once; do not wait long for its prompt.
        output, argv = run_on_target(board, image, selection, repeat, timeout, accel="kvm", boot_timeout=20)
        _, results = parse_run(output)
    except (EmulatorError, BenchmarkError) as error:
        return None, None, ("/dev/kvm opens, but the bench image does not run under -accel kvm: "
                            + emulator_failure_summary(error))
    return results, argv, None


def smallest(entry, objects):
    value = entry.get(objects)
    return value[0] if isinstance(value, tuple) else None


def report_entry(entry):
    """The kernel.json entry of a benchmark: the instruction figures."""
    return {
        "instructions_8": smallest(entry, 8),
        "instructions_4096": smallest(entry, 4096),
        "variable": entry["variable"],
        "cost": entry["cost"],
    }


def primitive_entry(name, entry, kvm_entry):
    """The primitives.json entry: the instruction figures, the seed's, and the KVM cycles when measured."""
    report = report_entry(entry)
    figure = SEED_FIGURES.get(name)
    report["seed_table"] = table_of(name) or None
    report["seed_microseconds"] = figure.microseconds if figure is not None else None
    # The KVM fields are always there, null when the KVM pass did not run.
    for objects in OBJECT_COUNTS:
        value = kvm_entry.get(objects) if kvm_entry is not None else None
        measured = isinstance(value, tuple)
        report[f"cycles_median_{objects}"] = kvm_entry.get("median", {}).get(objects) if measured else None
        report[f"cycles_min_{objects}"] = value[0] if measured else None
        report[f"cycles_max_{objects}"] = value[1] if measured else None
    return report


def count_text(value):
    if value is None:
        return "-"
    if isinstance(value, str):
        return "failed"
    low, high = value
    return str(low) if low == high else f"{low}..{high}"


def order_check(entry):
    """flat / NOT FLAT for O(1) primitives; O(log n) or variable otherwise."""
    if entry["cost"] == "log":
        return "O(log n)"
    if entry["cost"] == "variable":
        return "variable"
    small, large = entry.get(8), entry.get(4096)
    if not isinstance(small, tuple) or not isinstance(large, tuple):
        return "?"
    # The figures are the minimums (the maximum of a benchmark that runs with
    # interrupts enabled may include an interrupt handler).
    return "flat" if small[0] == large[0] else "NOT FLAT"


def cycles_text(kvm_entry):
    if kvm_entry is None:
        return "-"
    medians = kvm_entry.get("median", {})
    return " / ".join(str(medians[objects]) if isinstance(kvm_entry.get(objects), tuple) and objects in medians
                      else "-" for objects in OBJECT_COUNTS)


def table_rows(results, kvm_results, selection):
    """[(table, title, rows)] in the seed's order; a row per primitive.

    The seed's primitives come first, in the seed's order (a primitive DCOS
    does not have, or has not measured, shows "not in DCOS"), then the
    benchmarks the seed has no row for, by name.
    """
    def selected(name):
        return not selection or name == selection or name.split(".", 1)[0] == selection

    groups = []
    for table, title, _ in SEED_TABLES:
        names = [name for name, figure in SEED_FIGURES.items() if figure.table == table and selected(name)]
        names += sorted(name for name in results if table_of(name) == table and name not in SEED_FIGURES)
        rows = []
        for name in names:
            seed = seed_text(name) or "-"
            entry = results.get(name)
            if entry is None:
                rows.append((name, "-", "-", "not in DCOS", seed, ""))
                continue
            kvm = cycles_text(kvm_results.get(name)) if kvm_results is not None else ""
            rows.append((name, count_text(entry.get(8)), count_text(entry.get(4096)), order_check(entry), seed, kvm))
        if any(row[3] != "not in DCOS" for row in rows) or not selection:
            groups.append((table, title, rows))
    others = sorted(name for name in results if not table_of(name))
    if others:
        groups.append(("-", "Not in the seed's tables", [
            (name, count_text(results[name].get(8)), count_text(results[name].get(4096)),
             order_check(results[name]), "-",
             cycles_text(kvm_results.get(name)) if kvm_results is not None else "") for name in others]))
    return groups


def print_table(results, overhead, cpu, kvm_results=None, kvm_repeat=0, selection=""):
    print(f"DCOS primitives: bench image on -cpu {cpu}, -icount shift=0 (rdtsc = retired instructions)")
    print(f"figures: instructions retired by one call beyond an empty call (timing overhead {overhead['min']} "
          f"subtracted), smallest of {overhead['repeat']} after {overhead['warmup']} warm-up calls; "
          "a..b where the largest differs")
    print("flat/variable: flat = O(1) and the same count with 8 and 4096 objects; NOT FLAT = declared O(1) but "
          "the counts differ; variable = the seed's \"Variable\" (configuration services, first fit, ...)")
    print(f"seed: microseconds on a {SEED_PROCESSOR}, end to end through the trap interface (seed 9.3.7); "
          "orientation only, not instruction counts")
    if kvm_results is not None:
        print(f"KVM cycles: real time-stamp counter cycles of the host CPU under -accel kvm, median of {kvm_repeat} "
              "calls, with 8 / with 4096 objects; they vary from run to run")
    headers = ["primitive", "8 objects", "4096 objects", "flat/variable", "seed (P-150)"]
    aligns = ["<", ">", ">", "<", "<"]
    if kvm_results is not None:
        headers.append("KVM cycles (median 8 / 4096)")
        aligns.append(">")
    groups = table_rows(results, kvm_results, selection)
    all_rows = [row[:len(headers)] for _, _, rows in groups for row in rows]
    widths = [max(len(str(row[i])) for row in all_rows + [tuple(headers)]) for i in range(len(headers))]

    def line(cells):
        return "  ".join(f"{cell:{align}{width}}" for cell, align, width in zip(cells, aligns, widths)).rstrip()

    for table, title, rows in groups:
        print()
        print(f"Table {table}  {title}" if table != "-" else title)
        print("  " + line(headers))
        for row in rows:
            print("  " + line(row[:len(headers)]))
    print()
    for name in sorted(results):
        for objects in OBJECT_COUNTS:
            if isinstance(results[name].get(objects), str):
                print(f"{name} with {objects} objects: {results[name][objects]}")
    not_flat = [name for name in sorted(results) if order_check(results[name]) == "NOT FLAT"]
    if not_flat:
        print(f"NOT FLAT: {', '.join(not_flat)} declared O(1) but cost differs between 8 and 4096 objects")
    measured_seed = [name for name in SEED_FIGURES if name in results]
    print(f"{len(results)} benchmarks; {len(measured_seed)} of the seed's {len(SEED_FIGURES)} primitives measured "
          f"(the others are not in DCOS yet)")


# One CAN frame through the SJA1000 driver and the link layer
# (tests_renode/bench/CanBench.cpp): the pieces of a received and of a sent
# frame, and the worst-case frame rate of the issue: 8-byte standard frames
# at 1 Mbit/s, 135 bit times each with worst-case stuffing and the
# interframe space, 10^6 / 135 = 7,407 frames per second.
CAN_RECEIVE_PIECES = ("Can.ReceiveInterrupt", "Can.ReadFrame")
CAN_SEND_PIECES = ("Can.WriteFrame", "Can.TransmitInterrupt")
CAN_WORST_FRAME_RATE = 7407
# Instructions per second of the emulated CPU under -icount shift=0 (one per
# nanosecond), and, for orientation only, of an i486DX2-66 at an assumed
# average of two clock cycles per instruction (docs/performance.md).
EMULATED_INSTRUCTION_RATE = 1_000_000_000
REFERENCE_486_INSTRUCTION_RATE = 33_000_000


def can_summary(results):
    """Instructions per received and per sent CAN frame and the CPU share at
    CAN_WORST_FRAME_RATE; None when the CAN benchmarks did not all run."""
    def figure(name):
        entry = results.get(name)
        return smallest(entry, 8) if entry is not None else None

    pieces = {name: figure(name) for name in CAN_RECEIVE_PIECES + CAN_SEND_PIECES}
    if any(value is None for value in pieces.values()):
        return None
    entry = figure("Kernel.InterruptLatency")
    summary = {"frames_per_second": CAN_WORST_FRAME_RATE, "pieces": pieces,
               "interrupt_entry_instructions": entry}
    for direction, names in (("received", CAN_RECEIVE_PIECES), ("sent", CAN_SEND_PIECES)):
        per_frame = sum(pieces[name] for name in names)
        per_second = per_frame * CAN_WORST_FRAME_RATE
        summary[direction] = {
            "instructions_per_frame": per_frame,
            "instructions_per_second": per_second,
            "share_of_emulated_cpu": per_second / EMULATED_INSTRUCTION_RATE,
            "share_of_reference_486": per_second / REFERENCE_486_INSTRUCTION_RATE,
        }
    return summary


def print_can_summary(summary):
    print()
    print(f"CAN frames through the SJA1000 driver and the link layer, at the worst-case rate of 1 Mbit/s "
          f"({summary['frames_per_second']} frames/s; 8 data bytes, extended DCOS identifier)")
    for direction, names in (("received", CAN_RECEIVE_PIECES), ("sent", CAN_SEND_PIECES)):
        figures = summary[direction]
        parts = " + ".join(f"{name} {summary['pieces'][name]}" for name in names)
        print(f"  per {direction} frame: {figures['instructions_per_frame']} instructions ({parts}); "
              f"{figures['instructions_per_second'] / 1e6:.2f} million/s: "
              f"{100 * figures['share_of_emulated_cpu']:.2f} % of the emulated CPU (10^9/s), "
              f"{100 * figures['share_of_reference_486']:.1f} % of a 486 retiring 33 million/s")
    if summary["interrupt_entry_instructions"] is not None:
        print(f"  not included: the kernel's interrupt entry per routine (Kernel.InterruptLatency "
              f"{summary['interrupt_entry_instructions']}) and exit, and the ISA bus's wait states on the chip's "
              "18 port accesses per frame (docs/performance.md)")


# The Modbus RTU line (tests_renode/bench/ModbusBench.cpp): the pieces of a
# received character and the two handled requests, and the line's own limit
# at 115200 baud. A character is 11 bits ([SL] 2.5.1: start, 8 data, parity,
# stop); above 19200 baud t3.5 is the fixed 1.75 ms ([SL] 2.5.1.1). A
# transaction holds the line for the request, the t3.5 that ends it, the
# response and the t3.5 that ends that before the master's next request.
MODBUS_CHARACTER_PIECES = ("Modbus.ReceiveInterrupt", "Modbus.ReceiveCharacter")
MODBUS_BAUD = 115200
MODBUS_CHARACTER_BITS = 11
MODBUS_T35_SECONDS = 1.75e-3
# name: (what it is, request characters, response characters): read 10
# registers is 8 bytes in, 3 + 20 + 2 out; write 10 is 9 + 20 in, 8 out.
MODBUS_REQUESTS = {
    "Modbus.ReadHoldingRegisters": ("read 10 holding registers (03)", 8, 25),
    "Modbus.WriteMultipleRegisters": ("write 10 holding registers (10)", 29, 8),
}


def modbus_summary(results):
    """Instructions per received character and per transaction of the two
    requests, the line's transaction limit at MODBUS_BAUD and the CPU share
    there; None when the Modbus benchmarks did not all run."""
    def figure(name):
        entry = results.get(name)
        return smallest(entry, 8) if entry is not None else None

    pieces = {name: figure(name) for name in MODBUS_CHARACTER_PIECES + tuple(MODBUS_REQUESTS)}
    if any(value is None for value in pieces.values()):
        return None
    per_character = sum(pieces[name] for name in MODBUS_CHARACTER_PIECES)
    character_seconds = MODBUS_CHARACTER_BITS / MODBUS_BAUD
    summary = {"baud": MODBUS_BAUD, "character_bits": MODBUS_CHARACTER_BITS, "t35_seconds": MODBUS_T35_SECONDS,
               "pieces": pieces, "instructions_per_character": per_character,
               "interrupt_entry_instructions": figure("Kernel.InterruptLatency"), "requests": {}}
    for name, (title, request_characters, response_characters) in MODBUS_REQUESTS.items():
        line_seconds = (request_characters + response_characters) * character_seconds + 2 * MODBUS_T35_SECONDS
        limit = 1 / line_seconds
        # Every request character costs the interrupt and a wake-up of the
        # task; the request's figure takes the characters through the
        # receiver again, so this is an upper bound (docs/performance.md).
        per_transaction = request_characters * per_character + pieces[name]
        per_second = per_transaction * limit
        summary["requests"][name] = {
            "title": title,
            "request_characters": request_characters,
            "response_characters": response_characters,
            "instructions_per_request": pieces[name],
            "instructions_per_transaction": per_transaction,
            "line_limit_transactions_per_second": limit,
            # The response leaves only once the request is served: the answer's
            # instructions add to the line's time per transaction.
            "transactions_per_second_emulated_cpu": 1 / (line_seconds + pieces[name] / EMULATED_INSTRUCTION_RATE),
            "transactions_per_second_reference_486":
                1 / (line_seconds + pieces[name] / REFERENCE_486_INSTRUCTION_RATE),
            "instructions_per_second": per_second,
            "share_of_emulated_cpu": per_second / EMULATED_INSTRUCTION_RATE,
            "share_of_reference_486": per_second / REFERENCE_486_INSTRUCTION_RATE,
        }
    return summary


def print_modbus_summary(summary):
    print()
    print(f"Modbus RTU line through the 16550 driver, drivers/modbus and fieldbus/modbus, at {summary['baud']} baud "
          f"({summary['character_bits']}-bit characters, t3.5 {summary['t35_seconds'] * 1e3:g} ms)")
    parts = " + ".join(f"{name} {summary['pieces'][name]}" for name in MODBUS_CHARACTER_PIECES)
    print(f"  per received character: {summary['instructions_per_character']} instructions ({parts})")
    for name, figures in summary["requests"].items():
        print(f"  {figures['title']}: {name} {figures['instructions_per_request']} instructions; "
              f"{figures['request_characters']} + {figures['response_characters']} characters: line limit "
              f"{figures['line_limit_transactions_per_second']:.1f} transactions/s, reached "
              f"{figures['transactions_per_second_emulated_cpu']:.1f} (emulated CPU) / "
              f"{figures['transactions_per_second_reference_486']:.1f} (486 at 33 million/s); at the limit "
              f"{figures['instructions_per_transaction']} instructions per transaction, "
              f"{100 * figures['share_of_emulated_cpu']:.3f} % of the emulated CPU, "
              f"{100 * figures['share_of_reference_486']:.2f} % of the 486")
    if summary["interrupt_entry_instructions"] is not None:
        print(f"  not included: the kernel's interrupt entry per character (Kernel.InterruptLatency "
              f"{summary['interrupt_entry_instructions']}) and exit, the task's wake-up, the response's transmission "
              "(16550 transmit, its interrupts, the driver enable), the ISA bus's wait states (docs/performance.md)")


def budget_rows(budgets, report, selection):
    """budgets.py's rows for this run's primitives.json entries."""
    return budget_file.check_primitives(budgets, report, selection)


def attach_budgets(report, rows):
    """Puts each row's verdict into its benchmark's primitives.json entry ("budget", null when it has none)."""
    for entry in report.values():
        entry["budget"] = None
    for row in rows:
        if row["name"] in report:
            report[row["name"]]["budget"] = {
                "instructions": row["budget"], "flat": row["flat"], "now": row["now"], "bound": row["bound"],
                "note": row["note"], "verdict": row["verdict"], "flat_agrees": row["flat_agrees"],
                "offences": row["offences"]}
    return report


def write_json(path, report):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="utf-8") as handle:
        json.dump(report, handle, indent=2)
        handle.write("\n")
    print(f"wrote {path}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--board", default="isa486")
    parser.add_argument("--image", help="bench image (default: the board's 'benchmark' image)")
    parser.add_argument("--output", default=os.path.join(REPOSITORY, "build", "bench", "kernel.json"),
                        help="JSON report of the kernel core's benchmarks to write")
    parser.add_argument("--primitives", default=os.path.join(REPOSITORY, "build", "bench", "primitives.json"),
                        help="JSON report of every benchmark to write")
    parser.add_argument("--select", default="", help="one benchmark or one agent, e.g. Timer or Kernel.ResolveId")
    parser.add_argument("--repeat", type=int, default=0, help="measured calls per object count (default: target's)")
    parser.add_argument("--kvm", choices=("auto", "off"), default="auto",
                        help="auto: also measure real cycles under KVM where it works; off: never")
    parser.add_argument("--kvm-repeat", type=int, default=201,
                        help="measured calls per object count in the KVM pass, whose median is reported")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds for each wait on the emulator")
    parser.add_argument("--strict", action="store_true",
                        help="exit 1 when a figure offends its budget or an O(1) benchmark is NOT FLAT")
    parser.add_argument("--budgets", default=budget_file.DEFAULT_BUDGETS, help="the budget file (budgets.toml)")
    parser.add_argument("--can", default=os.path.join(REPOSITORY, "build", "bench", "can.json"),
                        help="JSON report of the CAN frame costs to write (when the CAN benchmarks ran)")
    parser.add_argument("--modbus", default=os.path.join(REPOSITORY, "build", "bench", "modbus.json"),
                        help="JSON report of the Modbus line's costs to write (when the Modbus benchmarks ran)")
    arguments = parser.parse_args()

    budgets = budget_file.load_budgets_for_command(arguments.budgets)
    if budgets is None:
        return 2
    board = load_board(arguments.board)
    if not board.benchmark_cpu:
        print(f"board {board.name} names no benchmark_cpu; the bench image needs a CPU with rdtsc", file=sys.stderr)
        return 2
    image = arguments.image or board.image("benchmark")
    try:
        output, argv = run_on_target(board, image, arguments.select, arguments.repeat, arguments.timeout)
        overhead, results = parse_run(output)
    except (EmulatorError, BenchmarkError) as error:
        print(f"make bench: the benchmark run failed.\n{error}", file=sys.stderr)
        return 1
    if not results:
        print(f"make bench: 'bench run' reported no benchmarks:\n{output}", file=sys.stderr)
        return 1
    missing = [name for name, entry in results.items() if any(objects not in entry for objects in OBJECT_COUNTS)]
    if missing:
        print(f"make bench: no figures for every object count from {', '.join(missing)}:\n{output}", file=sys.stderr)
        return 1

    kvm_results, kvm_argv, kvm_reason = None, None, "disabled with --kvm off"
    if arguments.kvm == "auto":
        kvm_results, kvm_argv, kvm_reason = run_kvm_pass(board, image, arguments.select, arguments.kvm_repeat,
                                                         arguments.timeout)

    print("emulator: " + " ".join(argv))
    if kvm_argv:
        print("emulator (KVM pass): " + " ".join(kvm_argv))
    print_table(results, overhead, board.benchmark_cpu, kvm_results, arguments.kvm_repeat, arguments.select)
    can = can_summary(results)
    if can is not None:
        print_can_summary(can)
    modbus = modbus_summary(results)
    if modbus is not None:
        print_modbus_summary(modbus)
    if kvm_results is None:
        print(f"KVM not available: real cycle figures not reported ({kvm_reason}). "
              "Every figure above is an exact instruction count under QEMU TCG with -icount.")
    primitives = {
        name: primitive_entry(name, results[name], kvm_results.get(name) if kvm_results is not None else None)
        for name in sorted(results)}
    rows = budget_rows(budgets, primitives, arguments.select)
    print()
    print("\n".join(budget_file.primitive_lines(rows, arguments.budgets)))

    write_json(arguments.output, {name: report_entry(results[name]) for name in sorted(results)
                                  if name.split(".", 1)[0] in KERNEL_AGENTS})
    write_json(arguments.primitives, attach_budgets(primitives, rows))
    if can is not None:
        write_json(arguments.can, can)
    if modbus is not None:
        write_json(arguments.modbus, modbus)
    found = budget_file.offenders(rows)
    if arguments.strict and (found or any(order_check(entry) == "NOT FLAT" for entry in results.values())):
        print(f"run_benchmarks.py --strict: {len(found)} offenders:", file=sys.stderr)
        for offence in found:
            print(f"  {offence}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
