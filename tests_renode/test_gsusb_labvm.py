"""The emulated candleLight (gs_usb) USB-CAN adapter against Linux's own gs_usb driver, in the lab VM.

tests_renode/labvm/gsusb_gadget.py builds the adapter in the VM as a USB
gadget (configfs, FunctionFS, dummy_hcd: docs/protocols/lab-usb-devices.md);
its CAN side is the VM's second serial port, whose host end this test holds as
a SlcanPort (the place where the lab bus hub's slcan bridge would sit). The
proof of fidelity is a driver we did not write: Linux 6.1's gs_usb probes the
adapter, configures it through its vendor requests and moves frames through
its bulk endpoints, so can0 carries the bus's frames to candump and cansend's
frames to the bus. A last phase unbinds gs_usb and drives the adapter from
user space through usbfs (the ioctls libusb uses), for the stalls, GET_STATE
and the injected faults a user-space host sees.

One VM boot serves the module: the VM runs one script in phases, telling the
test by `@@READY <phase>@@` on the console when its receivers listen, and the
test then writes the bus's frames into the serial socket. Every wait has a
time-out; a failing test prints the VM's console transcript.
"""

import json
import os
import re
import shutil
import sys
import tempfile

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from labvm import CanFrame, LabVM, LabVMError, SlcanError, SlcanPort  # noqa: E402
from labvm.gsusb_gadget import LAB_VM_LOAD, VM_SHELL  # noqa: E402

# The module's tests share a module-scoped lab VM: xdist (--dist loadgroup in
# pytest.ini) keeps them on one worker, in order.
pytestmark = pytest.mark.xdist_group("test_gsusb_labvm")

GADGET = os.path.join(os.path.dirname(os.path.abspath(__file__)), "labvm", "gsusb_gadget.py")
SERIAL = "LAB-GSUSB-0001"
BOOT_TIMEOUT = 240
STEP = 120  # any one wait for the VM; bounds a hang, does not measure speed
COMMAND_TIMEOUT = 420

RX_FRAMES = [
    CanFrame(0x123, b"\x11\x22\x33\x44"),
    CanFrame(0x1ABCDEF0, b"\x01\x02", extended=True),
    CanFrame(0x7FF, remote=True, dlc=2),
    CanFrame(0x1ABCDEF0, remote=True, dlc=0, extended=True),
    CanFrame(0x000, b""),
    CanFrame(0x456, bytes(range(8))),
    CanFrame(0x00000001, b"\xAA", extended=True),
]
RX_EXPECTED = ["can0 123#11223344", "can0 1ABCDEF0#0102", "can0 7FF#R2", "can0 1ABCDEF0#R", "can0 000#",
               "can0 456#0001020304050607", "can0 00000001#AA"]
TX_SENDS = ["321#DEADBEEF", "12345678#01", "7FF#R", "1FFFFFFF#R", "000#", "555#0102030405060708"]
TX_EXPECTED = ["t3214DEADBEEF", "T12345678101", "r7FF0", "R1FFFFFFF0", "t0000",
               "t55580102030405060708"]
BURST = [CanFrame(0x100 + index, bytes([index, 0xA5])) for index in range(100)]
QUEUE_LIMIT = 5
QUEUED = [CanFrame(0x200 + index, bytes([index])) for index in range(8)]


USBFS_PROBE = r"""
import fcntl, json, os, struct, sys, time, errno, ctypes

# Linux include/uapi/linux/usbdevice_fs.h on x86-64: struct usbdevfs_ctrltransfer (24 bytes) and
# struct usbdevfs_bulktransfer (24 bytes); _IOWR('U', 0 / 2, ...) and _IOR('U', 15, unsigned int).
USBDEVFS_CONTROL, USBDEVFS_BULK, USBDEVFS_CLAIMINTERFACE = 0xC0185500, 0xC0185502, 0x8004550F
VENDOR_IN, VENDOR_OUT = 0xC1, 0x41  # vendor request to the interface, device to host / host to device
CONTROL, STATUS = "/run/gsusb/control", "/run/gsusb/status"

def command(text):
    done = int(dict(l.split("=", 1) for l in open(STATUS).read().split())["commands"]) + 1
    with open(CONTROL, "w") as handle:
        handle.write(text + "\n")
    deadline = time.monotonic() + 30
    while "commands=%d\n" % done not in open(STATUS).read():
        assert time.monotonic() < deadline, "the gadget did not do " + text
        time.sleep(0.05)

device = "/sys/bus/usb/devices/1-1"
fd = os.open("/dev/bus/usb/%03d/%03d" % (int(open(device + "/busnum").read()), int(open(device + "/devnum").read())),
             os.O_RDWR)
fcntl.ioctl(fd, USBDEVFS_CLAIMINTERFACE, struct.pack("I", 0))

def control(request_type, request, value, length_or_data, timeout=2000):
    data = length_or_data if isinstance(length_or_data, bytes) else bytes(length_or_data)
    buffer = ctypes.create_string_buffer(data, len(data))
    block = bytearray(struct.pack("<BBHHHIxxxxQ", request_type, request, value, 0, len(data), timeout,
                                  ctypes.addressof(buffer)))
    try:
        count = fcntl.ioctl(fd, USBDEVFS_CONTROL, block, True)
    except OSError as error:
        return errno.errorcode[error.errno]
    return buffer.raw[:count].hex()

def bulk(endpoint, length_or_data, timeout=5000):
    data = length_or_data if isinstance(length_or_data, bytes) else bytes(length_or_data)
    buffer = ctypes.create_string_buffer(data, len(data))
    block = bytearray(struct.pack("<IIIxxxxQ", endpoint, len(data), timeout, ctypes.addressof(buffer)))
    try:
        count = fcntl.ioctl(fd, USBDEVFS_BULK, block, True)
    except OSError as error:
        return errno.errorcode[error.errno]
    return buffer.raw[:count].hex()

out = {}
out["device_config"] = control(VENDOR_IN, 5, 1, 12)
out["state_stopped"] = control(VENDOR_IN, 14, 0, 12)
out["berr"] = control(VENDOR_OUT, 3, 0, b"\0" * 4)            # candleLight has no BERR request: stall
out["short_wlength"] = control(VENDOR_IN, 5, 1, 4)            # wLength below the structure: stall
out["channel_1"] = control(VENDOR_IN, 4, 1, 40)               # there is no channel 1: stall
out["after_stalls"] = control(VENDOR_IN, 6, 0, 4) != "EPIPE"  # the next request works again
command("stall 5")
out["forced_stall"] = control(VENDOR_IN, 5, 1, 12)
out["after_forced"] = control(VENDOR_IN, 5, 1, 12)
# Start without timestamps, with bus-error reports: 20-byte frames.
control(VENDOR_OUT, 1, 0, struct.pack("<5I", 6, 7, 2, 1, 6))
control(VENDOR_OUT, 2, 0, struct.pack("<II", 1, 1 << 12))
command("error state warning 100 5")
out["state_warning"] = control(VENDOR_IN, 14, 0, 12)
out["warning_frame"] = bulk(0x81, 64)
command("error bus ack")
out["bus_error_frame"] = bulk(0x81, 64)
command("short-in 8")
command("bad-frame channel 2")
out["short_bad_channel"] = bulk(0x81, 64)
# A frame of our own: echoed with its echo_id.
frame = struct.pack("<IIBBBB8s", 0x1234, 0x7E0, 2, 0, 0, 0, b"\x10\x20".ljust(8, b"\0"))
out["sent"] = bulk(0x02, frame)
out["echo"] = bulk(0x81, 64)
control(VENDOR_OUT, 2, 0, struct.pack("<II", 0, 0))
out["state_reset"] = control(VENDOR_IN, 14, 0, 12)
print("@@USBFS " + json.dumps(out, sort_keys=True) + "@@", flush=True)
"""

VM_SCRIPT = (r"""
. /run/labvm/lib.sh
cd /tmp
""" + VM_SHELL + r"""
bound_interfaces() { ls /sys/bus/usb/drivers/gs_usb | grep ':' | tr '\n' ' '; }
bring_up() {
    ip link set can0 type can bitrate 500000
    ip link set can0 up
}
trap 'echo "----- gadget log -----"; cat /tmp/gadget.log' EXIT

# -- the adapter appears and Linux's gs_usb binds it --
/usr/bin/python3 -u /run/labvm/files/gsusb_gadget.py --serial __SERIAL__ >/tmp/gadget.log 2>&1 &
gadget=$!
wait_for 90 "can0 from gs_usb" has_can0
wait_for 30 "gadget status" test -s $S
echo "@@DRIVER $(bound_interfaces)@@"
for interface in /sys/bus/usb/drivers/gs_usb/*:*; do
    device=$(readlink -f "$interface/..")
    for attribute in idVendor idProduct serial manufacturer product speed bNumConfigurations; do
        echo "@@USB $attribute=$(cat "$device/$attribute")@@"
    done
    class=$(cat "$interface/bInterfaceClass")/$(cat "$interface/bInterfaceSubClass")
    echo "@@USB class=$class/$(cat "$interface/bInterfaceProtocol")@@"
    for endpoint in "$interface"/ep_*; do
        kind="$(cat "$endpoint/type") $(cat "$endpoint/direction")"
        echo "@@ENDPOINT $(basename "$endpoint") $kind $(cat "$endpoint/wMaxPacketSize")@@"
    done
done
echo "@@NETDEV $(basename "$(readlink -f /sys/class/net/can0/device)")@@"
bring_up
echo "@@IPLINK-BEGIN@@"; ip -details link show can0; echo "@@IPLINK-END@@"

# -- the bus's frames reach candump through the adapter --
timeout 90 candump -L -n __RX_COUNT__ can0 >/tmp/rx.log &
dump=$!
labvm_wait_receiver can0 raw || fail "candump does not listen"
echo "@@READY rx@@"
wait $dump || fail "candump of the bus's frames ended with $?"
echo "@@RX-BEGIN@@"; cut -d' ' -f2- /tmp/rx.log; echo "@@RX-END@@"

# -- cansend's frames reach the bus --
for frame in __TX_SENDS__; do cansend can0 "$frame" || fail "cansend $frame"; done
wait_for 30 "echo of every frame" at_least echoes __TX_COUNT__
echo "@@SENT tx@@"
echo "@@TXPACKETS $(cat /sys/class/net/can0/statistics/tx_packets)@@"

# -- a burst from the bus: nothing lost, nothing reordered --
timeout 120 candump -L -n __BURST_COUNT__ can0 >/tmp/burst.log &
dump=$!
labvm_wait_receiver can0 raw || fail "candump does not listen"
echo "@@READY burst@@"
wait $dump || fail "candump of the burst ended with $?"
echo "@@BURST-BEGIN@@"; cut -d' ' -f2- /tmp/burst.log; echo "@@BURST-END@@"

# -- a host that does not read: the bus's frames queue up to the bound, the rest are dropped and counted --
gsusb queue-limit __QUEUE_LIMIT__
gsusb pause-in
lines=$(status bus_lines)
timeout 120 candump -L -n $((__QUEUE_LIMIT__ + 1)) 'can0,0:0,#FFFFFFFF' >/tmp/queue.log &
dump=$!
labvm_wait_receiver can0 raw || fail "candump does not listen"
echo "@@READY queue@@"
wait_for 60 "frames from the host end" at_least bus_lines $((lines + __QUEUED_COUNT__))
echo "@@QUEUED rx_queue=$(status rx_queue) rx_dropped=$(status rx_dropped)@@"
gsusb resume-in
wait $dump || fail "candump of the queued frames ended with $?"
echo "@@QUEUE-BEGIN@@"; cut -d' ' -f2- /tmp/queue.log; echo "@@QUEUE-END@@"
echo "@@RXOVER $(cat /sys/class/net/can0/statistics/rx_over_errors)@@"
gsusb queue-limit 1024

# -- error states and bus errors the adapter reports --
timeout 60 candump -L -n 4 'can0,0~0,#FFFFFFFF' >/tmp/errors.log &
dump=$!
labvm_wait_receiver can0 raw || fail "candump does not listen"
gsusb error state warning 100 5
wait_for 30 "ERROR-WARNING" sh -c 'ip -details link show can0 | grep -q ERROR-WARNING'
echo "@@STATE-BEGIN warning@@"; ip -details -statistics link show can0; echo "@@STATE-END warning@@"
gsusb error state passive 130 5
wait_for 30 "ERROR-PASSIVE" sh -c 'ip -details link show can0 | grep -q ERROR-PASSIVE'
echo "@@STATE-BEGIN passive@@"; ip -details -statistics link show can0; echo "@@STATE-END passive@@"
gsusb error state active
gsusb error bus ack
gsusb error bus stuff force
wait $dump || fail "candump of the error frames ended with $?"
echo "@@STATE-BEGIN active@@"; ip -details -statistics link show can0; echo "@@STATE-END active@@"
echo "@@ERRORS-BEGIN@@"; cut -d' ' -f2- /tmp/errors.log; echo "@@ERRORS-END@@"

# -- malformed frames from the adapter: Linux clamps a DLC over 8 and rejects an echo id it never used --
timeout 60 candump -L -n 1 can0 >/tmp/dlc.log &
dump=$!
labvm_wait_receiver can0 raw || fail "candump does not listen"
gsusb bad-frame dlc 15
wait $dump || fail "candump of the bad DLC frame ended with $?"
echo "@@BADDLC $(cut -d' ' -f2- /tmp/dlc.log)@@"
gsusb bad-frame echo 7
wait_for 30 "rejection of echo id 7" sh -c 'dmesg | grep -q "Unexpected unused echo id 7"'
echo "@@BADECHO $(dmesg | grep -o 'Unexpected unused echo id 7' | head -n 1)@@"

# -- unplug and replug by control command: can0 goes and comes back, and works --
gsusb unplug
wait_for 30 "can0 gone after unplug" no_can0
echo "@@UNPLUGGED driver=[$(bound_interfaces)] bound=$(status bound)@@"
gsusb replug
wait_for 60 "can0 back after replug" has_can0
echo "@@REPLUGGED driver=[$(bound_interfaces)] bound=$(status bound)@@"
bring_up
timeout 60 candump -L -n 1 can0 >/tmp/replug.log &
dump=$!
labvm_wait_receiver can0 raw || fail "candump does not listen"
echo "@@READY replug@@"
wait $dump || fail "candump after replug ended with $?"
echo "@@REPLUGRX $(cut -d' ' -f2- /tmp/replug.log)@@"
echoes=$(status echoes)
cansend can0 654#99 || fail "cansend after replug"
wait_for 30 "echo after replug" at_least echoes $((echoes + 1))
echo "@@SENT replug@@"

# -- unplug and replug by signal --
to_bus=$(status to_bus)
kill -USR1 $gadget
wait_for 30 "can0 gone after SIGUSR1" no_can0
echo "@@SIGUSR1 driver=[$(bound_interfaces)]@@"
kill -USR2 $gadget
wait_for 60 "can0 back after SIGUSR2" has_can0
echo "@@SIGUSR2 driver=[$(bound_interfaces)]@@"

# -- a userspace host (usbfs, as libusb uses it) with the kernel driver unbound --
echo 1-1:1.0 >/sys/bus/usb/drivers/gs_usb/unbind
wait_for 30 "can0 gone after unbinding gs_usb" no_can0
timeout 120 /usr/bin/python3 /run/labvm/files/usbfs_probe.py || fail "the usbfs probe ended with $?"
wait_for 30 "the frame the usbfs host sent" at_least to_bus $((to_bus + 1))

# -- the gadget quits and cleans up --
echo quit >$C
wait $gadget
quit=$?
echo "@@QUIT status=$quit can0=$(has_can0 && echo present || echo gone) gadget=$(ls /sys/kernel/config/usb_gadget)@@"
echo "@@STATUS-BEGIN@@"; cat $S; echo "@@STATUS-END@@"
echo "@@DMESG-BEGIN@@"; dmesg | grep -E 'gs_usb|usb 1-1'; echo "@@DMESG-END@@"
""").replace("__SERIAL__", SERIAL).replace("__RX_COUNT__", str(len(RX_FRAMES))).replace(
    "__TX_SENDS__", " ".join(TX_SENDS)).replace("__TX_COUNT__", str(len(TX_SENDS))).replace(
    "__BURST_COUNT__", str(len(BURST))).replace("__QUEUE_LIMIT__", str(QUEUE_LIMIT)).replace(
    "__QUEUED_COUNT__", str(len(QUEUED)))


class Session:
    """What the one VM run gave: its output, its transcript, and the Lawicel lines the host end received."""

    def __init__(self, output, transcript, host_lines, tx_frames, replug_frame, usbfs_frame):
        self.output = output
        self.transcript = transcript
        self.host_lines = host_lines
        self.tx_frames = tx_frames
        self.replug_frame = replug_frame
        self.usbfs_frame = usbfs_frame

    def marker(self, name):
        """The text of every @@NAME text@@ line."""
        return [match.group(1) or "" for match in re.finditer(r"@@" + re.escape(name) + r"(?: (.*?))?@@", self.output)]

    def section(self, name, tag=""):
        begin = f"@@{name}-BEGIN{' ' + tag if tag else ''}@@\n"
        end = f"@@{name}-END{' ' + tag if tag else ''}@@"
        start = self.output.find(begin)
        stop = self.output.find(end, start)
        assert start >= 0 and stop >= 0, self.explain(f"no section {name} {tag}")
        return self.output[start + len(begin):stop]

    def explain(self, what):
        return (f"{what}\n----- host end received -----\n{self.host_lines}\n"
                f"----- lab VM console -----\n{self.transcript}")


@pytest.fixture(scope="module")
def session():
    with open(GADGET, encoding="utf-8") as handle:
        gadget = handle.read()
    directory = tempfile.mkdtemp(prefix="gsusb-")
    socket_path = os.path.join(directory, "bus.sock")
    vm = LabVM(VM_SCRIPT, files={"gsusb_gadget.py": gadget, "usbfs_probe.py": USBFS_PROBE}, load=LAB_VM_LOAD,
               timeout=COMMAND_TIMEOUT,
               boot_timeout=BOOT_TIMEOUT,
               qemu_args=["-chardev", f"socket,id=bus,path={socket_path},server=on,wait=off",
                          "-serial", "chardev:bus"])
    port = None
    try:
        vm.start()
        port = SlcanPort(socket_path, connect_timeout=30)
        vm.expect(r"@@READY rx@@", timeout=BOOT_TIMEOUT + STEP)
        for frame in RX_FRAMES:
            port.send(frame)
        vm.expect(r"@@SENT tx@@", timeout=STEP)
        tx_frames = [port.receive_frame(timeout=STEP) for _ in TX_SENDS]
        vm.expect(r"@@READY burst@@", timeout=STEP)
        for frame in BURST:
            port.send(frame)
        vm.expect(r"@@READY queue@@", timeout=STEP)
        for frame in QUEUED:
            port.send(frame)
        vm.expect(r"@@READY replug@@", timeout=STEP)
        port.send(CanFrame(0x321, b"\xAB\xCD"))
        vm.expect(r"@@SENT replug@@", timeout=STEP)
        replug_frame = port.receive_frame(timeout=STEP)
        result = vm.wait()
        usbfs_frame = port.receive_frame(timeout=STEP)
        host_lines = list(port.lines)
    except (LabVMError, SlcanError) as error:
        lines = list(port.lines) if port is not None else []
        pytest.fail(f"the lab VM session failed: {error}\n----- host end received -----\n{lines}\n"
                    f"----- lab VM console -----\n{vm.transcript}", pytrace=False)
    finally:
        if port is not None:
            port.close()
        vm.close()
        shutil.rmtree(directory, ignore_errors=True)
    found = Session(result.output, result.transcript, host_lines, tx_frames, replug_frame, usbfs_frame)
    if result.status != 0:
        pytest.fail(found.explain(f"the VM script ended with status {result.status}"), pytrace=False)
    return found


def test_linux_gs_usb_binds_the_emulated_adapter(session):
    assert session.marker("DRIVER") == ["1-1:1.0 "], session.explain("gs_usb bound no interface 1-1:1.0")
    usb = dict(item.split("=", 1) for item in session.marker("USB"))
    assert usb == {"idVendor": "1d50", "idProduct": "606f", "serial": SERIAL, "manufacturer": "bytewerk",
                   "product": "candleLight USB to CAN adapter", "speed": "12", "bNumConfigurations": "1",
                   "class": "ff/ff/ff"}, session.explain(usb)
    # candleLight's endpoints, which Linux's gs_usb hard-codes: bulk IN 0x81 and bulk OUT 0x02, 32 bytes.
    assert sorted(session.marker("ENDPOINT")) == ["ep_02 Bulk out 0020", "ep_81 Bulk in 0020"], \
        session.explain(session.marker("ENDPOINT"))
    assert session.marker("NETDEV") == ["1-1:1.0"], session.explain("can0 is not the adapter's interface")
    dmesg = session.section("DMESG")
    assert "gs_usb 1-1:1.0: Configuring for 1 interfaces" in dmesg, session.explain(dmesg)


def test_the_driver_reads_candlelights_bit_timing_constants_and_sets_500_kbit(session):
    link = session.section("IPLINK")
    assert "gs_usb: tseg1 1..16 tseg2 1..8 sjw 1..4 brp 1..1024 brp_inc 1" in link, session.explain(link)
    assert "clock 48000000" in link and "bitrate 500000 sample-point 0.875" in link, session.explain(link)
    assert "can state ERROR-ACTIVE" in link, session.explain(link)
    status = dict(line.split("=", 1) for line in session.section("STATUS").split())
    # Linux sent its byte-order word and started the channel with hardware timestamps, as gs_usb 6.1 does.
    assert status["host_format"] == "0xbeef" and status["bitrate"] == "500000", session.explain(status)


def test_the_channel_start_reaches_the_bus_side_as_lawicel_commands(session):
    # As slcand would: close, the bit rate the host set (S6 = 500 kbit/s), open; before any frame.
    assert session.host_lines[:3] == ["C", "S6", "O"], session.explain("no C, S6, O first")


def test_bus_frames_appear_in_candump(session):
    lines = session.section("RX").splitlines()
    assert lines == RX_EXPECTED, session.explain(lines)


def test_cansend_frames_reach_the_bus(session):
    assert [frame.lawicel().rstrip("\r") for frame in session.tx_frames] == TX_EXPECTED, \
        session.explain(session.tx_frames)
    # Every frame was echoed by the adapter: the kernel counts a frame sent only at its echo.
    assert session.marker("TXPACKETS") == [str(len(TX_SENDS))], session.explain(session.marker("TXPACKETS"))


def test_a_burst_of_100_bus_frames_arrives_complete_and_in_order(session):
    lines = session.section("BURST").splitlines()
    assert lines == [f"can0 {frame.can_id:03X}#{frame.data.hex().upper()}" for frame in BURST], \
        session.explain(lines)


def test_a_host_that_does_not_read_gets_the_queued_frames_and_an_overflow_report(session):
    assert session.marker("QUEUED") == [f"rx_queue={QUEUE_LIMIT} rx_dropped={len(QUEUED) - QUEUE_LIMIT}"], \
        session.explain(session.marker("QUEUED"))
    lines = session.section("QUEUE").splitlines()
    kept = [f"can0 {frame.can_id:03X}#{frame.data.hex().upper()}" for frame in QUEUED[:QUEUE_LIMIT]]
    # The first frame after the loss carries GS_CAN_FLAG_OVERFLOW: the kernel reports an rx-overflow
    # controller problem right after it and counts an rx_over_error.
    assert lines == kept[:1] + ["can0 20000004#0001000000000000"] + kept[1:], session.explain(lines)
    assert session.marker("RXOVER") == ["1"], session.explain(session.marker("RXOVER"))


def test_injected_error_states_reach_the_kernel(session):
    errors = session.section("ERRORS").splitlines()
    assert errors == [
        "can0 20000204#0008000000006405",  # controller problem, TX warning, counters 100/5
        "can0 20000204#0020000000008205",  # TX passive, 130/5
        "can0 20000204#0040000000000000",  # back to error active
        "can0 20000288#0000040000000000",  # a stuff error, forced: Linux 6.1 never enables bus-error reports
    ], session.explain(errors)
    warning = session.section("STATE", "warning")
    assert "can state ERROR-WARNING" in warning, session.explain(warning)
    passive = session.section("STATE", "passive")
    assert "can state ERROR-PASSIVE" in passive, session.explain(passive)
    active = session.section("STATE", "active")
    assert "can state ERROR-ACTIVE" in active, session.explain(active)
    # re-started bus-errors arbit-lost error-warn error-pass bus-off
    counts = re.search(r"re-started bus-errors arbit-lost error-warn error-pass bus-off\s+(\d+(?:\s+\d+){5})",
                       active)
    assert counts and counts.group(1).split() == ["0", "0", "0", "1", "1", "0"], session.explain(active)


def test_malformed_adapter_frames_are_clamped_or_rejected_by_the_driver(session):
    assert session.marker("BADDLC") == ["can0 123#0102030405060708"], session.explain(session.marker("BADDLC"))
    assert session.marker("BADECHO") == ["Unexpected unused echo id 7"], session.explain(session.marker("BADECHO"))


def test_unplug_and_replug_remove_and_restore_the_netdev(session):
    assert session.marker("UNPLUGGED") == ["driver=[] bound=0"], session.explain(session.marker("UNPLUGGED"))
    assert session.marker("REPLUGGED") == ["driver=[1-1:1.0 ] bound=1"], session.explain(session.marker("REPLUGGED"))
    assert session.marker("REPLUGRX") == ["can0 321#ABCD"], session.explain(session.marker("REPLUGRX"))
    assert session.replug_frame == CanFrame(0x654, b"\x99"), session.explain(session.replug_frame)
    assert session.marker("SIGUSR1") == ["driver=[]"], session.explain(session.marker("SIGUSR1"))
    assert session.marker("SIGUSR2") == ["driver=[1-1:1.0 ]"], session.explain(session.marker("SIGUSR2"))


def test_the_gadget_quits_cleanly_and_counted_no_loss_beyond_the_injected_one(session):
    assert session.marker("QUIT") == ["status=0 can0=gone gadget="], session.explain(session.marker("QUIT"))
    status = dict(line.split("=", 1) for line in session.section("STATUS").split())
    assert status["rx_dropped"] == str(len(QUEUED) - QUEUE_LIMIT), session.explain(status)
    assert status["malformed_lines"] == "0" and status["bad_commands"] == "0", session.explain(status)
    expected_bus = len(RX_FRAMES) + len(BURST) + len(QUEUED) + 1
    assert status["bus_lines"] == str(expected_bus), session.explain(status)


def test_a_usbfs_host_sees_candlelights_answers_stalls_and_injected_faults(session):
    [probe] = [json.loads(text) for text in session.marker("USBFS")] or [None]
    assert probe is not None, session.explain("the usbfs probe printed nothing")
    device_config = "00000000" "02000000" "01000000"  # icount 0, sw_version 2, hw_version 1
    assert probe["device_config"] == device_config and probe["after_forced"] == device_config, session.explain(probe)
    assert probe["state_stopped"] == "04000000" "00000000" "00000000", session.explain(probe)  # GS_CAN_STATE_STOPPED
    # What candleLight stalls: a request it does not know, a short wLength, a channel it does not have.
    assert [probe[key] for key in ("berr", "short_wlength", "channel_1", "forced_stall")] == ["EPIPE"] * 4, \
        session.explain(probe)
    assert probe["after_stalls"] is True, session.explain(probe)
    assert probe["state_warning"] == "01000000" "05000000" "64000000", session.explain(probe)  # state, rx, tx
    # 20-byte frames (no timestamps asked): echo_id, can_id, dlc, channel, flags, reserved, data.
    assert probe["warning_frame"] == "ffffffff" "04020020" "08000000" "0008000000006405", session.explain(probe)
    # With GS_CAN_MODE_BERR_REPORTING the bus error is reported without "force".
    assert probe["bus_error_frame"] == "ffffffff" "a8020020" "08000000" "0000000000006405", session.explain(probe)
    assert probe["short_bad_channel"] == "ffffffff" "23010000", session.explain(probe)  # cut to 8 bytes
    assert probe["echo"] == "34120000" "e0070000" "02000000" "1020000000000000", session.explain(probe)
    assert probe["state_reset"] == "04000000" "05000000" "64000000", session.explain(probe)
    assert session.usbfs_frame == CanFrame(0x7E0, b"\x10\x20"), session.explain(session.usbfs_frame)
