"""`make run`'s launcher boots the production image with the console on a terminal."""

import os
import sys

import pexpect

from dcoslab.board import REPOSITORY

LAUNCHER = os.path.join(REPOSITORY, "tests_renode", "launch.py")


def test_launcher_gives_an_interactive_console():
    # A pseudo-terminal, like the engineer's own terminal.
    session = pexpect.spawn(sys.executable, [LAUNCHER, "--board", "isa486"], timeout=60, encoding="latin-1")
    try:
        session.expect(r"DCOS \d+\.\d+\.\d+ - Distributed Controller Operating System")
        session.expect(r"dcos> ")
        session.send("help\r")
        session.expect(r"uptime +show the time")
        session.expect(r"dcos> ")
        # Ctrl-A X leaves the emulator, as the launcher says.
        session.send("\x01x")
        session.expect(pexpect.EOF)
    except (pexpect.TIMEOUT, pexpect.EOF) as error:
        raise AssertionError(f"launcher session failed: {error}\n----- console -----\n{session.before}") from None
    finally:
        session.close(force=True)


def test_launcher_boots_a_card_through_the_bios_and_the_stage_loader(tmp_path):
    # make run CARD=1 boots build/486/card-486.img; a copy here, since a boot
    # may write the card's boot state.
    card = tmp_path / "card.img"
    card.write_bytes(open(os.path.join(REPOSITORY, "build", "486", "card-486.img"), "rb").read())
    session = pexpect.spawn(sys.executable, [LAUNCHER, "--board", "isa486", "--card", str(card)], timeout=60,
                            encoding="latin-1")
    try:
        session.expect(r"stage: DCOS stage loader")
        session.expect(r"stage: slot A: isa486 \S+, signature and digest valid")
        session.expect(r"loaded by DCOS stage loader|command line: boot\.slot=A")
        session.expect(r"dcos> ")
        session.send("boot\r")
        session.expect(r"boot: slot A, version \S+")
        session.expect(r"dcos> ")
        session.send("\x01x")
        session.expect(pexpect.EOF)
    except (pexpect.TIMEOUT, pexpect.EOF) as error:
        raise AssertionError(f"launcher session failed: {error}\n----- console -----\n{session.before}") from None
    finally:
        session.close(force=True)


def test_unknown_board_is_refused_with_the_list():
    session = pexpect.spawn(sys.executable, [LAUNCHER, "--board", "vax"], timeout=60, encoding="latin-1")
    session.expect(pexpect.EOF)
    session.close()
    assert "unknown board 'vax'; the boards are: isa486" in session.before
    assert session.exitstatus != 0


def test_launcher_names_the_code_a_fault_report_points_at():
    """A task's fault report on the console is followed by its function and line."""
    image = os.path.join(REPOSITORY, "build", "486", "dcos486-test.elf")
    session = pexpect.spawn(sys.executable, [LAUNCHER, "--board", "isa486", "--image", image], timeout=60,
                            encoding="latin-1")
    try:
        session.expect(r"dcos> ")
        session.send("test nullwrite\r")
        session.expect(r"task nullwrite \(0x[0-9a-f]{8}\) terminated: fatal exception, vector 14 .* at EIP=([0-9a-f]{8})")
        eip = session.match.group(1)
        session.expect(rf"{eip} is \(anonymous namespace\)::nullWrite\(unsigned int\) at "
                       r"tests_renode/target/MemoryProtectionTest\.cpp:\d+")
        session.expect(r"TEST nullwrite: PASS")
        session.expect(r"dcos> ")
        session.send("\x01x")
        session.expect(pexpect.EOF)
    except (pexpect.TIMEOUT, pexpect.EOF) as error:
        raise AssertionError(f"launcher session failed: {error}\n----- console -----\n{session.before}") from None
    finally:
        session.close(force=True)


def test_make_run_passes_board_and_kernel_options():
    """`make run ARGS=...` hands launcher options through: a model property and two kernel options."""
    arguments = "--set isa-mfio.stuck-di-bit=3 --append node=3 --append tick_hz=100"
    session = pexpect.spawn("make", ["--no-print-directory", "-C", REPOSITORY, "run", f"ARGS={arguments}"],
                            timeout=300, encoding="latin-1")
    try:
        session.expect(r"node 3, \d+ KiB memory, tick 100 Hz")
        session.expect(r"dcos> ")
        # The stuck bit shows through the I/O board's loopback: DO bit 3 set, DI bit 3 stays 0.
        session.send("iobus write do 0x000f\r")
        session.expect(r"do=0x000f")
        session.expect(r"dcos> ")
        session.send("iobus read di\r")
        session.expect(r"di=0x0007")
        session.expect(r"dcos> ")
        session.send("\x01x")
        session.expect(pexpect.EOF)
    except (pexpect.TIMEOUT, pexpect.EOF) as error:
        raise AssertionError(f"make run session failed: {error}\n----- console -----\n{session.before}") from None
    finally:
        session.close(force=True)
