"""Applications outside the tree (seed 8.2): built, booted and tested against
the tree and against an installed DCOS, and every configuration error named.

The application build is mk/application.mk, installed as
share/dcos/application.mk; `make test` stages an installation in build/sdk,
which most tests here use directly, so that they never run two top-level
makes at once. The on-target loader tests live in
tests_renode/target/ApplicationLoaderTest.cpp.
"""

import json
import os
import re
import shutil
import subprocess
import textwrap

import pytest

from dcoslab.board import REPOSITORY
from dcoslab.target import run_target_test

# The tree's build folder (make's BUILD): build/, or the one DCOS_TEST_BUILD
# names (relative to the tree), for a run against another engineer's build.
BUILD = os.environ.get("DCOS_TEST_BUILD", "build")
STAGED_SDK = os.path.join(REPOSITORY, BUILD, "sdk")
APPLICATION_MAKEFILE = os.path.join(STAGED_SDK, "share", "dcos", "application.mk")
COUNTER_EXAMPLE = os.path.join(REPOSITORY, "docs", "examples", "counter")
# Generous: bounds a hung build or nested test run, it does not measure speed.
BUILD_TIMEOUT = 600

APPLICATION_TARGET_TESTS = [
    "appstart",  # every kind of object created, ids stored before any task runs, owners, stop
    "apprules",  # the compiler's rules checked again at run time: priority, stack, duplicate, reserved name
    "appfail",   # name in use, full table, no stack memory, overlapping areas: named, and all rolled back
]


@pytest.mark.parametrize("name", APPLICATION_TARGET_TESTS)
def test_application_loader(boot, isa486, name):
    run_target_test(boot(isa486, "test", icount=True), name)


def test_image_without_an_application_says_so(boot, isa486):
    emulator = boot(isa486)
    emulator.expect(r"dcos> ")
    assert emulator.command("app").strip() == "no application is linked into this image"


# --- Building applications with the staged installation ----------------------

HELLO_SOURCE = """\
#include <dcos/Application.hpp>
#include <bsp/Board.hpp>
#include <runtime/Format.hpp>

namespace {{
dcos::ObjectId greetings;

void greeter(uintptr_t)
{{
    dcos::Message message{{}};
    message.bytes[0] = 7;
    if (dcos::messagePortAgent.Send(greetings, message, 0) != dcos::Status::Ok) {{
        runtime::format(bsp::console(), "greeter: not sent\\r\\n");
    }}
}}

void listener(uintptr_t)
{{
    dcos::Message message{{}};
    if (dcos::messagePortAgent.Receive(greetings, message, dcos::kWaitForever) == dcos::Status::Ok) {{
        runtime::format(bsp::console(), "listener heard %u\\r\\n", static_cast<unsigned>(message.bytes[0]));
    }}
    // Stays, and with it the port it owns: a task that ends takes its objects along.
    // No one posts the event, so the wait's answer does not matter.
    (void)dcos::taskAgent.ReceiveEvent(1, dcos::EventWait::Any, dcos::kWaitForever);
}}

constexpr dcos::app::TaskDeclaration tasks[] = {{
    {{.name = "greeter", .entry = greeter, .priority = {greeter_priority}, .stackSize = {greeter_stack}}},
    {{.name = "{listener_name}", .entry = listener, .priority = 8}},
}};
constexpr dcos::app::MessagePortDeclaration ports[] = {{
    {{.name = "greetings", .receiver = "listener", .id = &greetings}},
}};
}} // namespace

DCOS_APPLICATION(hello, {{.name = "hello", .tasks = tasks, .messagePorts = ports}});
"""

HELLO_TEST = """\
import re


def test_listener_hears_the_greeter(application):
    assert "listener heard 7" in application.transcript
    listing = application.command("app")
    assert "application 'hello': running" in listing
    assert re.search(r"message port greetings +0x[0-9a-f]{8}  listener", listing)
"""


def write_hello(directory, greeter_priority=4, greeter_stack=4096, listener_name="listener", with_test=False):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "hello.cpp"), "w", encoding="utf-8") as handle:
        handle.write(HELLO_SOURCE.format(greeter_priority=greeter_priority, greeter_stack=greeter_stack,
                                         listener_name=listener_name))
    if with_test:
        os.makedirs(os.path.join(directory, "tests"), exist_ok=True)
        with open(os.path.join(directory, "tests", "test_hello.py"), "w", encoding="utf-8") as handle:
            handle.write(HELLO_TEST)
    return directory


def build_with_staged_sdk(directory, target="app"):
    """Runs the staged application build; returns the completed process."""
    return subprocess.run(
        ["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={directory}", target],
        capture_output=True, text=True, timeout=BUILD_TIMEOUT,
    )


def expect_build_failure(directory, *phrases):
    result = build_with_staged_sdk(directory)
    output = result.stdout + result.stderr
    assert result.returncode != 0, output
    for phrase in phrases:
        assert phrase in output, f"{phrase!r} not in the build's output:\n{output}"
    return output


@pytest.mark.parametrize("change, phrases", [
    (dict(greeter_priority=40), ['ObjectName{"greeter"}', "PriorityOutOfRange, 40, 31",
                                 "configuration error: task 'greeter': a task's priority must be 0 (highest) to 31 "
                                 "(lowest) (value 40, limit 31)"]),
    (dict(greeter_stack=1024), ['ObjectName{"greeter"}', "StackTooSmall, 1024, 2048",
                                "configuration error: task 'greeter': the task's stack is smaller than "
                                "dcos::kMinimumStackSize (limit) (value 1024, limit 2048)"]),
    (dict(greeter_stack="SIZE_MAX"), ['ObjectName{"greeter"}', "StacksExceedArena",
                                      "configuration error: task 'greeter': the stacks up to this task need more "
                                      "than the stack arena (DCOS_CONFIG_STACK_ARENA_KIB) (value 4294967295"]),
    (dict(listener_name="greeter"), ['ObjectName{"greeter"}', "DuplicateName",
                                     "configuration error: task 'greeter': two objects of this kind have this name"]),
    (dict(listener_name="shell"), ['ObjectName{"shell"}', "ReservedName",
                                   "configuration error: task 'shell': this is the name of a kernel task"]),
    (dict(listener_name="talker"), ['ObjectName{"greetings"}', "OwnerNotDeclared",
                                    "configuration error: message port 'greetings': its owner, receiver or writer is "
                                    "not a declared task"]),
])
def test_configuration_errors_name_the_object_at_compile_time(tmp_path, change, phrases):
    application = write_hello(str(tmp_path / "hello"), **change)
    output = expect_build_failure(application, *phrases)
    assert "DCOS_APPLICATION: the configuration breaks the rule named above" in output
    assert not os.path.exists(os.path.join(application, "build", "hello-486.elf"))


MAP_SOURCE = """\
#include <dcos/Application.hpp>

namespace {{
void control(uintptr_t) {{}}

constexpr dcos::app::TaskDeclaration tasks[] = {{{{.name = "control", .entry = control}}}};
constexpr dcos::app::PublisherDeclaration publishers[] = {{
    {{.name = "setpoint"}},
    {{.name = "measured", .writer = "control"}},
}};
using dcos::app::ModbusTable;
constexpr dcos::app::ModbusMapEntry map[] = {{
    {{.name = "setpoint", .table = ModbusTable::HoldingRegisters, .address = 0, .count = 4, .object = "setpoint"}},
    {{.name = "speed", .table = ModbusTable::{speed_table}, .address = {speed_address}, .count = {speed_count},
     .object = "{speed_object}", .offset = {speed_offset}}},
}};
}} // namespace

DCOS_APPLICATION(mapped, {{.name = "mapped", .tasks = tasks, .publishers = publishers, .modbusMap = map{slave}}});
"""


def write_map(directory, speed_table="HoldingRegisters", speed_address=4, speed_count=2, speed_object="setpoint",
              speed_offset=8, slave=""):
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "mapped.cpp"), "w", encoding="utf-8") as handle:
        handle.write(MAP_SOURCE.format(speed_table=speed_table, speed_address=speed_address,
                                       speed_count=speed_count, speed_object=speed_object,
                                       speed_offset=speed_offset, slave=slave))
    return directory


def test_a_valid_modbus_map_compiles(tmp_path, boot, isa486):
    """The map the failures below break one rule of builds, so each failure is the rule's own.

    It boots, and `app` lists the map with the notice that no slave serves it (none is declared).
    """
    application = write_map(str(tmp_path / "mapped"))
    result = build_with_staged_sdk(application)
    assert result.returncode == 0, result.stdout + result.stderr
    emulator = boot(isa486, os.path.join(application, "build", "mapped-486.elf"))
    emulator.expect(r"dcos> ")
    output = emulator.command("app")
    assert "application 'mapped': running" in output, output
    assert "modbus map, 2 entries, checked; not served: no modbusSlave declared" in output, output
    assert re.search(r"setpoint +holding +0-3 +publisher setpoint byte 0", output), output
    assert re.search(r"speed +holding +4-5 +publisher setpoint byte \d+", output), output


@pytest.mark.parametrize("change, phrases", [
    (dict(speed_address=3), ['ObjectName{"speed"}', "MapOverlap, 3, 3",
                             "configuration error: Modbus map entry 'speed': the Modbus map entry overlaps an "
                             "earlier entry of its table (value: the first shared address, limit: the last) "
                             "(value 3, limit 3)"]),
    (dict(speed_object="pressure"), ['ObjectName{"speed"}', "MapObjectNotDeclared",
                                     "configuration error: Modbus map entry 'speed': the Modbus map entry's object "
                                     "is not a declared publisher"]),
    (dict(speed_offset=14), ['ObjectName{"speed"}', "MapTooLarge, 18, 16",
                             "configuration error: Modbus map entry 'speed': the Modbus map entry does not fit its "
                             "source", "(value 18, limit 16)"]),
    (dict(speed_address=65535), ['ObjectName{"speed"}', "MapAddressPastEnd, 65536, 65535",
                                 "configuration error: Modbus map entry 'speed': the Modbus map entry runs past "
                                 "address 65535", "(value 65536, limit 65535)"]),
    (dict(speed_object="measured"), ['ObjectName{"speed"}', "MapWritesReadOnly",
                                     "configuration error: Modbus map entry 'speed': a coil or holding register "
                                     "entry is bound to something read-only"]),
    (dict(slave=", .modbusSlave = {.address = 248}"),
     ['ObjectName{"mapped"}', "SlaveAddressOutOfRange, 248, 247",
      "configuration error: Modbus slave 'mapped': a Modbus slave address must be 1 to 247", "(value 248, limit 247)"]),
    (dict(slave=", .modbusSlave = {.address = 17, .baud = 230400}"),
     ['ObjectName{"mapped"}', "BaudOutOfRange, 230400, 115200",
      "configuration error: Modbus slave 'mapped': the Modbus line's baud rate must be 300 to 115200"]),
])
def test_modbus_map_errors_name_the_entry_at_compile_time(tmp_path, change, phrases):
    application = write_map(str(tmp_path / "mapped"), **change)
    output = expect_build_failure(application, *phrases)
    assert "DCOS_APPLICATION: the configuration breaks the rule named above" in output
    assert not os.path.exists(os.path.join(application, "build", "mapped-486.elf"))


POLL_SOURCE = """\
#include <dcos/Application.hpp>

namespace {{
void control(uintptr_t) {{}}

constexpr dcos::app::TaskDeclaration tasks[] = {{{{.name = "control", .entry = control}}}};
constexpr dcos::app::PublisherDeclaration publishers[] = {{
    {{.name = "drive"}},
    {{.name = "command", .writer = "control"}},
}};
using dcos::app::ModbusTable;
constexpr dcos::app::ModbusPollEntry polls[] = {{
    {{.name = "speed", .unit = {unit}, .table = ModbusTable::InputRegisters, .address = 0, .count = {count},
     .periodMs = {period}, .object = "{speed_object}"}},
    {{.name = "setpoint", .unit = 17, .table = ModbusTable::{setpoint_table}, .write = true, .address = 0,
     .object = "command"}},
}};
}} // namespace

DCOS_APPLICATION(polling, {{.name = "polling", .tasks = tasks, .publishers = publishers, .modbusPolls = polls,
                           .modbusMaster = {{.baud = 19200, .timeoutMs = {timeout}}}}});
"""


@pytest.mark.parametrize("change, phrases", [
    (dict(), []),
    (dict(unit=0), ['ObjectName{"speed"}', "SlaveAddressOutOfRange, 0, 247",
                    "configuration error: Modbus poll entry 'speed': a Modbus slave address must be 1 to 247"]),
    (dict(period=0), ['ObjectName{"speed"}', "PollPeriodOutOfRange, 0, 3600000",
                      "configuration error: Modbus poll entry 'speed': a Modbus poll entry's period must be 1 to "
                      "3600000 ms", "(value 0, limit 3600000)"]),
    (dict(count=9), ['ObjectName{"speed"}', "MapTooLarge, 18, 16"]),
    (dict(speed_object="command"), ['ObjectName{"speed"}', "PollPublisherHasWriter",
                                    "configuration error: Modbus poll entry 'speed': a Modbus poll read publishes on "
                                    "a publisher with no writer task"]),
    (dict(setpoint_table="InputRegisters"), ['ObjectName{"setpoint"}', "PollWritesReadOnlyTable",
                                             "configuration error: Modbus poll entry 'setpoint': a Modbus poll entry "
                                             "writes only coils or holding registers"]),
    (dict(timeout=60001), ['ObjectName{"polling"}', "TimeoutOutOfRange, 60001, 60000",
                           "configuration error: Modbus master 'polling': the Modbus master's time-out must be 1 to "
                           "60000 ms", "(value 60001, limit 60000)"]),
])
def test_poll_schedule_errors_name_the_entry_at_compile_time(tmp_path, change, phrases):
    """The schedule with no change builds; each change breaks one rule, named in the build's last line."""
    directory = tmp_path / "polling"
    directory.mkdir()
    values = dict(unit=17, count=2, period=100, speed_object="drive", setpoint_table="HoldingRegisters", timeout=1000)
    values.update(change)
    (directory / "polling.cpp").write_text(POLL_SOURCE.format(**values))
    if not phrases:
        result = build_with_staged_sdk(str(directory))
        assert result.returncode == 0, result.stdout + result.stderr
        return
    output = expect_build_failure(str(directory), *phrases)
    assert "DCOS_APPLICATION: the configuration breaks the rule named above" in output


def test_an_unchecked_status_does_not_compile(tmp_path):
    """Status and Result are [[nodiscard]], and an application build refuses a dropped one."""
    application = write_hello(str(tmp_path / "hello"))
    source = os.path.join(application, "hello.cpp")
    with open(source, encoding="utf-8") as handle:
        text = handle.read()
    checked = "if (dcos::messagePortAgent.Send(greetings, message, 0) != dcos::Status::Ok) {"
    assert checked in text
    with open(source, "w", encoding="utf-8") as handle:
        handle.write(text.replace(checked, "dcos::messagePortAgent.Send(greetings, message, 0);\n    {"))
    expect_build_failure(application, "hello.cpp", "ignoring returned value of type", "nodiscard",
                         "-Werror=unused-result")


def test_too_many_tasks_names_the_first_that_does_not_fit(tmp_path):
    # The task table holds 256 tasks, three of which are the kernel's (idle, console, shell).
    directory = tmp_path / "crowd"
    directory.mkdir()
    declarations = ",\n".join(f'    {{.name = "worker{i}", .entry = work, .stackSize = 2048}}' for i in range(255))
    (directory / "crowd.cpp").write_text(textwrap.dedent("""\
        #include <dcos/Application.hpp>
        void work(uintptr_t) {}
        constexpr dcos::app::TaskDeclaration tasks[] = {
        %s
        };
        DCOS_APPLICATION(crowd, {.name = "crowd", .tasks = tasks});
        """) % declarations)
    expect_build_failure(str(directory), 'ObjectName{"worker253"}', "TooManyObjects, 258, 256",
                         "configuration error: task 'worker253': too many objects of this kind",
                         "(value 258, limit 256)")


def test_an_application_without_tests_says_so(tmp_path):
    hello = write_hello(str(tmp_path / "hello"))
    result = build_with_staged_sdk(hello, "test")
    assert result.returncode == 0, result.stdout + result.stderr
    assert f"application hello: no tests (add tests/test_*.py to {hello})" in result.stdout


def test_directory_without_an_application_is_refused_clearly(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    expect_build_failure(str(empty), f"error: {empty} holds no .cpp or .S source")

    undeclared = tmp_path / "undeclared"
    undeclared.mkdir()
    (undeclared / "main.cpp").write_text("void unused() {}\n")
    expect_build_failure(str(undeclared), "declares its application with DCOS_APPLICATION")

    hello = write_hello(str(tmp_path / "hello"))
    result = subprocess.run(["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={hello}", "BOARD=p5"],
                            capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode != 0
    assert "BOARD=p5 is not a board this DCOS builds for; its boards are: 486 p5smp" in result.stderr

    missing = tmp_path / "missing"
    result = build_with_staged_sdk(str(missing))
    assert result.returncode != 0
    assert f"application directory '{missing}' does not exist" in result.stderr


def test_configuration_error_only_the_node_finds_is_named_at_boot(tmp_path, boot, isa486):
    # Two pools over one area pass every compile-time rule; the pool agent
    # refuses the second at boot. Nothing of the application is created, and
    # the console still comes up to say why.
    directory = tmp_path / "overlap"
    directory.mkdir()
    (directory / "overlap.cpp").write_text(textwrap.dedent("""\
        #include <dcos/Application.hpp>
        #include <dcos/BufferPoolAgent.hpp>
        alignas(8) static uint8_t area[dcos::BufferPoolAgent::AreaBytes(16, 8)];
        void work(uintptr_t) {}
        constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "worker", .entry = work}};
        constexpr dcos::app::BufferPoolDeclaration pools[] = {
            {.name = "frames", .area = area, .areaBytes = sizeof area, .bufferSize = 16},
            {.name = "replies", .area = area, .areaBytes = sizeof area, .bufferSize = 16},
        };
        DCOS_APPLICATION(overlap, {.name = "overlap", .tasks = tasks, .bufferPools = pools});
        """))
    result = build_with_staged_sdk(str(directory))
    assert result.returncode == 0, result.stdout + result.stderr
    emulator = boot(isa486, str(directory / "build" / "overlap-486.elf"))
    emulator.expect(r"application 'overlap' not started: buffer pool 'replies' was refused by its agent "
                    r"\(already exists\)")
    emulator.expect(r"dcos> ")
    assert "not started" in emulator.command("app")
    assert "frames" not in emulator.command("pools")
    assert "worker" not in emulator.command("tasks")


def test_application_asks_for_its_tick_rate(tmp_path, boot, isa486):
    directory = tmp_path / "fasttick"
    directory.mkdir()
    (directory / "fasttick.cpp").write_text(textwrap.dedent("""\
        #include <dcos/Application.hpp>
        void work(uintptr_t) {}
        constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "worker", .entry = work}};
        DCOS_APPLICATION(fasttick, {.name = "fasttick", .tasks = tasks, .tickRateHz = 8000});
        """))
    result = build_with_staged_sdk(str(directory))
    assert result.returncode == 0, result.stdout + result.stderr
    image = str(directory / "build" / "fasttick-486.elf")
    emulator = boot(isa486, image)
    emulator.expect(r"tick 8000 Hz")
    # The command line still wins.
    emulator = boot(isa486, image, append="tick_hz=500")
    emulator.expect(r"tick 500 Hz")


# --- Against the tree (make test-app) and against an installed DCOS ----------

def run_make(arguments, cwd=REPOSITORY):
    # The tree's own makes build into BUILD; an application's Makefile has no use for it.
    tree = [f"BUILD={BUILD}"] if cwd == REPOSITORY and BUILD != "build" else []
    result = subprocess.run(["make", "--no-print-directory"] + tree + arguments, cwd=cwd, capture_output=True,
                            text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode == 0, f"make {' '.join(arguments)} failed:\n{result.stdout}\n{result.stderr}"
    return result.stdout + result.stderr


def passed_count(output):
    """The number of tests a nested pytest run reported passed (it exited 0)."""
    match = re.search(r"(\d+) passed", output)
    assert match, output
    return int(match.group(1))


def text_files_mentioning(root, needle):
    found = []
    for directory, _, files in os.walk(root):
        for name in files:
            path = os.path.join(directory, name)
            try:
                with open(path, encoding="utf-8") as handle:
                    if needle in handle.read():
                        found.append(path)
            except (UnicodeDecodeError, OSError):
                continue
    return found


def test_out_of_tree_application_against_the_tree_and_an_installed_dcos(tmp_path):
    # One test, in order: both steps run top-level makes of this tree,
    # which must not run side by side.
    hello = write_hello(str(tmp_path / "hello"), with_test=True)
    output = run_make(["test-app", f"APP={hello}"])
    assert passed_count(output) == 1
    # The tree's build keeps the application's directory clean.
    assert sorted(os.listdir(hello)) == ["hello.cpp", "tests"]

    prefix = tmp_path / "opt" / "dcos"
    run_make(["install", f"PREFIX={prefix}"])
    for installed in ["include/dcos/Application.hpp", "lib/dcos/486/libdcos486.a", "lib/dcos/486/libdcos486-minimal.a",
                      "lib/dcos/486/link.ld",
                      "share/dcos/application.mk", "share/dcos/boards/isa486.json",
                      "share/dcos/python/dcoslab/pytest_plugin.py", "libexec/dcos/qemu-system-i386",
                      "bin/mfio_bringup.py", "bin/plant_simulator.py", "share/dcos/tools/bringup/bringup_report.py",
                      "bin/dcos-can", "include/can/CanFrame.hpp", "include/sja1000/Sja1000Controller.hpp"]:
        assert (prefix / installed).exists(), installed
    assert text_files_mentioning(str(prefix), REPOSITORY) == [], "the installation refers to the source tree"
    unreadable = [os.path.join(directory, name) for directory, _, names in os.walk(prefix) for name in names
                  if not os.stat(os.path.join(directory, name)).st_mode & 0o004]
    assert unreadable == [], "installed files other users cannot read"

    # The counter example, copied out as a user would, built with its own
    # two-line Makefile against the installation, and its tests run.
    counter = tmp_path / "counter"
    shutil.copytree(COUNTER_EXAMPLE, counter, ignore=shutil.ignore_patterns("build", "__pycache__"))
    output = run_make([f"DCOS={prefix}", "test"], cwd=str(counter))
    assert passed_count(output) >= 1
    assert (counter / "build" / "counter-486.elf").exists()

    # The installation can be moved as a whole.
    moved = tmp_path / "elsewhere" / "dcos"
    moved.parent.mkdir()
    shutil.move(str(prefix), str(moved))
    run_make([f"DCOS={moved}", "clean"], cwd=str(counter))
    output = run_make([f"DCOS={moved}", "test"], cwd=str(counter))
    assert passed_count(output) >= 1

    # The engineers' host tools run from the moved installation, through its bin/.
    bringup, plant = moved / "bin" / "mfio_bringup.py", moved / "bin" / "plant_simulator.py"
    for tool in (bringup, plant):
        assert os.access(tool, os.X_OK), f"{tool} is not executable"
        result = subprocess.run([str(tool), "--help"], capture_output=True, text=True, timeout=60)
        assert result.returncode == 0 and "exit status" in result.stdout.lower(), result.stdout + result.stderr
    dcos_can = moved / "bin" / "dcos-can"
    result = subprocess.run([str(dcos_can), "--version"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout.startswith("dcos-can "), result.stdout + result.stderr
    result = subprocess.run([str(dcos_can), "-i", "slcan:/nonexistent", "dump"], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 3 and "cannot open /nonexistent" in result.stderr, result.stdout + result.stderr
    result = subprocess.run([str(plant), "--tau", "0", "--gain", "2"], input="SAMPLE 0 1.5 0 0 0 0 0 0 0 0001\n",
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and result.stdout.startswith("INPUT 3.000000 "), result.stdout + result.stderr
    # The bring-up tool boots the installed emulator with the installed board and image, and passes it.
    work = tmp_path / "bringup"
    work.mkdir()
    result = subprocess.run([str(bringup), "--emulator", "--timeout", "240", "--connect-timeout", "60",
                             "--json", "result.json", "--png", "sheet.png"], cwd=str(work), capture_output=True,
                            text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode == 0, result.stdout + result.stderr
    with open(work / "result.json", encoding="utf-8") as handle:
        document = json.load(handle)
    assert document["verdict"] == "pass" and document["firmware"]["version"] == "0.1.0"
    assert document["connection"]["emulator"][0] == str(moved / "libexec" / "dcos" / "qemu-system-i386")
    assert (work / "sheet.png").exists()


# --- The guide's own application ----------------------------------------------

GUIDE = os.path.join(REPOSITORY, "docs", "guide", "first-application.md")


def guide_files():
    """The files the guide writes: fenced blocks whose info string says file=<path>."""
    with open(GUIDE, encoding="utf-8") as handle:
        text = handle.read()
    return dict((path, body) for path, body in
                re.findall(r"^```\w+ file=(\S+)\n(.*?)^```$", text, flags=re.MULTILINE | re.DOTALL))


def test_the_guides_application_builds_runs_and_passes_its_tests(tmp_path):
    files = guide_files()
    assert sorted(files) == ["Makefile", "tank.cpp", "tests/test_tank.py"]
    tank = tmp_path / "tank"
    for path, body in files.items():
        (tank / path).parent.mkdir(parents=True, exist_ok=True)
        (tank / path).write_text(body)
    # Built as the guide says, with its Makefile, against the staged installation.
    result = subprocess.run(["make", "--no-print-directory", f"DCOS={STAGED_SDK}", "test"], cwd=str(tank),
                            capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert passed_count(result.stdout) == 2


def test_run_boots_the_application_with_its_console_on_a_terminal(tmp_path):
    # The application build's `run`, as `make run APP=<dir>` calls it, on a pseudo-terminal.
    import pexpect

    hello = write_hello(str(tmp_path / "hello"))
    session = pexpect.spawn("make", ["--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={hello}", "run"],
                            timeout=120, encoding="latin-1")
    try:
        session.expect(r"application 'hello' started: 2 tasks, 1 message port")
        session.expect(r"listener heard 7")
        session.send("app\r")
        session.expect(r"message port greetings +0x[0-9a-f]{8}  listener")
        session.expect(r"dcos> ")
        session.send("\x01x")
        session.expect(pexpect.EOF)
    except (pexpect.TIMEOUT, pexpect.EOF) as error:
        raise AssertionError(f"run session failed: {error}\n----- console -----\n{session.before}") from None
    finally:
        session.close(force=True)


def test_sources_in_a_subfolder_named_like_the_application_are_built(tmp_path):
    # The tree builds into build/apps/<name>; only a build folder inside the
    # application's directory is left out of its sources.
    application = tmp_path / "pump"
    (application / "pump").mkdir(parents=True)
    (application / "pump" / "main.cpp").write_text(textwrap.dedent("""\
        #include <dcos/Application.hpp>
        void run(uintptr_t) {}
        constexpr dcos::app::TaskDeclaration tasks[] = {{.name = "pump", .entry = run}};
        DCOS_APPLICATION(pump, {.name = "pump", .tasks = tasks});
        """))
    result = subprocess.run(["make", "--no-print-directory", "-f", APPLICATION_MAKEFILE, f"APP={application}",
                             f"APP_BUILD={tmp_path / 'elsewhere' / 'pump'}"],
                            capture_output=True, text=True, timeout=BUILD_TIMEOUT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert (tmp_path / "elsewhere" / "pump" / "pump-486.elf").exists()
