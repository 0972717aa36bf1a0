"""The dual-Pentium board (seed 9.2, controller nodes 2 and 3) on the emulated pc machine.

Node 2 runs on the bootstrap processor: its tick is its local APIC's
timer, calibrated against the 8254; the ISA lines reach it through the I/O
APIC as the BIOS's MP table routes them. The same on-target API suite the
ISA 486 board runs is run here on the same kernel, under -icount with both
processors present, so every timing it checks is exact.
"""

import dataclasses
import re
import time

import pytest

from dcoslab import gdbstub, remote
from dcoslab.board import EXIT_PASS
from dcoslab.node_console import NodeConsole
from dcoslab.board import load_board
from dcoslab.target import run_target_test

import test_board_486_interrupts as board_486
import test_iobus_driver as iobus
import test_kernel_core as kernel_core
import test_memory_agents as memory_agents
import test_object_ids as object_ids
import test_port_dsm as port_dsm
import test_runtime_486 as runtime_486
import test_semaphores as semaphores
import test_timing_bounds as timing_bounds

# 62.5 MHz: QEMU's APIC timer counts its 1 GHz bus clock, divided by 16.
APIC_TIMER_HZ = 62_500_000


def calibrated_hz(transcript):
    """The APIC timer's rate the board measured against the 8254, and its counts per tick."""
    match = re.search(r"local APIC timer (\d+) Hz \(against the 8254\), (\d+) counts per tick", transcript)
    assert match, transcript
    return int(match.group(1)), int(match.group(2))

# The API suite both boards run: every kernel, memory, communication and
# timing test, the I/O board's driver (its interrupt now through the I/O
# APIC) and the board's own tick and masking tests.
API_SUITE = (kernel_core.KERNEL_TARGET_TESTS + memory_agents.MEMORY_TARGET_TESTS + semaphores.SEMAPHORE_TARGET_TESTS
             + port_dsm.PORT_DSM_TARGET_TESTS + object_ids.OBJECT_ID_TARGET_TESTS
             + timing_bounds.TIMING_TARGET_TESTS + runtime_486.RUNTIME_TARGET_TESTS
             + [name for name in iobus.IOBUS_TARGET_TESTS if name not in iobus.BOOT_OPTIONS]
             + board_486.BOARD_TARGET_TESTS)


@pytest.fixture
def p5smp():
    return load_board("p5smp")


def test_the_board_reports_both_processors_its_mp_table_and_the_calibrated_tick(boot, p5smp):
    emulator = boot(p5smp, icount=True)
    emulator.expect(r"dcos> ")
    transcript = emulator.transcript
    assert re.search(r"MP 1\.4 table at 0x[0-9a-f]+ \(BOCHSCPU 0\.1\): 2 processors, bootstrap APIC 0; "
                     r"I/O APIC \d+ at 0xfec00000 \(24 pins\)", transcript), transcript
    # The calibration's 50 ms window of the 8254 measures the rate to a few counts in 3 million.
    hz, counts = calibrated_hz(transcript)
    assert abs(hz - APIC_TIMER_HZ) <= APIC_TIMER_HZ * 2e-6, transcript
    assert counts == 62_500
    assert "board p5smp (Pentium), node 2," in transcript, transcript
    assert "tick 1000 Hz" in transcript


def test_the_console_answers_through_the_io_apic(boot, p5smp):
    """COM1's interrupt (IRQ 4) reaches node 2 through the I/O APIC: the shell reads a command."""
    emulator = boot(p5smp)
    emulator.expect(r"dcos> ")
    output = emulator.command("version")
    assert "p5smp" in output, output


def test_one_processor_is_reported_and_the_node_runs(boot, p5smp):
    emulator = boot(dataclasses.replace(p5smp, smp=1), icount=True)
    emulator.expect(r"dcos> ")
    assert re.search(r"MP 1\.4 table at 0x[0-9a-f]+ \(BOCHSCPU 0\.1\): 1 processors", emulator.transcript), \
        emulator.transcript
    assert "one processor: node 3 is not started" in emulator.transcript


def boot_both_nodes(boot, p5smp, kind="production", append=""):
    """Boots the board with node 3's console on a socket; returns the emulator and node 3's console."""
    emulator = boot(p5smp, kind, append=append, icount=True, serial_sockets=("node3",))
    emulator.expect(r"node 3 started on the processor with APIC id 1 \(image at 0x1000000, \d+ bytes; console COM4\)")
    emulator.expect(r"dcos> ")
    node3 = NodeConsole(emulator, "node3")
    node3.prompt()
    return emulator, node3


def test_node_3_runs_on_the_second_processor_with_its_own_console(boot, p5smp):
    emulator, node3 = boot_both_nodes(boot, p5smp)
    version = node3.command("version")
    assert "board p5smp" in version and "loaded by node 2 (second processor start)" in version, version
    # Both consoles answer, each through its own line of the I/O APIC: IRQ 4 to node 2, IRQ 7 to node 3.
    assert "loaded by node 2" not in emulator.command("version")
    assert "up 0 d" in node3.command("uptime")


def uptime_rate(output):
    """Ticks per second of an `uptime` answer, and the rate it names."""
    match = re.search(r"up (\d+) d (\d+):(\d+):(\d+)\.(\d+) \((\d+) ticks at (\d+) Hz\)", output)
    assert match, output
    days, hours, minutes, seconds, millis, ticks, rate = (int(group) for group in match.groups())
    elapsed = ((days * 24 + hours) * 60 + minutes) * 60 + seconds + millis / 1000
    return ticks / elapsed, rate


def test_each_node_ticks_at_its_own_rate(boot, p5smp):
    emulator, node3 = boot_both_nodes(boot, p5smp, append="tick_hz=250 node3.tick_hz=100")
    time.sleep(1.0)  # Emulated seconds pass while the test waits: both clocks run on.
    node2_measured, node2_rate = uptime_rate(emulator.command("uptime"))
    node3_measured, node3_rate = uptime_rate(node3.command("uptime"))
    assert (node2_rate, node3_rate) == (250, 100)
    assert abs(node2_measured - 250) < 2 and abs(node3_measured - 100) < 2, (node2_measured, node3_measured)


@pytest.mark.parametrize("name", API_SUITE)
def test_api_suite(boot, p5smp, name):
    run_target_test(boot(p5smp, "test", icount=True), name)


@pytest.mark.parametrize("rate", [None, 19, 100, 2000])
def test_the_tick_follows_the_apic_timer(boot, p5smp, rate):
    append = f"tick_hz={rate}" if rate else ""
    emulator = run_target_test(boot(p5smp, "test", append=append, icount=True), "tick")
    configured = rate or 1000
    hz, counts = calibrated_hz(emulator.transcript)
    assert counts == (hz + configured // 2) // configured
    match = re.search(r"tick rate: (\d+) ticks in 2 s of emulator time; configured (\d+) Hz", emulator.transcript)
    assert match, "the tick test printed no measurement"
    assert int(match.group(2)) == configured
    assert abs(int(match.group(1)) - 2 * APIC_TIMER_HZ / counts) <= 1.5


def test_the_crystal_model_shortens_the_apic_period(boot, p5smp):
    emulator = run_target_test(boot(p5smp, "test", append="tick_hz=100 crystal_ppm=100", icount=True), "tick")
    # 625,000 counts per tick at 100 Hz: 100 ppm is 62.49 counts, so 62 come off (99.2 ppm).
    hz, counts = calibrated_hz(emulator.transcript)
    assert counts == 625_000
    match = re.search(r"crystal model: the tick timer counts (\d+) of 625000, the clock runs ([\d.]+) ppm fast",
                      emulator.transcript)
    assert match, emulator.transcript
    assert 625_000 - int(match.group(1)) == 62
    assert abs(float(match.group(2)) - 100) < 1.0
    ticks = int(re.search(r"tick rate: (\d+) ticks in 2 s", emulator.transcript).group(1))
    assert abs(ticks - 2 * APIC_TIMER_HZ / int(match.group(1))) <= 1.5


def find_mp_table(stub):
    """The floating pointer's and the configuration table's addresses in the BIOS ROM area."""
    rom = stub.read_memory(0xF0000, 0x10000)
    for offset in range(0, len(rom), 16):
        if rom[offset:offset + 4] == b"_MP_" and sum(rom[offset:offset + 16]) & 0xFF == 0:
            return 0xF0000 + offset, int.from_bytes(rom[offset + 4:offset + 8], "little")
    raise AssertionError("no MP floating pointer in the BIOS ROM area")


def boot_at_the_kernel_entry(boot, p5smp, tmp_path):
    """Boots the board paused, runs it to node 2's kernel entry (the BIOS's tables are built by then).

    Returns the emulator, the GDB stub (detach it to let the kernel run) and the MP table's address."""
    socket_path = tmp_path / "gdb.sock"
    emulator = boot(p5smp, icount=True, extra_args=gdbstub.paused_boot_args(socket_path))
    stub = gdbstub.GdbStub(str(socket_path))
    try:
        stub.run_to(gdbstub.elf_entry(p5smp.image()))
        _, table = find_mp_table(stub)
    except BaseException:
        stub.detach()
        raise
    return emulator, stub, table


@pytest.mark.parametrize("damage, reported", [
    ("checksum", "the MP configuration table's checksum is wrong"),
    ("signature", "the MP floating pointer does not point at a PCMP configuration table"),
])
def test_a_corrupt_mp_table_is_reported_and_the_node_runs_on_defaults(boot, p5smp, tmp_path, damage, reported):
    """The BIOS's table damaged before the kernel starts: a clear report, and node 2 runs on the defaults."""
    emulator, stub, table = boot_at_the_kernel_entry(boot, p5smp, tmp_path)
    try:
        if damage == "checksum":
            byte = stub.read_memory(table + 7, 1)[0]
            stub.write_memory(table + 7, bytes([byte ^ 0x5A]))
        else:
            stub.write_memory(table, b"XCMP")
    finally:
        stub.detach()
    emulator.expect(r"dcos> ")
    transcript = emulator.transcript
    match = re.search(r"warning: MP configuration not used: ([^(]+) \(at 0x([0-9a-f]+)\); the default configuration "
                      r"is assumed .* and no second processor is started", transcript)
    assert match, transcript
    assert match.group(1).strip() == reported
    assert int(match.group(2), 16) == table
    # The defaults route the console's line as the table did: the shell answers.
    assert "p5smp" in emulator.command("version")


# The same suite on node 3, whose spare lines are 12 and 13
# (bsp::spareInterruptLine), but for "intlevel", which checks the levels of
# the console's line 4 and its neighbours 5-7: node 2's lines, which node 3
# reports held off for good (they cannot reach it), and the I/O board's
# driver, whose line 5 is node 2's.
NODE3_SUITE = [name for name in kernel_core.KERNEL_TARGET_TESTS + memory_agents.MEMORY_TARGET_TESTS
               + semaphores.SEMAPHORE_TARGET_TESTS + port_dsm.PORT_DSM_TARGET_TESTS
               + timing_bounds.TIMING_TARGET_TESTS + board_486.BOARD_TARGET_TESTS if name != "intlevel"]


@pytest.mark.parametrize("name", NODE3_SUITE)
def test_api_suite_on_node_3(boot, p5smp, name):
    emulator, node3 = boot_both_nodes(boot, p5smp, kind="test")
    node3.send(f"test {name} --exit\r")
    node3.expect(rf"TEST {name}: (PASS|FAIL)", timeout=120)
    emulator.expect_exit(EXIT_PASS, timeout=120)


# The on-target tests of the dual board alone (test_kernel_core.py checks that some emulator test runs each).
P5SMP_TARGET_TESTS = [
    "nodelines",   # each line interrupts only the node that owns it (NodeLinesTest.cpp)
    "remoteheld",  # a remote call with dispatch held is refused (RemoteDispatchHeldTest.cpp)
]


@pytest.mark.parametrize("tested", ["node2", "node3"])
def test_each_line_interrupts_only_the_node_that_owns_it(boot, p5smp, tested):
    """NodeLinesTest.cpp, after both consoles' lines (IRQ 4 for node 2, IRQ 7 for node 3) have interrupted."""
    emulator, node3 = boot_both_nodes(boot, p5smp, kind="test")
    for _ in range(3):
        assert "p5smp" in emulator.command("version") and "p5smp" in node3.command("version")
    console = node3 if tested == "node3" else emulator
    console.send("test nodelines --exit\r")
    console.expect(r"TEST nodelines: (PASS|FAIL)", timeout=120)
    emulator.expect_exit(EXIT_PASS, timeout=120)


def test_a_remote_call_with_dispatch_held_is_refused_on_node_2(boot, p5smp):
    """RemoteDispatchHeldTest.cpp: Deadlock at once, never a blocked caller; then node 3 answers the same call."""
    emulator, _ = boot_both_nodes(boot, p5smp, kind="test")
    emulator.send("test remoteheld --exit\r")
    emulator.expect(r"TEST remoteheld: (PASS|FAIL)", timeout=120)
    emulator.expect_exit(EXIT_PASS, timeout=120)


def test_a_remote_call_with_dispatch_held_is_refused_on_node_3(boot, p5smp):
    emulator, node3 = boot_both_nodes(boot, p5smp, kind="test")
    node3.send("test remoteheld --exit\r")
    node3.expect(r"TEST remoteheld: (PASS|FAIL)", timeout=120)
    emulator.expect_exit(EXIT_PASS, timeout=120)


def test_a_second_processor_that_never_answers_is_reported_and_node_2_runs_on(boot, p5smp, tmp_path):
    """The MP table names a second processor at an APIC id nothing answers: STARTUP goes unanswered."""
    emulator, stub, table = boot_at_the_kernel_entry(boot, p5smp, tmp_path)
    try:
        header = stub.read_memory(table, 44)
        length = int.from_bytes(header[4:6], "little")
        entries = stub.read_memory(table + 44, length - 44)
        offset = 0
        while entries[offset] != 0 or not entries[offset + 3] & 1 or entries[offset + 3] & 2:
            offset += 20 if entries[offset] == 0 else 8  # the enabled processor that is not the bootstrap one
        old_id = entries[offset + 1]
        assert old_id == 1
        # APIC id 5 instead of 1, and the checksum moved by as much the other way.
        stub.write_memory(table + 44 + offset + 1, bytes([5]))
        stub.write_memory(table + 7, bytes([(header[7] - (5 - old_id)) & 0xFF]))
    finally:
        stub.detach()
    emulator.expect(r"dcos> ")
    assert "node 3 is not started on the processor with APIC id 5: the second processor did not answer STARTUP" \
        in emulator.transcript, emulator.transcript
    assert "p5smp" in emulator.command("version")


def test_node_3_uses_a_semaphore_on_node_2_over_shared_memory(boot, p5smp):
    """The remote primitives run between the board's two nodes as over CAN: the same answers as a local call."""
    emulator, node3 = boot_both_nodes(boot, p5smp, kind="test")
    assert "shared-memory network: interface 0, 130.3.0.2/16, physical 0; node 3 at physical 1" \
        in emulator.transcript, emulator.transcript
    interfaces = node3.command("net")
    assert "130.3.0.3/16" in interfaces, interfaces
    far_semaphore, far = remote.semaphore_sequence(node3, emulator)
    assert far_semaphore.startswith("0x0002")
    # Node 3's 200 ms wait was node 2's, and the answer came after it.
    assert 200_000 <= far[4][2] < 1_000_000
    served = remote.net_counters(emulator)
    assert served["served"] == len(remote.SEMAPHORE_SEQUENCE), served
    assert remote.net_counters(node3)["unreachable"] == 0
    # Every message crossed the rings with its interrupt: what one node sent the other received and was
    # interrupted for, and each interrupt's latency was measured from the sender's stamp.
    counts = {}
    for console, node in ((emulator, 2), (node3, 3)):
        line = console.command("shm")
        match = re.search(rf"shm node {node} to node {5 - node}: (.*)", line)
        assert match, line
        counts[node] = {key: int(value) for key, value in re.findall(r"(\w+)=(\d+)", match.group(1))}
    for sender, receiver in ((2, 3), (3, 2)):
        assert counts[sender]["sent"] > 0 and counts[sender]["sent"] == counts[receiver]["received"], counts
        assert 0 < counts[receiver]["interrupts"] <= counts[sender]["sent"], counts
        assert 0 < counts[receiver]["latency_min"] <= counts[receiver]["latency_max"] < 10_000_000, counts
    assert all(counts[node][key] == 0 for node in (2, 3) for key in ("ring_full", "not_signalled", "corrupted"))


def lent(console, line):
    """A `remote` call on console: (status, value)."""
    status, value, _ = remote.call(console, line)
    return status, value


def test_node_3_uses_a_pool_and_a_heap_of_node_2_through_their_shared_memory(boot, p5smp):
    """Pools and heaps by another node's id (seed 7.7, 7.8) between the board's nodes: node 2 lends its buffers,
    node 3 writes into them and node 2 reads what it wrote; only the node that holds one returns it."""
    emulator, node3 = boot_both_nodes(boot, p5smp, kind="test")
    pool = remote.created(emulator, "remote pool", "RPOOL")
    heap = remote.created(emulator, "remote heap", "RHEAP")
    assert pool.startswith("0x0002") and heap.startswith("0x0002")
    # Node 3 takes all eight buffers; the ninth Allocate finds the pool empty, as a local one would.
    buffers = []
    for _ in range(8):
        status, address = lent(node3, f"alloc {pool}")
        assert status == "ok" and address >= 0x100000, (status, address)
        buffers.append(address)
    assert len(set(buffers)) == 8 and all(b % 4 == 0 for b in buffers), buffers
    assert lent(node3, f"alloc {pool}")[0] == "out of memory"
    # The memory is the same on both processors: what node 3 writes, node 2 reads, and the other way.
    assert lent(node3, f"poke 0x{buffers[0]:x} 0x600dcafe") == ("ok", 0x600DCAFE)
    assert lent(emulator, f"peek 0x{buffers[0]:x}") == ("ok", 0x600DCAFE)
    assert lent(emulator, f"poke 0x{buffers[7]:x} 12345") == ("ok", 12345)
    assert lent(node3, f"peek 0x{buffers[7]:x}") == ("ok", 12345)
    # Node 2 counts the eight as allocated until node 3 returns them, and its own tasks cannot return them
    # behind node 3's back (the pool would then see node 3's return as a second one and disable itself).
    assert lent(emulator, f"free {pool} {buffers[1]}")[0] == "not owner"
    pools = emulator.command("pools")
    assert re.search(r"lent\s+64\s+8\s+0\s", pools), pools
    # A buffer not handed to node 3, and one returned twice, are refused without touching the pool.
    assert lent(node3, f"free {pool} {buffers[0] + 4}")[0] == "invalid argument"
    for address in buffers:
        assert lent(node3, f"free {pool} {address}")[0] == "ok"
    assert lent(node3, f"free {pool} {buffers[3]}")[0] == "invalid argument"
    assert re.search(r"lent\s+64\s+8\s+8\s", emulator.command("pools")), emulator.command("pools")
    # A heap's segments the same way, of the sizes asked.
    status, segment = lent(node3, f"halloc {heap} 300")
    assert status == "ok", status
    assert lent(node3, f"poke 0x{segment + 296:x} 7") == ("ok", 7)
    assert lent(emulator, f"peek 0x{segment + 296:x}") == ("ok", 7)
    assert lent(node3, f"halloc {heap} 100000")[0] == "out of memory"
    assert lent(node3, f"hfree {heap} {segment}")[0] == "ok"
    counters = remote.net_counters(emulator)
    assert (counters["memory-lent"], counters["memory-returned"]) == (9, 9), counters
    assert counters["served"] >= 9 + 2 + 2, counters
    # A pool of node 2 asked for from node 2 itself is the local call, unchanged.
    status, mine = lent(emulator, f"alloc {pool}")
    assert status == "ok" and lent(emulator, f"free {pool} {mine}")[0] == "ok"


# QEMU's own Kvaser PCIcan model (hw/net/can/can_kvaser_pci.c), which we did not write, twice on one of
# QEMU's CAN buses: the PCI front end of our SJA1000 driver finds both cards by enumeration, routes their
# interrupt pins through the I/O APIC as the MP table says, and moves frames from one to the other.
# SeaBIOS steers the INTA# of slot 4 to IRQ 11 and that of slot 5 to IRQ 10 (measured), and lists both
# pins in its MP table as PCI interrupts, level triggered.
QEMU_KVASER_CARDS = ["-object", "can-bus,id=qemucan", "-device", "kvaser_pci,canbus=qemucan,addr=0x4",
                     "-device", "kvaser_pci,canbus=qemucan,addr=0x5"]
# QEMU's SJA1000 core builds the single acceptance filter's mask of a standard identifier from AMR1 << 5
# where the chip's layout needs AMR1 >> 5, so with every mask bit set it still compares ID.2-0 with ACR1
# (docs/protocols/labbus.md, "What the chip does"): of standard frames it passes only identifiers whose
# three low bits are 0. Extended frames, which DCOS's protocols use, pass whole.
QEMU_KVASER_FRAMES = ("12345678#DEADBEEF", "120#0102030405060708", "1ABCDEF0#R")


def dumped_frames(dump, channel):
    """The frames a `can dump` printed, in cansend's form: "can0  120  [2]  01 02" is 120#0102."""
    frames = []
    for match in re.finditer(rf"^{channel}  ([0-9A-F]+) +\[(\d)\]  (remote request|[0-9A-F ]*?)\s*$", dump, re.M):
        identifier, _, data = match.groups()
        frames.append(f"{identifier}#R" if data == "remote request" else f"{identifier}#{data.replace(' ', '')}")
    return frames


def test_node_2_drives_qemus_kvaser_pci_cards(boot, p5smp):
    # The lab's own card, in slot 5 on the board, makes room for QEMU's two.
    emulator = boot(p5smp, icount=True, without_devices=["lab-kvaser-pci"], extra_args=QEMU_KVASER_CARDS)
    emulator.expect(r"dcos> ")
    up0 = emulator.command("can up can0 500000")
    up1 = emulator.command("can up can1 500000")
    assert re.search(r"can0 up at 0x[0-9a-f]+ irq 11 \(PCI 00:04\.0, Kvaser PCIcan chip 0\): 500000 bit/s", up0), up0
    assert re.search(r"can1 up at 0x[0-9a-f]+ irq 10 \(PCI 00:05\.0, Kvaser PCIcan chip 0\): 500000 bit/s", up1), up1
    for sender, receiver in (("can0", "can1"), ("can1", "can0")):
        for frame in QEMU_KVASER_FRAMES:
            sent = emulator.command(f"can send {sender} {frame}")
            assert "error" not in sent and "sent" in sent, sent
            dump = emulator.command(f"can dump {receiver} 1 1000")
            assert dumped_frames(dump, receiver) == [frame], dump
    stats = emulator.command("can stats can1")
    assert re.search(r"sent=3 received=3 ", stats) and re.search(r"interrupts=[1-9]", stats), stats
    assert "can0 down" in emulator.command("can down can0")
    assert "can1 down" in emulator.command("can down can1")
