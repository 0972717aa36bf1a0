"""dcos-can (host_tools/can) against the Linux kernel's own CAN stack, in the lab VM.

The machine the project is built on has no SocketCAN, so the tool's
SocketCAN transport and its ISO-TP endpoint (the link layer's state machines,
the same code the firmware runs) are proven inside the lab VM against
implementations we did not write: the kernel's can-raw with can-utils'
candump and cansend, and the kernel's can-isotp with isotpsend and
isotprecv. The tool binary goes into the VM as a file (the host's /tmp,
where a CI clone may live, is not visible inside).
"""

import json
import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.board import REPOSITORY  # noqa: E402
from labvm import LabVMError, check_command, parse_checks, run  # noqa: E402

# The module's tests share a module-scoped lab VM: xdist (--dist loadgroup in
# pytest.ini) keeps them on one worker, in order: one VM runs every check the tests read.
pytestmark = pytest.mark.xdist_group("test_dcos_can_labvm")

DCOS_CAN = os.path.join(REPOSITORY, "build", "host_tools", "bin", "dcos-can")
BOOT_TIMEOUT = 240
CHECK_TIMEOUT = 60

PRELUDE = """. /run/labvm/lib.sh
cp /run/labvm/files/dcos-can /tmp/dcos-can
chmod 755 /tmp/dcos-can
"""

MESSAGE = " ".join(f"{byte:02X}" for byte in range(100))

CHECKS = {
    # dcos-can sends, candump logs.
    "send": PRELUDE + r"""
timeout 30 candump -L -n 3 vcan0 >/tmp/send.log &
dump=$!
labvm_wait_receiver vcan0 raw
/tmp/dcos-can -i vcan0 send 123#11223344 1ABCDEF0#01.02 7FF#R2
wait $dump
cut -d' ' -f2- /tmp/send.log
""",
    # cansend sends, dcos-can dumps (JSON, with the DCOS identifier decoded).
    "dump": PRELUDE + r"""
timeout 30 /tmp/dcos-can -i vcan0 --json dump -n 2 -t 20000 --decode >/tmp/dump.json &
dump=$!
labvm_wait_receiver vcan0 raw
cansend vcan0 0320FF05#0102
cansend vcan0 456#DEADBEEF
wait $dump
cat /tmp/dump.json
""",
    # Our ISO-TP sender to the kernel's receiver.
    "isotp_to_kernel": PRELUDE + r"""
timeout 30 isotprecv -s 7E8 -d 7E0 vcan0 >/tmp/received &
receiver=$!
labvm_wait_receiver vcan0 isotp 7e0
/tmp/dcos-can -i vcan0 isotp-send -s 7E0 -d 7E8 "__MESSAGE__"
wait $receiver
echo "received: $(cat /tmp/received)"
""".replace("__MESSAGE__", MESSAGE),
    # The kernel's ISO-TP sender to our receiver, padded as isotpsend -p pads.
    "isotp_from_kernel": PRELUDE + r"""
timeout 30 /tmp/dcos-can -i vcan0 isotp-recv -s 7E8 -d 7E0 -t 20000 >/tmp/received &
receiver=$!
labvm_wait_receiver vcan0 raw
echo "__MESSAGE__" | timeout 30 isotpsend -s 7E0 -d 7E8 -p CC vcan0
wait $receiver
echo "received: $(cat /tmp/received)"
""".replace("__MESSAGE__", MESSAGE),
    # The kernel's ISO-TP socket (dcos-can --kernel) sends, our own state machines receive.
    "kernel_isotp_to_ours": PRELUDE + r"""
timeout 30 /tmp/dcos-can -i vcan0 isotp-recv -s 7E8 -d 7E0 -t 20000 >/tmp/received &
receiver=$!
labvm_wait_receiver vcan0 raw
/tmp/dcos-can -i vcan0 isotp-send --kernel -s 7E0 -d 7E8 "__MESSAGE__"
echo "sent: $?"
wait $receiver
echo "received: $(cat /tmp/received)"
""".replace("__MESSAGE__", MESSAGE),
    # Our own state machines send, the kernel's ISO-TP socket (dcos-can --kernel) receives.
    "ours_to_kernel_isotp": PRELUDE + r"""
timeout 30 /tmp/dcos-can -i vcan0 --json isotp-recv --kernel -s 7E8 -d 7E0 -t 20000 >/tmp/received &
receiver=$!
labvm_wait_receiver vcan0 isotp 7e0
/tmp/dcos-can -i vcan0 isotp-send -s 7E0 -d 7E8 "__MESSAGE__"
wait $receiver
cat /tmp/received
""".replace("__MESSAGE__", MESSAGE),
    # Counting: five frames of 8 bytes in a listening window.
    "stats": PRELUDE + r"""
timeout 30 /tmp/dcos-can -i vcan0 --json stats -s 4 --bitrate 500000 >/tmp/stats.json &
stats=$!
labvm_wait_receiver vcan0 raw
for i in 1 2 3 4 5; do cansend vcan0 12345678#0011223344556677; done
wait $stats
cat /tmp/stats.json
""",
}


@pytest.fixture(scope="module")
def outcome():
    if not os.path.exists(DCOS_CAN):
        pytest.fail(f"{DCOS_CAN} is not built; run make", pytrace=False)
    with open(DCOS_CAN, "rb") as handle:
        binary = handle.read()
    command, files = check_command(CHECKS, timeout_each=CHECK_TIMEOUT)
    files["dcos-can"] = binary
    try:
        result = run(command, vcan=["vcan0"], files=files, boot_timeout=BOOT_TIMEOUT,
                     timeout=CHECK_TIMEOUT * len(CHECKS) + 30)
    except LabVMError as error:
        pytest.fail(f"the lab VM failed:\n{error}", pytrace=False)
    return result, parse_checks(result, CHECKS)


def check(outcome, name):
    result, checks = outcome
    found = checks[name]
    assert found.status == 0, (f"check {name} ended with status {found.status}:\n{found.output}\n"
                               f"----- lab VM console -----\n{result.transcript}")
    return found.output


def test_frames_dcos_can_sends_reach_candump(outcome):
    output = check(outcome, "send")
    assert output.splitlines() == ["vcan0 123#11223344", "vcan0 1ABCDEF0#0102", "vcan0 7FF#R2"], output


def test_dcos_can_dumps_what_cansend_sends_and_decodes_dcos_frames(outcome):
    lines = [json.loads(line) for line in check(outcome, "dump").splitlines() if line.startswith("{")]
    assert [(frame["id"], frame["extended"], frame["data"]) for frame in lines] == [
        (0x0320FF05, True, "0102"), (0x456, False, "DEADBEEF")], lines
    # Two bytes are no part of a publication (docs/protocols/publications.md): said so, not guessed at.
    assert lines[0]["dcos"] == {"priority": 3, "type": "DSM publication", "source": 5, "destination": 255,
                                "publication": {"malformed": "wrong length"}}
    assert "dcos" not in lines[1], "a standard frame is not a DCOS frame"
    assert all(frame["timestamp_ns"] > 0 for frame in lines), "the kernel's receive timestamps"


def test_our_isotp_sender_is_understood_by_the_kernel(outcome):
    received = [line for line in check(outcome, "isotp_to_kernel").splitlines() if line.startswith("received:")]
    assert received and received[0].split()[1:] == MESSAGE.split(), received


def test_our_isotp_receiver_understands_the_kernel(outcome):
    received = [line for line in check(outcome, "isotp_from_kernel").splitlines() if line.startswith("received:")]
    assert received and received[0].split()[1:] == MESSAGE.split(), received


def test_the_kernels_isotp_socket_through_dcos_can_talks_to_our_own_isotp(outcome):
    output = check(outcome, "kernel_isotp_to_ours")
    assert "sent: 0" in output, output
    received = [line for line in output.splitlines() if line.startswith("received:")]
    assert received and received[0].split()[1:] == MESSAGE.split(), output


def test_our_own_isotp_reaches_the_kernels_isotp_socket_through_dcos_can(outcome):
    [answer] = [json.loads(line) for line in check(outcome, "ours_to_kernel_isotp").splitlines() if line.startswith("{")]
    assert answer["length"] == 100 and answer["data"].split() == MESSAGE.split(), answer


def test_stats_counts_frames_and_bus_load(outcome):
    lines = [json.loads(line) for line in check(outcome, "stats").splitlines() if line.startswith("{")]
    assert len(lines) == 1, lines
    stats = lines[0]
    assert stats["frames"] == 5 and stats["extended_frames"] == 5, stats
    # Five 160-bit frames at 500 kbit/s in about 4 s: 0.04 % of the bus.
    assert 0.02 < stats["bus_load_percent"] < 0.1, stats
