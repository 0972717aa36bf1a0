"""The console shell on the production image: banner, commands, line editing, errors."""

import re

from dcoslab.board import EXIT_PASS

PROMPT = r"dcos> "

# On-target tests this module runs (see test_kernel_core.test_every_target_test_is_run).
BOARD_TARGET_TESTS = ["txflood"]


def test_banner_and_prompt(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(r"DCOS \d+\.\d+\.\d+ - Distributed Controller Operating System\r\n")
    emulator.expect(r"board isa486 \(i486DX\), node 1, \d+ KiB memory, tick 1000 Hz\r\n")
    emulator.expect(PROMPT)


def test_help_lists_every_command(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    output = emulator.command("help")
    names = re.findall(r"^  (\S+) ", output, re.MULTILINE)
    assert names == sorted(names)
    assert {"echo", "help", "mem", "uptime", "version"} <= set(names)
    assert "test" not in names, "the production image must not contain the test command"
    assert "usage: uptime" in emulator.command("help uptime")


def test_version_names_release_board_and_loader(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    output = emulator.command("version")
    assert re.search(r"DCOS \d+\.\d+\.\d+ \(revision \S+\)", output)
    assert "board isa486, processor i486DX" in output
    assert "loaded by" in output


def test_uptime_advances(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    pattern = r"up 0 d \d\d:\d\d:\d\d\.\d\d\d \((\d+) ticks at 1000 Hz\)"
    first = int(re.search(pattern, emulator.command("uptime")).group(1))
    second = first
    for _ in range(50):
        second = int(re.search(pattern, emulator.command("uptime")).group(1))
        if second > first:
            break
    assert second > first


def test_mem_shows_the_memory_map(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    output = emulator.command("mem")
    assert re.search(r"memory +6\d\d KiB conventional, 15\d\d\d KiB extended", output)
    image = re.search(r"image +([0-9a-f]{8})-([0-9a-f]{8})", output)
    assert image and int(image.group(1), 16) == 0x100000
    # The page tables follow the image; free memory follows them, to the end.
    paging = re.search(r"paging +([0-9a-f]{8})-([0-9a-f]{8})", output)
    assert paging and paging.group(1) == image.group(2)
    free = re.search(r"free +([0-9a-f]{8})-([0-9a-f]{8})", output)
    assert free and free.group(1) == paging.group(2) and int(free.group(1), 16) % 4096 == 0
    assert int(free.group(2), 16) == 0x1000000


def test_bad_arguments_print_the_usage_line(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    assert emulator.command("uptime now") == "usage: uptime\r\n"
    assert emulator.command("mem all") == "usage: mem\r\n"
    assert emulator.command("version 2") == "usage: version\r\n"
    assert emulator.command("help a b") == "usage: help [command]\r\n"


def test_unknown_command_is_named(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    assert emulator.command("reboot now") == "error: unknown command 'reboot'; type 'help' for the list\r\n"


def test_backspace_edits_the_line(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    emulator.send("ecgo\b\bho hello\x7f\x7fp!\r")
    emulator.expect(r"\r\nhelp!\r\n" + PROMPT)


def test_line_longer_than_the_receive_ring_is_received_whole(boot, isa486):
    # The UART's receive ring holds 64 bytes; this line is 4 times longer
    # and is sent in one burst.
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    text = "".join(chr(ord("a") + i % 26) for i in range(240))
    output = emulator.command("echo " + text)
    assert output == text + "\r\n"


def test_line_longer_than_the_editor_is_refused_and_nothing_runs(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    emulator.send("echo " + "x" * 400 + "\r")
    emulator.expect(r"error: line too long \(at most 255 characters\); nothing was run\r\n" + PROMPT)
    assert emulator.command("echo still alive") == "still alive\r\n"


def test_output_longer_than_the_transmit_ring_arrives_intact(boot, isa486):
    emulator = boot(isa486, "test")
    emulator.expect(PROMPT)
    emulator.send("test txflood --exit\r")
    emulator.expect(r"TEST txflood: start\r\n")
    for line in range(64):
        body = "".join(chr(ord("A") + (line + column) % 26) for column in range(5, 70))
        emulator.expect(re.escape(f"{line:04d}:{body}\r\n"), timeout=60)
    emulator.expect(r"TEST txflood: PASS")
    emulator.expect_exit(EXIT_PASS)


def test_arrow_keys_recall_and_edit_lines_instead_of_running_as_commands(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    emulator.command("version")
    # Up recalls "version"; Enter runs it again (its echo is the redrawn line).
    emulator.send("\x1b[A\r")
    emulator.expect(r"version\r\nDCOS \d+\.\d+\.\d+", timeout=10)
    emulator.expect(PROMPT)
    # Left twice, Delete, Right, "e": "uptiem" becomes "uptime".
    emulator.send("uptiem\x1b[D\x1b[D\x1b[3~\x1b[Ce\r")
    emulator.expect(r"up \d+ d \d\d:\d\d:\d\d", timeout=10)
    emulator.expect(PROMPT)
    # A function key, Home/End and a modified arrow do nothing at all: the
    # line stays empty and Enter shows just another prompt.
    emulator.send("\x1b[15~\x1b[H\x1b[F\x1b[1;5D\x1bOP\r")
    emulator.expect(PROMPT, timeout=10)
    assert "unknown command" not in emulator.transcript


# Every listing writes an object id as 0x and eight hex digits; a bare
# eight-digit word in one of them is an id written the old way.
OBJECT_ID = re.compile(r"\b0x[0-9a-f]{8}\b")
BARE_WORD = re.compile(r"(?<![x0-9a-f])[0-9a-f]{8}\b")
LISTINGS = ("tasks", "semaphores", "ports", "pools", "heaps", "devices")


def test_listings_write_ids_one_way_and_name_their_objects(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    assert "present" in emulator.command("iobus probe")  # installs the device mfio0
    outputs = {listing: emulator.command(listing) for listing in LISTINGS}
    for listing, output in outputs.items():
        header = output.splitlines()[0]
        assert header.startswith("id  "), (listing, output)
        for row in output.splitlines()[1:]:
            assert not BARE_WORD.search(OBJECT_ID.sub("", row)), (listing, row)
    # Names where the agents keep them: the kernel's tasks, the shell's life semaphore, the device.
    assert re.search(r"^0x[0-9a-f]{8} +shell +\d+ ", outputs["tasks"], re.MULTILINE), outputs["tasks"]
    assert re.search(r"^0x[0-9a-f]{8} +shell-life +binary +0 +0x[0-9a-f]{8} +priority +", outputs["semaphores"],
                     re.MULTILINE), outputs["semaphores"]
    assert re.search(r"^0x[0-9a-f]{8}  mfio0 +0  system +regional", outputs["devices"], re.MULTILINE), \
        outputs["devices"]
    # The id of the shell in 'tasks' is the holder of its life semaphore in 'semaphores'.
    shell_id = re.search(r"^(0x[0-9a-f]{8}) +shell ", outputs["tasks"], re.MULTILINE).group(1)
    assert re.search(rf"shell-life +binary +0 +{shell_id} ", outputs["semaphores"]), outputs["semaphores"]


def test_help_explains_the_columns_and_flags_of_listings(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(PROMPT)
    tasks = emulator.command("help tasks")
    assert "usage: tasks" in tasks
    assert "flags: S super-user, T time slicing, F floating point, D deadline scheduling" in tasks
    assert "used: its high-water mark" in tasks
    for listing in LISTINGS:
        assert "id: the object id, 0x and eight hex digits" in emulator.command(f"help {listing}"), listing
