#!/usr/bin/env python3
"""Runs the CAN link layer's libFuzzer targets and writes a JUnit XML report.

For each target two test cases run, one after the other:

- ``<target>.corpus``: every seed input in fieldbus/can/fuzz/corpus/<target>/
  is executed once (``-runs=0`` over the seed directory), so a crash that was
  fixed and kept as a seed stays fixed;
- ``<target>.fuzz``: the target fuzzes for a bounded time (``-max_total_time``),
  starting from the seeds plus what earlier runs found (kept in the build
  directory, so the tree's corpus stays small).

A crash, a leak, a sanitizer report, a time-out or an out-of-memory stops
the target with a non-zero status: the test case fails, and its message names
the input libFuzzer saved (under <build>/artifacts/<target>/) so that
``<build>/fuzz_<target> <that file>`` replays it. The report goes where
mk/summarize_reports.py counts it, into the closing 'N passed, N failed'.
The exit status is 1 if any test case failed.
"""

import argparse
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ElementTree
from pathlib import Path

# Seconds one input may take before libFuzzer calls it a hang: every target
# handles an input in microseconds, so this only catches an endless loop.
INPUT_TIMEOUT_SECONDS = 10
# Lines of a failing run's output kept in the report.
OUTPUT_TAIL_LINES = 60
ARTIFACT = re.compile(r"Test unit written to (\S+)")
EXECUTIONS = re.compile(r"stat::number_of_executed_units:\s*(\d+)")


def run(command, timeout):
    """Runs a command; returns (exit status, combined output, seconds taken)."""
    started = time.monotonic()
    try:
        completed = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                   text=True, errors="replace", timeout=timeout, check=False)
        status, output = completed.returncode, completed.stdout
    except subprocess.TimeoutExpired as expired:
        status = -1
        output = (expired.stdout or "") if isinstance(expired.stdout, str) else ""
        output += f"\nthe fuzzer did not stop within {timeout} s and was killed\n"
    return status, output, time.monotonic() - started


def case(suite, name, status, output, seconds, what):
    """Adds one test case to the suite; returns True if it passed."""
    element = ElementTree.SubElement(suite, "testcase", classname="fuzz", name=name, time=f"{seconds:.3f}")
    executions = EXECUTIONS.findall(output)
    if status == 0:
        runs = f", {executions[-1]} inputs" if executions else ""
        print(f"  PASS  {name} ({seconds:.1f} s{runs})")
        return True
    artifacts = ARTIFACT.findall(output)
    message = f"{what} failed with status {status}"
    if artifacts:
        message += f"; replay with the saved input {artifacts[-1]}"
    tail = "\n".join(output.splitlines()[-OUTPUT_TAIL_LINES:])
    failure = ElementTree.SubElement(element, "failure", message=message)
    failure.text = tail
    print(f"  FAIL  {name}: {message}")
    print(tail)
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--build", required=True, type=Path, help="where the fuzz_<target> binaries are")
    parser.add_argument("--corpus", required=True, type=Path, help="the seed corpus, one directory per target")
    parser.add_argument("--seconds", required=True, type=int, help="fuzzing time per target")
    parser.add_argument("--report", required=True, type=Path, help="the JUnit XML report to write")
    parser.add_argument("--build-failed", action="store_true",
                        help="the targets did not build: report that as a failure and run nothing")
    parser.add_argument("targets", nargs="+")
    arguments = parser.parse_args()

    suite = ElementTree.Element("testsuite", name="fuzz")
    passed = True
    if arguments.build_failed:
        passed = case(suite, "build", 1, "the fuzz targets did not compile; see the compiler output above", 0.0,
                      "building the fuzz targets")
    else:
        for target in arguments.targets:
            binary = arguments.build / f"fuzz_{target}"
            seeds = arguments.corpus / target
            found = arguments.build / "corpus" / target
            artifacts = arguments.build / "artifacts" / target
            found.mkdir(parents=True, exist_ok=True)
            artifacts.mkdir(parents=True, exist_ok=True)
            common = [str(binary), f"-timeout={INPUT_TIMEOUT_SECONDS}", f"-artifact_prefix={artifacts}/",
                      "-print_final_stats=1"]

            status, output, seconds = run(common + ["-runs=0", str(seeds)], timeout=120)
            passed &= case(suite, f"{target}.corpus", status, output, seconds, f"replaying the {target} seeds")

            status, output, seconds = run(common + [f"-max_total_time={arguments.seconds}", str(found), str(seeds)],
                                          timeout=arguments.seconds + 120)
            passed &= case(suite, f"{target}.fuzz", status, output, seconds,
                           f"fuzzing {target} for {arguments.seconds} s")

    cases = suite.findall("testcase")
    suite.set("tests", str(len(cases)))
    suite.set("failures", str(sum(1 for c in cases if c.find("failure") is not None)))
    arguments.report.parent.mkdir(parents=True, exist_ok=True)
    ElementTree.ElementTree(suite).write(arguments.report, encoding="utf-8", xml_declaration=True)
    sys.exit(0 if passed else 1)


if __name__ == "__main__":
    main()
