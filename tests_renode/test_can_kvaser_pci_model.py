"""The lab's Kvaser PCIcan (QEMU device lab-kvaser-pci) on the host, without a guest.

QEMU's qtest accelerator runs the pc machine with no processor: the test is
the CPU, and reads and writes I/O ports, PCI configuration (mechanism #1,
ports 0xCF8/0xCFC) and the emulated clock through the qtest protocol on
QEMU's stdin and stdout, and it sees the I/O APIC's inputs rise and fall
(`irq_intercept_in ioapic`). So the card's PCI side is checked exactly and in
a second: its identity and BARs against QEMU's own kvaser_pci, the chips
counted as Linux's kvaser_pci counts them, the S5920's INTCSR and PTCR, the
Xilinx version, INTA# gated by the add-on interrupt enable, and the reset.

The chips' own behaviour on the lab bus is proven elsewhere: on the ISA card
by test_can_bus.py and test_can_driver.py (the same chip core,
sja1000_lab_chip.c), and on this card by Linux's driver in
test_can_sja1000_linux.py (its pci run). Here a chip raises its interrupt by itself: in
self test mode on its lone bus (no hub), a self reception request completes
without acknowledge (TI) and receives the frame (RI).

Every wait has a time-out; a failing test's message carries the qtest
conversation and what QEMU printed on stderr.
"""

import json
import os
import queue
import socket
import subprocess
import tempfile
import threading
import time

import pytest

from dcoslab.built_emulator import built_emulator_path

TIMEOUT = 30.0  # any one answer from QEMU; bounds a hang
BIOS = ("-L", "/usr/share/seabios", "-L", "/usr/share/qemu")
SLOT = 5  # the card's PCI slot: INTA# of slot 5 is the PIIX3's PIRQA (i440FX swizzle (pin + slot - 1) & 3)
PIRQ_IRQ = 11  # where PIRQA is routed (the PIIX3's PIRQRC[A], config 0x60)
PIIX3 = (0, 1, 0)
# Where the test puts the BARs (the BIOS would, on a real boot).
BRIDGE, CHIPS, XILINX = 0xC000, 0xC100, 0xC200

# PCI configuration header offsets and bits (PCI Local Bus 3.0, 6.2).
PCI_COMMAND, PCI_STATUS, PCI_BAR0, PCI_INTERRUPT_LINE = 0x04, 0x06, 0x10, 0x3C
COMMAND_IO = 0x0001
STATUS_INTERRUPT = 0x0008  # the function asserts its INTx# (PCI 2.3)
PIIX3_PIRQA = 0x60

# The card (drivers/can/include/sja1000/KvaserPciCard.hpp, Linux's kvaser_pci.c).
S5920_INTCSR, S5920_PTCR = 0x38, 0x60
ADDON_INTENABLE = 1 << 13
INTERRUPT_ASSERTED = 1 << 23
XILINX_VERINT = 7
CHIP_STRIDE = 0x20

# SJA1000 registers, PeliCAN (DS 6.4).
MOD, CMR, SR, IR, IER, BTR0, BTR1, ACR0, AMR0, TXB, CDR = 0, 1, 2, 3, 4, 6, 7, 0x10, 0x14, 0x10, 0x1F
MOD_RM, MOD_STM = 0x01, 0x04
CMR_SRR = 0x10
IR_RI, IR_TI = 0x01, 0x02
CDR_PELICAN, CDR_CBP = 0x80, 0x40
SR_RBS = 0x01


class QTest:
    """qemu-system-i386 -accel qtest on the pc machine, spoken to over its stdin and stdout."""

    def __init__(self, devices, extra=()):
        self.workdir = tempfile.TemporaryDirectory(prefix="kvaser-qtest-")
        self.qmp_path = os.path.join(self.workdir.name, "qmp.sock")
        self.argv = [built_emulator_path(), "-M", "pc", "-accel", "qtest", "-qtest", "stdio", "-qtest-log", "none",
                     "-display", "none", "-nodefaults", *BIOS, "-qmp", f"unix:{self.qmp_path},server=on,wait=off",
                     *extra]
        for device in devices:
            self.argv += ["-device", device]
        self.stderr = open(os.path.join(self.workdir.name, "stderr"), "w+")
        self.process = subprocess.Popen(self.argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.stderr,
                                        text=True, bufsize=1, start_new_session=True)
        self.lines = queue.Queue()
        self.conversation = []
        self.irq_events = []  # ("raise" | "lower", line), in order
        self._qmp = None
        self.qmp_events = []
        threading.Thread(target=self._reader, daemon=True).start()

    def _reader(self):
        for line in self.process.stdout:
            self.lines.put(line.rstrip("\n"))
        self.lines.put(None)

    def report(self):
        self.stderr.flush()
        self.stderr.seek(0)
        return (f"QEMU: {' '.join(self.argv)}\n----- qtest conversation (last 60) -----\n"
                + "\n".join(self.conversation[-60:]) + f"\n----- QEMU's stderr -----\n{self.stderr.read()}")

    def command(self, text):
        """Sends one qtest command and returns its answer's words after OK."""
        self.conversation.append(f"> {text}")
        self.process.stdin.write(text + "\n")
        self.process.stdin.flush()
        deadline = time.monotonic() + TIMEOUT
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                raise AssertionError(f"no answer to {text!r} in {TIMEOUT} s\n{self.report()}") from None
            if line is None:
                raise AssertionError(f"QEMU ended before answering {text!r}\n{self.report()}")
            self.conversation.append(f"< {line}")
            words = line.split()
            if words[:1] == ["IRQ"]:
                self.irq_events.append((words[1], int(words[2])))
                continue
            if words[:1] != ["OK"]:
                raise AssertionError(f"qtest said {line!r} to {text!r}\n{self.report()}")
            return words[1:]

    # -- ports, configuration, clock ---------------------------------------------------

    def inp(self, port, size=1):
        return int(self.command(f"in{'bwl'[size.bit_length() - 1]} {port:#x}")[0], 16)

    def out(self, port, value, size=1):
        self.command(f"out{'bwl'[size.bit_length() - 1]} {port:#x} {value:#x}")

    def config_read(self, offset, size=4, device=(0, SLOT, 0)):
        bus, slot, function = device
        self.out(0xCF8, 0x80000000 | bus << 16 | slot << 11 | function << 8 | (offset & 0xFC), 4)
        return self.inp(0xCFC + (offset & 3), size)

    def config_write(self, offset, value, size=4, device=(0, SLOT, 0)):
        bus, slot, function = device
        self.out(0xCF8, 0x80000000 | bus << 16 | slot << 11 | function << 8 | (offset & 0xFC), 4)
        self.out(0xCFC + (offset & 3), value, size)

    def step(self, nanoseconds):
        self.command(f"clock_step {nanoseconds}")

    def place_card(self):
        """What the BIOS does: BARs at BRIDGE, CHIPS and XILINX, I/O decode on, PIRQA to PIRQ_IRQ."""
        for bar, base in enumerate((BRIDGE, CHIPS, XILINX)):
            self.config_write(PCI_BAR0 + 4 * bar, base)
        self.config_write(PCI_COMMAND, COMMAND_IO, 2)
        self.config_write(PIIX3_PIRQA, PIRQ_IRQ, 1, device=PIIX3)

    def card_line(self):
        """What the I/O APIC's input of the card's line did, in order: ["raise", "lower", ...]."""
        return [kind for kind, line in self.irq_events if line == PIRQ_IRQ]

    def inta_asserted(self):
        return bool(self.config_read(PCI_STATUS, 2) & STATUS_INTERRUPT)

    # -- the machine's reset, through QMP ---------------------------------------------

    def _qmp_call(self, command):
        if self._qmp is None:
            self._qmp = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            self._qmp.settimeout(TIMEOUT)
            self._qmp.connect(self.qmp_path)
            self._qmp_file = self._qmp.makefile("r")
            self._qmp_file.readline()  # the greeting
            self._qmp_call("qmp_capabilities")
        self._qmp.sendall(json.dumps({"execute": command}).encode() + b"\n")
        return self._qmp_until(lambda message: "return" in message or "error" in message, command)

    def _qmp_until(self, wanted, what):
        """Reads QMP messages until one is wanted; the events read meanwhile are kept in qmp_events."""
        while True:
            try:
                line = self._qmp_file.readline()
            except OSError as error:
                raise AssertionError(f"no QMP answer while waiting for {what}: {error}\n{self.report()}") from None
            if not line:
                raise AssertionError(f"QMP closed while waiting for {what}\n{self.report()}")
            message = json.loads(line)
            if "error" in message:
                raise AssertionError(f"QMP refused {what}: {message}\n{self.report()}")
            if wanted(message):
                return message
            if "event" in message:
                self.qmp_events.append(message["event"])

    def system_reset(self):
        """Resets the machine (PCI RST#) and returns once QEMU reports the reset done."""
        self.qmp_events = []
        self._qmp_call("system_reset")
        # The event may come before the command's answer.
        if "RESET" not in self.qmp_events:
            self._qmp_until(lambda message: message.get("event") == "RESET", "the RESET event")

    def close(self):
        if self._qmp is not None:
            self._qmp.close()
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait(timeout=TIMEOUT)
        self.stderr.close()
        self.workdir.cleanup()


@pytest.fixture
def qtest():
    """qtest(devices..., extra=()) -> a started QTest; closed after the test."""
    started = []

    def start(*devices, extra=()):
        machine = QTest(devices, extra)
        started.append(machine)
        machine.command("irq_intercept_in ioapic")
        return machine

    yield start
    for machine in started:
        machine.close()


def card(channels=None, **properties):
    text = f"lab-kvaser-pci,addr={SLOT}"
    if channels is not None:
        text += f",channels={channels}"
    return text + "".join(f",{name}={value}" for name, value in properties.items())


def header_and_bar_sizes(machine):
    """The configuration header's first 64 bytes, with each BAR replaced by what it reads after all ones."""
    sizes = []
    for bar in range(6):
        machine.config_write(PCI_BAR0 + 4 * bar, 0xFFFFFFFF)
        sizes.append(machine.config_read(PCI_BAR0 + 4 * bar))
        machine.config_write(PCI_BAR0 + 4 * bar, 0)
    words = [machine.config_read(offset) for offset in range(0, 0x40, 4)]
    words[4:10] = sizes
    return words


def chip_count_as_linux_counts(machine):
    """Linux's number_of_sja1000_chip: MOD.RM written to each position of BAR1, until one does not read it back."""
    for chip in range(4):
        machine.out(CHIPS + chip * CHIP_STRIDE + MOD, MOD_RM)
        if not machine.inp(CHIPS + chip * CHIP_STRIDE + MOD) & MOD_RM:
            return chip
    return 4


def self_receive(machine, chip=0):
    """Chip `chip` (PeliCAN, filter open, RI and TI enabled) in self test mode sends one frame to itself."""
    base = CHIPS + chip * CHIP_STRIDE
    machine.out(base + MOD, MOD_RM)
    machine.out(base + CDR, CDR_PELICAN | CDR_CBP)
    for offset in range(4):
        machine.out(base + ACR0 + offset, 0)
        machine.out(base + AMR0 + offset, 0xFF)
    machine.out(base + BTR0, 0x00)  # 500 kbit/s from the 16 MHz oscillator: 2 us, 87.5 %
    machine.out(base + BTR1, 0x1C)
    machine.out(base + IER, IR_RI | IR_TI)
    machine.out(base + MOD, MOD_STM)
    machine.step(100_000)  # the bus-free signal after reset mode (11 bits)
    for offset, byte in enumerate((0x01, 0x24, 0x60, 0x5A)):  # standard frame 0x123, one byte 0x5A
        machine.out(base + TXB + offset, byte)
    machine.out(base + CMR, CMR_SRR)
    machine.step(1_000_000)  # the frame, 2 us a bit, and more
    assert machine.inp(base + SR) & SR_RBS, machine.report()


def test_identity_and_bars_are_those_of_qemus_kvaser_pci(qtest):
    ours = header_and_bar_sizes(qtest(card()))
    stock = header_and_bar_sizes(qtest(f"kvaser_pci,addr={SLOT},canbus=lab", extra=("-object", "can-bus,id=lab")))
    assert ours == stock, "\n".join(f"{offset:#04x}: ours {a:#010x} stock {b:#010x}"
                                    for offset, a, b in zip(range(0, 0x40, 4), ours, stock) if a != b)
    # And what that is (KvaserPciCard.hpp, Linux's KVASER_PCI_VENDOR_ID1/DEVICE_ID1, QEMU's class 0x00ff00).
    assert ours[0] == 0x8406_10E8
    assert ours[2] == 0xFF00_0000  # class 0xFF, subclass 0, interface 0, revision 0
    assert ours[4:10] == [0xFFFFFF81, 0xFFFFFF81, 0xFFFFFFF9, 0, 0, 0]  # I/O 0x80, 0x80, 8; no more BARs
    assert ours[15] >> 8 & 0xFF == 1  # Interrupt Pin: INTA#


@pytest.mark.parametrize("channels", [1, 2, 3, 4])
def test_linux_counts_the_chips_the_card_carries_and_the_rest_read_zero(qtest, channels):
    machine = qtest(card(channels))
    machine.place_card()
    assert chip_count_as_linux_counts(machine) == channels, machine.report()
    for chip in range(channels, 4):
        base = CHIPS + chip * CHIP_STRIDE
        machine.out(base + CDR, CDR_PELICAN)
        assert [machine.inp(base + reg) for reg in range(CHIP_STRIDE)] == [0] * CHIP_STRIDE, machine.report()
    # A chip there reads its hardware reset: reset mode, TBS, TCS, RS and TS (DS 6.4.2, Table 8).
    for chip in range(channels):
        assert machine.inp(CHIPS + chip * CHIP_STRIDE + MOD) == MOD_RM
        assert machine.inp(CHIPS + chip * CHIP_STRIDE + SR) == 0x3C


def test_the_default_card_carries_one_chip(qtest):
    machine = qtest(card())
    machine.place_card()
    assert chip_count_as_linux_counts(machine) == 1


@pytest.mark.parametrize("properties, message", [
    ({"channels": 0}, "channels=0 is not 1 to 4"),
    ({"channels": 5}, "channels=5 is not 1 to 4"),
    ({"channels": 2, "bus2": "can0", "hub": "/nonexistent"}, "bus2=can0 names a chip the card does not carry"),
    ({"bus0": "can0"}, "bus0=can0 needs hub="),
])
def test_a_card_qemu_cannot_build_is_refused_with_the_reason(properties, message):
    argv = [built_emulator_path(), "-M", "pc", "-accel", "qtest", "-display", "none", "-nodefaults", *BIOS,
            "-device", card(**properties)]
    result = subprocess.run(argv, capture_output=True, text=True, timeout=TIMEOUT)
    assert result.returncode != 0 and f"lab-kvaser-pci: {message}" in result.stderr, result


def test_the_bridge_and_the_xilinx_logic(qtest):
    machine = qtest(card())
    machine.place_card()
    # Xilinx register 7: version 13 in the high nibble, as QEMU's model; the others read 0.
    assert machine.inp(XILINX + XILINX_VERINT) >> 4 == 13
    assert [machine.inp(XILINX + reg) for reg in range(7)] == [0] * 7
    # PTCR is kept: Linux writes 0x80808080 ("assert PTADR#").
    assert machine.inp(BRIDGE + S5920_PTCR, 4) == 0
    machine.out(BRIDGE + S5920_PTCR, 0x80808080, 4)
    assert machine.inp(BRIDGE + S5920_PTCR, 4) == 0x80808080
    # INTCSR: 0 after reset; written bits read back, bit 23 is read only.
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == 0
    machine.out(BRIDGE + S5920_INTCSR, ADDON_INTENABLE | INTERRUPT_ASSERTED | 0x1, 4)
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == ADDON_INTENABLE | 0x1
    # A byte access reaches its part of the doubleword.
    assert machine.inp(BRIDGE + S5920_INTCSR + 1) == ADDON_INTENABLE >> 8
    machine.out(BRIDGE + S5920_INTCSR, 0, 4)
    # Every other S5920 register reads 0, written or not.
    for offset in range(0, 0x80, 4):
        if offset not in (S5920_INTCSR, S5920_PTCR):
            machine.out(BRIDGE + offset, 0xFFFFFFFF, 4)
            assert machine.inp(BRIDGE + offset, 4) == 0, f"S5920 register {offset:#x}\n{machine.report()}"
    assert machine.card_line() == [] and not machine.inta_asserted(), machine.report()


def test_inta_follows_the_chips_only_while_the_addon_interrupt_is_enabled(qtest):
    machine = qtest(card(2))
    machine.place_card()
    machine.out(BRIDGE + S5920_PTCR, 0x80808080, 4)
    # Enable off (after reset): the chip interrupts, INTCSR says so, but INTA# stays high (not asserted).
    self_receive(machine, chip=0)
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == INTERRUPT_ASSERTED, machine.report()
    assert not machine.inta_asserted(), machine.report()
    machine.step(1_000_000)
    assert machine.card_line() == [], machine.report()
    # Enabled while the chip interrupts: INTA# at once, and the I/O APIC's input rises.
    machine.out(BRIDGE + S5920_INTCSR, ADDON_INTENABLE, 4)
    assert machine.inta_asserted(), machine.report()
    assert machine.card_line() == ["raise"], machine.report()
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == ADDON_INTENABLE | INTERRUPT_ASSERTED
    # Disabled again (Linux's kvaser_pci_disable_irq): INTA# released with the chip still interrupting.
    machine.out(BRIDGE + S5920_INTCSR, 0, 4)
    assert not machine.inta_asserted() and machine.card_line()[-1] == "lower", machine.report()
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == INTERRUPT_ASSERTED
    machine.out(BRIDGE + S5920_INTCSR, ADDON_INTENABLE, 4)
    assert machine.card_line()[-1] == "raise", machine.report()
    # Reading IR clears TI, RI stays while the FIFO holds the frame; releasing it ends the interrupt.
    assert machine.inp(CHIPS + IR) == IR_RI | IR_TI
    assert machine.inta_asserted(), machine.report()
    machine.out(CHIPS + CMR, 0x04)  # RRB
    assert not machine.inta_asserted(), machine.report()
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == ADDON_INTENABLE
    assert machine.card_line()[-1] == "lower", machine.report()
    # The second chip drives the same INTA#.
    count = len(machine.card_line())
    self_receive(machine, chip=1)
    assert machine.card_line()[count:] == ["raise"], machine.report()
    assert machine.inp(CHIPS + CHIP_STRIDE + IR) == IR_RI | IR_TI


def test_the_cards_reset_resets_every_chip_and_turns_its_interrupt_off(qtest):
    machine = qtest(card(2))
    machine.place_card()
    machine.out(BRIDGE + S5920_PTCR, 0x80808080, 4)
    machine.out(BRIDGE + S5920_INTCSR, ADDON_INTENABLE, 4)
    self_receive(machine, chip=0)
    self_receive(machine, chip=1)
    assert machine.inta_asserted() and machine.card_line()[-1] == "raise", machine.report()
    machine.system_reset()
    # The reset clears the BARs too (QEMU's PCI reset): placed again as a BIOS would.
    machine.place_card()
    assert machine.card_line()[-1] == "lower", machine.report()
    assert not machine.inta_asserted(), machine.report()
    assert machine.inp(BRIDGE + S5920_INTCSR, 4) == 0
    assert machine.inp(BRIDGE + S5920_PTCR, 4) == 0
    for chip in range(2):
        base = CHIPS + chip * CHIP_STRIDE
        # Reset mode, BasicCAN (CDR 0), the FIFO empty, no interrupt.
        assert [machine.inp(base + reg) for reg in (MOD, CDR, SR, IR)] == [MOD_RM, 0, 0x3C, 0], machine.report()
    assert chip_count_as_linux_counts(machine) == 2
