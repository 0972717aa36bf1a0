#!/usr/bin/env python3
"""Sums up a DCOS application's configuration error from the compiler's messages.

DCOS_APPLICATION turns a broken configuration rule into a compile-time error
(firmware/dcos/include/dcos/internal/ConfigurationCheck.hpp). GCC reports it
correctly but at length: the object, the rule, the value and the limit sit in
the arguments of a template instantiation, several lines above the
static_assert that says what the rule is. The application build
(mk/application.mk) passes the compiler's messages through this filter when a
compilation fails; it prints them unchanged and then, if they hold a
configuration error, one line for the engineer:

    configuration error: task 'greeter': a task's priority must be 0 (highest)
    to 31 (lowest) (value 40, limit 31)

Usage: explain_configuration_error.py [messages file]   (default: standard input)
Exits 0; it only explains.
"""

import re
import sys

REJECTED = re.compile(
    r"ConfigurationRejected<dcos::app::ObjectKind::(?P<kind>\w+), "
    r"dcos::internal::ObjectName\{\"(?P<name>[^\"]*)\"\}, "
    r"dcos::app::ConfigurationRule::(?P<rule>\w+), (?P<value>\d+), (?P<limit>\d+)>"
)
ASSERTION = re.compile(r"static assertion failed: (?P<text>.+)$", re.MULTILINE)
KIND_NAMES = {
    "Application": "application",
    "Task": "task",
    "Semaphore": "semaphore",
    "MessagePort": "message port",
    "Publisher": "publisher",
    "BufferPool": "buffer pool",
    "Heap": "heap",
}
# Rules whose value and limit mean something (ConfigurationReport.cpp shows the same ones).
RULES_WITH_VALUES = {"NameTooLong", "PriorityOutOfRange", "StackTooSmall", "StacksExceedArena", "TooManyObjects",
                     "InitialCountTooLarge", "TickRateOutOfRange", "AreaTooSmall", "BufferTooSmall"}


def explain(messages):
    """The one-line summary of the first configuration error in messages, or None."""
    rejected = REJECTED.search(messages)
    if rejected is None:
        return None
    assertion = ASSERTION.search(messages, rejected.end())
    rule_text = assertion.group("text") if assertion else rejected.group("rule")
    kind = KIND_NAMES.get(rejected.group("kind"), rejected.group("kind"))
    name = rejected.group("name")
    if rejected.group("rule") == "NameMissing":
        subject = f"{kind} number {int(rejected.group('value')) + 1} in its list"
    else:
        subject = f"{kind} '{name}'"
    line = f"configuration error: {subject}: {rule_text}"
    if rejected.group("rule") in RULES_WITH_VALUES:
        line += f" (value {rejected.group('value')}, limit {rejected.group('limit')})"
    return line


def main():
    if len(sys.argv) > 2:
        sys.exit(__doc__.split("\n\n")[-1])
    if len(sys.argv) == 2:
        with open(sys.argv[1], encoding="utf-8", errors="replace") as handle:
            messages = handle.read()
    else:
        messages = sys.stdin.read()
    sys.stderr.write(messages)
    summary = explain(messages)
    if summary:
        sys.stderr.write(summary + "\n")


if __name__ == "__main__":
    main()
