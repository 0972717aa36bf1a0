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

The messages are read as bytes and decoded leniently, so any file (a binary
one, a truncated one, one in another encoding) is explained or passed through,
never a crash.
"""

import argparse
import re
import sys

EXIT_OK = 0
EXIT_USAGE = 2

# The compiler prints the value and the limit as integers of at most 20 digits
# (64 bits), and names and identifiers are short; the bounded repetitions keep
# every match attempt short, so a search over messages of any size takes time
# proportional to their length.
REJECTED = re.compile(
    r"ConfigurationRejected<dcos::app::ObjectKind::(?P<kind>\w{1,64}), "
    r"dcos::internal::ObjectName\{\"(?P<name>[^\"\n]{0,256})\"\}, "
    r"dcos::app::ConfigurationRule::(?P<rule>\w{1,64}), (?P<value>[0-9]{1,20}), (?P<limit>[0-9]{1,20})>"
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
    "ModbusMapEntry": "Modbus map entry",
    "ModbusSlave": "Modbus slave",
    "ModbusPollEntry": "Modbus poll entry",
    "ModbusMaster": "Modbus master",
}
# Rules whose value and limit mean something (ConfigurationReport.cpp shows the same ones).
RULES_WITH_VALUES = {"NameTooLong", "PriorityOutOfRange", "StackTooSmall", "StacksExceedArena", "TooManyObjects",
                     "InitialCountTooLarge", "TickRateOutOfRange", "AreaTooSmall", "BufferTooSmall",
                     "MapAddressPastEnd", "MapTooLarge", "MapOverlap", "SlaveAddressOutOfRange",
                     "BaudOutOfRange", "PollPeriodOutOfRange", "TimeoutOutOfRange", "RetriesOutOfRange"}
# The summary is one line: a name or rule text longer than this is cut.
MAX_PART = 200


def _cut(text):
    text = text.replace("\n", " ").replace("\r", " ")
    return text if len(text) <= MAX_PART else text[:MAX_PART] + "..."


def explain(messages):
    """The one-line summary of the first configuration error in messages, or None. Never raises for a str."""
    rejected = REJECTED.search(messages)
    if rejected is None:
        return None
    assertion = ASSERTION.search(messages, rejected.end())
    rule_text = _cut(assertion.group("text") if assertion else rejected.group("rule"))
    kind = KIND_NAMES.get(rejected.group("kind"), _cut(rejected.group("kind")))
    name = _cut(rejected.group("name"))
    if rejected.group("rule") == "NameMissing":
        subject = f"{kind} number {int(rejected.group('value')) + 1} in its list"
    else:
        subject = f"{kind} '{name}'"
    line = f"configuration error: {subject}: {rule_text}"
    if rejected.group("rule") in RULES_WITH_VALUES:
        line += f" (value {rejected.group('value')}, limit {rejected.group('limit')})"
    return line


def build_parser():
    parser = argparse.ArgumentParser(
        prog="explain_configuration_error.py",
        description="Copies a failed compilation's messages to stderr and, when they hold a DCOS application "
                    "configuration error, adds a one-line summary naming the object, the rule, the value and "
                    "the limit.",
        epilog="exit status: 0 the messages were read (explained or passed through unchanged); 2 bad usage, or "
               "the messages file cannot be read (the reason is printed).",
    )
    parser.add_argument("messages", nargs="?", metavar="MESSAGES",
                        help="file with the compiler's messages (default: standard input)")
    return parser


def main(argv=None):
    parser = build_parser()
    options = parser.parse_args(argv)
    try:
        if options.messages is None:
            data = sys.stdin.buffer.read()
        else:
            with open(options.messages, "rb") as handle:
                data = handle.read()
    except OSError as error:
        print(f"explain_configuration_error.py: cannot read the compiler's messages from {options.messages}: "
              f"{error.strerror or error}", file=sys.stderr)
        return EXIT_USAGE
    messages = data.decode("utf-8", errors="replace")
    sys.stderr.write(messages)
    summary = explain(messages)
    if summary:
        sys.stderr.write(summary + "\n")
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
