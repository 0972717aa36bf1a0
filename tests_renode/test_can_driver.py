"""The SJA1000 driver (drivers/can) and its `can` console command on emulated boards joined by the lab's CAN bus.

The production image drives the card through the driver, as an engineer
would at the console: channels come up at a bit rate, frames go out and come
in as can-utils writes them, a lone node backs off, and ISO-TP messages pass
between two controllers. The hub's bus log is the independent witness of
what was on the bus. The driver's register-level behaviour is tested on the
host against a fake chip (drivers/can/unit_tests); the card itself in
test_can_bus.py.
"""

import re
import time

import pytest

from dcoslab.canbus import Frame
from dcoslab.target import run_target_test

# On-target tests of the driver, in the test image (tests_renode/target/CanDriverTest.cpp).
CAN_DRIVER_TARGET_TESTS = [
    "candrvbusoff",  # 1,000 CPU-forced bus-offs, each recovered and reported to the owner
]

TWO_BOARDS = {"board1": {"bus0": "can0"}, "board2": {"bus0": "can0"}}
# Emulated time per wall second: the tests type commands while the bus runs.
PACE = 1.0


# Bounds a hung board or hub; never a measure of speed.
TIMEOUT = 120.0


def up(board, rate):
    output = board.command(f"can up can0 {rate}")
    assert re.search(rf"can0 up at 0x280 irq 10: {rate} bit/s, sample point \d+\.\d %, error-active", output), output


def stats(board):
    """The counters of `can stats can0` as a dict."""
    output = board.command("can stats can0")
    match = re.search(r"can0 (sent=.*?)\r?$", output, re.MULTILINE)
    assert match, output
    return {key: int(value) for key, value in (word.split("=") for word in match.group(1).split())}


def events(board, count=0, ms=5000):
    """The state changes the driver reported to the console task, its owner: [(state, was, rx, tx)] and lost."""
    output = board.command(f"can events can0 {count} {ms}")
    changes = [(m.group(1), m.group(2), int(m.group(3)), int(m.group(4))) for m in re.finditer(
        r"^can0  (\S+)  was (\S+)  rx errors (\d+)  tx errors (\d+)\r?$", output, re.MULTILINE)]
    lost = re.search(r"^can0  (\d+) earlier state changes lost", output, re.MULTILINE)
    assert len(changes) >= count, output
    return changes, int(lost.group(1)) if lost else 0


def test_frames_sent_at_one_console_are_dumped_at_the_other(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    sender, receiver = lab.board("board1"), lab.board("board2")
    for board in (sender, receiver):
        up(board, 500_000)
    receiver.emulator.send("can dump can0 2 60000\r")
    receiver.emulator.expect(r"can dump can0 2 60000\r\n")
    for frame, shown in (("1ABCDEF0#DE.AD.BE.EF", "1ABCDEF0   [4]  DE AD BE EF"), ("123#R2", "123        [2]  remote request")):
        output = sender.command(f"can send can0 {frame}")
        assert f"can0  {shown}  sent" in output, output
        receiver.emulator.expect(re.escape(f"can0  {shown}") + r"\r\n")
    receiver.emulator.expect(r"dcos> ")
    records = [r for r in lab.hub.frames() if r.sender == "board1.0"]
    assert [(r.frame.id, r.frame.extended, r.outcome, r.ack) for r in records] == [
        (0x1ABCDEF0, True, "ok", ("board2.0",)), (0x123, False, "ok", ("board2.0",))], lab.hub.log_text()
    state = receiver.command("can stats can0")
    assert re.search(r"can0 sent=0 received=2 ", state), state


def test_a_lone_node_backs_off_instead_of_flooding_the_bus(canlab):
    lab = canlab({"can0": 500_000}, {"board1": {"bus0": "can0"}}, pace=PACE, kind="production")
    board = lab.board("board1")
    up(board, 500_000)
    output = board.command("can send can0 123#01 3000")
    assert ("error: not sent within 3000 ms: error-passive, 128 transmit errors, no other node acknowledges; "
            "the frame stays queued") in output, output
    assert "can0  error-passive  500000 bit/s  rx errors 0  tx errors 128  queued 1  no acknowledge: held" in \
        board.command("can state can0")
    attempts = len([r for r in lab.hub.frames() if r.sender == "board1.0"])
    # 16 acknowledge errors, then the abort; one attempt may be under way when it comes.
    assert 16 <= attempts <= 17, lab.hub.log_text()
    assert all(r.outcome == "ack-error" for r in lab.hub.frames()), lab.hub.log_text()
    stats = board.command("can stats can0")
    assert re.search(r"ack_errors=1[67] .* lone_node_holds=1 ", stats), stats
    # The owner learned it: the counters' way to error-passive, then the hold.
    output = board.command("can events can0")
    assert re.findall(r"^can0  (.*?)  rx errors (\d+)  tx errors (\d+)\r?$", output, re.MULTILINE) == [
        ("error-warning  was error-active", "0", "96"), ("error-passive  was error-warning", "0", "128"),
        ("no acknowledge: held  error-passive", "0", "128")], output
    # Held: nothing more goes on the bus while nobody is there.
    board.command("can dump can0 1 500")
    assert len([r for r in lab.hub.frames() if r.sender == "board1.0"]) == attempts, lab.hub.log_text()


def test_an_isotp_message_passes_between_two_controllers(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    sender, receiver = lab.board("board1"), lab.board("board2")
    for board in (sender, receiver):
        up(board, 500_000)
    message = bytes(range(100))
    receiver.emulator.send("can isotp-recv can0 7E8 7E0 60000\r")
    receiver.emulator.expect(r"can isotp-recv can0 7E8 7E0 60000\r\n")
    output = sender.command(f"can isotp-send can0 7E0 7E8 {message.hex()}")
    assert "can0  isotp 100 bytes sent" in output, output
    receiver.emulator.expect(r"can0  isotp 100 bytes: ((?:[0-9A-F]{2} ?)+)\r\n")
    received = receiver.emulator.transcript.split("isotp 100 bytes: ")[1].split("\r\n")[0]
    assert bytes.fromhex(received) == message
    frames = [r.frame for r in lab.hub.frames()]
    # A first frame, 14 consecutive frames on 7E0, and the flow control on 7E8.
    assert sum(1 for f in frames if f.id == 0x7E0) == 15 and sum(1 for f in frames if f.id == 0x7E8) == 1, \
        lab.hub.log_text()
    assert frames[0].data[:2] == bytes([0x10, 100]), lab.hub.log_text()


def test_a_stale_flow_control_does_not_start_the_next_isotp_transfer(canlab):
    # A flow control that came after an earlier transfer timed out (a slow
    # peer) waits in the channel's queue. The next transfer must wait for the
    # flow control its own first frame asks for, as a Linux can-isotp socket
    # does, and not send consecutive frames to a peer that is not listening.
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    sender, other = lab.board("board1"), lab.board("board2")
    for board in (sender, other):
        up(board, 500_000)
    lab.hub.inject("can0", "lab", Frame.data_frame(0x7E8, bytes([0x30, 0x00, 0x00])))
    deadline = time.monotonic() + TIMEOUT
    while not any(r.frame.id == 0x7E8 and r.outcome == "ok" for r in lab.hub.frames()):
        assert time.monotonic() < deadline, lab.hub.log_text()
        time.sleep(0.05)
    output = sender.command(f"can isotp-send can0 7E0 7E8 {bytes(range(100)).hex()}")
    assert "error: ISO-TP transfer failed: N_Bs time-out" in output, output
    sent = [r.frame for r in lab.hub.frames() if r.sender == "board1.0"]
    assert len(sent) == 1 and sent[0].id == 0x7E0 and sent[0].data[:2] == bytes([0x10, 100]), lab.hub.log_text()


# -- faults on the driver: each reported to the owner and shown by `can state`/`can stats` --


def test_forced_error_passive_is_reported_to_the_owner_and_sending_brings_it_back_to_error_active(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    board, other = lab.board("board1"), lab.board("board2")
    for each in (board, other):
        up(each, 500_000)
    lab.hub.force_passive("board1.0")
    changes, lost = events(board, 1)
    assert changes == [("error-passive", "error-active", 0, 128)] and lost == 0, changes
    assert "can0  error-passive  500000 bit/s  rx errors 0  tx errors 128  queued 0" in board.command("can state can0")
    # Each frame sent takes one from TEC: below 128 error-active again, with
    # the warning flag (SR.ES) until below the warning limit of 96.
    assert "sent" in board.command("can send can0 123#01")
    changes, _ = events(board, 1)
    assert changes == [("error-warning", "error-passive", 0, 127)], changes
    for n in range(32):
        output = board.command(f"can send can0 123#{n:02X}")
        assert f"can0  123        [1]  {n:02X}  sent" in output, output
    changes, _ = events(board, 1)
    assert changes == [("error-active", "error-warning", 0, 95)], changes
    assert "can0  error-active  500000 bit/s  rx errors 0  tx errors 95  queued 0" in board.command("can state can0")
    counters = stats(board)
    assert (counters["passives"], counters["warnings"], counters["actives"], counters["sent"], counters["bus_offs"]) \
        == (1, 1, 1, 33, 0), counters
    assert stats(other)["received"] == 33
    assert all(r.outcome == "ok" for r in lab.hub.frames()), lab.hub.log_text()


def test_bus_off_forced_by_the_hub_and_automatic_recovery_a_hundred_times_without_lock_up(canlab):
    # One board: a recovery needs only the idle bus. At any bit rate it is
    # 128 x 11 bit times, 35.2 of the hub's quanta of 40 bit times, so each
    # cycle costs some 39 lock-step quanta of wall time, whatever the rate;
    # everything is decided by emulated time alone. A hundred cycles through
    # the hub here (a few seconds); the thousand run on target, without the
    # hub's lock-step (candrvbusoff, below), in about 1.4 s of emulated time.
    lab = canlab({"can0": 1_000_000}, {"board1": {"bus0": "can0"}}, kind="production")
    board = lab.board("board1")
    up(board, 1_000_000)
    T, Q = lab.bit_ns("can0"), lab.hub.quantum_ns
    recovery = 128 * 11 * T
    cycles = 100
    started = time.monotonic()
    for _ in range(cycles):
        # The fault lands at the next boundary, at most two quanta on; the
        # board's routine restarts the chip at once (microseconds), and the
        # hub tells the 128th bus-free signal at most one quantum late. One
        # quantum more is ample for the routine that sees the recovery end.
        now = lab.hub.now_ns
        lab.hub.force_bus_off("board1.0")
        lab.hub.wait_until(now + 4 * Q + recovery, TIMEOUT)
    print(f"{cycles} bus-off cycles in {time.monotonic() - started:.1f} s wall time")
    assert lab.hub.log_text().count("fault board1.0 busoff") == cycles
    counters = stats(board)
    assert (counters["bus_offs"], counters["restarts"], counters["recoveries"], counters["actives"]) == \
        (cycles, cycles, cycles, cycles), counters
    assert counters["interrupt_loop_limits"] == 0, counters
    # The owner was told of every change; its log kept the newest 16.
    changes, lost = events(board)
    assert counters["state_changes_lost"] == lost, counters
    assert lost == 2 * cycles - 16 and len(changes) == 16, (lost, changes)
    assert changes[-2:] == [("bus-off", "error-active", 0, 127), ("error-active", "bus-off", 0, 0)], changes
    assert "can0  error-active  1000000 bit/s  rx errors 0  tx errors 0  queued 0" in board.command("can state can0")
    # Not locked up: it receives and sends as before (a hub node is the other end).
    lab.hub.inject("can0", "peer", Frame.data_frame(0x321, b"\x09"))
    assert "can0  321        [1]  09" in board.command("can dump can0 1 5000")
    assert "can0  1ABCDEF0   [2]  01 02  sent" in board.command("can send can0 1ABCDEF0#01.02")
    counters = stats(board)
    assert (counters["sent"], counters["received"], counters["bus_errors"]) == (1, 1, 0), counters
    assert [(r.sender, r.outcome) for r in lab.hub.frames()] == [("hub.peer", "ok"), ("board1.0", "ok")], \
        lab.hub.log_text()


def test_bus_off_waits_for_restart_under_the_manual_policy_then_recovers_in_128_times_11_bits(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    board, other = lab.board("board1"), lab.board("board2")
    for each in (board, other):
        up(each, 500_000)
    assert "can0  after bus-off: wait for 'can restart'" in board.command("can policy can0 manual")
    lab.hub.force_bus_off("board1.0")
    changes, _ = events(board, 1)
    assert changes == [("bus-off", "error-active", 0, 127)], changes
    assert "can0  1 of 1 frames queued" in board.command("can queue can0 0AA#55")
    # Far longer than a recovery: it stays off the bus, its frame queued.
    T = lab.bit_ns("can0")
    lab.hub.wait_until(lab.hub.now_ns + 3 * 128 * 11 * T, TIMEOUT)
    assert "can0  bus-off  500000 bit/s  rx errors 0  tx errors 127  queued 1" in board.command("can state can0")
    assert not lab.hub.frames(), lab.hub.log_text()
    assert "can0  restarted" in board.command("can restart can0")
    changes, _ = events(board, 1)
    assert changes == [("error-active", "bus-off", 0, 0)], changes
    assert "can0  0AA        [1]  55" in other.command("can dump can0 1 5000")
    [record] = lab.hub.frames()
    assert record.sender == "board1.0" and record.outcome == "ok", lab.hub.log_text()
    # The restart left the chip its own recovery: the frame went only after
    # 128 bus-free signals of 11 bits from the moment it left reset mode.
    recover = [int(m.group(1)) for m in re.finditer(r"board1\.0 recover from (\d+) ns", lab.hub.log_text())]
    assert len(recover) == 1, lab.hub.log_text()
    assert record.start >= recover[0] + 128 * 11 * T, (record.start, recover, lab.hub.log_text())
    counters = stats(board)
    assert (counters["bus_offs"], counters["restarts"], counters["recoveries"], counters["sent"]) == (1, 1, 1, 1), \
        counters


def test_a_babbling_node_holds_the_queued_frames_back_and_they_all_go_once_it_stops(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    board, other = lab.board("board1"), lab.board("board2")
    for each in (board, other):
        up(each, 500_000)
    assert "can0  filter standard only" in other.command("can filter can0 std 100 7FC")
    chatter = Frame.data_frame(0x010, bytes(range(8)))
    lab.hub.babble("can0", "babbler", chatter)
    lab.hub.wait_for_records(lambda records: records, TIMEOUT)
    assert "can0  3 of 3 frames queued" in board.command("can queue can0 102#02 100#00 101#01")
    lab.hub.wait_for_records(lambda records: len(records) >= 40, TIMEOUT)
    assert not [r for r in lab.hub.frames() if r.sender == "board1.0"], lab.hub.log_text()
    # Waiting is no error: still error-active, everything still queued.
    assert "can0  error-active  500000 bit/s  rx errors 0  tx errors 0  queued 3" in board.command("can state can0")
    held = stats(board)
    assert held["sent"] == 0 and held["arbitration_lost"] >= 10 and held["bus_errors"] == 0, held
    lab.hub.stop_babble("babbler")
    output = other.command("can dump can0 3 5000")
    assert re.findall(r"can0  (10[0-2])  ", output) == ["100", "101", "102"], output
    mine = [r for r in lab.hub.frames() if r.sender == "board1.0"]
    assert [(r.frame.id, r.outcome) for r in mine] == [(0x100, "ok"), (0x101, "ok"), (0x102, "ok")], \
        lab.hub.log_text()
    last_babble = [r for r in lab.hub.frames() if r.sender == "hub.babbler"][-1]
    assert mine[0].start > last_babble.start
    counters = stats(board)
    assert counters["sent"] == 3 and counters["aborts"] == 0, counters
    assert "queued 0" in board.command("can state can0")
    assert stats(other)["received"] == 3


def test_corrupted_frames_are_counted_by_the_sending_and_the_receiving_driver(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    sender, receiver = lab.board("board1"), lab.board("board2")
    for each in (sender, receiver):
        up(each, 500_000)
    lab.hub.corrupt("board1.0", 3)
    lab.hub.sync_commands()  # The fault is armed before the frame starts.
    assert "can0  077        [2]  AA BB  sent" in sender.command("can send can0 077#AA.BB")
    assert "can0  077        [2]  AA BB" in receiver.command("can dump can0 1 5000")
    assert [r.outcome for r in lab.hub.frames()] == ["form-error"] * 3 + ["ok"], lab.hub.log_text()
    sent, heard = stats(sender), stats(receiver)
    # Three error frames: a bit error for the sender (TEC + 8 each), a form
    # error for the receiver (REC + 1 each); then one good frame (- 1 each).
    assert (sent["bus_errors"], sent["ack_errors"], sent["sent"]) == (3, 0, 1), sent
    assert (heard["bus_errors"], heard["received"]) == (3, 1), heard
    assert "can0  error-active  500000 bit/s  rx errors 0  tx errors 23  queued 0" in sender.command("can state can0")
    assert "can0  error-active  500000 bit/s  rx errors 2  tx errors 0  queued 0" in receiver.command("can state can0")


# -- bad input from the bus --


def inject_and_receive(lab, board, frames, good):
    """Has a hub node send frames and then a good one; returns the board's dump of one frame."""
    for frame in frames + [good]:
        lab.hub.inject("can0", "lab", frame)
    output = board.command("can dump can0 1 5000")
    lab.hub.wait_for_records(lambda records: len(records) == len(frames) + 1, TIMEOUT)
    assert all(r.outcome == "ok" for r in lab.hub.frames()), lab.hub.log_text()
    return output


def test_frames_with_a_bad_identifier_are_rejected_and_counted_and_the_next_good_one_is_intact(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    board, other = lab.board("board1"), lab.board("board2")
    for each in (board, other):
        up(each, 500_000)
    # Extended identifiers with ID.28 set, as the filter asks. The chip takes
    # standard frames with ID.10 set as well (it has no format bit to compare).
    assert "can0  filter extended only" in board.command("can filter can0 ext 10000000 10000000")
    assert "can0  filter extended only" in other.command("can filter can0 ext 10000043 1FFFFFFF")
    assert "error: '800' is not a hexadecimal number up to 7FF" in board.command("can filter can0 std 800 7FF")
    assert "usage: can policy" in board.command("can policy can0 sometimes")
    wrong_format = Frame.data_frame(0x400, b"\x01\x02")    # through the chip's filter, not the driver's
    filtered = Frame.data_frame(0x123, b"\x03")              # stopped by the chip's filter, never seen
    good = Frame.data_frame(0x10000042, bytes.fromhex("DEADBEEF"), extended=True)
    output = inject_and_receive(lab, board, [wrong_format, filtered], good)
    assert "can0  10000042   [4]  DE AD BE EF" in output, output
    assert "0 of 1 frames" in board.command("can dump can0 1 500"), "nothing else was passed on"
    counters = stats(board)
    assert (counters["received"], counters["malformed"], counters["bad_ids"]) == (1, 0, 1), counters
    assert (counters["chip_overruns"], counters["rx_queue_overruns"], counters["bus_errors"]) == (0, 0, 0), counters
    assert "can0  error-active  500000 bit/s  rx errors 0  tx errors 0  queued 0" in board.command("can state can0")
    # Nothing else disturbed: the channel sends as before.
    assert "can0  10000043   [1]  01  sent" in board.command("can send can0 10000043#01")
    assert "can0  10000043   [1]  01" in other.command("can dump can0 1 5000")


# A data frame of DLC 9-15 and a remote frame asking for data used to leave
# the card's receive FIFO out of step (the model stored and released them
# with different lengths), so the frame after them was garbage: the good
# frame after each is the check.
def test_frames_with_a_bad_length_are_rejected_and_counted_and_the_next_good_one_is_intact(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    board, other = lab.board("board1"), lab.board("board2")
    for each in (board, other):
        up(each, 500_000)
    bad_lengths = [Frame(0x10000001, True, False, dlc, bytes(range(8))) for dlc in range(9, 16)]
    bad_lengths.append(Frame(0x10000002, True, True, 12, b""))  # a remote frame asking for 12 bytes
    good = Frame.data_frame(0x10000042, bytes.fromhex("DEADBEEF"), extended=True)
    output = inject_and_receive(lab, board, bad_lengths, good)
    assert "can0  10000042   [4]  DE AD BE EF" in output, output
    assert "0 of 1 frames" in board.command("can dump can0 1 500"), "nothing else was passed on"
    counters = stats(board)
    assert (counters["received"], counters["malformed"], counters["chip_overruns"]) == (1, 8, 0), counters


# The same with ordinary traffic: a remote frame asking for two bytes, then a data frame.
def test_a_remote_frame_with_a_length_code_and_the_frame_after_it_arrive_intact(canlab):
    lab = canlab({"can0": 500_000}, TWO_BOARDS, pace=PACE, kind="production")
    board, other = lab.board("board1"), lab.board("board2")
    for each in (board, other):
        up(each, 500_000)
    output = inject_and_receive(lab, board, [Frame(0x123, False, True, 2, b"")], Frame.data_frame(0x124, b"\x01\x02"))
    assert "can0  123        [2]  remote request" in output, output
    output += board.command("can dump can0 1 5000")
    assert "can0  124        [2]  01 02" in output, output


@pytest.mark.parametrize("name", CAN_DRIVER_TARGET_TESTS)
def test_can_driver_on_target(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)
