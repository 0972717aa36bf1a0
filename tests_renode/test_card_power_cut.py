"""Power cuts at every write of a controller's boot-state changes, on the
emulated board (docs/boot.md, "Power cuts"): the harness stops the board
at exactly its Nth write to the card (dcoslab/powercut.py), starts it again
on the same card, and checks that it runs the old or the new verified image
and that the update can be retried to its end.

The phases here are the trial (the stage loader records it), the
confirmation and the revert, each of whose writes is cut in turn; and the
download, cut at sampled writes (every write of a download, torn or not,
is cut in the host tests, firmware/flash/unit_tests/PowerCutTest.cpp, on
the same session code).
"""
import os
import subprocess

import pytest

from dcoslab.cards import BIN, DEVELOPMENT_KEY, card_state, new_card, signed, tool


def updating_card(tmp_path, boot, isa486):
    """A card whose slot A (1.0.0) is confirmed and whose slot B (1.1.0) is pending."""
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False))
    first = boot(isa486, card=card)
    first.expect(r"dcos> ")
    first.close()
    tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.0"), "--pending")
    return card


def settle(boot, isa486, card):
    """Starts the board after a cut; returns (emulator at its prompt, slot it runs, on trial)."""
    emulator = boot(isa486, card=card)
    # To the line's end: the console may have printed only part of it yet.
    match = emulator.expect(r"command line: node=3 boot\.slot=([AB]) boot\.version=(\S+?)( boot\.trial=1)?"
                            r"( boot\.reverted=1)?\r\n")
    slot, version, trial = match.group(1).decode(), match.group(2).decode(), match.group(3) is not None
    assert (slot, version) in (("A", "1.0.0"), ("B", "1.1.0")), (slot, version)
    if version == "1.1.0" and not trial:
        assert card_state_of(emulator, card)["boot_state"]["confirmed"] == "B", "the new image runs unconfirmed"
    emulator.expect(r"dcos> ")
    return emulator, slot, trial


def card_state_of(emulator, card):
    emulator.close()
    return card_state(card)


# The writes of the update after the download: the stage loader records the
# trial (write 1), the new image confirms (write 2).
@pytest.mark.parametrize("writes", [0, 1])
def test_a_power_cut_at_each_write_of_a_trial_and_its_confirmation(boot, isa486, tmp_path, writes):
    card = updating_card(tmp_path, boot, isa486)
    emulator = boot(isa486, card=card, power_cut_after=writes)
    if writes >= 1:
        emulator.expect(r"boot\.trial=1")
        emulator.expect(r"dcos> ")
        emulator.send("boot confirm\r")
    emulator.wait_power_cut()
    emulator.close()
    # Power back: the old image, or the new one on trial; then the update to its end.
    after, slot, trial = settle(boot, isa486, card)
    if trial:
        assert "confirmed:" in after.command("boot confirm")
    after.close()
    if slot == "A":
        tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.0"), "--pending")
        retried = boot(isa486, card=card)
        retried.expect(r"boot\.slot=B boot\.version=1\.1\.0 boot\.trial=1")
        retried.expect(r"dcos> ")
        assert "confirmed:" in retried.command("boot confirm")
        retried.close()
    state = card_state(card)["boot_state"]
    assert state["confirmed"] == "B" and state["trial"] == "none", state


def test_a_power_cut_at_the_revert_of_a_trial_that_never_confirmed(boot, isa486, tmp_path):
    card = updating_card(tmp_path, boot, isa486)
    trial = boot(isa486, card=card)
    trial.expect(r"boot\.trial=1")
    trial.close()  # It never confirms: the board is reset (here: switched off).
    # The next start's stage loader writes the revert first: cut that write.
    emulator = boot(isa486, card=card, power_cut_after=0)
    emulator.expect(r"stage: boot state \d+: confirmed slot A, trial booting in slot B")
    emulator.wait_power_cut()
    emulator.close()
    after, slot, is_trial = settle(boot, isa486, card)
    assert (slot, is_trial) == ("A", False), "the revert is made again"
    after.close()
    state = card_state(card)["boot_state"]
    assert state["confirmed"] == "A" and state["trial"] == "none" and state["reverts"] == 1, state


# A download of the minimal image over the serial line writes the slot's
# header sector, its payload's 243 sectors one by one, and the pending
# state: 245 writes. Cut before the first, in the middle, and before the
# payload's last sector; the cut before the pending state is below.
# How long dcos-flash waits for each answer before it says "no answer"
# (exit 4). This board runs in host time, so on a host busy with other
# emulators (a lab VM beside it in the suite) a write that did not fail can
# take seconds to be answered; 4 s was once too short, and dcos-flash gave up
# before the board reached the cut write. The wait is spent only once, after
# the cut.
ANSWER_TIMEOUT_MS = "10000"


def assert_cut(cut):
    """dcos-flash's end at the cut: the board stopped at the failed write,
    so nothing answered (exit 4). On a busy host the board's ATA driver may
    give up on the write first (its wait is a count of polls, and this
    board runs in host time), and the node answers that its card failed
    (exit 1); the write did not reach the card either way. After exit 4 the
    board stops at it (wait_power_cut); after exit 1 it may never issue it."""
    assert (cut.returncode == 4 and "no answer" in cut.stderr) or \
        (cut.returncode == 1 and "the node's card cannot be read or written" in cut.stderr), cut.stdout + cut.stderr


@pytest.mark.parametrize("writes", [0, 122, 243])
def test_a_power_cut_during_a_download_leaves_the_card_as_it_was_and_the_download_can_be_retried(
        boot, isa486, tmp_path, writes):
    card = new_card(tmp_path, append="node=4")
    image = signed(tmp_path, "2.0.0", firmware="dcos486-minimal.elf")
    # A first start records the new card's boot state, so that the writes
    # counted below are the download's.
    first = boot(isa486, card=card)
    first.expect(r"stage: recovery: waiting for an image on this serial line")
    first.close()
    emulator = boot(isa486, card=card, power_cut_after=writes)
    emulator.expect(r"stage: recovery: waiting for an image on this serial line")
    emulator.release_console()
    cut = subprocess.run([os.path.join(BIN, "dcos-flash"), "-d", f"unix:{emulator.console_socket_path}",
                          "-k", DEVELOPMENT_KEY, "--timeout-ms", ANSWER_TIMEOUT_MS, "--retries", "0", image],
                         capture_output=True, text=True, timeout=300)
    assert_cut(cut)
    if cut.returncode == 4:
        emulator.wait_power_cut()
    # Exit 1: the board's driver gave up on a write first (a busy host, see
    # assert_cut) and abandoned the download, so the write after the cut may
    # never be issued and the board need not stop; the card holds at most
    # the first N writes either way, which is what the rest checks.
    emulator.close()
    assert card_state(card)["boot_state"]["trial"] == "none", "nothing half-written is pending"
    again = boot(isa486, card=card)
    again.expect(r"stage: recovery: waiting for an image on this serial line")
    again.release_console()
    tool("dcos-flash", "-d", f"unix:{again.console_socket_path}", "-k", DEVELOPMENT_KEY, "--no-restart", image,
         timeout=300)
    again.close()
    state = card_state(card)
    assert state["boot_state"]["trial"] == "pending" and state["slots"]["A"]["version"] == "2.0.0", state


def test_a_power_cut_before_a_whole_download_is_marked_pending_leaves_it_a_trial(boot, isa486, tmp_path):
    # Cut at the 245th write: the payload is whole on the card and verifies,
    # but it was never marked pending. With nothing confirmed, the next
    # start runs it, but only as a trial that must confirm.
    card = new_card(tmp_path, append="node=4")
    image = signed(tmp_path, "2.0.0", firmware="dcos486-minimal.elf")
    first = boot(isa486, card=card)
    first.expect(r"stage: recovery: waiting for an image on this serial line")
    first.close()
    emulator = boot(isa486, card=card, power_cut_after=244)
    emulator.expect(r"stage: recovery: waiting for an image on this serial line")
    emulator.release_console()
    cut = subprocess.run([os.path.join(BIN, "dcos-flash"), "-d", f"unix:{emulator.console_socket_path}",
                          "-k", DEVELOPMENT_KEY, "--timeout-ms", ANSWER_TIMEOUT_MS, "--retries", "0", image],
                         capture_output=True, text=True, timeout=300)
    assert_cut(cut)
    emulator.wait_power_cut()
    emulator.close()
    state = card_state(card)
    assert state["boot_state"]["trial"] == "none" and state["slots"]["A"]["valid"] is True, state
    again = boot(isa486, card=card)
    again.expect(r"stage: no confirmed image: a valid one on trial")
    again.expect(r"stage: watchdog armed")
    again.expect(r"SELFCHECK: PASS")
