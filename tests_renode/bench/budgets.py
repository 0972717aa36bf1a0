#!/usr/bin/python3
"""Checks `make bench`'s figures against tests_renode/bench/budgets.toml.

The library half is used by run_benchmarks.py, run_thread_metric.py and
footprint.py, which print their figures beside the budgets and put the
comparison into their JSON reports. Run as a program it is the last step of
`make bench`: it reads those reports, lists every offender, writes
build/bench/budgets.json and, with --strict (`make bench STRICT=1`), exits 1
when there is any offender:

  - a figure over its budget (instructions, instructions per Thread-Metric
    iteration, bytes of kernel code);
  - a budgeted figure that must be flat and differs between 8 and 4,096
    objects;
  - a fixed-cost benchmark (cost "constant") that is NOT FLAT, budgeted or
    not: the design claims O(1) for it;
  - a budget whose benchmark or test reported no figure although it is
    expected to be measured;
  - a remote transaction's instruction count (remote_bench.py's
    remote.json, the [remote] table) that is absent or not positive, over
    a budget set for it, or not the same on every call where the entry
    asks for identical calls.

A budget marked `measured = false` is reported as "not measured yet" and is
never an offender: its benchmark or image does not exist yet, and no figure
is made up for it. Without --strict the verdict is printed and the exit
status is 0. Only the standard library is used (tomllib, Python 3.11).
"""

import argparse
import json
import os
import sys
import tomllib

HERE = os.path.dirname(os.path.abspath(__file__))
REPOSITORY = os.path.dirname(os.path.dirname(HERE))
DEFAULT_BUDGETS = os.path.join(HERE, "budgets.toml")
OBJECT_COUNTS = (8, 4096)

WITHIN = "within"
OVER = "over"
NOT_MEASURED_YET = "not measured yet"
MISSING = "missing"
NO_COUNT = "no count"

_PRIMITIVE_KEYS = {"budget", "flat", "now", "measured", "note", "bound"}
_THREAD_METRIC_KEYS = {"freertos", "budget", "now", "note", "measured"}
_FOOTPRINT_KEYS = {"image", "kernel", "text_budget", "now", "note", "measured"}
_REMOTE_KEYS = {"figures", "identical", "budget", "now", "bound", "note", "measured"}
# The instruction figures remote_bench.py reports per primitive: a spread
# over the calls ({"min", "median", "max"}) each, in remote.json's
# "instructions", and the two receive interrupts (one count each).
REMOTE_FIGURES = ("caller_request", "caller_reply", "caller_own", "caller_span", "caller_waiting", "callee",
                  "callee_parts_before", "receive_interrupt_caller", "receive_interrupt_callee")


class BudgetFileError(Exception):
    pass


def load_budgets(path=DEFAULT_BUDGETS):
    """Reads and checks the budget file; raises BudgetFileError on a malformed one.

    A typing error in a key would otherwise silently drop a budget, so
    unknown keys are refused rather than ignored.
    """
    try:
        with open(path, "rb") as handle:
            data = tomllib.load(handle)
    except (OSError, tomllib.TOMLDecodeError) as error:
        raise BudgetFileError(f"{path}: {error}") from error
    return parse_budgets(data, path)


def parse_budgets(data, origin="budgets"):
    """Checks a budget file's parsed TOML and fills in the defaults."""
    unknown_tables = set(data) - {"primitives", "thread_metric", "footprint", "remote"}
    if unknown_tables:
        raise BudgetFileError(f"{origin}: unknown tables {sorted(unknown_tables)}")
    budgets = {"primitives": {}, "thread_metric": {}, "footprint": {}, "remote": {}}
    for table, allowed in (("primitives", _PRIMITIVE_KEYS), ("thread_metric", _THREAD_METRIC_KEYS),
                           ("footprint", _FOOTPRINT_KEYS)):
        for name, entry in data.get(table, {}).items():
            unknown = set(entry) - allowed
            if unknown:
                raise BudgetFileError(f"{origin}: [{table}.\"{name}\"] has unknown keys {sorted(unknown)}")
            entry = dict(entry)
            entry.setdefault("measured", True)
            entry.setdefault("note", "")
            for key in ("budget", "text_budget", "freertos", "now"):
                if key in entry and (not isinstance(entry[key], (int, float)) or entry[key] < 0):
                    raise BudgetFileError(f"{origin}: [{table}.\"{name}\"] {key} must be a number >= 0")
            if table == "primitives":
                entry.setdefault("flat", False)
                if "budget" not in entry and not entry["flat"] and "bound" not in entry:
                    raise BudgetFileError(f"{origin}: [primitives.\"{name}\"] sets neither a budget, flat nor a bound")
            if table == "thread_metric" and "budget" not in entry:
                raise BudgetFileError(f"{origin}: [thread_metric.{name}] has no budget")
            if table == "footprint":
                if "text_budget" not in entry:
                    raise BudgetFileError(f"{origin}: [footprint.{name}] has no text_budget")
                entry.setdefault("kernel", ["firmware/dcos/"])
                if entry["measured"] and "image" not in entry:
                    raise BudgetFileError(f"{origin}: [footprint.{name}] is measured but names no image")
            budgets[table][name] = entry
    for name, entry in data.get("remote", {}).items():
        budgets["remote"][name] = _parse_remote(name, entry, origin)
    return budgets


def _parse_remote(name, entry, origin):
    """Checks one [remote."<primitive>"] entry and fills in the defaults."""
    where = f'{origin}: [remote."{name}"]'
    unknown = set(entry) - _REMOTE_KEYS
    if unknown:
        raise BudgetFileError(f"{where} has unknown keys {sorted(unknown)}")
    entry = dict(entry)
    entry.setdefault("measured", True)
    entry.setdefault("note", "")
    entry.setdefault("identical", False)
    entry.setdefault("budget", {})
    entry.setdefault("now", {})
    figures = entry.get("figures")
    if not isinstance(figures, list) or not figures:
        raise BudgetFileError(f"{where} names no figures")
    for figure in figures:
        if figure not in REMOTE_FIGURES:
            raise BudgetFileError(f"{where}: unknown figure {figure!r}; the figures are {', '.join(REMOTE_FIGURES)}")
    for key in ("budget", "now"):
        if not isinstance(entry[key], dict):
            raise BudgetFileError(f"{where} {key} must be a table of figures")
        for figure, value in entry[key].items():
            if figure not in figures:
                raise BudgetFileError(f"{where} {key} names {figure!r}, which is not among its figures")
            if not isinstance(value, (int, float)) or value < 0:
                raise BudgetFileError(f"{where} {key}.{figure} must be a number >= 0")
    if not entry["budget"] and not entry["identical"] and "bound" not in entry:
        raise BudgetFileError(f"{where} sets neither a budget, identical nor a bound")
    return entry


def _figure(report_entry, objects):
    """The instruction figure of a primitives.json entry for that object count, or None."""
    if report_entry is None:
        return None
    value = report_entry.get(f"instructions_{objects}")
    return value if isinstance(value, int) else None


def check_primitive(name, budget, report_entry):
    """Compares one budgeted benchmark with its primitives.json entry (None when it did not run).

    Returns a row: the budget's fields, the two figures, "verdict" (within,
    over, "no count" where the budget is flatness or a bound only, not
    measured yet, missing), "flat_agrees" (True, False,
    or None when flatness is not required or cannot be told) and
    "offences", the reasons it fails strict mode (empty when it does not).
    """
    small, large = _figure(report_entry, 8), _figure(report_entry, 4096)
    row = {"name": name, "budget": budget.get("budget"), "flat": budget["flat"], "now": budget.get("now"),
           "bound": budget.get("bound"), "note": budget["note"], "measured": budget["measured"],
           "instructions_8": small, "instructions_4096": large, "flat_agrees": None, "offences": []}
    if report_entry is None:
        if not budget["measured"]:
            row["verdict"] = NOT_MEASURED_YET
        else:
            row["verdict"] = MISSING
            row["offences"].append(f"{name}: no figure (no benchmark of that name ran)")
        return row
    if small is None or large is None:
        row["verdict"] = MISSING
        absent = " and ".join(str(objects) for objects, value in zip(OBJECT_COUNTS, (small, large)) if value is None)
        row["offences"].append(f"{name}: no figure with {absent} objects")
        return row
    if "budget" in budget:
        worst = max(small, large)
        row["verdict"] = OVER if worst > budget["budget"] else WITHIN
        if row["verdict"] == OVER:
            row["offences"].append(f"{name}: {worst} instructions, over its budget of {budget['budget']}")
    else:
        row["verdict"] = NO_COUNT
    # A benchmark declared O(1) must be flat whatever its budget says: the
    # budget file cannot excuse the design's own claim.
    if budget["flat"] or report_entry.get("cost") == "constant":
        row["flat"] = True
        row["flat_agrees"] = small == large
        if not row["flat_agrees"]:
            row["offences"].append(f"{name}: {small} with 8 objects, {large} with 4096: must be flat")
    return row


def check_primitives(budgets, report, selection=""):
    """Rows for every budgeted benchmark, then the unbudgeted fixed-cost benchmarks that are NOT FLAT.

    report is primitives.json: {name: {"instructions_8", "instructions_4096",
    "cost", ...}}. selection (an agent or a full name, as run_benchmarks.py
    --select) leaves out the budgets of benchmarks that were not run.
    """
    def selected(name):
        return not selection or name == selection or name.split(".", 1)[0] == selection

    rows = [check_primitive(name, budget, report.get(name))
            for name, budget in budgets["primitives"].items() if selected(name)]
    for name in sorted(report):
        if name in budgets["primitives"] or report[name].get("cost") != "constant":
            continue
        small, large = _figure(report[name], 8), _figure(report[name], 4096)
        if small is not None and large is not None and small != large:
            rows.append({"name": name, "budget": None, "flat": True, "now": None, "bound": None,
                         "note": "fixed-cost (O(1)) benchmark without a budget", "measured": True,
                         "instructions_8": small, "instructions_4096": large, "verdict": NO_COUNT,
                         "flat_agrees": False,
                         "offences": [f"{name}: {small} with 8 objects, {large} with 4096: "
                                      "declared O(1) but NOT FLAT"]})
    return rows


def _judge(row, budget, figure, limit, missing, over):
    """The verdict on one figure against limit. With no figure: "not measured
    yet" where the budget file says no benchmark or image exists yet,
    otherwise a missing figure, offence `missing`; over the limit, the
    offence over() says."""
    if figure is None:
        row["verdict"] = NOT_MEASURED_YET if not budget["measured"] else MISSING
        if budget["measured"]:
            row["offences"].append(missing)
        return
    row["verdict"] = OVER if figure > limit else WITHIN
    if row["verdict"] == OVER:
        row["offences"].append(over())


def load_budgets_for_command(path):
    """load_budgets for a `make bench` step: the budgets, or None after
    saying on stderr why the file was refused (the step then exits 2)."""
    try:
        return load_budgets(path)
    except BudgetFileError as error:
        print(f"make bench: {error}", file=sys.stderr)
        return None


def check_thread_metric(budgets, results):
    """Rows for every budgeted Thread-Metric test; results is thread_metric.json's {test: {...}}."""
    rows = []
    for name, budget in budgets["thread_metric"].items():
        entry = results.get(name)
        figure = entry.get("instructions_per_iteration") if entry else None
        # The exact quotient where the totals are there: the printed figure
        # is rounded to two decimals, which could decide a verdict at the edge.
        if entry and entry.get("iterations") and entry.get("instructions") is not None:
            figure = entry["instructions"] / entry["iterations"]
        row = {"name": name, "budget": budget["budget"], "freertos": budget.get("freertos"),
               "now": budget.get("now"), "note": budget["note"], "measured": budget["measured"],
               "instructions_per_iteration": figure, "offences": []}
        _judge(row, budget, figure, budget["budget"], f"Thread-Metric {name}: no figure",
               lambda: f"Thread-Metric {name}: {figure:g} instructions per iteration, over its budget of "
                       f"{budget['budget']:g} (half of FreeRTOS's {budget.get('freertos', 2 * budget['budget']):g})")
        rows.append(row)
    return rows


def check_footprint(budgets, images):
    """Rows for every footprint budget; images maps a budget's name to its
    measured kernel code in bytes (footprint.py), absent when not built."""
    rows = []
    for name, budget in budgets["footprint"].items():
        text = images.get(name)
        row = {"name": name, "text_budget": budget["text_budget"], "now": budget.get("now"),
               "image": budget.get("image"), "kernel": budget["kernel"], "note": budget["note"],
               "measured": budget["measured"], "kernel_text": text, "offences": []}
        _judge(row, budget, text, budget["text_budget"], f"footprint {name}: no figure for {budget.get('image')}",
               lambda: f"footprint {name}: kernel code {text} bytes, over its budget of {budget['text_budget']} bytes")
        rows.append(row)
    return rows


def _remote_spread(entry, figure):
    """A figure of one primitive's remote.json entry as (min, max), or None when absent."""
    counts = (entry or {}).get("instructions") or {}
    value = counts.get(figure)
    if isinstance(value, dict):
        low, high = value.get("min"), value.get("max")
    else:
        low = high = value
    if not isinstance(low, (int, float)) or not isinstance(high, (int, float)):
        return None
    return low, high


def check_remote(budgets, results):
    """Rows for every figure a [remote] budget names; results is remote.json's "primitives".

    A row: "primitive", "figure", "budget" (or None), "now", "bound",
    "note", "measured", "min" and "max" over the calls, "verdict" (within,
    over, "no count" where no number is set, missing, not measured yet),
    "identical" (whether it is asked for), "identical_agrees" (True, False,
    or None where it is not asked for or cannot be told) and "offences".
    """
    rows = []
    for name, budget in budgets.get("remote", {}).items():
        entry = results.get(name)
        for figure in budget["figures"]:
            spread = _remote_spread(entry, figure)
            row = {"primitive": name, "figure": figure, "budget": budget["budget"].get(figure),
                   "now": budget["now"].get(figure), "bound": budget.get("bound"), "note": budget["note"],
                   "measured": budget["measured"], "identical": budget["identical"],
                   "min": spread[0] if spread else None, "max": spread[1] if spread else None,
                   "identical_agrees": None, "offences": []}
            label = f"remote {name} {figure}"
            if spread is None:
                row["verdict"] = NOT_MEASURED_YET if not budget["measured"] else MISSING
                if budget["measured"]:
                    row["offences"].append(f"{label}: no figure (remote.json has none)")
                rows.append(row)
                continue
            low, high = spread
            if low <= 0:
                row["offences"].append(f"{label}: {low} instructions: not counted")
            if row["budget"] is not None:
                row["verdict"] = OVER if high > row["budget"] else WITHIN
                if row["verdict"] == OVER:
                    row["offences"].append(f"{label}: {high} instructions, over its budget of {row['budget']}")
            else:
                row["verdict"] = NO_COUNT
            if budget["identical"]:
                row["identical_agrees"] = low == high
                if not row["identical_agrees"]:
                    row["offences"].append(f"{label}: {low} to {high} instructions: every call must count the same")
            rows.append(row)
    return rows


def remote_lines(rows, budget_path):
    """The console table of the remote budgets."""
    lines = [f"Remote budgets ({os.path.relpath(budget_path, REPOSITORY)}, [remote]): each figure's largest count "
             "over the calls against its budget; identical: whether every call counted the same where it must"]
    if not rows:
        return lines + ["  (none)"]
    table = [(row["primitive"], row["figure"], count_text(row["min"]), count_text(row["max"]),
              count_text(row["budget"]) if row["budget"] is not None else (row["bound"] and "bound") or "-",
              verdict_text(row), identical_text(row), count_text(row["now"])) for row in rows]
    lines += _table(("primitive", "figure", "min", "max", "budget", "verdict", "identical", "now"), table,
                    ("<", "<", ">", ">", ">", "<", "<", ">"))
    bounds = {}
    for row in rows:
        if row["bound"] and row["primitive"] not in bounds.setdefault(row["bound"], []):
            bounds[row["bound"]].append(row["primitive"])
    for bound, primitives in bounds.items():
        lines.append(f"  {', '.join(primitives)}: bound: {bound}")
    lines.append("  " + summary_text(rows))
    return lines


def identical_text(row):
    if not row["identical"]:
        return "-"
    if row["identical_agrees"] is None:
        return "?"
    return "agree" if row["identical_agrees"] else "DIFFER"


def offenders(*row_lists):
    """Every offence of every row, in order."""
    return [offence for rows in row_lists for row in rows for offence in row["offences"]]


def count_text(value):
    return "-" if value is None else f"{value:g}" if isinstance(value, float) else str(value)


def _table(headers, rows, aligns):
    widths = [max(len(str(row[i])) for row in rows + [headers]) for i in range(len(headers))]

    def line(cells):
        return "  ".join(f"{cell:{align}{width}}" for cell, align, width in zip(cells, aligns, widths)).rstrip()

    return ["  " + line(headers)] + ["  " + line(row) for row in rows]


def verdict_text(row):
    if row["verdict"] == OVER:
        return "OVER"
    if row["verdict"] == MISSING:
        return "MISSING"
    if row["verdict"] == NO_COUNT:
        return "-"
    return row["verdict"]


def flat_text(row):
    if not row["flat"]:
        return "-"
    if row["flat_agrees"] is None:
        return "?"
    return "agree" if row["flat_agrees"] else "DIFFER"


def primitive_lines(rows, budget_path):
    """The console table of the budgeted benchmarks (and the unbudgeted NOT FLAT ones)."""
    lines = [f"Budgets ({os.path.relpath(budget_path, REPOSITORY)}, issue 12): the larger of the 8- and "
             "4096-object figures against the budget; flat: whether 8 and 4096 agree where they must"]
    table = [(row["name"], count_text(row["instructions_8"]), count_text(row["instructions_4096"]),
              count_text(row["budget"]) if row["budget"] is not None else (row["bound"] and "bound") or "-",
              verdict_text(row), flat_text(row), count_text(row["now"])) for row in rows]
    lines += _table(("primitive", "8 objects", "4096 objects", "budget", "verdict", "flat", "now (issue)"),
                    table, ("<", ">", ">", ">", "<", "<", ">"))
    for row in rows:
        if row["bound"]:
            lines.append(f"  {row['name']}: bound: {row['bound']}")
        if row["verdict"] == NOT_MEASURED_YET:
            lines.append(f"  {row['name']}: not measured yet: {row['note']}")
    lines.append("  " + summary_text(rows))
    return lines


def thread_metric_lines(rows):
    lines = ["Thread-Metric budgets (issue 12): at most half of FreeRTOS 11.1's instructions per iteration"]
    table = [(row["name"], count_text(row["instructions_per_iteration"]), count_text(row["budget"]),
              verdict_text(row), count_text(row["freertos"]), count_text(row["now"])) for row in rows]
    lines += _table(("test", "per iteration", "budget", "verdict", "FreeRTOS", "now (issue)"), table,
                    ("<", ">", ">", "<", ">", ">"))
    lines.append("  " + summary_text(rows))
    return lines


def summary_text(rows):
    counts = {}
    for row in rows:
        counts[row["verdict"]] = counts.get(row["verdict"], 0) + 1
    differ = sum(1 for row in rows if row.get("flat_agrees") is False)
    unequal = sum(1 for row in rows if row.get("identical_agrees") is False)
    parts = [f"{counts[key]} {key}" for key in (WITHIN, OVER, NO_COUNT, MISSING, NOT_MEASURED_YET) if key in counts]
    if differ:
        parts.append(f"{differ} not flat")
    if unequal:
        parts.append(f"{unequal} not identical")
    found = sum(len(row["offences"]) for row in rows)
    return "; ".join(parts) + f"; {found} offender{'' if found == 1 else 's'}"


def read_json(path):
    """A report's contents, or None when it is absent (its step did not run)."""
    try:
        with open(path, encoding="utf-8") as handle:
            return json.load(handle)
    except FileNotFoundError:
        return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    bench = os.path.join(REPOSITORY, "build", "bench")
    parser.add_argument("--budgets", default=DEFAULT_BUDGETS)
    parser.add_argument("--primitives", default=os.path.join(bench, "primitives.json"))
    parser.add_argument("--thread-metric", default=os.path.join(bench, "thread_metric.json"))
    parser.add_argument("--footprint", default=os.path.join(bench, "footprint.json"))
    parser.add_argument("--remote", default=os.path.join(bench, "remote.json"))
    parser.add_argument("--output", default=os.path.join(bench, "budgets.json"))
    parser.add_argument("--strict", action="store_true", help="exit 1 when any figure offends its budget")
    arguments = parser.parse_args()

    try:
        budgets = load_budgets(arguments.budgets)
    except BudgetFileError as error:
        print(f"make bench: {error}", file=sys.stderr)
        return 2
    # A report that is absent makes every budget it carries "missing", so a
    # step that did not run can never pass strict mode by saying nothing.
    primitives = check_primitives(budgets, read_json(arguments.primitives) or {})
    thread_metric = check_thread_metric(budgets, read_json(arguments.thread_metric) or {})
    footprint_report = read_json(arguments.footprint) or {}
    footprint = check_footprint(budgets, {name: image["kernel"]["text"]
                                          for name, image in footprint_report.get("images", {}).items()})
    remote = check_remote(budgets, (read_json(arguments.remote) or {}).get("primitives", {}))
    found = offenders(primitives, thread_metric, footprint, remote)
    not_measured = [row["name"] for rows in (primitives, thread_metric, footprint) for row in rows
                    if row["verdict"] == NOT_MEASURED_YET]
    not_measured += [f"remote {row['primitive']} {row['figure']}" for row in remote
                     if row["verdict"] == NOT_MEASURED_YET]

    os.makedirs(os.path.dirname(os.path.abspath(arguments.output)), exist_ok=True)
    with open(arguments.output, "w", encoding="utf-8") as handle:
        json.dump({"strict": arguments.strict, "offenders": found, "not_measured_yet": not_measured,
                   "primitives": primitives, "thread_metric": thread_metric, "footprint": footprint,
                   "remote": remote},
                  handle, indent=2)
        handle.write("\n")

    print()
    print(f"Budget verdict: {len(found)} offender{'' if len(found) == 1 else 's'}; primitives: {summary_text(primitives)}; "
          f"Thread-Metric: {summary_text(thread_metric)}; footprint: {summary_text(footprint)}; "
          f"remote: {summary_text(remote)}")
    if not_measured:
        print(f"not measured yet (budget recorded, no benchmark or image yet): {', '.join(not_measured)}")
    print(f"wrote {arguments.output}")
    if arguments.strict and found:
        print(f"make bench STRICT=1: {len(found)} offenders:", file=sys.stderr)
        for offence in found:
            print(f"  {offence}", file=sys.stderr)
        return 1
    if found:
        print("(offenders are reported, not enforced; `make bench STRICT=1` fails on them)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
