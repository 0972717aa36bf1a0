"""Fixtures for the emulator regression suite.

`boot` starts a board image and stops it after the test. The console
transcript of every emulator a test started is attached to the report of a
failing test, so it is always printed with the failure.
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from dcoslab.board import load_board  # noqa: E402
from dcoslab.emulator import Emulator  # noqa: E402


@pytest.fixture
def isa486():
    return load_board("isa486")


@pytest.fixture
def boot(request):
    """boot(board, kind="production", append="", icount=False, ...) -> running Emulator.

    Optional, per test: device_properties={"isa-mfio": {"no-irq": "on"}} adds
    or replaces device properties, without_devices=["isa-mfio"] leaves devices
    out, extra_args=[...] go to the emulator as they are.
    """
    started = []
    request.node.dcos_emulators = started

    def start(board, kind="production", append="", icount=False, device_properties=None, without_devices=(),
              extra_args=()):
        emulator = Emulator(board, board.image(kind), append=append, icount=icount,
                            device_properties=device_properties, without_devices=without_devices,
                            extra_args=extra_args)
        started.append(emulator)
        return emulator.start()

    yield start
    for emulator in started:
        emulator.close()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if report.failed:
        for index, emulator in enumerate(getattr(item, "dcos_emulators", [])):
            report.sections.append(
                (f"console transcript of emulator {index + 1}: {' '.join(getattr(emulator, 'argv', []))}", emulator.transcript)
            )
