"""The semaphore agent on the emulated 486 board (seed 7.11).

Each case boots the test image under -icount, so the scheduling sequences the
on-target tests check are exact and repeatable.
"""

import pytest

from dcoslab.target import run_target_test

SEMAPHORE_TARGET_TESTS = [
    "semaphores",  # binary and counting, poll, time-out, Deadlock, NotOwner, maximum, id errors
    "semdelete",   # Delete and holder death wake every waiter with an error
    "inherit",     # priority inheritance: low/medium/high, a holder of two semaphores, time-out
    "inheritfifo",     # a FIFO queue lends its most urgent waiter's priority, not its oldest's
    "inheritdeadline", # a deadline waiter's urgency reaches a static-priority holder
]


@pytest.mark.parametrize("name", SEMAPHORE_TARGET_TESTS)
def test_semaphore(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)
