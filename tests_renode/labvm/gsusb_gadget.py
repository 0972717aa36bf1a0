#!/usr/bin/python3
"""An emulated candleLight (gs_usb) USB-CAN adapter for the lab VM, built as a USB gadget.

Run inside the lab VM (docs/guide/lab-vm.md) as root, with the modules
configfs, libcomposite, usb_f_fs and dummy_hcd loaded (and gs_usb, for the
kernel's own driver to bind the adapter):

    /usr/bin/python3 gsusb_gadget.py --serial LAB0001 [--tty /dev/ttyS1] [options]

The program builds a gadget in configfs (VID 1d50, PID 606f, the ids Linux's
gs_usb driver binds as a "GS_USB_1" / candleLight) with one FunctionFS
function, writes the FunctionFS descriptors (full and high speed: one
vendor-specific interface with a bulk IN endpoint 0x81 and a bulk OUT endpoint
0x02, as candleLight firmware has) and binds the gadget to the dummy UDC. The
USB host side of dummy_hcd is the same kernel, so Linux's gs_usb (or a libusb
program, once gs_usb is unbound) sees a real USB device. docs/protocols/lab-usb-devices.md
describes the design; this docstring is the contract of its controls.

What it answers (as candleLight firmware does for a single classic-CAN
channel; everything the Linux 6.1 gs_usb driver asks):

- vendor (or class) requests on endpoint 0, recipient interface or device:
  HOST_FORMAT, BITTIMING, MODE (start and reset), IDENTIFY (host to device);
  BT_CONST, DEVICE_CONFIG, TIMESTAMP, GET_STATE (device to host). Per-channel
  requests need wValue 0 (the channel); a wLength shorter than the request's
  structure, an unknown request (BERR, USER_ID, DATA_BITTIMING, BT_CONST_EXT,
  the termination requests, ...) or a wrong direction is stalled. An invalid
  bit timing is accepted and ignored, as the firmware does (it cannot stall
  after the data stage).
- bulk OUT: host frames (struct gs_host_frame, 20 bytes or more). Shorter
  transfers and frames for another channel are ignored, as the firmware does.
  While the channel is started, each frame goes to the bus as a Lawicel line
  on --tty and comes back on bulk IN as its echo (the same echo_id); in
  listen-only mode nothing is sent and nothing echoed; in loop-back mode the
  frame is also received back as an RX frame, and the bus is not listened to.
- bulk IN: echoes, RX frames from the bus (echo_id 0xFFFFFFFF) and error
  frames (CAN_ERR_FLAG), 20 bytes, or 24 with the 32-bit microsecond
  timestamp when the host started the channel with GS_CAN_MODE_HW_TIMESTAMP,
  padded to 32 bytes with GS_CAN_MODE_PAD_PKTS_TO_MAX_PKT_SIZE.

The CAN side is the --tty serial line (the lab VM's ttyS1, joined to a unix
socket on the host), speaking Lawicel exactly as the kernel's slcan driver
does towards its adapter: frames t/T/r/R both ways, and "C", "S<n>" (the bit
rate the host set, when it is one of Lawicel's) and "O" when the host starts
the channel, "C" when it stops it or the adapter is unplugged. So the host end
of the socket can be a test's SlcanPort or the lab bus hub's SlcanBridge
(tests_renode/dcoslab/slcan_bridge.py), whose CR and BEL answers are ignored.
Frames from the bus are forwarded only while the channel is started (a real
adapter's controller is off otherwise). While the host does not read bulk IN
they queue, up to --queue frames from the bus (echoes and error frames always
queue); a frame beyond that is dropped and counted (rx_dropped), and the next
frame the host gets carries GS_CAN_FLAG_OVERFLOW (Linux counts it as an
rx_over_error and reports an rx-overflow error frame).

Controls: commands, one per line, written to the FIFO --control
(default /run/gsusb/control), e.g. `echo unplug >/run/gsusb/control`:

    unplug                 unbind the gadget from the UDC: the host sees the
                           adapter disconnected (signal SIGUSR1 does the same)
    replug | plug          bind it again: the host enumerates it anew (SIGUSR2)
    error state S [TX RX]  an error-state change, as candleLight reports one:
                           S is active, warning, passive or busoff; TX and RX
                           are the error counters (defaults 0/96/128/256 by S);
                           GET_STATE reports them afterwards
    error bus KIND [force] a bus error (KIND stuff, form, ack, bit0, bit1, crc)
                           with CAN_ERR_PROT|CAN_ERR_BUSERROR|CAN_ERR_CNT; sent
                           only if the host enabled GS_CAN_MODE_BERR_REPORTING,
                           as the firmware does, unless "force" is given
    error overflow         the next frame to the host carries GS_CAN_FLAG_OVERFLOW
    short-in [N]           the next bulk IN transfer is cut to N bytes (default 8)
    bad-frame KIND [V]     send the host a malformed frame: "channel" (channel
                           V, default 0xFF; NB Linux 6.1's gs_usb detaches the
                           netdev for a channel >= 3 and dereferences NULL for
                           an unused channel 1 or 2, so use those only with a
                           libusb host), "dlc" (can_dlc V, default 15), "echo"
                           (an echo_id V the host never used, default 7)
    stall REQUEST          stall the next control request with this bRequest
    pause-in | resume-in   stop/restart writing bulk IN (a host that does not
                           read: frames from the bus queue, then drop)
    queue-limit N          the bound of queued frames from the bus
    status                 rewrite the status file now
    quit                   unplug, clean up and exit (SIGTERM/SIGINT do the same)

After each command the status file (--status, default /run/gsusb/status) is
rewritten with commands=<number of commands done>; a shell waits for its
command with e.g.
    n=$(( $(sed -n 's/^commands=//p' /run/gsusb/status) + 1 ))
    echo unplug >/run/gsusb/control
    until grep -qx "commands=$n" /run/gsusb/status; do sleep 0.1; done
The status file holds key=value lines: ready, bound, configured, started,
bitrate, mode_flags, timestamps, state, txerr, rxerr, to_bus, to_host, echoes,
error_frames, bus_lines, rx_queue, rx_dropped, host_frames, host_ignored,
requests, stalls, paused, commands. The program prints "gsusb: ..." lines on
stdout (the console) for what happens; "gsusb: ready" once first bound.
"""

import argparse
import collections
import ctypes
import errno
import os
import select
import signal
import struct
import subprocess
import sys
import termios
import threading
import time
import tty

# ---------------------------------------------------------------------------
# USB, chapter 9 of the USB 2.0 specification (Linux include/uapi/linux/usb/ch9.h)
USB_DIR_IN = 0x80  # bmRequestType bit 7, and bEndpointAddress bit 7
USB_TYPE_MASK = 0x60  # bmRequestType bits 6..5
USB_TYPE_STANDARD = 0x00
USB_TYPE_CLASS = 0x20
USB_TYPE_VENDOR = 0x40
USB_DT_INTERFACE = 0x04  # descriptor types
USB_DT_ENDPOINT = 0x05
USB_DT_INTERFACE_SIZE = 9
USB_DT_ENDPOINT_SIZE = 7
USB_CLASS_VENDOR_SPEC = 0xFF
USB_ENDPOINT_XFER_BULK = 0x02  # bmAttributes of an endpoint
EP0_BUFFER = 64  # candleLight's ep0_buf (CAN_CMD_PACKET_SIZE): longer OUT data stages are stalled

# The endpoints of candleLight firmware (include/gs_usb.h GSUSB_ENDPOINT_IN/OUT); Linux's gs_usb hard-codes
# them (GS_USB_ENDPOINT_IN 1, GS_USB_ENDPOINT_OUT 2). dummy_hcd's UDC has ep1in-bulk and ep2out-bulk first
# in its endpoint list, so the gadget core's endpoint autoconfiguration gives these very numbers.
GSUSB_ENDPOINT_IN = 0x81
GSUSB_ENDPOINT_OUT = 0x02
# wMaxPacketSize of the bulk endpoints: candleLight (a full-speed STM32 device) uses 32
# (usbd_gs_can.h CAN_DATA_MAX_PACKET_SIZE, classic CAN builds); high speed requires 512 for bulk.
FS_BULK_MAX_PACKET = 32
HS_BULK_MAX_PACKET = 512
PAD_PACKET_SIZE = FS_BULK_MAX_PACKET  # what GS_CAN_MODE_PAD_PKTS_TO_MAX_PKT_SIZE pads IN transfers to

# ---------------------------------------------------------------------------
# FunctionFS (Linux include/uapi/linux/usb/functionfs.h, drivers/usb/gadget/function/f_fs.c)
FUNCTIONFS_DESCRIPTORS_MAGIC_V2 = 3  # struct usb_functionfs_descs_head_v2: magic, length, flags (__le32 each)
FUNCTIONFS_STRINGS_MAGIC = 2  # struct usb_functionfs_strings_head: magic, length, str_count, lang_count
FUNCTIONFS_HAS_FS_DESC = 1  # flags: a __le32 count of full-speed descriptors follows the header
FUNCTIONFS_HAS_HS_DESC = 2  # flags: ... of high-speed descriptors (counts in the order fs, hs, ss)
FUNCTIONFS_ALL_CTRL_RECIP = 64  # flags: setup requests of any recipient reach us, not only interface/endpoint
# struct usb_functionfs_event: struct usb_ctrlrequest (bRequestType, bRequest, wValue, wIndex, wLength,
# little endian) then __u8 type and 3 bytes of padding; 12 bytes, read from ep0.
FFS_EVENT = struct.Struct("<BBHHHB3x")
FUNCTIONFS_BIND, FUNCTIONFS_UNBIND, FUNCTIONFS_ENABLE, FUNCTIONFS_DISABLE = 0, 1, 2, 3  # enum usb_functionfs_event_type
FUNCTIONFS_SETUP, FUNCTIONFS_SUSPEND, FUNCTIONFS_RESUME = 4, 5, 6
FFS_EVENT_NAMES = {0: "bind", 1: "unbind", 2: "enable", 3: "disable", 4: "setup", 5: "suspend", 6: "resume"}
# f_fs.c: ep0 read with a setup pending whose data stage is IN (or a write for an OUT one) halts ep0 and
# fails with EL2HLT; a setup the host gave up on fails with EIDRM.
EP0_STALLED = errno.EL2HLT

# ---------------------------------------------------------------------------
# gs_usb: Linux drivers/net/can/usb/gs_usb.c (6.1) and candleLight firmware (include/gs_usb.h,
# src/usbd_gs_can.c, src/can_common.c, src/can/bxcan.c); all fields little endian.
GS_USB_VENDOR_ID = 0x1D50  # USB_GS_USB_1_VENDOR_ID (OpenMoko, Inc.)
GS_USB_PRODUCT_ID = 0x606F  # USB_GS_USB_1_PRODUCT_ID (Geschwister Schneider USB/CAN)
# enum gs_usb_breq (bRequest of the vendor requests)
GS_USB_BREQ_HOST_FORMAT = 0
GS_USB_BREQ_BITTIMING = 1
GS_USB_BREQ_MODE = 2
GS_USB_BREQ_BERR = 3
GS_USB_BREQ_BT_CONST = 4
GS_USB_BREQ_DEVICE_CONFIG = 5
GS_USB_BREQ_TIMESTAMP = 6
GS_USB_BREQ_IDENTIFY = 7
GS_USB_BREQ_GET_USER_ID = 8
GS_USB_BREQ_SET_USER_ID = 9
GS_USB_BREQ_DATA_BITTIMING = 10
GS_USB_BREQ_BT_CONST_EXT = 11
GS_USB_BREQ_SET_TERMINATION = 12
GS_USB_BREQ_GET_TERMINATION = 13
GS_USB_BREQ_GET_STATE = 14  # Linux 6.2 and later ask it (GS_CAN_FEATURE_GET_STATE); 6.1 does not
# enum gs_can_mode (struct gs_device_mode.mode)
GS_CAN_MODE_RESET = 0
GS_CAN_MODE_START = 1
# struct gs_device_mode.flags
GS_CAN_MODE_LISTEN_ONLY = 1 << 0
GS_CAN_MODE_LOOP_BACK = 1 << 1
GS_CAN_MODE_TRIPLE_SAMPLE = 1 << 2
GS_CAN_MODE_ONE_SHOT = 1 << 3
GS_CAN_MODE_HW_TIMESTAMP = 1 << 4
GS_CAN_MODE_PAD_PKTS_TO_MAX_PKT_SIZE = 1 << 7
GS_CAN_MODE_BERR_REPORTING = 1 << 12
# struct gs_device_bt_const.feature
GS_CAN_FEATURE_LISTEN_ONLY = 1 << 0
GS_CAN_FEATURE_LOOP_BACK = 1 << 1
GS_CAN_FEATURE_TRIPLE_SAMPLE = 1 << 2
GS_CAN_FEATURE_ONE_SHOT = 1 << 3
GS_CAN_FEATURE_HW_TIMESTAMP = 1 << 4
GS_CAN_FEATURE_IDENTIFY = 1 << 5
GS_CAN_FEATURE_USER_ID = 1 << 6
GS_CAN_FEATURE_PAD_PKTS_TO_MAX_PKT_SIZE = 1 << 7
GS_CAN_FEATURE_FD = 1 << 8
GS_CAN_FEATURE_BT_CONST_EXT = 1 << 10
GS_CAN_FEATURE_TERMINATION = 1 << 11
GS_CAN_FEATURE_BERR_REPORTING = 1 << 12
GS_CAN_FEATURE_GET_STATE = 1 << 13
# What candleLight's bxCAN build (src/can/bxcan.c CAN_btconst) reports, without termination and filters.
# Linux 6.1 masks the feature word with GENMASK(11, 0), so it ignores the last two.
CANDLELIGHT_FEATURES = (GS_CAN_FEATURE_LISTEN_ONLY | GS_CAN_FEATURE_LOOP_BACK | GS_CAN_FEATURE_ONE_SHOT
                        | GS_CAN_FEATURE_HW_TIMESTAMP | GS_CAN_FEATURE_IDENTIFY
                        | GS_CAN_FEATURE_PAD_PKTS_TO_MAX_PKT_SIZE | GS_CAN_FEATURE_BERR_REPORTING
                        | GS_CAN_FEATURE_GET_STATE)
CANDLELIGHT_FCLK_CAN = 48_000_000  # the STM32F0's CAN clock (CAN_CLOCK_SPEED)
# struct can_bittiming_const of CAN_btconst: tseg1, tseg2, sjw, brp limits
CANDLELIGHT_BTC = dict(tseg1_min=1, tseg1_max=16, tseg2_min=1, tseg2_max=8, sjw_max=4, brp_min=1, brp_max=1024,
                       brp_inc=1)
CANDLELIGHT_SW_VERSION = 2  # struct gs_device_config (usbd_gs_can.c USBD_GS_CAN_dconf); Linux enables
CANDLELIGHT_HW_VERSION = 1  # IDENTIFY only for sw_version > 1
CHANNELS = 1  # icount = CHANNELS - 1
# enum gs_can_state (struct gs_device_state.state)
GS_CAN_STATE_ERROR_ACTIVE, GS_CAN_STATE_ERROR_WARNING, GS_CAN_STATE_ERROR_PASSIVE = 0, 1, 2
GS_CAN_STATE_BUS_OFF, GS_CAN_STATE_STOPPED = 3, 4
STATE_NAMES = {"active": GS_CAN_STATE_ERROR_ACTIVE, "warning": GS_CAN_STATE_ERROR_WARNING,
               "passive": GS_CAN_STATE_ERROR_PASSIVE, "busoff": GS_CAN_STATE_BUS_OFF}
# Error counter thresholds (can_common.c CAN_ERROR_*_THRESHOLD)
CAN_ERROR_WARNING_THRESHOLD, CAN_ERROR_PASSIVE_THRESHOLD, CAN_BUS_OFF_THRESHOLD = 96, 128, 256
# Structures exchanged on endpoint 0
GS_HOST_CONFIG = struct.Struct("<I")  # byte_order (Linux sends 0x0000beef; candleLight ignores it)
GS_DEVICE_CONFIG = struct.Struct("<BBBBII")  # reserved1..3, icount, sw_version, hw_version
GS_DEVICE_MODE = struct.Struct("<II")  # mode, flags
GS_DEVICE_STATE = struct.Struct("<III")  # state, rxerr, txerr
GS_DEVICE_BITTIMING = struct.Struct("<IIIII")  # prop_seg, phase_seg1, phase_seg2, sjw, brp
GS_IDENTIFY_MODE = struct.Struct("<I")  # mode: 0 off, 1 on
GS_DEVICE_BT_CONST = struct.Struct("<10I")  # feature, fclk_can, tseg1_min/max, tseg2_min/max, sjw_max, brp_min/max/inc
GS_TIMESTAMP = struct.Struct("<I")  # microseconds
# struct gs_host_frame (classic CAN): echo_id, can_id, can_dlc, channel, flags, reserved, data[8];
# then __le32 timestamp_us when timestamps are on (struct classic_can_ts)
GS_HOST_FRAME = struct.Struct("<IIBBBB8s")
GS_TIMESTAMP_SIZE = 4
GS_HOST_FRAME_ECHO_ID_RX = 0xFFFFFFFF  # echo_id of a received (not echoed) frame
GS_CAN_FLAG_OVERFLOW = 1 << 0  # gs_host_frame.flags
GS_CAN_FLAG_FD = 1 << 1
# SocketCAN's can_id flags and error frame classes (Linux include/uapi/linux/can.h, can/error.h)
CAN_EFF_FLAG = 0x80000000
CAN_RTR_FLAG = 0x40000000
CAN_ERR_FLAG = 0x20000000
CAN_SFF_MASK = 0x7FF
CAN_EFF_MASK = 0x1FFFFFFF
CAN_ERR_DLC = 8
CAN_ERR_ACK = 0x20
CAN_ERR_CRTL = 0x04
CAN_ERR_PROT = 0x08
CAN_ERR_BUSOFF = 0x40
CAN_ERR_BUSERROR = 0x80
CAN_ERR_CNT = 0x200  # data[6] and data[7] hold the TX and RX error counters
CAN_ERR_CRTL_RX_WARNING, CAN_ERR_CRTL_TX_WARNING = 0x04, 0x08  # data[1]
CAN_ERR_CRTL_RX_PASSIVE, CAN_ERR_CRTL_TX_PASSIVE = 0x10, 0x20
CAN_ERR_CRTL_ACTIVE = 0x40
CAN_ERR_PROT_FORM, CAN_ERR_PROT_STUFF = 0x02, 0x04  # data[2]
CAN_ERR_PROT_BIT0, CAN_ERR_PROT_BIT1 = 0x08, 0x10
CAN_ERR_PROT_LOC_CRC_SEQ = 0x08  # data[3]
# candleLight's last-error-code mapping (can_common.c can_lec_error_to_frame): (can_id bits, data index, bits)
BUS_ERRORS = {"stuff": (0, 2, CAN_ERR_PROT_STUFF), "form": (0, 2, CAN_ERR_PROT_FORM), "ack": (CAN_ERR_ACK, 2, 0),
              "bit1": (0, 2, CAN_ERR_PROT_BIT1), "bit0": (0, 2, CAN_ERR_PROT_BIT0),
              "crc": (0, 3, CAN_ERR_PROT_LOC_CRC_SEQ)}

# Lawicel "S<n>" codes (as tests_renode/labvm/slcan.py BITRATE_CODES)
BITRATE_CODES = {10000: 0, 20000: 1, 50000: 2, 100000: 3, 125000: 4, 250000: 5, 500000: 6, 800000: 7, 1000000: 8}

# The modules the lab VM loads at boot for the adapter, as LabVM(load=LAB_VM_LOAD): the gadget stack and the
# host side, all modules of Debian's 6.1 kernel. gs_usb is loaded too because the VM runs no udev, so nothing
# would load it when the adapter appears (leave it out, or unbind it, for a libusb host). dummy_hcd runs at
# full speed, as candleLight (an STM32F0) does.
LAB_VM_LOAD = ("configfs", "libcomposite", "usb_f_fs", "dummy_hcd is_high_speed=0", "gs_usb")

# Shell functions of the VM scripts that drive the adapter, after `. /run/labvm/lib.sh` (whose labvm_uptime they
# call), for the test modules that use it (test_gsusb_labvm.py, test_gsusb_libusb_labvm.py,
# test_flash_gsusb_labvm.py). Every wait has a bound; fail prints what the adapter and the kernel say.
VM_SHELL = r"""
S=/run/gsusb/status
C=/run/gsusb/control
fail() {
    echo "@@FAILED $*@@"
    echo "----- gadget status -----"; cat $S
    if [ -e /sys/class/net/can0 ]; then echo "----- can0 -----"; ip -details -statistics link show can0; fi
    echo "----- kernel log -----"; dmesg | tail -n 20
    exit 1
}
# status KEY: the gadget's status value KEY.
status() { sed -n "s/^$1=//p" $S; }
# gsusb COMMAND...: a control command to the gadget, waiting until it is done.
gsusb() {
    _n=$(( $(status commands) + 1 ))
    echo "$*" >$C
    _deadline=$(( $(labvm_uptime) + 30 ))
    until grep -qx "commands=$_n" $S; do
        [ "$(labvm_uptime)" -lt $_deadline ] || fail "the gadget did not do '$*' in 30 s"
        sleep 0.1
    done
}
# wait_for SECONDS WHAT TEST...: polls TEST until it succeeds.
wait_for() {
    _deadline=$(( $(labvm_uptime) + $1 )); _what=$2; shift 2
    until "$@"; do
        [ "$(labvm_uptime)" -lt $_deadline ] || fail "no $_what"
        sleep 0.1
    done
}
at_least() { [ "$(status $1)" -ge "$2" ]; }  # the gadget's counter $1 has reached $2
started() { [ "$(status started)" = 1 ]; }
stopped() { [ "$(status started)" = 0 ]; }
bound() { [ "$(status bound)" = 1 ]; }
has_can0() { [ -e /sys/class/net/can0 ]; }
no_can0() { [ ! -e /sys/class/net/can0 ]; }
"""

CONFIGFS = "/sys/kernel/config"
GADGETS = CONFIGFS + "/usb_gadget"
WAKE_SIGNAL = signal.SIGURG  # sent to the bulk IN writer thread to abort a transfer the host never took
CONTROL_SIGNALS = {signal.SIGUSR1: "unplug", signal.SIGUSR2: "replug", signal.SIGTERM: "quit", signal.SIGINT: "quit"}

_libc = ctypes.CDLL(None, use_errno=True)
_libc.write.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_size_t]
_libc.write.restype = ctypes.c_ssize_t


def log(message):
    sys.stdout.write(f"gsusb: {message}\n")
    sys.stdout.flush()


def raw_write(fd, data):
    """write(2) without Python's retry on EINTR, so a signal can abort a transfer the host does not take."""
    written = _libc.write(fd, data, len(data))
    if written < 0:
        code = ctypes.get_errno()
        raise OSError(code, os.strerror(code))
    return written


def block_control_signals():
    """Worker threads leave the process-directed signals to the main thread."""
    signal.pthread_sigmask(signal.SIG_BLOCK, set(CONTROL_SIGNALS))


def write_file(path, text):
    with open(path, "w") as handle:
        handle.write(text)


# ---------------------------------------------------------------------------
# Descriptors

def interface_descriptor():
    return struct.pack("<BBBBBBBBB", USB_DT_INTERFACE_SIZE, USB_DT_INTERFACE, 0, 0, 2, USB_CLASS_VENDOR_SPEC,
                       USB_CLASS_VENDOR_SPEC, USB_CLASS_VENDOR_SPEC, 0)


def endpoint_descriptor(address, max_packet):
    return struct.pack("<BBBBHB", USB_DT_ENDPOINT_SIZE, USB_DT_ENDPOINT, address, USB_ENDPOINT_XFER_BULK,
                       max_packet, 0)


def functionfs_descriptors():
    """FunctionFS v2 descriptors: the interface, bulk IN (ep1 file) then bulk OUT (ep2 file), FS and HS."""
    speeds = []
    for max_packet in (FS_BULK_MAX_PACKET, HS_BULK_MAX_PACKET):
        speeds.append(interface_descriptor() + endpoint_descriptor(GSUSB_ENDPOINT_IN, max_packet)
                      + endpoint_descriptor(GSUSB_ENDPOINT_OUT, max_packet))
    flags = FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC | FUNCTIONFS_ALL_CTRL_RECIP
    body = struct.pack("<II", 3, 3) + b"".join(speeds)
    return struct.pack("<III", FUNCTIONFS_DESCRIPTORS_MAGIC_V2, 12 + len(body), flags) + body


def functionfs_strings():
    """No strings (candleLight's GS_USB interface has iInterface 0)."""
    return struct.pack("<IIII", FUNCTIONFS_STRINGS_MAGIC, 16, 0, 0)


# ---------------------------------------------------------------------------
# Lawicel

def lawicel_line(can_id, dlc, data):
    """The Lawicel line (with CR) for a frame from the host; dlc 9-15 goes out as 8 (Lawicel has one digit)."""
    remote = bool(can_id & CAN_RTR_FLAG)
    length = min(dlc, 8)
    if can_id & CAN_EFF_FLAG:
        head = f"{'R' if remote else 'T'}{can_id & CAN_EFF_MASK:08X}"
    else:
        head = f"{'r' if remote else 't'}{can_id & CAN_SFF_MASK:03X}"
    payload = "" if remote else data[:length].hex().upper()
    return f"{head}{length}{payload}\r".encode("ascii")


def parse_lawicel(line):
    """(can_id with flags, dlc, 8 data bytes) for a Lawicel frame line, or None if it is not one."""
    if not line or line[0] not in "tTrR":
        return None
    extended = line[0] in "TR"
    remote = line[0] in "rR"
    width = 8 if extended else 3
    try:
        identifier = int(line[1:1 + width], 16)
        dlc = int(line[1 + width], 10)
        payload = line[2 + width:]
        data = b"" if remote else bytes.fromhex(payload)
    except (ValueError, IndexError):
        return None
    if len(line[1:1 + width]) != width or dlc > 8 or (remote and payload) or (not remote and len(data) != dlc):
        return None
    if identifier > (CAN_EFF_MASK if extended else CAN_SFF_MASK):
        return None
    can_id = identifier | (CAN_EFF_FLAG if extended else 0) | (CAN_RTR_FLAG if remote else 0)
    return can_id, dlc, data.ljust(8, b"\0")


# ---------------------------------------------------------------------------

class ToHost:
    """One transfer for bulk IN: a frame (encoded when written, with the host's current settings) or raw bytes."""

    __slots__ = ("echo_id", "can_id", "dlc", "flags", "data", "timestamp", "raw", "from_bus", "channel")

    def __init__(self, echo_id=GS_HOST_FRAME_ECHO_ID_RX, can_id=0, dlc=0, data=b"\0" * 8, timestamp=0, raw=None,
                 from_bus=False, channel=0, flags=0):
        self.echo_id = echo_id
        self.can_id = can_id
        self.dlc = dlc
        self.flags = flags
        self.data = bytes(data).ljust(8, b"\0")[:8]
        self.timestamp = timestamp
        self.raw = raw
        self.from_bus = from_bus
        self.channel = channel


class Gadget:
    def __init__(self, options):
        self.options = options
        self.name = options.name
        self.gadget_dir = os.path.join(GADGETS, self.name)
        self.function_dir = os.path.join(self.gadget_dir, "functions", f"ffs.{self.name}")
        self.config_dir = os.path.join(self.gadget_dir, "configs", "c.1")
        self.ffs_dir = options.ffs_dir
        self.udc = options.udc
        self.lock = threading.RLock()  # the channel's state and counters
        self.in_condition = threading.Condition(self.lock)
        self.queue = collections.deque()  # ToHost items for bulk IN
        self.queue_limit = options.queue
        self.generation = 0  # bumped by a purge: items taken before it are not written
        self.writing_generation = None  # the generation of the item being written, or None
        self.writer_thread = None
        self.tty_lock = threading.Lock()
        self.tty_fd = None
        self.ep0 = self.ep_in = self.ep_out = None
        self.running = True
        self.bound = False
        self.configured = False
        self.started = False
        self.mode_flags = 0
        self.bitrate = None
        self.bittiming = None
        self.host_format = None
        self.identify = False
        self.state = GS_CAN_STATE_STOPPED
        self.txerr = self.rxerr = 0
        self.overflow_pending = False
        self.short_in = None
        self.stall_next = set()
        self.paused = False
        self.counters = collections.Counter()
        self.commands = 0
        self.ready = False
        self.status_dirty = threading.Event()
        self.status_lock = threading.Lock()
        self.epoch = time.monotonic()

    # -- time --------------------------------------------------------------

    def microseconds(self):
        return int((time.monotonic() - self.epoch) * 1_000_000) & 0xFFFFFFFF

    # -- set up and tear down ------------------------------------------------

    def setup(self):
        if not os.path.isdir(GADGETS):
            if not os.path.isdir(CONFIGFS):
                raise SystemExit(f"gsusb: no {CONFIGFS}: is the configfs module loaded?")
            subprocess.run(["mount", "-t", "configfs", "none", CONFIGFS], check=False)
        if not os.path.isdir(GADGETS):
            raise SystemExit(f"gsusb: no {GADGETS}: is the libcomposite module loaded?")
        if self.udc is None:
            udcs = sorted(os.listdir("/sys/class/udc")) if os.path.isdir("/sys/class/udc") else []
            if not udcs:
                raise SystemExit("gsusb: no USB device controller in /sys/class/udc: is dummy_hcd loaded?")
            self.udc = udcs[0]
        if os.path.exists(self.gadget_dir):
            log(f"removing a stale gadget {self.gadget_dir}")
            self.remove_configfs()
        os.makedirs(self.gadget_dir)
        attributes = {"idVendor": f"{GS_USB_VENDOR_ID:#06x}", "idProduct": f"{GS_USB_PRODUCT_ID:#06x}",
                      "bcdDevice": "0x0000", "bcdUSB": "0x0200", "bDeviceClass": "0x00",
                      "bDeviceSubClass": "0x00", "bDeviceProtocol": "0x00"}
        for name, value in attributes.items():
            write_file(os.path.join(self.gadget_dir, name), value)
        strings = os.path.join(self.gadget_dir, "strings", "0x409")
        os.makedirs(strings)
        write_file(os.path.join(strings, "manufacturer"), self.options.manufacturer)
        write_file(os.path.join(strings, "product"), self.options.product)
        write_file(os.path.join(strings, "serialnumber"), self.options.serial)
        os.makedirs(self.config_dir)
        write_file(os.path.join(self.config_dir, "MaxPower"), "150")  # candleLight: bMaxPower 0x4B (150 mA)
        write_file(os.path.join(self.config_dir, "bmAttributes"), "0x80")
        os.makedirs(self.function_dir)
        os.symlink(self.function_dir, os.path.join(self.config_dir, f"ffs.{self.name}"))
        os.makedirs(self.ffs_dir, exist_ok=True)
        subprocess.run(["mount", "-t", "functionfs", self.name, self.ffs_dir], check=True)
        self.ep0 = os.open(os.path.join(self.ffs_dir, "ep0"), os.O_RDWR)
        os.write(self.ep0, functionfs_descriptors())
        os.write(self.ep0, functionfs_strings())
        self.ep_in = os.open(os.path.join(self.ffs_dir, "ep1"), os.O_RDWR)
        self.ep_out = os.open(os.path.join(self.ffs_dir, "ep2"), os.O_RDWR)
        if self.options.tty != "none":
            self.tty_fd = os.open(self.options.tty, os.O_RDWR | os.O_NOCTTY)
            tty.setraw(self.tty_fd, termios.TCSANOW)

    def remove_configfs(self):
        """Best effort: unbinds and removes a gadget tree of this name (configfs wants rmdir, innermost first)."""
        try:
            write_file(os.path.join(self.gadget_dir, "UDC"), "\n")
        except OSError:
            pass
        link = os.path.join(self.config_dir, f"ffs.{self.name}")
        if os.path.islink(link):
            os.unlink(link)
        subprocess.run(["umount", "-l", self.ffs_dir], check=False, stderr=subprocess.DEVNULL)
        for path in (os.path.join(self.config_dir, "strings", "0x409"), self.config_dir, self.function_dir,
                     os.path.join(self.gadget_dir, "strings", "0x409"), self.gadget_dir):
            try:
                os.rmdir(path)
            except OSError:
                pass

    def start_threads(self):
        for target, name in ((self.ep0_loop, "ep0"), (self.out_loop, "bulk-out"), (self.in_loop, "bulk-in"),
                             (self.status_loop, "status")):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            if name == "bulk-in":
                self.writer_thread = thread
        if self.tty_fd is not None:
            threading.Thread(target=self.tty_loop, name="tty", daemon=True).start()

    # -- plugging ------------------------------------------------------------

    def plug(self):
        with self.lock:
            if self.bound:
                return
        write_file(os.path.join(self.gadget_dir, "UDC"), self.udc)
        with self.lock:
            self.bound = True
        log(f"bound to {self.udc}")
        self.mark()

    def unplug(self):
        with self.lock:
            if not self.bound:
                return
        self.stop_channel("unplugged")
        write_file(os.path.join(self.gadget_dir, "UDC"), "\n")
        with self.lock:
            self.bound = False
            self.configured = False
        log("unbound: the adapter is unplugged")
        self.mark()

    # -- the channel -----------------------------------------------------------

    def tty_send(self, line):
        if self.tty_fd is None:
            return
        with self.tty_lock:
            try:
                os.write(self.tty_fd, line)
            except OSError as error:
                log(f"cannot write {self.options.tty}: {error}")

    def start_channel(self, flags):
        with self.lock:
            self.started = True
            self.mode_flags = flags
            self.state = GS_CAN_STATE_ERROR_ACTIVE
            self.txerr = self.rxerr = 0
            bitrate = self.bitrate
        self.tty_send(b"C\r")
        if bitrate in BITRATE_CODES:
            self.tty_send(b"S%d\r" % BITRATE_CODES[bitrate])
        self.tty_send(b"O\r")
        log(f"channel 0 started, flags {flags:#x}, bit rate {bitrate}")
        self.mark()

    def stop_channel(self, why):
        with self.lock:
            was_started = self.started
            self.started = False
            self.state = GS_CAN_STATE_STOPPED
        self.purge()
        if was_started:
            self.tty_send(b"C\r")
            log(f"channel 0 stopped ({why})")
        self.mark()

    def purge(self):
        """Drops what waits for bulk IN, and aborts a transfer the host has not taken (candleLight's can_disable
        purges its to-host list the same way)."""
        with self.lock:
            self.queue.clear()
            self.generation += 1
            generation = self.generation
        deadline = time.monotonic() + 2.0
        while time.monotonic() < deadline:
            with self.lock:
                busy = self.writing_generation is not None and self.writing_generation < generation
            if not busy or self.writer_thread is None:
                return
            signal.pthread_kill(self.writer_thread.ident, WAKE_SIGNAL)
            time.sleep(0.02)
        log("warning: the bulk IN writer did not let go of its transfer")

    def to_host(self, item):
        """Queues an item for bulk IN; frames from the bus beyond the bound are dropped and counted."""
        with self.lock:
            if item.from_bus:
                waiting = sum(1 for queued in self.queue if queued.from_bus)
                if waiting >= self.queue_limit:
                    self.counters["rx_dropped"] += 1
                    self.overflow_pending = True
                    self.status_dirty.set()
                    return
            self.queue.append(item)
            self.in_condition.notify_all()
            self.status_dirty.set()

    def encode(self, item):
        """The bytes of one bulk IN transfer, with the host's timestamp and padding settings; lock held."""
        if item.raw is not None:
            data = item.raw
        else:
            flags = item.flags
            if self.overflow_pending:
                flags |= GS_CAN_FLAG_OVERFLOW
                self.overflow_pending = False
            data = GS_HOST_FRAME.pack(item.echo_id, item.can_id, item.dlc, item.channel, flags, 0, item.data)
            if self.mode_flags & GS_CAN_MODE_HW_TIMESTAMP:
                data += GS_TIMESTAMP.pack(item.timestamp)
            if self.mode_flags & GS_CAN_MODE_PAD_PKTS_TO_MAX_PKT_SIZE:
                data = data.ljust(PAD_PACKET_SIZE, b"\0")
        if self.short_in is not None:
            data = data[:self.short_in]
            self.short_in = None
            self.counters["short_in"] += 1
        return data

    # -- threads ---------------------------------------------------------------

    def in_loop(self):
        block_control_signals()
        while self.running:
            with self.lock:
                while self.running and (self.paused or not self.queue):
                    self.in_condition.wait(1.0)
                if not self.running:
                    return
                item = self.queue.popleft()
                generation = self.generation
                self.writing_generation = generation
                data = self.encode(item)
            delivered = False
            try:
                while True:
                    try:
                        raw_write(self.ep_in, data)
                        delivered = True
                        break
                    except InterruptedError:
                        with self.lock:
                            if self.generation != generation or not self.running:
                                self.counters["in_aborted"] += 1
                                break
                    except OSError as error:
                        # ESHUTDOWN and friends: the endpoint went away (unplug, USB reset): the frame is lost.
                        with self.lock:
                            self.counters["in_lost"] += 1
                        if error.errno not in (errno.ESHUTDOWN, errno.ENODEV, errno.ECONNRESET, errno.EPIPE):
                            log(f"bulk IN write failed: {error}")
                            time.sleep(0.1)
                        break
                with self.lock:
                    if not delivered:
                        pass
                    elif item.raw is not None:
                        self.counters["raw_to_host"] += 1
                    elif item.echo_id != GS_HOST_FRAME_ECHO_ID_RX:
                        self.counters["echoes"] += 1
                    elif item.can_id & CAN_ERR_FLAG:
                        self.counters["error_frames"] += 1
                    else:
                        self.counters["to_host"] += 1
                    self.status_dirty.set()
            finally:
                with self.lock:
                    self.writing_generation = None

    def out_loop(self):
        block_control_signals()
        while self.running:
            try:
                data = os.read(self.ep_out, HS_BULK_MAX_PACKET)
            except OSError as error:
                if error.errno not in (errno.ESHUTDOWN, errno.ENODEV, errno.ECONNRESET, errno.EINTR):
                    log(f"bulk OUT read failed: {error}")
                time.sleep(0.05)
                continue
            self.host_frame(data)

    def host_frame(self, data):
        with self.lock:
            self.counters["host_frames"] += 1
            self.status_dirty.set()
            if len(data) < GS_HOST_FRAME.size:
                self.counters["host_ignored"] += 1  # candleLight: "Invalid frame length, just ignore it"
                return
            echo_id, can_id, dlc, channel, _flags, _reserved, payload = GS_HOST_FRAME.unpack_from(data)
            if channel >= CHANNELS or not self.started:
                self.counters["host_ignored"] += 1
                return
            flags = self.mode_flags
            listen_only = bool(flags & GS_CAN_MODE_LISTEN_ONLY)
            loop_back = bool(flags & GS_CAN_MODE_LOOP_BACK)
        if listen_only and not loop_back:
            with self.lock:
                self.counters["host_ignored"] += 1  # a silent controller never transmits, so never echoes
            return
        if not listen_only:
            self.tty_send(lawicel_line(can_id, dlc, payload))
            with self.lock:
                self.counters["to_bus"] += 1
        stamp = self.microseconds()
        self.to_host(ToHost(echo_id=echo_id, can_id=can_id, dlc=dlc, data=payload, timestamp=stamp))
        if loop_back:
            self.to_host(ToHost(can_id=can_id, dlc=dlc, data=payload, timestamp=stamp))

    def tty_loop(self):
        block_control_signals()
        pending = b""
        while self.running:
            try:
                chunk = os.read(self.tty_fd, 4096)
            except OSError as error:
                log(f"cannot read {self.options.tty}: {error}")
                return
            if not chunk:
                time.sleep(0.05)
                continue
            pending += chunk
            while True:
                ends = [index for index in (pending.find(b"\r"), pending.find(b"\n"), pending.find(b"\a"))
                        if index >= 0]
                if not ends:
                    if len(pending) > 256:
                        pending = b""
                        with self.lock:
                            self.counters["malformed_lines"] += 1
                    break
                end = min(ends)
                line = pending[:end].decode("ascii", "replace").strip()
                pending = pending[end + 1:]
                if line:
                    self.bus_line(line)

    def bus_line(self, line):
        frame = parse_lawicel(line)
        with self.lock:
            self.status_dirty.set()
            if frame is None:
                self.counters["malformed_lines"] += 1
                return
            self.counters["bus_lines"] += 1
            if not self.started or self.mode_flags & GS_CAN_MODE_LOOP_BACK:
                self.counters["bus_ignored"] += 1
                return
        can_id, dlc, data = frame
        self.to_host(ToHost(can_id=can_id, dlc=dlc, data=data, timestamp=self.microseconds(), from_bus=True))

    def ep0_loop(self):
        block_control_signals()
        while self.running:
            try:
                event = os.read(self.ep0, FFS_EVENT.size)
            except OSError as error:
                if error.errno in (errno.EINTR, errno.EIDRM):
                    continue
                log(f"ep0 read failed: {error}")
                time.sleep(0.1)
                continue
            if len(event) < FFS_EVENT.size:
                continue
            request_type, request, value, index, length, kind = FFS_EVENT.unpack(event)
            if kind == FUNCTIONFS_SETUP:
                self.setup_request(request_type, request, value, index, length)
                continue
            log(f"event {FFS_EVENT_NAMES.get(kind, kind)}")
            with self.lock:
                if kind == FUNCTIONFS_ENABLE:
                    self.configured = True
                elif kind in (FUNCTIONFS_DISABLE, FUNCTIONFS_UNBIND):
                    self.configured = False
            if kind == FUNCTIONFS_SUSPEND:
                self.stop_channel("USB suspend")  # candleLight: USBD_GS_CAN_SuspendCallback
            self.mark()

    def status_loop(self):
        block_control_signals()
        while self.running:
            self.status_dirty.wait(1.0)
            if self.status_dirty.is_set():
                self.status_dirty.clear()
                self.write_status()
                time.sleep(0.2)

    # -- endpoint 0 --------------------------------------------------------------

    def stall(self, request_type, request, why):
        with self.lock:
            self.counters["stalls"] += 1
            self.status_dirty.set()
        log(f"stall request {request} ({why})")
        try:
            if request_type & USB_DIR_IN:
                os.read(self.ep0, 1)
            else:
                os.write(self.ep0, b"\0")
        except OSError as error:
            if error.errno not in (EP0_STALLED, errno.EIDRM):
                log(f"stalling ep0: {error}")

    def reply(self, data):
        try:
            os.write(self.ep0, data)
        except OSError as error:
            log(f"ep0 reply failed: {error}")

    def receive(self, length):
        try:
            return os.read(self.ep0, max(length, 1))
        except OSError as error:
            log(f"ep0 data stage failed: {error}")
            return None

    # bRequest: (direction IN?, length of its structure)
    REQUESTS = {
        GS_USB_BREQ_HOST_FORMAT: (False, GS_HOST_CONFIG.size),
        GS_USB_BREQ_BITTIMING: (False, GS_DEVICE_BITTIMING.size),
        GS_USB_BREQ_MODE: (False, GS_DEVICE_MODE.size),
        GS_USB_BREQ_BT_CONST: (True, GS_DEVICE_BT_CONST.size),
        GS_USB_BREQ_DEVICE_CONFIG: (True, GS_DEVICE_CONFIG.size),
        GS_USB_BREQ_TIMESTAMP: (True, GS_TIMESTAMP.size),
        GS_USB_BREQ_IDENTIFY: (False, GS_IDENTIFY_MODE.size),
        GS_USB_BREQ_GET_STATE: (True, GS_DEVICE_STATE.size),
    }

    def setup_request(self, request_type, request, value, index, length):
        with self.lock:
            self.counters["requests"] += 1
            self.status_dirty.set()
            forced_stall = request in self.stall_next
            self.stall_next.discard(request)
        if forced_stall:
            return self.stall(request_type, request, "asked by the stall command")
        if request_type & USB_TYPE_MASK not in (USB_TYPE_VENDOR, USB_TYPE_CLASS):
            return self.stall(request_type, request, f"standard request type {request_type:#04x}")
        spec = self.REQUESTS.get(request)
        if spec is None:
            return self.stall(request_type, request, "not a request candleLight answers")
        direction_in, size = spec
        # HOST_FORMAT and DEVICE_CONFIG are per device (Linux sends wValue 1); the others name the channel.
        if request not in (GS_USB_BREQ_HOST_FORMAT, GS_USB_BREQ_DEVICE_CONFIG) and value >= CHANNELS:
            return self.stall(request_type, request, f"no channel {value}")
        if length < size:
            return self.stall(request_type, request, f"wLength {length} < {size}")
        if bool(request_type & USB_DIR_IN) != direction_in:
            return self.stall(request_type, request, "wrong direction")
        if direction_in:
            return self.reply(self.answer(request))
        if length > EP0_BUFFER:
            return self.stall(request_type, request, f"wLength {length} > {EP0_BUFFER}")
        data = self.receive(length)
        if data is not None and len(data) >= size:
            self.apply(request, data)

    def answer(self, request):
        with self.lock:
            if request == GS_USB_BREQ_BT_CONST:
                btc = CANDLELIGHT_BTC
                return GS_DEVICE_BT_CONST.pack(CANDLELIGHT_FEATURES, CANDLELIGHT_FCLK_CAN, btc["tseg1_min"],
                                               btc["tseg1_max"], btc["tseg2_min"], btc["tseg2_max"], btc["sjw_max"],
                                               btc["brp_min"], btc["brp_max"], btc["brp_inc"])
            if request == GS_USB_BREQ_DEVICE_CONFIG:
                return GS_DEVICE_CONFIG.pack(0, 0, 0, CHANNELS - 1, CANDLELIGHT_SW_VERSION, CANDLELIGHT_HW_VERSION)
            if request == GS_USB_BREQ_TIMESTAMP:
                return GS_TIMESTAMP.pack(self.microseconds())
            if request == GS_USB_BREQ_GET_STATE:
                return GS_DEVICE_STATE.pack(self.state, self.rxerr, self.txerr)
        raise AssertionError(request)

    def apply(self, request, data):
        if request == GS_USB_BREQ_HOST_FORMAT:
            with self.lock:
                self.host_format = GS_HOST_CONFIG.unpack_from(data)[0]
        elif request == GS_USB_BREQ_BITTIMING:
            prop_seg, phase_seg1, phase_seg2, sjw, brp = GS_DEVICE_BITTIMING.unpack_from(data)
            btc = CANDLELIGHT_BTC
            tseg1 = prop_seg + phase_seg1
            if not (btc["tseg1_min"] <= tseg1 <= btc["tseg1_max"] and btc["tseg2_min"] <= phase_seg2 <= btc["tseg2_max"]
                    and sjw <= btc["sjw_max"] and btc["brp_min"] <= brp <= btc["brp_max"]):
                log(f"bit timing {prop_seg}/{phase_seg1}/{phase_seg2} sjw {sjw} brp {brp} out of range: ignored")
                with self.lock:
                    self.counters["bittiming_rejected"] += 1
                return
            with self.lock:
                self.bittiming = (prop_seg, phase_seg1, phase_seg2, sjw, brp)
                self.bitrate = CANDLELIGHT_FCLK_CAN // (brp * (1 + tseg1 + phase_seg2))
            log(f"bit timing prop {prop_seg} seg1 {phase_seg1} seg2 {phase_seg2} sjw {sjw} brp {brp}: "
                f"{self.bitrate} bit/s")
        elif request == GS_USB_BREQ_MODE:
            mode, flags = GS_DEVICE_MODE.unpack_from(data)
            if mode == GS_CAN_MODE_RESET:
                self.stop_channel("MODE reset")
            elif mode == GS_CAN_MODE_START:
                self.start_channel(flags)
        elif request == GS_USB_BREQ_IDENTIFY:
            with self.lock:
                self.identify = bool(GS_IDENTIFY_MODE.unpack_from(data)[0])
            log(f"identify {'on' if self.identify else 'off'}")
        self.mark()

    # -- controls ----------------------------------------------------------------

    def error_frame(self, can_id, data):
        with self.lock:
            started = self.started
        if not started:
            log("error frame not sent: the channel is not started")
            return
        self.to_host(ToHost(can_id=CAN_ERR_FLAG | can_id, dlc=CAN_ERR_DLC, data=bytes(data),
                            timestamp=self.microseconds()))

    @staticmethod
    def counter_state(counter):
        if counter < CAN_ERROR_WARNING_THRESHOLD:
            return GS_CAN_STATE_ERROR_ACTIVE
        if counter < CAN_ERROR_PASSIVE_THRESHOLD:
            return GS_CAN_STATE_ERROR_WARNING
        if counter < CAN_BUS_OFF_THRESHOLD:
            return GS_CAN_STATE_ERROR_PASSIVE
        return GS_CAN_STATE_BUS_OFF

    def inject_state(self, name, txerr=None, rxerr=None):
        defaults = {"active": 0, "warning": CAN_ERROR_WARNING_THRESHOLD, "passive": CAN_ERROR_PASSIVE_THRESHOLD,
                    "busoff": CAN_BUS_OFF_THRESHOLD}
        state = STATE_NAMES[name]
        txerr = defaults[name] if txerr is None else txerr
        rxerr = 0 if rxerr is None else rxerr
        with self.lock:
            self.state = state
            self.txerr, self.rxerr = txerr, rxerr
        data = bytearray(8)
        if state == GS_CAN_STATE_BUS_OFF:
            can_id = CAN_ERR_BUSOFF
        else:
            # As candleLight's can_drv_handle_state_change: the worse of the TX and RX states is reported.
            can_id = CAN_ERR_CRTL | CAN_ERR_CNT
            tx_state, rx_state = self.counter_state(txerr), self.counter_state(rxerr)
            tx_bits = {0: CAN_ERR_CRTL_ACTIVE, 1: CAN_ERR_CRTL_TX_WARNING, 2: CAN_ERR_CRTL_TX_PASSIVE}
            rx_bits = {0: CAN_ERR_CRTL_ACTIVE, 1: CAN_ERR_CRTL_RX_WARNING, 2: CAN_ERR_CRTL_RX_PASSIVE}
            if tx_state >= rx_state:
                data[1] |= tx_bits.get(tx_state, 0)
            if tx_state <= rx_state:
                data[1] |= rx_bits.get(rx_state, 0)
            data[6], data[7] = txerr & 0xFF, rxerr & 0xFF
        self.error_frame(can_id, data)

    def inject_bus_error(self, kind, force):
        with self.lock:
            enabled = bool(self.mode_flags & GS_CAN_MODE_BERR_REPORTING)
            txerr, rxerr = self.txerr, self.rxerr
        if not enabled and not force:
            log(f"bus error {kind} not reported: the host did not enable GS_CAN_MODE_BERR_REPORTING")
            return
        extra_id, index, bits = BUS_ERRORS[kind]
        data = bytearray(8)
        data[index] |= bits
        data[6], data[7] = txerr & 0xFF, rxerr & 0xFF
        self.error_frame(CAN_ERR_PROT | CAN_ERR_BUSERROR | CAN_ERR_CNT | extra_id, data)

    def bad_frame(self, kind, value):
        if kind == "channel":
            frame = GS_HOST_FRAME.pack(GS_HOST_FRAME_ECHO_ID_RX, 0x123, 1, 0xFF if value is None else value, 0, 0,
                                       b"\x42".ljust(8, b"\0"))
        elif kind == "dlc":
            frame = GS_HOST_FRAME.pack(GS_HOST_FRAME_ECHO_ID_RX, 0x123, 15 if value is None else value, 0, 0, 0,
                                       bytes(range(1, 9)))
        elif kind == "echo":
            frame = GS_HOST_FRAME.pack(7 if value is None else value, 0x123, 1, 0, 0, 0, b"\x42".ljust(8, b"\0"))
        else:
            raise ValueError(f"bad-frame {kind}: channel, dlc or echo")
        with self.lock:
            if self.mode_flags & GS_CAN_MODE_HW_TIMESTAMP:
                frame += GS_TIMESTAMP.pack(self.microseconds())
        self.to_host(ToHost(raw=frame))

    def command(self, line):
        words = line.split()
        if not words:
            return
        verb, arguments = words[0], words[1:]

        def number(index, default=None):
            return int(arguments[index], 0) if len(arguments) > index else default

        try:
            if verb == "unplug":
                self.unplug()
            elif verb in ("replug", "plug"):
                self.plug()
            elif verb == "error" and arguments[:1] == ["state"] and len(arguments) >= 2:
                self.inject_state(arguments[1], number(2), number(3))
            elif verb == "error" and arguments[:1] == ["bus"] and len(arguments) >= 2:
                self.inject_bus_error(arguments[1], "force" in arguments[2:])
            elif verb == "error" and arguments == ["overflow"]:
                with self.lock:
                    self.overflow_pending = True
            elif verb == "short-in":
                with self.lock:
                    self.short_in = number(0, 8)
            elif verb == "bad-frame" and arguments:
                self.bad_frame(arguments[0], number(1))
            elif verb == "stall" and arguments:
                with self.lock:
                    self.stall_next.add(number(0))
            elif verb in ("pause-in", "resume-in"):
                with self.lock:
                    self.paused = verb == "pause-in"
                    self.in_condition.notify_all()
            elif verb == "queue-limit" and arguments:
                with self.lock:
                    self.queue_limit = number(0)
            elif verb == "status":
                pass
            elif verb == "quit":
                self.running = False
            else:
                log(f"unknown command {line!r}")
                self.counters["bad_commands"] += 1
        except (ValueError, KeyError, IndexError, OSError) as error:
            log(f"command {line!r} failed: {error}")
            self.counters["bad_commands"] += 1
        else:
            log(f"command {line!r} done")
        self.commands += 1
        self.write_status()

    # -- status ------------------------------------------------------------------

    def mark(self):
        self.status_dirty.set()

    def write_status(self):
        with self.lock:
            values = {
                "ready": int(self.ready), "bound": int(self.bound), "configured": int(self.configured),
                "started": int(self.started), "bitrate": self.bitrate or 0, "mode_flags": f"{self.mode_flags:#x}",
                "timestamps": int(bool(self.mode_flags & GS_CAN_MODE_HW_TIMESTAMP)), "state": self.state,
                "txerr": self.txerr, "rxerr": self.rxerr, "identify": int(self.identify),
                "host_format": f"{self.host_format:#x}" if self.host_format is not None else "none",
                "rx_queue": sum(1 for item in self.queue if item.from_bus), "queue": len(self.queue),
                "paused": int(self.paused), "udc": self.udc,
            }
            for key in ("to_bus", "to_host", "echoes", "error_frames", "raw_to_host", "bus_lines", "bus_ignored",
                        "rx_dropped", "host_frames", "host_ignored", "requests", "stalls", "malformed_lines",
                        "in_aborted", "in_lost", "short_in", "bittiming_rejected", "bad_commands"):
                values[key] = self.counters[key]
            values["commands"] = self.commands
        text = "".join(f"{key}={value}\n" for key, value in values.items())
        path = self.options.status
        with self.status_lock:  # the status thread and the main thread both write it
            try:
                write_file(path + ".new", text)
                os.replace(path + ".new", path)
            except OSError as error:
                log(f"cannot write {path}: {error}")

    # -- main ------------------------------------------------------------------

    def serve(self):
        control = self.options.control
        os.makedirs(os.path.dirname(control), exist_ok=True)
        if os.path.exists(control):
            os.unlink(control)
        os.mkfifo(control, 0o600)
        control_fd = os.open(control, os.O_RDWR | os.O_NONBLOCK)  # our own writer end: never EOF
        wake_read, wake_write = os.pipe()
        os.set_blocking(wake_write, False)
        for number in list(CONTROL_SIGNALS) + [WAKE_SIGNAL]:
            signal.signal(number, lambda *_: None)
        signal.set_wakeup_fd(wake_write, warn_on_full_buffer=False)
        self.setup()
        self.start_threads()
        if not self.options.unplugged:
            self.plug()
        with self.lock:
            self.ready = True
        self.write_status()
        log(f"ready: serial {self.options.serial}, control {control}, status {self.options.status}")
        pending = b""
        while self.running:
            readable, _, _ = select.select([control_fd, wake_read], [], [], 1.0)
            if wake_read in readable:
                for number in os.read(wake_read, 64):
                    if number in CONTROL_SIGNALS:
                        self.command(CONTROL_SIGNALS[number])
            if control_fd in readable:
                try:
                    pending += os.read(control_fd, 4096)
                except BlockingIOError:
                    continue
                while b"\n" in pending:
                    line, pending = pending.split(b"\n", 1)
                    self.command(line.decode("utf-8", "replace").strip())
        log("quitting")
        self.unplug()
        with self.lock:
            self.in_condition.notify_all()
        self.remove_configfs()
        self.write_status()
        os.unlink(control)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--serial", default="000000000001", help="the USB serial number string")
    parser.add_argument("--manufacturer", default="bytewerk", help="the USB manufacturer string (candleLight's)")
    parser.add_argument("--product", default="candleLight USB to CAN adapter", help="the USB product string")
    parser.add_argument("--tty", default="/dev/ttyS1", help="the serial line to the bus (Lawicel), or none")
    parser.add_argument("--udc", help="the USB device controller (default: the first in /sys/class/udc)")
    parser.add_argument("--name", default="gsusb", help="the gadget's and FunctionFS instance's name")
    parser.add_argument("--ffs-dir", default="/run/gsusb/ffs", help="where FunctionFS is mounted")
    parser.add_argument("--control", default="/run/gsusb/control", help="the control FIFO")
    parser.add_argument("--status", default="/run/gsusb/status", help="the status file")
    parser.add_argument("--queue", type=int, default=1024, help="frames from the bus queued for the host at most")
    parser.add_argument("--unplugged", action="store_true", help="start unbound; `replug` binds")
    options = parser.parse_args(argv)
    os.makedirs(os.path.dirname(options.status), exist_ok=True)
    Gadget(options).serve()
    return 0


if __name__ == "__main__":
    sys.exit(main())
