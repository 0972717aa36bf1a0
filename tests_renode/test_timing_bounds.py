"""Time-outs, deadlines, SleepTill and the clock's range, in exact emulated time.

Every blocking time-out (Acquire, Receive, ReceiveEvent, SleepFor, DSM Read)
expires no earlier than asked and at most one tick late; a missed deadline
is reported within one tick; SleepTill follows a change of the clock; and a
time-out within a tick of 2^64 ns is a long wait, not an immediate expiry.
"""

import pytest

from dcoslab.target import run_target_test

TIMING_TARGET_TESTS = ["timeoutbounds", "sleeptillclock", "hugetimeouts"]


@pytest.mark.parametrize("name", TIMING_TARGET_TESTS)
def test_timing(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)


def test_date_refuses_a_time_the_clock_cannot_carry(boot, isa486):
    emulator = boot(isa486, icount=True)
    emulator.expect(r"dcos> ")
    refused = emulator.command("date 2554-07-21 23:34:33")
    assert "error: 2554-07-21 23:34:33 is not a date and time from 1970-01-01 00:00:00 to 2399-12-31 23:59:59" in refused
    assert "error:" in emulator.command("date 2400-01-01 00:00:00")
    assert "error:" in emulator.command("date 2023-02-29 12:00:00")
    accepted = emulator.command("date 2399-12-31 23:59:59")
    assert "2399-12-31 23:59:59" in accepted
    later = emulator.command("date")
    assert "2399-12-31" in later or "2400-01-01" in later, later


def test_the_time_of_day_comes_from_the_real_time_clock_at_boot(boot, isa486):
    emulator = boot(isa486, icount=True, extra_args=["-rtc", "base=2031-05-06T07:08:09"])
    emulator.expect(r"time of day 2031-05-06 07:08:09 from the real-time clock")
    emulator.expect(r"dcos> ")
    assert "2031-05-06 07:08:" in emulator.command("date")


def test_the_clock_reads_the_hosts_date_without_a_base(boot, isa486):
    emulator = boot(isa486)
    match = emulator.expect(r"time of day (\d{4})-\d\d-\d\d \d\d:\d\d:\d\d from the real-time clock")
    assert int(match.group(1)) >= 2024
