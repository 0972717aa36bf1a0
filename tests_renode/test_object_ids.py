"""A deleted object's id stays stale for as long as the 12-bit index allows.

Every object table hands out all 4,096 index values before a freed one comes
back, so a kept id never reaches a newer object before 4,096 - N Creates in
its table (N objects alive). The on-target tests cycle semaphores, ports,
timers and tasks 3,000 times, far past the old limits of 496 to 1,024.
"""

import pytest

from dcoslab.target import run_target_test

OBJECT_ID_TARGET_TESTS = ["stalesem", "staleport", "staletimer", "staletask"]


@pytest.mark.parametrize("name", OBJECT_ID_TARGET_TESTS)
def test_deleted_ids_stay_stale(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)
