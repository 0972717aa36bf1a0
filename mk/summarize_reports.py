#!/usr/bin/env python3
"""Adds up the JUnit XML reports of every test suite and prints one closing line.

GoogleTest and pytest both write JUnit XML; this prints 'N passed, N failed'
(and ', N skipped' when any were skipped) over all of them, and exits 1 if a
test failed or a suite that should have reported did not.
"""

import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

EXPECTED_SUITES = ("host-unit-tests.xml", "emulator-tests.xml")


def main():
    directory = Path(sys.argv[1])
    passed = failed = skipped = 0
    missing = [name for name in EXPECTED_SUITES if not (directory / name).exists()]
    for report in sorted(directory.glob("*.xml")):
        root = ElementTree.parse(report).getroot()
        for case in root.iter("testcase"):
            outcome = {child.tag for child in case}
            if outcome & {"failure", "error"}:
                failed += 1
            elif "skipped" in outcome:
                skipped += 1
            else:
                passed += 1
    for name in missing:
        print(f"suite report {name} is missing: that suite did not run to completion")
    failed += len(missing)
    line = f"{passed} passed, {failed} failed"
    if skipped:
        line += f", {skipped} skipped"
    print(line)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
