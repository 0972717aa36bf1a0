"""The lab VM for dcoslab users: Debian's Linux under QEMU with real SocketCAN.

This re-exports tests_renode/labvm (see docs/guide/lab-vm.md) and adds a
pytest fixture:

    from dcoslab.labvm import lab_vm  # noqa: F401  (makes the fixture available in this test module)

    def test_candump_sees_it(lab_vm):
        vm = lab_vm("candump -n 1 vcan0 & . /run/labvm/lib.sh; labvm_wait_receiver vcan0 raw; "
                    "cansend vcan0 123#11; wait", vcan=["vcan0"])
        assert vm.wait().check().output.split() == ["vcan0", "123", "[1]", "11"]

`lab_vm(command, **options)` starts a LabVM (options as LabVM's) and stops it
after the test. The VMs a test started are listed with the emulators the
lab's `boot` fixture started, so a failing test's report carries their
console transcripts like any board's (dcoslab/pytest_plugin.py); that list is
shared with `boot` when `boot` is requested first.
"""

import os
import sys

import pytest

_TESTS_RENODE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if os.path.isdir(os.path.join(_TESTS_RENODE, "labvm")) and _TESTS_RENODE not in sys.path:
    sys.path.insert(0, _TESTS_RENODE)

try:
    from labvm import (BITRATE_CODES, CanFrame, CheckResult, KvaserPciSetup, LabVM, LabVMError,  # noqa: F401
                       LabVMSetupError, Result, SlcanError, SlcanPort, SlcanSetup, Sja1000Setup, built_qemu_x86_64,
                       check_command, obtain_kernel, parse_checks, run)
except ImportError as error:  # an installed DCOS without the source tree's tests_renode/labvm
    raise ImportError(f"the lab VM lives in the DCOS source tree (tests_renode/labvm), not found from "
                      f"{_TESTS_RENODE}: {error}") from None

__all__ = [
    "BITRATE_CODES", "CanFrame", "CheckResult", "KvaserPciSetup", "LabVM", "LabVMError", "LabVMSetupError", "Result",
    "SlcanError", "SlcanPort", "SlcanSetup", "Sja1000Setup", "built_qemu_x86_64", "check_command", "lab_vm",
    "obtain_kernel", "parse_checks", "run",
]


@pytest.fixture
def lab_vm(request):
    """lab_vm(command, **options) -> a started LabVM, stopped after the test."""
    started = getattr(request.node, "dcos_emulators", None)
    if started is None:
        started = []
        request.node.dcos_emulators = started
    vms = []

    def start(command, **options):
        vm = LabVM(command, **options)
        vms.append(vm)
        started.append(vm)
        return vm.start()

    yield start
    for vm in vms:
        vm.close()
