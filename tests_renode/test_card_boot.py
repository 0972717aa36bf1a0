"""The controller starts from its CompactFlash card (docs/boot.md): the BIOS
runs the card's boot sector, which starts the stage loader, which verifies
the slots' signed images and starts one. Each test makes its own card with
dcos-card from the built boot sector, stage loader and development key
(mk/card.mk), so what is on the card is what the test says.
"""
import os
import re
import subprocess
import time

from dcoslab.cards import (BIN, BUILT, DEVELOPMENT_KEY, SECTOR, SLOT_LBA, card_state, new_card, put_in_slot, signed,
                           tool)

FIRMWARE = os.path.join(BUILT, "dcos486.elf")


def flip_payload_byte(path, slot, offset):
    with open(path, "r+b") as card:
        card.seek((SLOT_LBA[slot] + 1) * SECTOR + offset)
        byte = card.read(1)[0]
        card.seek(-1, os.SEEK_CUR)
        card.write(bytes([byte ^ 0x01]))


def test_the_board_boots_its_card_through_the_bios_and_the_stage_loader(boot, isa486, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0+1"), False))
    # dcos-card confirms the image it writes to a card that confirms nothing yet.
    assert card_state(card)["boot_state"]["confirmed"] == "A"
    emulator = boot(isa486, card=card)
    emulator.expect(r"stage: DCOS stage loader")
    emulator.expect(r"stage: configuration 1: 1 trusted key")
    emulator.expect(r"stage: boot state 1: confirmed slot A, trial none")
    emulator.expect(r"stage: slot A: isa486 1\.0\.0\+1, signature and digest valid")
    emulator.expect(r"stage: the confirmed image")
    emulator.expect(r"stage: starting slot A")
    emulator.expect(r"board isa486 \(i486DX\), node 3,")
    emulator.expect(r"command line: node=3 boot\.slot=A boot\.version=1\.0\.0\+1")
    emulator.expect(r"dcos> ")
    assert "boot.trial" not in emulator.transcript
    emulator.close()
    state = card_state(card)["boot_state"]
    assert state["confirmed"] == "A" and state["trial"] == "none" and state["sequence"] == 1, state


def test_an_image_nothing_confirmed_boots_only_as_a_trial(boot, isa486, tmp_path):
    # A valid image on a card that confirms nothing (written by a card
    # reader, or a download cut before it was marked pending) must prove
    # itself like any new image.
    card = new_card(tmp_path)
    put_in_slot(card, "A", signed(tmp_path, "1.0.0"))
    emulator = boot(isa486, card=card)
    emulator.expect(r"stage: no boot state on the card: a new card")
    emulator.expect(r"stage: no confirmed image: a valid one on trial")
    emulator.expect(r"command line: node=3 boot\.slot=A boot\.version=1\.0\.0 boot\.trial=1")
    emulator.expect(r"dcos> ")
    assert "confirmed:" in emulator.command("boot confirm")
    emulator.close()
    assert card_state(card)["boot_state"]["confirmed"] == "A"


def test_an_altered_confirmed_image_is_refused_and_the_other_slot_boots(boot, isa486, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False), ("B", signed(tmp_path, "1.0.1"), False))
    flip_payload_byte(card, "A", 100000)
    emulator = boot(isa486, card=card)
    emulator.expect(r"stage: slot A: isa486 1\.0\.0: the payload is not the one its signed header describes")
    emulator.expect(r"stage: slot B: isa486 1\.0\.1, signature and digest valid")
    emulator.expect(r"command line: node=3 boot\.slot=B boot\.version=1\.0\.1")
    emulator.expect(r"dcos> ")
    emulator.close()
    assert card_state(card)["boot_state"]["confirmed"] == "B"


def test_a_card_without_a_trusted_image_stays_in_recovery(boot, isa486, tmp_path):
    other = tmp_path / "other.pem"
    tool("dcos-image", "keygen", "-o", str(other))
    stranger = signed(tmp_path, "9.0.0", key=str(other))
    card = new_card(tmp_path)
    # dcos-card refuses the stranger's image (the card does not trust its
    # key); a card reader would not: put it there byte for byte.
    put_in_slot(card, "A", stranger)
    emulator = boot(isa486, card=card)
    emulator.expect(r"stage: slot A: signed by a key this controller does not trust")
    emulator.expect(r"stage: slot B: not a DCOS controller image")
    emulator.expect(r"stage: recovery: no valid image on the card: recovery")
    emulator.close()
    assert "dcos> " not in emulator.transcript, "no kernel started"


def test_a_pending_image_boots_once_as_a_trial_and_is_reverted_when_it_never_confirms(boot, isa486, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False))
    first = boot(isa486, card=card)
    first.expect(r"dcos> ")
    first.close()
    tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.0"), "--pending")
    assert card_state(card)["boot_state"]["trial"] == "pending"
    # Exact emulated time: the idle node's 30 s of watchdog pass in a
    # second or two of the host's.
    emulator = boot(isa486, card=card, icount=True)
    emulator.expect(r"stage: a new image on trial: it must confirm before the watchdog expires")
    emulator.expect(r"stage: watchdog armed")
    emulator.expect(r"command line: node=3 boot\.slot=B boot\.version=1\.1\.0 boot\.trial=1")
    emulator.expect(r"dcos> ")
    # Nobody confirms: the watchdog resets the board, and the stage loader
    # reverts to the confirmed image.
    emulator.expect(r"stage: DCOS stage loader", timeout=120)
    emulator.expect(r"stage: boot state \d+: confirmed slot A, trial booting in slot B")
    emulator.expect(r"stage: the new image never confirmed: reverted to the confirmed one")
    emulator.expect(r"command line: node=3 boot\.slot=A boot\.version=1\.0\.0 boot\.reverted=1")
    emulator.expect(r"dcos> ")
    emulator.close()
    state = card_state(card)["boot_state"]
    assert state["confirmed"] == "A" and state["trial"] == "none" and state["reverts"] == 1, state


def test_dcos_card_refuses_what_the_stage_loader_would_not_boot(tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False))
    shown = card_state(card)
    assert shown["slots"]["A"]["valid"] is True and shown["slots"]["B"] is None
    assert shown["configuration"]["command_line"] == "node=3"
    tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.0"), "--pending")
    assert card_state(card)["boot_state"]["trial"] == "pending"
    tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.1"))
    assert card_state(card)["boot_state"]["trial"] == "none", "the image the trial was for is gone"
    card_tool = os.path.join(BIN, "dcos-card")

    def refused(*arguments, code=1):
        result = subprocess.run([card_tool, *arguments], capture_output=True, text=True, timeout=60)
        assert result.returncode == code, result.stdout + result.stderr
        return result.stderr

    other = tmp_path / "other.pem"
    tool("dcos-image", "keygen", "-o", str(other))
    assert "does not trust" in refused("write", card, "--slot", "B", signed(tmp_path, "2.0.0", key=str(other)))
    assert "neither A nor B" in refused("write", card, "--slot", "C", signed(tmp_path, "2.0.0"), code=2)
    assert "not a card image" in refused("show", signed(tmp_path, "2.0.0"))
    small = tmp_path / "small.bin"
    small.write_bytes(bytes(100))
    assert "boot sector" in refused("create", "-o", str(tmp_path / "x.img"), "--boot-sector", str(small),
                                    "--stage", os.path.join(BUILT, "stage-loader.bin"), "-p", DEVELOPMENT_KEY + ".pub")
    assert not (tmp_path / "x.img").exists()


def test_dcos_card_writes_the_nodes_identity_for_the_configuration_protocol(tmp_path):
    # docs/protocols/config.md: the serial number a scan finds the node by,
    # its configuration key, whether queries are closed, the lockout.
    key = tmp_path / "node.key"
    key.write_text("00112233445566778899aabbccddeeff" * 2 + "\n")
    card = new_card(tmp_path, options=("--serial", "4711", "--config-key", str(key), "--closed-queries",
                                       "--lockout", "90"))
    configuration = card_state(card)["configuration"]
    assert (configuration["serial"], configuration["configuration_key"], configuration["queries"],
            configuration["lockout_seconds"]) == (4711, True, "closed", 90), configuration
    with open(card, "rb") as handle:
        handle.seek(SECTOR * 256 + 440)  # The configuration's first copy (docs/boot.md), its identity fields.
        fields = handle.read(39)
    assert fields[:4] == (4711).to_bytes(4, "little") and fields[4:36] == bytes.fromhex(key.read_text().strip())
    assert fields[36] == 3 and fields[37:39] == (90).to_bytes(2, "little")
    # Without them: no serial, no key (nothing can be changed over the bus), open queries, 60 s.
    (tmp_path / "plain").mkdir()
    plain = card_state(new_card(tmp_path / "plain"))["configuration"]
    assert (plain["serial"], plain["configuration_key"], plain["queries"], plain["lockout_seconds"]) == \
        (0, False, "open", 60), plain
    # A key file that is not 64 hexadecimal digits is refused before any card is made.
    bad = tmp_path / "bad.key"
    bad.write_text("00112233")
    result = subprocess.run([os.path.join(BIN, "dcos-card"), "create", "-o", str(tmp_path / "bad.img"),
                             "--boot-sector", os.path.join(BUILT, "boot-sector.bin"), "--stage",
                             os.path.join(BUILT, "stage-loader.bin"), "-p", DEVELOPMENT_KEY + ".pub",
                             "--config-key", str(bad)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 4 and "64 hexadecimal digits" in result.stderr, result.stderr
    assert not (tmp_path / "bad.img").exists()


def test_dcos_card_keeps_the_confirmed_slot_and_refuses_a_downgrade(boot, isa486, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.2.0"), False))
    emulator = boot(isa486, card=card)
    emulator.expect(r"dcos> ")
    emulator.close()
    card_tool = os.path.join(BIN, "dcos-card")
    result = subprocess.run([card_tool, "write", card, "--slot", "A", signed(tmp_path, "1.3.0")],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 1 and "holds the confirmed image" in result.stderr, result.stderr
    result = subprocess.run([card_tool, "write", card, "--slot", "B", signed(tmp_path, "1.1.9")],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 1 and "older than the installed image" in result.stderr, result.stderr
    tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.9"), "--allow-downgrade")
    assert card_state(card)["slots"]["B"]["version"] == "1.1.9"


def emulated_seconds(emulator):
    """The node's uptime in whole seconds, from the uptime command."""
    output = emulator.command("uptime")
    match = re.search(r"up (\d+) d (\d+):(\d+):(\d+)", output)
    assert match, output
    days, hours, minutes, seconds = (int(group) for group in match.groups())
    return ((days * 24 + hours) * 60 + minutes) * 60 + seconds


def test_a_trial_that_confirms_stays_and_boots_from_then_on(boot, isa486, tmp_path):
    card = new_card(tmp_path, ("A", signed(tmp_path, "1.0.0"), False))
    first = boot(isa486, card=card)
    first.expect(r"dcos> ")
    assert "this image is confirmed already" in first.command("boot confirm")
    first.close()
    tool("dcos-card", "write", card, "--slot", "B", signed(tmp_path, "1.1.0"), "--pending")
    emulator = boot(isa486, card=card, icount=True)
    emulator.expect(r"boot\.trial=1")
    emulator.expect(r"dcos> ")
    status = emulator.command("boot")
    assert "boot: slot B, version 1.1.0, on trial" in status, status
    assert "confirmed slot A, trial booting in slot B" in status, status
    assert "confirmed: this image boots from now on, and the watchdog is stopped" in emulator.command("boot confirm")
    assert "confirmed slot B, trial none" in emulator.command("boot")
    # Well past the watchdog's 30 s of emulated time: no reset comes.
    deadline = time.monotonic() + 120
    while emulated_seconds(emulator) < 45:
        assert time.monotonic() < deadline, "the emulated clock did not reach 45 s"
        time.sleep(0.2)
    assert emulator.transcript.count("stage: DCOS stage loader") == 1, "the board was reset"
    emulator.close()
    state = card_state(card)["boot_state"]
    assert state["confirmed"] == "B" and state["trial"] == "none" and state["reverts"] == 0, state
    again = boot(isa486, card=card)
    again.expect(r"stage: the confirmed image")
    again.expect(r"command line: node=3 boot\.slot=B boot\.version=1\.1\.0\r")
    again.expect(r"dcos> ")


def test_a_node_started_without_its_card_has_nothing_to_confirm(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(r"dcos> ")
    assert "not from the card" in emulator.command("boot")
    emulator.send("boot confirm\r")
    emulator.expect(r"boot: this node was not started from its card: there is nothing to confirm")
