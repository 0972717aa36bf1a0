"""Our SJA1000 cards against Linux's own drivers for them, on the lab bus (issue 11).

The module runs once per card, the params of its VM fixture:

- isa: our ISA SJA1000 card (isa-sja1000) at 0x280 with IRQ 5 (10 and 11 are
  the PCI interrupt links on QEMU's pc machine). The kernel's sja1000_isa
  driver, loaded at boot with `port=0x280 irq=5`, makes it can0.
- pci: the lab's Kvaser PCIcan (lab-kvaser-pci) with two chips, chip 0 wired
  to the lab bus can0 and chip 1 to none (a chip alone on its bus), as a
  two-channel PCIcan. The BIOS places its three I/O BARs and routes its
  INTA#; the kernel's kvaser_pci driver, loaded at boot, binds to it by its
  PCI identity (AMCC 0x10E8, Kvaser's 0x8406), counts the chips as it counts
  them on real cards (MOD.RM written to each 32-port slot of BAR1 until one
  does not read it back), enables the card's interrupt at the S5920 bridge
  (INTCSR's add-on interrupt enable) and makes can0 and can1.

The card is in the lab VM (Debian's Linux), on QEMU's pc machine of the
qemu-system-x86_64 built with the lab's models (tests_renode/qemu/build_qemu.sh).
The setup gives can0 500 kbit/s and brings it up. The card's link joins the
lab CAN bus hub as a real-time participant (`hub-realtime=on`,
docs/protocols/labbus.md): the VM runs without -icount and is never held at
boundaries, while a production-image 486 board on the same bus keeps the
hub's lock-step (paced to wall time).

So a third-party driver, written against the data sheet and real chips,
drives our models: probing, bit timing, PeliCAN mode, the acceptance filter,
transmission completing with TI (the driver echoes a sent frame only then),
reception through the FIFO with RI, the error counters it reads for
`berr-counter`, error passive and warning, and bus-off with EI and the
recovery after a restart. Both cards carry the same chips
(sja1000_lab_chip.c); what the pci run adds is the PCI side as a third-party
driver uses it: identity, BARs, the chip count, the S5920's INTCSR and PTCR,
the Xilinx version, and every interrupt (TI, RI, EI, EPI) reaching the kernel
through the card's one level-triggered INTA#, shared with the virtio-9p
device. The host-level checks of the PCI card (the add-on interrupt disabled
keeps INTA# off, the reset) are test_can_kvaser_pci_model.py.

Per card the VM boots once and runs VM_SCRIPT in phases; the two worlds
synchronise through the console and the bus, never by sleeps: the VM prints
`@@READY <phase>@@` once its receivers listen, and where it must act only
after the controller is receiving, a hub node puts a "go" frame (0x7F1-0x7F4)
on the bus, which the VM waits for with candump. A failing test's report
carries the board's console, the VM's console and the bus log.
"""

import re
from dataclasses import dataclass
from typing import Callable

import pytest

from dcoslab.board import load_board
from dcoslab.canlab import CanLab
from dcoslab import vmworld
from dcoslab.labvm import KvaserPciSetup, LabVM, Sja1000Setup
from dcoslab.vmworld import World, attach_reports, candump_form, hold_world

# The module's tests share a module-scoped lab VM per card: xdist (--dist loadgroup in pytest.ini) keeps them
# on one worker, in order: the VM runs one script in phases that the tests follow in order. pytest runs all
# of one card's tests before the other card's (it orders a module-scoped fixture's params so).
pytestmark = pytest.mark.xdist_group("test_can_sja1000_linux")

BITRATE = 500_000
PACE = 1.0  # emulated time runs no faster than wall time while the slow VM works
BOOT_TIMEOUT = 240  # the VM's boot; generous, it bounds a hang
STEP = 120  # any one wait for the other world; bounds a hang, does not measure speed
LAST_FRAME = "124#BEEF"
UNACKED = 16  # one-shot frames nobody acknowledges: TEC 16 x 8 = 128, error passive

VM_SCRIPT = r"""
. /run/labvm/lib.sh
cd /tmp
""" + vmworld.PHASE_SHELL + r"""
# Waits (at most $2 s) until can0's state is $1, as `ip -details link show` prints it (after the
# control modes, e.g. "can <ONE-SHOT> state ERROR-PASSIVE").
wait_state() {
    deadline=$(( $(labvm_uptime) + $2 ))
    until ip -details link show can0 | grep -Eq "can (<[^>]*> )?state $1 "; do
        if [ "$(labvm_uptime)" -ge "$deadline" ]; then
            echo "can0 did not reach state $1 within $2 s" >&2
            ip -details -statistics link show can0 >&2
            return 1
        fi
        sleep 0.05
    done
}
link() {
    echo "@@LINK $1"; ip -details -statistics link show can0; echo "@@END LINK $1@@"
}
# The card's driver as check_probe reads it; `interrupts <phase>` prints what vm_interrupts reads.
__PROBE__
link up
interrupts up
# Every frame can0 sees, for the whole session (the test compares it with the bus log).
candump -L can0 >/tmp/trace.log &
trace=$!

# -- raw frames both ways --
raw_phase 123#0011223344556677 18DAF110#CAFE0042
link after-raw
interrupts after-raw

# -- error passive: nobody acknowledges (the lab drops the others' acknowledge); each one-shot frame is
#    one ACK error, TEC + 8 --
timeout 150 candump -n 1 can0,7F3:7FF >/dev/null &
go=$!
labvm_wait_receiver can0 raw 7f3 30
echo "@@READY passive@@"
wait $go
# candump ends when its interface goes down: the session's trace goes on in a second one.
ip link set can0 down
kill -INT $trace 2>/dev/null
wait $trace
ip link set can0 type can bitrate 500000 one-shot on
ip link set can0 up
candump -L can0 >>/tmp/trace.log &
trace=$!
i=0
while [ $i -lt __UNACKED__ ]; do
    cansend can0 321#$(printf %02X $i)
    i=$((i + 1))
    # The driver counts a one-shot frame that failed at its TX interrupt: one frame at a time.
    deadline=$(( $(labvm_uptime) + 30 ))
    until [ "$(cat /sys/class/net/can0/statistics/tx_errors)" -ge $i ]; do
        [ "$(labvm_uptime)" -lt "$deadline" ] || { echo "frame $i: no TX error counted in 30 s" >&2; break 2; }
        sleep 0.05
    done
done
wait_state ERROR-PASSIVE 60
link passive
timeout 150 candump -n 1 can0,7F4:7FF >/dev/null &
go=$!
labvm_wait_receiver can0 raw 7f4 30
echo "@@READY acknowledged@@"
wait $go
cansend can0 322#AA
wait_state ERROR-WARNING 60
link warning

# -- bus-off forced by the lab, seen by the driver; then a restart --
echo "@@READY busoff@@"
wait_state BUS-OFF 60
link busoff
ip link set can0 type can restart
wait_state ERROR-ACTIVE 60
timeout 150 candump -n 1 can0,7F2:7FF >/dev/null &
go=$!
labvm_wait_receiver can0 raw 7f2 30
echo "@@READY restarted@@"
wait $go
cansend can0 __LAST_FRAME__
link restarted

# -- the session's trace --
end_trace __LAST_FRAME__
""".replace("__LAST_FRAME__", LAST_FRAME).replace("__UNACKED__", str(UNACKED))


def vm_interrupts(world, phase):
    """(IRQ line, interrupts counted on it, the rest of its /proc/interrupts row) as the VM printed them."""
    match = world.vm.expect(rf"@@IRQ {phase} (\d+) +(\d+): ([^@]*)@@", timeout=STEP)
    line, row_line, row = int(match.group(1)), int(match.group(2)), match.group(3).decode().split()
    assert row_line == line, match.group(0)
    counts = [int(word) for word in row if word.isdigit()]  # one column per CPU (the VM has one)
    return line, sum(counts), " ".join(row[len(counts):])


ISA_PROBE = r"""
interrupts() { :; }  # the ISA card's edge-triggered line is not counted
echo "@@DRIVER $(cat /sys/class/net/can0/device/driver/module/parameters/port 2>/dev/null) \
$(readlink /sys/class/net/can0/device/driver)@@"
"""


def check_isa_probe(world):
    driver = world.vm.expect(r"@@DRIVER ([^@]*)@@", timeout=BOOT_TIMEOUT).group(1).decode()
    world.mark("VM booted")
    # The module's port array, and can0 bound to the sja1000_isa platform driver.
    assert driver.split()[0].startswith("640") and driver.endswith("/sja1000_isa"), driver


PCI_PROBE = r"""
# The card's interrupt line and its row in /proc/interrupts (the chips' routines are named after their
# interfaces).
interrupts() {
    irq=$(cat /sys/class/net/can0/device/irq)
    echo "@@IRQ $1 $irq $(grep -E "^ *$irq:" /proc/interrupts | tr -s ' ' | sed 's/^ //')@@"
}
device=/sys/class/net/can0/device
echo "@@DRIVER $(readlink $device/driver) $(cat $device/vendor) $(cat $device/device) $(cat $device/class)@@"
echo "@@INTERFACES $(ls $device/net | tr '\n' ' ')@@"
echo "@@DMESG"; dmesg | grep -E 'kvaser_pci|sja1000'; echo "@@END DMESG@@"
"""


def check_pci_probe(world):
    driver = world.vm.expect(r"@@DRIVER ([^@]*)@@", timeout=BOOT_TIMEOUT).group(1).decode().split()
    world.mark("VM booted")
    # can0 is a function of the PCI device kvaser_pci bound, by the card's identity.
    assert driver[0].endswith("/kvaser_pci") and driver[1:] == ["0x10e8", "0x8406", "0xff0000"], driver
    # Two chips counted, one interface each, under the one PCI device.
    interfaces = world.vm.expect(r"@@INTERFACES ([^@]*)@@", timeout=STEP).group(1).decode().split()
    assert interfaces == ["can0", "can1"], interfaces
    dmesg = vm_section(world, "DMESG")
    assert re.search(r"kvaser_pci \S+: initializing device 10e8:8406", dmesg), dmesg
    # One "reg_base" line per chip, both on the card's one interrupt line; the Xilinx version and the count.
    assert len(re.findall(r"kvaser_pci \S+: reg_base=\S+ conf_addr=\S+ irq=\d+", dmesg)) == 2, dmesg
    assert re.search(r"kvaser_pci \S+: xilinx version=13 number of channels=2", dmesg), dmesg
    assert "probing failed" not in dmesg and "Registering device failed" not in dmesg, dmesg


@dataclass(frozen=True)
class Card:
    """What differs between the cards: the VM's setup, the driver's probe (the shell that shows it and the
    check of it), and whether the card's interrupt line is counted."""
    id: str
    setup: Callable  # (the hub's socket path) -> LabVM's sja1000= setup, with can0 on the bus can0
    probe: str  # shell, run first: prints what check_probe reads and defines `interrupts <phase>`
    check_probe: Callable  # (world): reads and checks what probe printed
    counts_interrupts: bool  # interrupts prints the card's line (@@IRQ <phase> ...@@): the PCI card's INTA#


CARDS = [
    Card("isa", lambda hub: Sja1000Setup(hub, bus0="can0", name="linux", bitrate=BITRATE), ISA_PROBE,
         check_isa_probe, counts_interrupts=False),
    # Chip 1 is on no bus: the driver counts it all the same.
    Card("pci", lambda hub: KvaserPciSetup(hub, buses=("can0", None), name="linux", bitrate=BITRATE), PCI_PROBE,
         check_pci_probe, counts_interrupts=True),
]


@pytest.fixture(scope="module", params=CARDS, ids=[card.id for card in CARDS])
def world(request):
    card = request.param

    def build(world):
        world.card = card
        world.lab = CanLab(world.boot, load_board("isa486"), {"can0": BITRATE}, {"board1": {"bus0": "can0"}},
                           pace=PACE, kind="production")
        world.board = world.lab.board("board1")
        output = world.board.command(f"can up can0 {BITRATE}")
        assert re.search(rf"can0 up at 0x280 irq 10: {BITRATE} bit/s", output), output
        world.mark("board up")
        world.vm = LabVM(VM_SCRIPT.replace("__PROBE__", card.probe.strip()),
                         sja1000=card.setup(world.lab.socket_path), boot_timeout=BOOT_TIMEOUT, timeout=600)
        world.vm.start()

    yield from hold_world(World(), build)


@pytest.fixture(autouse=True)
def _reports(request):
    """Puts the board's and the VM's consoles and the bus log into a failing test's report."""
    attach_reports(request)


def go(world, can_id, phase):
    vmworld.go(world.lab, can_id, phase)


def vm_section(world, name):
    return vmworld.vm_section(world.vm, name, STEP)


def vm_frames(world, name):
    return vmworld.vm_frames(world.vm, name, STEP)


def can_state(link_text):
    """(state, tx errors, rx errors) from `ip -details link show`."""
    match = re.search(r"can (?:<[^>]*> )?state (\S+) \(berr-counter tx (\d+) rx (\d+)\)", link_text)
    assert match, link_text
    return match.group(1), int(match.group(2)), int(match.group(3))


def can_statistics(link_text):
    """The CAN statistics row of `ip -details -statistics link show`: re-started, bus-errors, ..., bus-off."""
    match = re.search(r"re-started\s+bus-errors\s+arbit-lost\s+error-warn\s+error-pass\s+bus-off\s*\n\s*"
                      r"(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)\s+(\d+)", link_text)
    assert match, link_text
    return dict(zip(("re-started", "bus-errors", "arbit-lost", "error-warn", "error-pass", "bus-off"),
                    map(int, match.groups())))


def test_the_kernels_driver_probes_the_card_and_configures_it(world):
    world.card.check_probe(world)
    text = vm_section(world, "LINK up")
    assert "<NOARP,UP,LOWER_UP,ECHO>" in text, text
    assert can_state(text) == ("ERROR-ACTIVE", 0, 0)
    # The driver's bit timing for 500 kbit/s from the card's 8 MHz CAN clock (the ISA card's 16 MHz crystal
    # halved, the PCI card's KVASER_PCI_CAN_CLOCK): 2 us, 87.5 %.
    assert re.search(r"bitrate 500000 sample-point 0\.875", text), text
    assert re.search(r"sja1000: tseg1 1\.\.16 tseg2 1\.\.8 sjw 1\.\.4 brp 1\.\.64 brp[-_]inc 1", text), text
    assert "clock 8000000" in text, text
    if world.card.counts_interrupts:
        # The chip's routine is on the card's line, a level-triggered (fasteoi) input of the I/O APIC.
        line, world.interrupts_up, row = vm_interrupts(world, "up")
        assert re.search(rf"IO-APIC +{line}-fasteoi .*\bcan0\b", row), row
    # At the hub the port of can0's chip left reset mode at the bus's bit time, as a real-time participant (it
    # then joins at the bus-free signal the hub counts; the next test sees it acknowledge); the card's other
    # channel is on no bus.
    log = world.lab.hub.log_text()
    assert "linux joined (realtime)" in log, log
    assert re.search(r"linux\.0 wait from \d+ ns: 2000 ns/bit, sample point 87\.5 %", log), log
    assert "linux.1" not in log, log


def test_frames_pass_both_ways_between_the_controller_and_the_kernels_driver(world):
    world.vm.expect(r"@@READY raw@@", timeout=BOOT_TIMEOUT)
    world.mark("raw: VM ready")
    board = world.board
    output = board.command("can send can0 1ABCDEF0#0102")
    assert "can0  1ABCDEF0   [2]  01 02  sent" in output, output
    board.emulator.send("can dump can0 3 60000\r")
    board.emulator.expect(r"can dump can0 3 60000\r\n")
    go(world, 0x7F1, 1)
    board.emulator.expect(r"can0  7F1        \[1\]  01\r\n", timeout=STEP)
    board.emulator.expect(r"can0  123        \[8\]  00 11 22 33 44 55 66 77\r\n", timeout=STEP)
    board.emulator.expect(r"can0  18DAF110   \[4\]  CA FE 00 42\r\n", timeout=STEP)
    board.emulator.expect(r"dcos> ", timeout=STEP)
    trace = vm_frames(world, "RAW")
    world.mark("raw: done")
    # The driver echoes its own frame to candump only at its TX interrupt: the bus said TXOK.
    assert trace == ["1ABCDEF0#0102", "7F1#01", "123#0011223344556677", "18DAF110#CAFE0042"], trace
    records = world.lab.hub.frames()
    assert [(candump_form(r.frame), r.sender, r.outcome) for r in records] == [
        ("1ABCDEF0#0102", "board1.0", "ok"), ("7F1#01", "hub.lab", "ok"), ("123#0011223344556677", "linux.0", "ok"),
        ("18DAF110#CAFE0042", "linux.0", "ok")], world.lab.hub.log_text()
    # The card received and acknowledged the others' frames; the board acknowledged the card's.
    for record in records:
        others = {"board1.0", "linux.0"} - {record.sender}
        assert others <= set(record.rx) and others <= set(record.ack), record.line()
    text = vm_section(world, "LINK after-raw")
    assert can_state(text) == ("ERROR-ACTIVE", 0, 0), text
    assert re.search(r"TX:\s+bytes\s+packets[^\n]*\n\s+12\s+2\s", text), text
    assert re.search(r"RX:\s+bytes\s+packets[^\n]*\n\s+3\s+2\s", text), text
    if world.card.counts_interrupts:
        # Two frames received (RI) and two sent (TI) came through INTA#: at least four interrupts on the line
        # since can0 came up (the line is shared with virtio-9p, which may add its own).
        before = getattr(world, "interrupts_up", None)
        assert before is not None, "the first test did not read the line's count when can0 came up"
        _, after, row = vm_interrupts(world, "after-raw")
        assert after - before >= 4, (before, after, row)


def test_unacknowledged_frames_make_the_chip_error_passive_for_the_kernel(world):
    world.vm.expect(r"@@READY passive@@", timeout=STEP)
    world.mark("passive: VM ready")
    hub = world.lab.hub
    hub.drop_ack("board1")
    hub.drop_ack("hub.lab")
    go(world, 0x7F3, 3)  # the card alone acknowledges it
    text = vm_section(world, "LINK passive")
    world.mark("passive: seen by the kernel")
    # ACK errors of an error-active transmitter: TEC + 8 each (ISO 11898-1); ES (EI) at 96, EPI at 128.
    assert can_state(text) == ("ERROR-PASSIVE", 8 * UNACKED, 0), text
    statistics = can_statistics(text)
    assert (statistics["error-warn"], statistics["error-pass"], statistics["bus-off"]) == (1, 1, 0), statistics
    assert re.search(rf"TX:\s+bytes\s+packets\s+errors[^\n]*\n\s+\d+\s+\d+\s+{UNACKED}\s", text), text
    failed = [record for record in hub.frames() if record.outcome != "ok"]
    assert [(candump_form(r.frame), r.sender, r.outcome, r.ack) for r in failed] == [
        (f"321#{i:02X}", "linux.0", "ack-error", ()) for i in range(UNACKED)], hub.log_text()
    # Acknowledged again: one frame sent, TEC 127, EPI, and the kernel's state is error warning (TEC >= 96).
    world.vm.expect(r"@@READY acknowledged@@", timeout=STEP)
    hub.drop_ack("board1", False)
    hub.drop_ack("hub.lab", False)
    go(world, 0x7F4, 4)
    text = vm_section(world, "LINK warning")
    world.mark("passive: back to warning")
    assert can_state(text) == ("ERROR-WARNING", 8 * UNACKED - 1, 0), text
    record = hub.frames()[-1]
    assert (candump_form(record.frame), record.outcome, record.ack) == ("322#AA", "ok", ("board1.0", "hub.lab")), \
        hub.log_text()
    # The controller received the go frames and the acknowledged frame; the unacknowledged ones were form
    # errors for it (the sender's error flag), never frames.
    output = world.board.command("can dump can0 3 60000", timeout=STEP)
    assert re.findall(r"can0  (\S+) +\[\d\]  ([0-9A-F ]*?)\r?\n", output) == [
        ("7F3", "03"), ("7F4", "04"), ("322", "AA")], output


def test_a_bus_off_the_lab_forces_is_the_kernels_bus_off_and_a_restart_recovers(world):
    world.vm.expect(r"@@READY busoff@@", timeout=STEP)
    world.mark("busoff: VM ready")
    world.lab.hub.force_bus_off("linux.0")
    text = vm_section(world, "LINK busoff")
    world.mark("busoff: seen by the kernel")
    # TXERR reads 127 in bus-off (the recovery would count down from there), RXERR 0.
    assert can_state(text) == ("BUS-OFF", 127, 0), text
    assert "NO-CARRIER" in text, text
    statistics = can_statistics(text)
    assert statistics["bus-off"] == 1 and statistics["re-started"] == 0, statistics
    # The restart writes TXERR and RXERR 0 in reset mode, which ends bus-off at once (DS 6.4.12), and
    # leaves reset mode: the chip joins at the next bus-free signal, error active, and sends again.
    world.vm.expect(r"@@READY restarted@@", timeout=STEP)
    world.mark("restart: VM ready")
    board = world.board
    board.emulator.send("can dump can0 2 60000\r")
    board.emulator.expect(r"can dump can0 2 60000\r\n")
    go(world, 0x7F2, 2)
    board.emulator.expect(r"can0  7F2        \[1\]  02\r\n", timeout=STEP)
    board.emulator.expect(r"can0  124        \[2\]  BE EF\r\n", timeout=STEP)
    board.emulator.expect(r"dcos> ", timeout=STEP)
    text = vm_section(world, "LINK restarted")
    world.mark("restart: done")
    assert can_state(text) == ("ERROR-ACTIVE", 0, 0), text
    assert can_statistics(text)["re-started"] == 1, text
    log = world.lab.hub.log_text()
    after_fault = log[log.index("fault linux.0 busoff"):]
    assert re.search(r"linux\.0 off from \d+ ns.*\n(.*\n)*.*linux\.0 wait from", after_fault), log


def test_the_vms_whole_trace_is_the_bus_log(world):
    trace = vm_frames(world, "TRACE")
    result = world.vm.wait()
    world.mark("VM finished")
    print(f"timings (s from the module's start): {world.timings}")
    assert result.status == 0, result.output
    # Every frame that went through, and none of the unacknowledged ones (the driver echoes a frame only
    # when it was sent).
    frames = [candump_form(record.frame) for record in world.lab.hub.frames() if record.outcome == "ok"]
    assert trace == frames, f"VM trace:\n{trace}\nbus log:\n{world.lab.hub.log_text()}"
    outcomes = [record.outcome for record in world.lab.hub.frames()]
    assert outcomes.count("ack-error") == UNACKED and set(outcomes) == {"ok", "ack-error"}, world.lab.hub.log_text()
