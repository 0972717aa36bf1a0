#!/usr/bin/python3
"""An emulated Microchip MCP2221A USB bridge for the lab VM, as a uhid device, whose GPIO pins are a board's reset line and recovery strap.

Run inside the lab VM (docs/guide/lab-vm.md) as root, with the module uhid
loaded (and hid-mcp2221 for Linux's own driver to bind it, or hid-generic for
a hidraw node that hidapi opens):

    /usr/bin/python3 mcp2221_bridge.py --tty /dev/ttyS2 [--serial LAB-MCP-0001] [options]

The program creates a HID device through /dev/uhid (UHID_CREATE2) on the USB
bus with the MCP2221A's identity (VID 0x04D8, PID 0x00DD) and a report
descriptor of one 64-byte input and one 64-byte output report without report
IDs, as the chip's HID interface has. It answers the commands of the data
sheet (Microchip DS20005565B, section 3.1) that Linux 6.1's hid-mcp2221 and
dcos-flash --recover send, one 64-byte input report per request:

- 0x10 STATUS/SET PARAMETERS: the I2C cancel and speed fields echoed as the
  chip does, the I2C engine idle, the address-NACK flag (byte 20, bit 6)
  after an I2C transfer (no I2C device is on this bridge's bus), the
  hardware revision 'A6' and firmware revision '12' (bytes 46-49);
- 0x50 SET GPIO OUTPUT VALUES, 0x51 GET GPIO VALUES: four bytes per pin from
  byte 2 (alter value, value, alter direction, direction) and two per pin
  (value, direction); 0xEE (and 0xEF for a direction) for a pin not
  designated as GPIO;
- 0x60 SET SRAM SETTINGS (only the GP settings of bytes 8-11, taken when
  byte 7 has bit 7 set) and 0x61 GET SRAM SETTINGS (the GP settings in bytes
  22-25, the lengths 18 and 4 in bytes 2 and 3);
- I2C writes and reads (0x90, 0x91, 0x93, 0x94) are accepted and end in an
  address NACK; 0x40 I2C GET DATA answers 0x25 (address NACK).
Other commands are not answered (logged), so a host's request times out.

Output reports arrive as the host sent them: hid-mcp2221 sends only the bytes
it uses (1 to 64, no report ID); hidraw (hidapi) writes 65 bytes whose first
is the report ID 0, which is dropped here as the USB HID driver drops it.
Missing bytes are zero.

The pins: every pin powers up as a GPIO input (GP setting 0x08, or
--power-up), so both lines are released at power-up. A pin's level on the
wire is its output value while it is a GPIO output, and high otherwise (the
board's pull-up). --reset-pin and --strap-pin (0 and 1) say which pins are
wired to the board's reset line and recovery strap; each change of such a
pin's level goes out on --tty as one line of the board header's protocol,
"reset=0", "reset=1", "strap=0", "strap=1" (tests_renode/models/isa_gpio_header.c),
and the current levels once at start. What the header answers ("ok ...",
"restart") is read and logged. GET GPIO VALUES reads an input pin as the
wire's level: high for the wired pins, and for the others high unless a
control command says otherwise.

Controls: commands, one per line, written to the FIFO --control (default
/run/mcp2221/control); after each, the status file --status (default
/run/mcp2221/status) is rewritten with key=value lines (commands=<done>,
created, opened, requests, replies, ignored, faults, line_changes, and the
pins' settings and levels):

    short N            the next reply is cut to N bytes (default 8)
    wrong-command      the next reply echoes another command code (code ^ 0x01)
    fail S             the next reply's status byte is S (hex, default 01)
    silent             the next request is not answered
    input PIN LEVEL    an unwired pin, as an input, reads LEVEL (0 or 1)
    unplug | replug    UHID_DESTROY, and UHID_CREATE2 again (a new device:
                       the HID core binds it afresh, e.g. to hid-generic once
                       hid-mcp2221 is removed)
    status             rewrite the status file
    quit               destroy the device and exit (also SIGTERM)

docs/protocols/lab-usb-devices.md, "The emulated MCP2221A", has the design.
"""

import argparse
import os
import select
import signal
import struct
import sys
import termios
import time
import tty as ttymodule

# -- Linux include/uapi/linux/uhid.h ----------------------------------------------------------------
UHID_DESTROY = 1
UHID_START = 2
UHID_STOP = 3
UHID_OPEN = 4
UHID_CLOSE = 5
UHID_OUTPUT = 6
UHID_GET_REPORT = 9
UHID_GET_REPORT_REPLY = 10
UHID_CREATE2 = 11
UHID_INPUT2 = 12
UHID_SET_REPORT = 13
UHID_SET_REPORT_REPLY = 14
UHID_DATA_MAX = 4096
HID_MAX_DESCRIPTOR_SIZE = 4096
# struct uhid_event is packed: the 32-bit type, then a union whose largest member is
# struct uhid_create2_req (name 128, phys 64, uniq 64, rd_size 2, bus 2, vendor 4, product 4,
# version 4, country 4, rd_data 4096).
UHID_EVENT_SIZE = 4 + 128 + 64 + 64 + 2 + 2 + 4 * 4 + HID_MAX_DESCRIPTOR_SIZE
BUS_USB = 0x03  # include/uapi/linux/input.h

# -- the MCP2221A (DS20005565B) ---------------------------------------------------------------------
VENDOR_ID = 0x04D8
PRODUCT_ID = 0x00DD
REPORT_SIZE = 64
PIN_COUNT = 4
# One vendor-defined application collection (usage page 0xFF00, usage 1) with one input and one
# output report of 64 bytes of 0-255, no report ID: the MCP2221A's HID interface (DS20005565B, 3.0).
REPORT_DESCRIPTOR = bytes([
    0x06, 0x00, 0xFF,  # Usage Page (vendor defined 0xFF00)
    0x09, 0x01,        # Usage (1)
    0xA1, 0x01,        # Collection (Application)
    0x19, 0x01,        #   Usage Minimum (1)
    0x29, 0x40,        #   Usage Maximum (64)
    0x15, 0x00,        #   Logical Minimum (0)
    0x26, 0xFF, 0x00,  #   Logical Maximum (255)
    0x75, 0x08,        #   Report Size (8)
    0x95, 0x40,        #   Report Count (64)
    0x81, 0x00,        #   Input (Data, Array, Absolute)
    0x19, 0x01,        #   Usage Minimum (1)
    0x29, 0x40,        #   Usage Maximum (64)
    0x91, 0x00,        #   Output (Data, Array, Absolute)
    0xC0,              # End Collection
])

CMD_STATUS_SET_PARAMETERS = 0x10   # 3.1.1
CMD_I2C_GET_DATA = 0x40            # 3.1.10
CMD_SET_GPIO_OUTPUT_VALUES = 0x50  # 3.1.11
CMD_GET_GPIO_VALUES = 0x51         # 3.1.12
CMD_SET_SRAM_SETTINGS = 0x60       # 3.1.13
CMD_GET_SRAM_SETTINGS = 0x61       # 3.1.14
CMD_I2C_WRITES_AND_READS = (0x90, 0x91, 0x93, 0x94)  # 3.1.5 to 3.1.9
STATUS_COMPLETED = 0x00
STATUS_CANCEL_REQUESTED = 0x10     # 3.1.1: byte 2 of the request, "cancel current I2C transfer"
STATUS_SET_SPEED = 0x20            # 3.1.1: byte 3 of the request, "set I2C speed"
I2C_ADDRESS_NACK = 0x25            # the engine state after an address NACK (Linux's MCP2221_I2C_ADDR_NACK)
STATUS_ADDRESS_NACK_BIT = 0x40     # 3.1.1, reply byte 20, bit 6
HARDWARE_REVISION = b"A6"          # 3.1.1, reply bytes 46-47
FIRMWARE_REVISION = b"12"          # 3.1.1, reply bytes 48-49
NOT_GPIO_VALUE = 0xEE              # 3.1.11, 3.1.12
NOT_GPIO_DIRECTION = 0xEF          # 3.1.12
DIRECTION_OUTPUT, DIRECTION_INPUT = 0x00, 0x01
ALTER_GPIO_CONFIGURATION = 0x80    # 3.1.13, byte 7
GP_OUTPUT_HIGH, GP_INPUT, GP_DESIGNATION = 0x10, 0x08, 0x07  # a GP setting byte (3.1.13, 3.1.14)
CHIP_SETTINGS_LENGTH, GP_SETTINGS_LENGTH = 18, 4  # 3.1.14, reply bytes 2 and 3


# The modules the lab VM loads for the bridge: uhid for the device and hid-generic for its hidraw
# node (hidapi's way in). hid-mcp2221, Linux's own driver, takes the device from hid-generic once
# it is loaded, and gives it no hidraw node.
LAB_VM_LOAD = ["uhid", "hid-generic"]


class Pin:
    """One GP pin: its designation (0 GPIO), direction and output value."""

    def __init__(self, setting):
        self.designation = setting & GP_DESIGNATION
        self.output = not setting & GP_INPUT
        self.value = 1 if setting & GP_OUTPUT_HIGH else 0
        self.input_level = 1  # what an unwired input reads

    @property
    def gpio(self):
        return self.designation == 0

    def setting(self):
        return self.designation | (0 if self.output else GP_INPUT) | (GP_OUTPUT_HIGH if self.value else 0)

    def wire_level(self):
        """The level the board sees: the output's value, else its pull-up."""
        return self.value if self.gpio and self.output else 1


class Bridge:
    def __init__(self, arguments):
        self.arguments = arguments
        self.pins = [Pin(setting) for setting in arguments.power_up]
        self.wired = {arguments.reset_pin: "reset", arguments.strap_pin: "strap"}
        self.levels = {}
        self.counters = {"commands": 0, "created": 0, "opened": 0, "requests": 0, "replies": 0, "ignored": 0,
                         "faults": 0, "line_changes": 0}
        self.fault = None
        self.i2c_nack = False
        self.uhid = os.open("/dev/uhid", os.O_RDWR)
        self.tty = os.open(arguments.tty, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        ttymodule.setraw(self.tty, termios.TCSANOW)
        os.makedirs(os.path.dirname(arguments.control), exist_ok=True)
        if not os.path.exists(arguments.control):
            os.mkfifo(arguments.control)
        # Opened read-write, so that the FIFO never reports end of file between writers.
        self.control = os.open(arguments.control, os.O_RDWR | os.O_NONBLOCK)
        self.control_buffer = b""
        self.tty_buffer = b""
        self.running = True

    # -- uhid ----------------------------------------------------------------------------------------
    def create(self):
        name = b"Microchip Technology Inc. MCP2221 USB-I2C/UART Combo"
        event = struct.pack("<I128s64s64sHHIIII", UHID_CREATE2, name, b"lab-vm/mcp2221_bridge",
                            self.arguments.serial.encode(), len(REPORT_DESCRIPTOR), BUS_USB, VENDOR_ID, PRODUCT_ID,
                            0x0100, 0)
        event += REPORT_DESCRIPTOR.ljust(HID_MAX_DESCRIPTOR_SIZE, b"\0")
        os.write(self.uhid, event)
        self.counters["created"] += 1
        log(f"created {VENDOR_ID:04x}:{PRODUCT_ID:04x} serial {self.arguments.serial}")

    def destroy(self):
        os.write(self.uhid, struct.pack("<I", UHID_DESTROY).ljust(UHID_EVENT_SIZE, b"\0"))
        log("destroyed")

    def send_input(self, data):
        event = struct.pack("<IH", UHID_INPUT2, len(data)) + bytes(data)
        os.write(self.uhid, event.ljust(UHID_EVENT_SIZE, b"\0"))

    def uhid_event(self):
        event = os.read(self.uhid, UHID_EVENT_SIZE + 64)
        kind = struct.unpack_from("<I", event)[0]
        if kind == UHID_OUTPUT:
            data = event[4:4 + UHID_DATA_MAX]
            size = struct.unpack_from("<H", event, 4 + UHID_DATA_MAX)[0]
            self.request(data[:size])
        elif kind == UHID_OPEN:
            self.counters["opened"] += 1
        elif kind == UHID_GET_REPORT:
            # The chip has no feature reports: refuse, as a USB device would stall.
            request_id = struct.unpack_from("<I", event, 4)[0]
            reply = struct.pack("<IIHH", UHID_GET_REPORT_REPLY, request_id, 5, 0)  # EIO
            os.write(self.uhid, reply.ljust(UHID_EVENT_SIZE, b"\0"))
        elif kind == UHID_SET_REPORT:
            request_id = struct.unpack_from("<I", event, 4)[0]
            reply = struct.pack("<IIH", UHID_SET_REPORT_REPLY, request_id, 5)
            os.write(self.uhid, reply.ljust(UHID_EVENT_SIZE, b"\0"))

    # -- the chip --------------------------------------------------------------------------------------
    def request(self, data):
        if len(data) == REPORT_SIZE + 1 and data[0] == 0:
            data = data[1:]  # hidraw's report ID 0
        report = bytes(data[:REPORT_SIZE]).ljust(REPORT_SIZE, b"\0")
        if not report:
            return
        self.counters["requests"] += 1
        reply = self.answer(report)
        if reply is None:
            self.counters["ignored"] += 1
            log(f"no answer to command 0x{report[0]:02x}")
            return
        fault, self.fault = self.fault, None
        if fault is not None:
            self.counters["faults"] += 1
            kind, value = fault
            if kind == "silent":
                log(f"fault: no answer to 0x{report[0]:02x}")
                self.write_status()
                return
            if kind == "short":
                reply = reply[:value]
            elif kind == "wrong-command":
                reply[0] ^= 0x01
            elif kind == "fail":
                reply[1] = value
            log(f"fault: {kind} in the answer to 0x{report[0]:02x}")
        self.send_input(reply)
        self.counters["replies"] += 1
        self.update_lines()
        self.write_status()

    def answer(self, report):
        command = report[0]
        reply = bytearray(REPORT_SIZE)
        reply[0] = command
        reply[1] = STATUS_COMPLETED
        if command == CMD_STATUS_SET_PARAMETERS:
            if report[2] == STATUS_CANCEL_REQUESTED:
                reply[2] = STATUS_CANCEL_REQUESTED
                self.i2c_nack = False
            if report[3] == STATUS_SET_SPEED:
                reply[3] = STATUS_SET_SPEED
                reply[4] = report[4]
            if self.i2c_nack:
                reply[20] = STATUS_ADDRESS_NACK_BIT
            reply[46:48] = HARDWARE_REVISION
            reply[48:50] = FIRMWARE_REVISION
        elif command in CMD_I2C_WRITES_AND_READS:
            self.i2c_nack = True  # no device answers on this bridge's I2C bus
        elif command == CMD_I2C_GET_DATA:
            reply[2] = I2C_ADDRESS_NACK
        elif command == CMD_SET_GPIO_OUTPUT_VALUES:
            for index, pin in enumerate(self.pins):
                at = 2 + 4 * index
                if not pin.gpio:
                    reply[at:at + 4] = bytes([NOT_GPIO_VALUE] * 4)
                    continue
                if report[at + 2] == 1:
                    pin.output = report[at + 3] == DIRECTION_OUTPUT
                if report[at] == 1:
                    pin.value = 1 if report[at + 1] else 0
                reply[at:at + 4] = report[at:at + 4]
        elif command == CMD_GET_GPIO_VALUES:
            for index, pin in enumerate(self.pins):
                at = 2 + 2 * index
                if not pin.gpio:
                    reply[at], reply[at + 1] = NOT_GPIO_VALUE, NOT_GPIO_DIRECTION
                    continue
                if pin.output:
                    level = pin.value
                else:
                    level = 1 if index in self.wired else pin.input_level
                reply[at] = level
                reply[at + 1] = DIRECTION_OUTPUT if pin.output else DIRECTION_INPUT
        elif command == CMD_SET_SRAM_SETTINGS:
            if report[7] & ALTER_GPIO_CONFIGURATION:
                for index, pin in enumerate(self.pins):
                    level = pin.input_level
                    self.pins[index] = Pin(report[8 + index])
                    self.pins[index].input_level = level
        elif command == CMD_GET_SRAM_SETTINGS:
            reply[2] = CHIP_SETTINGS_LENGTH
            reply[3] = GP_SETTINGS_LENGTH
            for index, pin in enumerate(self.pins):
                reply[22 + index] = pin.setting()
        else:
            return None
        return reply

    # -- the board's header ----------------------------------------------------------------------------
    def update_lines(self, force=False):
        for index, name in sorted(self.wired.items(), key=lambda item: item[1], reverse=True):
            level = self.pins[index].wire_level()
            if force or self.levels.get(name) != level:
                self.levels[name] = level
                if not force:
                    self.counters["line_changes"] += 1
                line = f"{name}={level}\n".encode()
                os.write(self.tty, line)  # a few bytes: the port's buffer takes them
                log(f"line {name}={level}")

    def tty_input(self):
        try:
            data = os.read(self.tty, 4096)
        except BlockingIOError:
            return
        self.tty_buffer += data
        while b"\n" in self.tty_buffer:
            line, self.tty_buffer = self.tty_buffer.split(b"\n", 1)
            log(f"header: {line.decode('ascii', 'replace').strip()}")

    # -- controls -----------------------------------------------------------------------------------------
    def control_input(self):
        try:
            data = os.read(self.control, 4096)
        except BlockingIOError:
            return
        self.control_buffer += data
        while b"\n" in self.control_buffer:
            line, self.control_buffer = self.control_buffer.split(b"\n", 1)
            words = line.decode("ascii", "replace").split()
            if words:
                self.command(words)
                self.counters["commands"] += 1
                self.write_status()

    def command(self, words):
        verb, rest = words[0], words[1:]
        if verb == "short":
            self.fault = ("short", int(rest[0]) if rest else 8)
        elif verb == "wrong-command":
            self.fault = ("wrong-command", None)
        elif verb == "fail":
            self.fault = ("fail", int(rest[0], 16) if rest else 0x01)
        elif verb == "silent":
            self.fault = ("silent", None)
        elif verb == "input" and len(rest) == 2:
            self.pins[int(rest[0])].input_level = 1 if rest[1] == "1" else 0
        elif verb == "unplug":
            self.destroy()
        elif verb == "replug":
            self.create()
        elif verb == "quit":
            self.running = False
        elif verb != "status":
            log(f"unknown control command: {' '.join(words)}")

    def write_status(self):
        lines = [f"{key}={value}" for key, value in self.counters.items()]
        for index, pin in enumerate(self.pins):
            lines.append(f"gp{index}=setting:{pin.setting():02x},wire:{pin.wire_level()}")
        for name, level in sorted(self.levels.items()):
            lines.append(f"{name}={level}")
        temporary = self.arguments.status + ".new"
        with open(temporary, "w", encoding="ascii") as handle:
            handle.write("\n".join(lines) + "\n")
        os.replace(temporary, self.arguments.status)

    def run(self):
        self.create()
        self.update_lines(force=True)
        self.write_status()
        poller = select.poll()
        for fd in (self.uhid, self.tty, self.control):
            poller.register(fd, select.POLLIN)
        while self.running:
            for fd, _ in poller.poll(500):
                if fd == self.uhid:
                    self.uhid_event()
                elif fd == self.tty:
                    self.tty_input()
                else:
                    self.control_input()
        self.destroy()
        self.write_status()


def log(text):
    print(f"mcp2221: {time.monotonic():.3f} {text}", flush=True)


def settings(text):
    values = [int(part, 16) for part in text.split(",")]
    if len(values) != PIN_COUNT or any(value > 0xFF for value in values):
        raise argparse.ArgumentTypeError("four GP setting bytes in hex, e.g. 08,08,08,08")
    return values


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tty", required=True, help="the serial port to the board's header (e.g. /dev/ttyS2)")
    parser.add_argument("--serial", default="LAB-MCP-0001", help="the device's serial number (HID uniq)")
    parser.add_argument("--reset-pin", type=int, default=0, choices=range(PIN_COUNT))
    parser.add_argument("--strap-pin", type=int, default=1, choices=range(PIN_COUNT))
    parser.add_argument("--power-up", type=settings, default=[GP_INPUT] * PIN_COUNT,
                        help="the four GP settings at power-up, hex (default 08,08,08,08: GPIO inputs)")
    parser.add_argument("--control", default="/run/mcp2221/control")
    parser.add_argument("--status", default="/run/mcp2221/status")
    arguments = parser.parse_args()
    if arguments.reset_pin == arguments.strap_pin:
        parser.error("the reset and strap lines need a pin each")
    bridge = Bridge(arguments)

    def stop(*_):
        bridge.running = False

    signal.signal(signal.SIGTERM, stop)
    bridge.run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
