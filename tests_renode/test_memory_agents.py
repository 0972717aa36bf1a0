"""The buffer pool and segmented heap memory agents on the emulated 486 board (seed 7.7, 7.8).

Each case boots the test image under -icount and runs one on-target test from
tests_renode/target/MemoryAgentsTest.cpp, which prints what it checked; a
failure shows the failed check in the console transcript. The algorithms
themselves are tested on the host (BufferPoolTest, SegmentedHeapTest).
"""

import re

import pytest

from dcoslab.target import run_target_test

MEMORY_TARGET_TESTS = [
    "pools",        # Create/Delete/Allocate/Return/GetStatistics/NameToObject/XferOwnership, holders, id errors
    "heaps",        # the same for heaps, with the header, alignment, minimum, segregated fit and merging
    "memtables",    # full pool and heap tables, AddObjects
    "poolcorrupt",  # double return, overwritten free list, wild pointer: Corrupted until Delete
    "heapcorrupt",  # double return, overrun into a header, overwritten link: Corrupted until Delete
    "memisr",       # Allocate in an interrupt handler gives system-held memory any task may return
    "memrecovery",  # a killed or self-deleting task gives back its buffers, segments, pools and heaps
    "heldlists",    # recovery finds a killed task's memory from its held lists, however it changed hands
    "heldlost",     # a held list through a corrupted pool is lost; recovery walks every pool instead
]


@pytest.mark.parametrize("name", MEMORY_TARGET_TESTS)
def test_memory_agent(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)


def test_pools_and_heaps_commands_list_usage_and_corruption(boot, isa486):
    emulator = boot(isa486, "test", icount=True)
    emulator.expect(r"dcos> ")
    pools = emulator.command("pools")
    assert re.search(r"0 of 8 pool slots used, 64 reserved", pools), pools
    heaps = emulator.command("heaps")
    assert re.search(r"0 of 8 heap slots used, 64 reserved", heaps), heaps
    # The corruption tests list their disabled pool and heap before deleting them.
    emulator.send("test poolcorrupt\r")
    emulator.expect(r"0x[0-9a-f]{8}  bad-pool +32 +8 +\d+ +\d+ +\d+ +\d+  0x[0-9a-f]{8}  CORRUPTED")
    emulator.expect(r"TEST poolcorrupt: PASS")
    emulator.expect(r"dcos> ")
    emulator.send("test heapcorrupt\r")
    emulator.expect(r"0x[0-9a-f]{8}  bad-heap +4096 +\d+ +\d+ +\d+ +\d+ +\d+  0x[0-9a-f]{8}  CORRUPTED")
    emulator.expect(r"TEST heapcorrupt: PASS")
