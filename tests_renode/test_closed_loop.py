"""A closed loop on the emulated board: a DCOS controller task and the host plant simulator.

The isa-mfio model is wired to host_tools/plant_simulator (first order plus
dead time) over its lock-step plant socket, and the test image's
`closedloop` test runs a proportional controller task that must hold the
plant at its set point within the stated band. Under -icount the whole loop
is exact and repeatable.
"""

import os
import subprocess
import sys
import time

from dcoslab.board import REPOSITORY
from dcoslab.target import run_target_test

# On-target tests this module runs (see test_kernel_core.test_every_target_test_is_run).
CLOSED_LOOP_TARGET_TESTS = ["closedloop"]

MFIO = "isa-mfio"


def test_p_controller_holds_the_plant_at_its_set_point(boot, isa486, tmp_path):
    plant_socket = tmp_path / "plant.sock"
    plant = subprocess.Popen(
        [sys.executable, os.path.join(REPOSITORY, "host_tools", "plant_simulator", "plant_simulator.py"),
         "--socket", str(plant_socket), "--gain", "1", "--tau", "0.2", "--dead-time", "0.02",
         "--input-channel", "0", "--output-channel", "0", "--accept-timeout", "120"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not plant_socket.exists():
            assert plant.poll() is None and time.monotonic() < deadline, "the plant simulator did not listen"
            time.sleep(0.05)
        emulator = boot(isa486, "test", icount=True,
                        device_properties={MFIO: {"wiring": "plant", "plant": "plant"}},
                        extra_args=["-chardev", f"socket,id=plant,path={plant_socket}"])
        run_target_test(emulator, "closedloop", timeout=300)
        assert "worst in the last second" in emulator.transcript
    finally:
        if plant.poll() is None:
            plant.kill()
        plant.wait(timeout=30)
