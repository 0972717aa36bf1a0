"""The lab's pytest fixtures, for the repository's suite and for applications' own tests.

The repository's tests_renode/conftest.py loads this plugin; an application's
tests get it from `make test-app` (or its own `make test` against an installed
DCOS), which runs pytest with `-p dcoslab.pytest_plugin --dcos-image=<image>`.

Fixtures:
- `boot(board, kind="production", append="", icount=False, ...)` starts a
  board image and stops it after the test;
- `isa486`: the ISA 486 board definition;
- `dcos_board`: the board named by --dcos-board (default isa486);
- `dcos_image`: the image named by --dcos-image (an application's tests);
- `application`: a booted emulator running --dcos-image on --dcos-board
  (built with the kernel configuration --dcos-kernel-config, default full),
  with exact emulated time (-icount), at its first shell prompt;
- `hub_factory(buses, expect=(), pace=None, **options)`: a lab hub alone,
  for tests that play the boards themselves;
- `canlab(buses, wiring, pace=None, kind="test")`: the CAN bus hub with
  the named buses and bit rates, and the boards wired to them, booted in
  step (dcoslab/canlab.py).

The console transcript of every emulator a test started, and the bus log of
every CAN hub, are attached to the report of a failing test, so they are
always printed with the failure.
"""

import os
import tempfile

import pytest

from .board import load_board
from .canbus import Hub
from .canlab import CanLab
from .emulator import Emulator
from .symbolize import explain


def pytest_addoption(parser):
    group = parser.getgroup("dcos", "DCOS emulator lab")
    group.addoption("--dcos-image", default=None, help="firmware image the `application` fixture boots")
    group.addoption("--dcos-board", default="isa486", help="board the `application` fixture boots (default isa486)")
    group.addoption("--dcos-kernel-config", default="full", choices=("full", "minimal"),
                    help="the kernel configuration the image was built with (default full)")


# How long a hub of hub_factory waits for a silent participant: it bounds a hung test only.
HUB_TIMEOUT = 60.0


@pytest.fixture
def isa486():
    return load_board("isa486")


@pytest.fixture
def dcos_board(request):
    return load_board(request.config.getoption("--dcos-board"))


@pytest.fixture
def dcos_image(request):
    image = request.config.getoption("--dcos-image")
    if not image:
        raise pytest.UsageError("this test needs --dcos-image=<firmware image> (make test-app passes it)")
    if not os.path.exists(image):
        raise pytest.UsageError(f"--dcos-image {image} does not exist; build the application first")
    return os.path.abspath(image)


@pytest.fixture
def boot(request):
    """boot(board, kind="production", append="", icount=False, ...) -> running Emulator.

    kind is an image kind of the board ("production", "test", ...) or the
    path of an image file. Optional, per test: device_properties={"isa-mfio":
    {"no-irq": "on"}} adds or replaces device properties, without_devices=
    ["isa-mfio"] leaves devices out, extra_args=[...] go to the emulator as
    they are, serial_sockets=["rs485"] joins serial ports to Unix sockets
    (Emulator.serial_socket_path), line_ports={"rs485": {"hub": ..., "hub-name":
    ..., "line": ...}} puts serial ports on a lab line (dcoslab/rs485.py),
    cpu="pentium" replaces the board's CPU model, card="path/to/card.img"
    boots the board from that CompactFlash card image instead of an image
    kind (docs/boot.md), and power_cut_after=N cuts that card's power after
    its Nth write (dcoslab/powercut.py).
    """
    started = []
    request.node.dcos_emulators = started

    def start(board, kind="production", append="", icount=False, device_properties=None, without_devices=(),
              extra_args=(), name=None, serial_sockets=(), line_ports=None, cpu=None, card=None,
              power_cut_after=None):
        image = card or (kind if os.path.sep in kind else board.image(kind))
        emulator = Emulator(board, image, append=append, icount=icount, cpu=cpu, device_properties=device_properties,
                            without_devices=without_devices, extra_args=extra_args, name=name,
                            serial_sockets=serial_sockets, line_ports=line_ports, card=card is not None,
                            power_cut_after=power_cut_after)
        started.append(emulator)
        return emulator.start()

    yield start
    for emulator in started:
        emulator.close()


@pytest.fixture
def canlab(request, boot, isa486):
    """canlab(buses, wiring, pace=None, kind="test", lines=None, append="") -> CanLab, stopped after the test.

    buses maps bus names to bit rates ({"can0": 500_000}); wiring maps board
    names to their card's channels ({"board1": {"bus0": "can0"}}) and, with
    the key "rs485", to the RS-485 line their COM2 is on; lines maps line
    names to a baud rate and format ({"line0": (19200, "8E1")}). The ISA
    486 board is booted once per name, in step with the others.
    """
    labs = []
    request.node.dcos_canlabs = labs

    def start(buses, wiring, pace=None, kind="test", lines=None, append=""):
        lab = CanLab(boot, isa486, buses, wiring, pace=pace, kind=kind, lines=lines, append=append)
        labs.append(lab)
        return lab

    yield start
    for lab in labs:
        lab.close()


@pytest.fixture
def hub_factory():
    """hub_factory(buses, expect=(), pace=None, **options) -> a started lab hub (dcoslab/canbus.py's Hub)
    on a socket of its own, stopped after the test; options go to Hub (e.g. lines=, quantum_ns=)."""
    hubs = []
    directory = tempfile.TemporaryDirectory(prefix="dcos-canhub-")

    def make(buses, expect=(), pace=None, **options):
        options.setdefault("timeout", HUB_TIMEOUT)
        hub = Hub(os.path.join(directory.name, f"hub{len(hubs)}.sock"), buses, expect=expect, pace=pace, **options)
        hubs.append(hub)
        return hub.start()

    yield make
    for hub in hubs:
        hub.stop()
    directory.cleanup()


@pytest.fixture
def application(request, boot, dcos_board, dcos_image):
    """The application image booted with exact emulated time, at its first prompt.

    An image of the minimal kernel configuration has no console shell and so
    no prompt: it is returned once the kernel has started the application.
    """
    emulator = boot(dcos_board, dcos_image, icount=True)
    if request.config.getoption("--dcos-kernel-config") == "minimal":
        emulator.expect(r"kernel configuration minimal\r\n")
        emulator.expect(r"application '[^']*' (started|not started)[^\r]*\r\n")
    else:
        emulator.expect(r"dcos> ")
    return emulator


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.failed:
        for index, emulator in enumerate(getattr(item, "dcos_emulators", [])):
            report.sections.append(
                (f"console transcript of emulator {index + 1} ({emulator.name}): "
                 f"{' '.join(getattr(emulator, 'argv', []))}", emulator.transcript)
            )
            code = explain(emulator.transcript, getattr(emulator, "image", None))
            if code:
                report.sections.append((f"code addresses in the transcript of emulator {index + 1}", code))
        for index, lab in enumerate(getattr(item, "dcos_canlabs", [])):
            hub = lab.hub
            problems = "".join(f"hub error: {error}\n" for error in hub.errors)
            media = [f"{bus.name} {bus.bitrate} bit/s" for bus in hub.buses.values()]
            media += [f"{line.name} {line.baud} baud {line.format}" for line in hub.lines.values()]
            report.sections.append((f"CAN bus and RS-485 line log of lab {index + 1} ({', '.join(media)}, "
                                    f"quantum {hub.quantum_ns} ns)", problems + hub.log_text()))
