"""Flashing a controller over its serial line (docs/protocols/flash.md,
docs/guide/flashing.md): dcos-flash against the stage loader in recovery on
the emulated board's COM1, with the board's own card.

The images are the minimal firmware (about 120 KiB, some 11 s of the
115200 bit/s line), signed with the development key the card trusts. The
boards run in real time: the emulated UART sends at its bit rate in the
emulator's clock, and a stage loader that polls it makes exact-time
emulation crawl (the trial's watchdog and its revert are
test_card_boot.py's, in exact time).
"""
import json
import os
import signal
import subprocess
import time

from dcoslab import cards
from dcoslab.cards import BIN, BUILT, DEVELOPMENT_KEY, tool



def signed(directory, version, key=DEVELOPMENT_KEY):
    return cards.signed(directory, version, firmware="dcos486-minimal.elf", key=key)


def empty_card(tmp_path):
    path = tmp_path / "card.img"
    tool("dcos-card", "create", "-o", str(path), "--boot-sector", os.path.join(BUILT, "boot-sector.bin"),
         "--stage", os.path.join(BUILT, "stage-loader.bin"), "-p", DEVELOPMENT_KEY + ".pub", "--append", "node=4")
    return str(path)


def in_recovery(boot, isa486, card):
    emulator = boot(isa486, card=card)
    emulator.expect(r"stage: recovery: waiting for an image on this serial line")
    emulator.release_console()
    return emulator


def flash(emulator, *arguments, code=0):
    return tool("dcos-flash", "-d", f"unix:{emulator.console_socket_path}", "--json", *arguments, code=code,
                timeout=300)


def test_a_node_in_recovery_takes_an_image_over_its_serial_line_and_tries_it(boot, isa486, tmp_path):
    card = empty_card(tmp_path)
    emulator = in_recovery(boot, isa486, card)
    info = json.loads(flash(emulator, "info").stdout)
    assert info == {"node": 4, "mode": "recovery", "protocol": 1, "confirmed": "none", "trial": "none",
                    "trial_slot": "none", "slot_a": "empty", "slot_b": "empty", "transfer_slot": "none",
                    "transfer_offset": 0}, info
    image = signed(tmp_path, "2.0.0")
    done = json.loads(flash(emulator, "-k", DEVELOPMENT_KEY, "-n", "4", image).stdout)
    assert done["slot"] == "A" and done["version"] == "2.0.0" and done["restarted"] is True, done
    assert done["bytes"] == os.path.getsize(image) - 256 and done["resumed_from"] == 0, done
    # The node restarted into the trial: the minimal image's self-check,
    # which ends some seconds after the restart, shows it running.
    emulator.reattach_console()
    emulator.expect(r"SELFCHECK: PASS", timeout=120)
    emulator.close()
    state = json.loads(tool("dcos-card", "--json", "show", card).stdout)
    assert state["boot_state"]["trial"] == "booting" and state["boot_state"]["trial_slot"] == "A", state
    assert state["slots"]["A"]["valid"] is True and state["slots"]["A"]["version"] == "2.0.0", state


def test_the_node_refuses_a_stranger_and_an_image_it_does_not_trust(boot, isa486, tmp_path):
    card = empty_card(tmp_path)
    emulator = in_recovery(boot, isa486, card)
    stranger = tmp_path / "stranger.pem"
    tool("dcos-image", "keygen", "-o", str(stranger))
    refused = flash(emulator, "-k", str(stranger), signed(tmp_path, "2.0.0"), code=1)
    assert "authentication failed" in refused.stderr, refused.stderr
    untrusted = signed(tmp_path, "2.0.1", key=str(stranger))
    refused = flash(emulator, "-k", DEVELOPMENT_KEY, untrusted, code=1)
    assert "the image is refused: signed by a key this controller does not trust" in refused.stderr, refused.stderr
    assert "not node 9" in flash(emulator, "-k", DEVELOPMENT_KEY, "-n", "9", signed(tmp_path, "2.0.2"),
                                 code=1).stderr
    info = json.loads(flash(emulator, "info").stdout)
    assert info["slot_a"] == "empty" and info["trial"] == "none", "nothing was written"


def test_an_interrupted_transfer_resumes_where_it_stopped(boot, isa486, tmp_path):
    card = empty_card(tmp_path)
    emulator = in_recovery(boot, isa486, card)
    image = signed(tmp_path, "2.0.0")
    command = [os.path.join(BIN, "dcos-flash"), "-d", f"unix:{emulator.console_socket_path}", "-k",
               DEVELOPMENT_KEY, "--json", "--no-restart", image]
    first = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    time.sleep(3)  # About a quarter of the transfer.
    first.send_signal(signal.SIGKILL)
    first.wait(timeout=30)
    held = json.loads(tool("dcos-flash", "-d", f"unix:{emulator.console_socket_path}", "--json", "info").stdout)
    assert held["transfer_slot"] == "A" and held["transfer_offset"] > 0, held
    refused = tool("dcos-flash", "-d", f"unix:{emulator.console_socket_path}", "-k", DEVELOPMENT_KEY, "--resume",
                   signed(tmp_path, "2.0.1"), code=1)
    assert "holds no interrupted transfer" in refused.stderr, "another image is not the one to resume"
    done = json.loads(tool("dcos-flash", *command[1:], "--resume", timeout=300).stdout)
    assert 0 < done["resumed_from"] < done["bytes"], done
    assert done["restarted"] is False
    emulator.close()
    # A power cycle: the card's pending image starts as a trial, whole.
    again = boot(isa486, card=card)
    again.expect(r"stage: slot A: isa486 2\.0\.0, signature and digest valid")
    again.expect(r"stage: a new image on trial")
    again.expect(r"SELFCHECK: PASS")
