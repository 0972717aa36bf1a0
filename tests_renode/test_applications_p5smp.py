"""Applications for the dual-Pentium board (BOARD=p5smp): one application, both nodes.

An application built with BOARD=p5smp is linked twice from its objects and
libdcosp5smp.a: as node 3's image at 16 MiB, stripped and carried as data
in node 2's image, which starts it on the second processor
(mk/application.mk, docs/guide/dual-pentium-board.md). These tests build
from a fresh installation and from the staged one in <build>/sdk, check
both images, and boot the board with node 3's console on a socket
(dcoslab/node_console.py). A failure names both consoles' transcripts.
test_applications.py holds the build helpers and DCOS_TEST_BUILD.
"""

import contextlib
import os
import re
import subprocess
import tty

import pexpect
import pexpect.fdpexpect
import pytest

from dcoslab.board import load_board
from dcoslab.emulator import EmulatorError
from dcoslab.node_console import NodeConsole

from test_applications import APPLICATION_MAKEFILE, BUILD_TIMEOUT, run_make

NODE3_ADDRESS = 0x1000000

# One source on both nodes: the worker says where it runs, and counts rounds.
TWO_NODE_SOURCE = """\
#include <dcos/Application.hpp>
#include <dcos/TaskAgent.hpp>
#include <bsp/Board.hpp>
#include <runtime/Format.hpp>
#include <shell/Shell.hpp>
#include <shell/ShellCommand.hpp>

#if !defined(DCOS_BOARD_P5SMP)
#error "built for the dual-Pentium board only"
#endif

namespace {
volatile uint32_t rounds;
volatile unsigned ranOn;

void worker(uintptr_t)
{
    ranOn = bsp::nodeId();
    runtime::format(bsp::console(), "twonode: worker runs on node %u\\r\\n", unsigned(bsp::nodeId()));
    for (uint32_t round = 1;; ++round) {
        (void)dcos::taskAgent.SleepFor(100'000'000);
        rounds = round;
    }
}

shell::CommandResult whereCommand(shell::Shell& shell, int, char**)
{
    shell.print("twonode: worker on node %u, %lu rounds\\r\\n", ranOn, static_cast<unsigned long>(rounds));
    return shell::CommandResult::Ok;
}

constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "worker", .entry = worker, .priority = 12}};
} // namespace

DCOS_SHELL_COMMAND(whereShellCommand, "where", "where the twonode worker runs", "where", whereCommand);
DCOS_APPLICATION(twonode, {.name = "twonode", .tasks = tasks});
"""

# The minimal kernel has no shell: the worker says where it runs every round,
# so that node 3's console, reached after it booted, still hears it.
MINIMAL_SOURCE = """\
#include <dcos/Application.hpp>
#include <dcos/TaskAgent.hpp>
#include <bsp/Board.hpp>
#include <runtime/Format.hpp>

namespace {
void worker(uintptr_t)
{
    for (unsigned long round = 1;; ++round) {
        (void)dcos::taskAgent.SleepFor(200'000'000);
        runtime::format(bsp::console(), "twonode: node %u round %lu\\r\\n", unsigned(bsp::nodeId()), round);
    }
}
constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "worker", .entry = worker}};
} // namespace

DCOS_APPLICATION(twonode, {.name = "twonode", .tasks = tasks});
"""


@pytest.fixture
def p5smp():
    return load_board("p5smp")


def write_application(directory, source=TWO_NODE_SOURCE):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "twonode.cpp"), "w", encoding="utf-8") as handle:
        handle.write(source)
    return directory


def build(makefile, directory, *arguments):
    result = subprocess.run(["make", "--no-print-directory", "-f", str(makefile), f"APP={directory}", "BOARD=p5smp",
                             *arguments], capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode == 0, result.stdout + result.stderr
    return result.stdout + result.stderr


def load_segments(image):
    """The virtual addresses of an ELF image's loadable segments."""
    output = subprocess.run(["readelf", "-lW", image], capture_output=True, text=True, check=True, timeout=60).stdout
    return [int(address, 16) for address in re.findall(r"^\s+LOAD\s+0x[0-9a-f]+ (0x[0-9a-f]+)", output, re.M)]


def symbols(image):
    output = subprocess.run(["nm", image], capture_output=True, text=True, check=True, timeout=60).stdout
    return {name: int(value, 16) for value, _, name in (line.split() for line in output.splitlines()
                                                          if len(line.split()) == 3)}


def check_both_images(node2_image, node3_image, tmp_path, checker):
    # Node 3's image lies wholly in the upper half; node 2's below it.
    assert load_segments(node3_image) and min(load_segments(node3_image)) >= NODE3_ADDRESS
    assert load_segments(node2_image) and max(load_segments(node2_image)) < NODE3_ADDRESS
    # Node 2's image carries node 3's, stripped, under the names BoardP5smp.cpp looks for.
    stripped = tmp_path / "node3-stripped.elf"
    subprocess.run(["objcopy", "--strip-all", node3_image, str(stripped)], check=True, timeout=60)
    found = symbols(node2_image)
    assert found["_binary_node3_stripped_elf_end"] - found["_binary_node3_stripped_elf_start"] == \
        os.path.getsize(stripped)
    # Both pass the Pentium's instruction check, as the build ran it.
    for image in (node2_image, node3_image):
        result = subprocess.run(["/usr/bin/python3", str(checker), "--cpu", "pentium", image], capture_output=True,
                                text=True, timeout=300)
        assert result.returncode == 0 and "pentium clean" in result.stdout, result.stdout + result.stderr


@contextlib.contextmanager
def node3_console(emulator):
    """Node 3's console, at a fresh prompt; a failure inside carries its transcript."""
    node3 = NodeConsole(emulator, "node3")
    try:
        yield node3
    except AssertionError as error:
        raise AssertionError(f"{error}\n----- node 3 console -----\n{node3.transcript}") from None
    finally:
        node3.close()


def boot_both_nodes(boot, board, image, icount=True):
    emulator = boot(board, image, icount=icount, serial_sockets=("node3",))
    emulator.expect(r"node 3 started on the processor with APIC id 1 \(image at 0x1000000, \d+ bytes; console COM4\)")
    return emulator


def test_an_application_from_a_fresh_install_runs_on_both_nodes(tmp_path, boot, p5smp):
    prefix = tmp_path / "opt" / "dcos"
    run_make(["install", f"PREFIX={prefix}"])
    for installed in ["lib/dcos/p5smp/libdcosp5smp.a", "lib/dcos/p5smp/libdcosp5smp-minimal.a",
                      "lib/dcos/p5smp/link.ld", "lib/dcos/p5smp/dcos-p5smp.elf", "share/dcos/board-p5smp.mk",
                      "share/dcos/board-486.mk", "lib/dcos/486/libdcos486.a", "share/dcos/boards/p5smp.json",
                      "lib/dcos/p5smp/include/bsp/P5smpBoard.hpp"]:
        assert (prefix / installed).exists(), installed
    # Each board's tick header where that board's builds find it first.
    assert "tickTimerDivisor" in (prefix / "include" / "bsp" / "BoardTick.hpp").read_text()
    assert "apicTickCounts" in (prefix / "lib" / "dcos" / "p5smp" / "include" / "bsp" / "BoardTick.hpp").read_text()
    assert '"production": "lib/dcos/p5smp/dcos-p5smp.elf"' in (prefix / "share/dcos/boards/p5smp.json").read_text()
    assert '"production": "lib/dcos/486/dcos486.elf"' in (prefix / "share/dcos/boards/isa486.json").read_text()

    application = write_application(str(tmp_path / "twonode"))
    output = build(prefix / "share" / "dcos" / "application.mk", application)
    node2_image = os.path.join(application, "build", "twonode-p5smp.elf")
    node3_image = os.path.join(application, "build", "twonode-p5smp-node3.elf")
    assert f"{node3_image}: pentium clean" in output and f"{node2_image}: pentium clean" in output, output
    assert f"application twonode: {node2_image} (carries twonode-p5smp-node3.elf)" in output, output
    check_both_images(node2_image, node3_image, tmp_path, prefix / "share" / "dcos" / "tools" / "check_i486.py")

    emulator = boot_both_nodes(boot, p5smp, node2_image)
    emulator.expect(r"application 'twonode' started: 1 task\r\n")
    emulator.expect(r"twonode: worker runs on node 2\r\n")
    emulator.expect(r"dcos> ")
    with node3_console(emulator) as node3:
        node3.prompt()
        listing = node3.command("app")
        assert "application 'twonode': running" in listing, listing
        assert re.search(r"task +worker +0x0003[0-9a-f]{4}", listing), listing
        assert re.search(r"twonode: worker on node 3, \d+ rounds", node3.command("where"))
        version = node3.command("version")
        assert "board p5smp" in version and "loaded by node 2 (second processor start)" in version, version
    assert re.search(r"twonode: worker on node 2, \d+ rounds", emulator.command("where"))
    assert re.search(r"task +worker +0x0002[0-9a-f]{4}", emulator.command("app"))


def test_a_board_the_installation_lacks_is_named_with_the_installed_ones(tmp_path):
    application = write_application(str(tmp_path / "twonode"))
    result = subprocess.run(["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={application}",
                             "BOARD=pentium"], capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode != 0
    assert "BOARD=pentium is not a board this DCOS builds for; its boards are: 486 p5smp" in result.stderr


def test_a_486_build_of_a_p5smp_only_source_is_refused_by_its_board_macro(tmp_path):
    # DCOS_BOARD_486 / DCOS_BOARD_P5SMP: the board an application is compiled for.
    application = write_application(str(tmp_path / "twonode"))
    result = subprocess.run(["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={application}"],
                            capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode != 0
    assert "built for the dual-Pentium board only" in result.stderr


def test_the_minimal_configuration_runs_on_both_nodes(tmp_path, boot, p5smp):
    application = write_application(str(tmp_path / "twonode"), MINIMAL_SOURCE)
    output = build(APPLICATION_MAKEFILE, application, "KERNEL_CONFIG=minimal")
    node2_image = os.path.join(application, "build", "twonode-p5smp-minimal.elf")
    node3_image = os.path.join(application, "build", "twonode-p5smp-minimal-node3.elf")
    assert f"{node3_image}: pentium clean" in output, output
    check_both_images(node2_image, node3_image, tmp_path,
                      os.path.join(os.path.dirname(APPLICATION_MAKEFILE), "tools", "check_i486.py"))
    emulator = boot_both_nodes(boot, p5smp, node2_image)
    emulator.expect(r"kernel configuration minimal\r\n")
    emulator.expect(r"application 'twonode' started: 1 task\r\n")
    emulator.expect(r"twonode: node 2 round 3\r\n")
    with node3_console(emulator) as node3:
        try:
            node3.expect(r"twonode: node 3 round \d+\r\n")
        except EmulatorError as error:
            raise AssertionError(str(error)) from None


def test_run_boots_both_nodes_with_node_3_on_a_terminal(tmp_path):
    # The application build's `run`, as `make run APP=<dir> BOARD=p5smp` calls it.
    application = write_application(str(tmp_path / "twonode"))
    build(APPLICATION_MAKEFILE, application)
    session = pexpect.spawn("make", ["--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={application}",
                                     "BOARD=p5smp", "run"], timeout=120, encoding="latin-1")
    node3 = None
    try:
        session.expect(r"char device redirected to (/dev/pts/\d+) \(label node3\)")
        terminal = session.match.group(1)
        session.expect(r"application 'twonode' started: 1 task")
        session.expect(r"twonode: worker runs on node 2")
        descriptor = os.open(terminal, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(descriptor)
        node3 = pexpect.fdpexpect.fdspawn(descriptor, timeout=60, encoding="latin-1")
        node3.send("where\r")
        node3.expect(r"twonode: worker on node 3, \d+ rounds")
        node3.expect(r"dcos> ")
        session.send("\x01x")
        session.expect(pexpect.EOF)
    except (pexpect.TIMEOUT, pexpect.EOF) as error:
        raise AssertionError(f"run session failed: {error}\n----- node 2 console -----\n{session.before}"
                             f"\n----- node 3 console -----\n{node3.before if node3 else ''}") from None
    finally:
        if node3 is not None:
            node3.close()
        session.close(force=True)
