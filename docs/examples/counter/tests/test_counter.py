"""The counter application on the emulated ISA 486 board.

Every test boots the application with exact emulated time (the
`application` fixture: -icount, at the first prompt) and reads the
statistics the `counter` command prints. Emulated time runs several times
faster than the host's here, so waiting for a number of published values
is how a test waits for emulated time.
"""

import re
import time

PERIOD_NS = 10_000_000
# The default tick: the 8254's divisor for 1000 Hz is 1193, one tick
# 1193 / 1193182 Hz = 999.847 us.
TICK_NS = 999_847
# Time from a tick to the publisher reading the uptime: a handful of
# instructions under -icount (1 ns each); a generous bound.
LATENCY_NS = 100_000

PUBLISHER = re.compile(
    r"publisher: period (?P<period_ns>\d+) ns, published (?P<published>\d+), last value (?P<value>\d+) "
    r"at uptime (?P<uptime_ns>\d+) ns, write errors (?P<write_errors>\d+), faults injected (?P<faults>\d+)"
)
SUBSCRIBER = re.compile(
    r"subscriber: received (?P<received>\d+), last value (?P<value>\d+), data id (?P<data_id>\d+), "
    r"skipped (?P<skipped>\d+), out of order (?P<out_of_order>\d+), missed pages (?P<missed>\d+), "
    r"read errors (?P<read_errors>\d+), stalls (?P<stalls>\d+)"
)


def statistics(application):
    """Runs `counter` and returns (publisher, subscriber) as dicts of ints."""
    output = application.command("counter")
    lines = output.strip().split("\r\n")
    assert len(lines) == 2, f"`counter` printed {output!r}"
    publisher = PUBLISHER.fullmatch(lines[0])
    subscriber = SUBSCRIBER.fullmatch(lines[1])
    assert publisher, f"unexpected publisher line {lines[0]!r}"
    assert subscriber, f"unexpected subscriber line {lines[1]!r}"
    as_ints = lambda match: {key: int(value) for key, value in match.groupdict().items()}
    return as_ints(publisher), as_ints(subscriber)


def wait_for_published(application, count, timeout=60.0):
    """Polls `counter` until the publisher has published at least count values."""
    deadline = time.monotonic() + timeout
    while True:
        publisher, subscriber = statistics(application)
        if publisher["published"] >= count:
            return publisher, subscriber
        assert time.monotonic() < deadline, f"only {publisher['published']} of {count} values published"
        time.sleep(0.05)


def assert_clean(publisher, subscriber):
    assert publisher["write_errors"] == 0
    assert subscriber["read_errors"] == 0
    assert subscriber["stalls"] == 0
    # At one page per 10 ms the subscriber reads every page.
    assert subscriber["missed"] == 0


def test_the_command_prints_both_lines_and_refuses_bad_arguments(application):
    assert "application 'counter' started: 2 tasks, 1 semaphore, 1 publisher" in application.transcript
    publisher, subscriber = statistics(application)
    assert publisher["period_ns"] == PERIOD_NS
    assert application.command("counter bogus").strip() == "usage: counter [skip|repeat]"
    assert application.command("counter skip extra").strip() == "usage: counter [skip|repeat]"
    assert "counter [skip|repeat]" in application.command("help counter")


def test_the_counter_advances_once_per_period_on_an_absolute_schedule(application):
    first, _ = wait_for_published(application, 10)
    last, subscriber = wait_for_published(application, first["published"] + 300)
    assert last["value"] > first["value"]
    # Without faults the counter is the number of pages published.
    assert last["value"] == last["published"]
    periods = last["value"] - first["value"]
    elapsed_ns = last["uptime_ns"] - first["uptime_ns"]
    # Each value is written at the first tick at or after its due time
    # (start + n periods), plus the tick's latency to the task. So the time
    # between two values is a whole number of periods to within one tick.
    # A relative schedule (sleep a period after each write) would instead
    # fall behind by one to two ticks every period: 300 ms or more here.
    assert abs(elapsed_ns - periods * PERIOD_NS) < TICK_NS + LATENCY_NS, (first, last)
    assert_clean(last, subscriber)


def test_no_value_is_skipped_or_out_of_order_over_ten_seconds(application):
    publisher, subscriber = wait_for_published(application, 1000)
    assert subscriber["skipped"] == 0
    assert subscriber["out_of_order"] == 0
    assert_clean(publisher, subscriber)
    # The subscriber is at most one page behind the publisher, and its
    # last page carries counter == data id, as every page has so far.
    assert publisher["published"] - subscriber["received"] in (0, 1)
    assert subscriber["value"] == subscriber["data_id"]
    assert publisher["faults"] == 0


def test_a_skipped_value_is_reported_exactly_once(application):
    before, _ = wait_for_published(application, 20)
    assert "will skip one value" in application.command("counter skip")
    publisher, subscriber = wait_for_published(application, before["published"] + 50)
    assert publisher["faults"] == 1
    assert subscriber["skipped"] == 1
    assert subscriber["out_of_order"] == 0
    # From the skip on, the counter runs one ahead of the data id, and the
    # checker, which compares advances, does not report it again.
    assert subscriber["value"] == subscriber["data_id"] + 1
    assert_clean(publisher, subscriber)


def test_a_repeated_value_is_reported_as_out_of_order_exactly_once(application):
    before, _ = wait_for_published(application, 20)
    assert "publish its last value again" in application.command("counter repeat")
    publisher, subscriber = wait_for_published(application, before["published"] + 50)
    assert publisher["faults"] == 1
    assert subscriber["out_of_order"] == 1
    assert subscriber["skipped"] == 0
    assert subscriber["value"] == subscriber["data_id"] - 1
    assert_clean(publisher, subscriber)
