"""`make plant`'s launcher (plant.py, installed beside the lab) on this application's image.

A short run of the two-node configuration: the launcher must settle the
plant at both set points, print its progress, and write the trajectory, the
bus traffic decoded by dcos-can and the trend plot (docs/guide/distributed-plant.md).
"""

import os
import subprocess
import sys

from dcoslab.layout import HERE

LAUNCHER = os.path.join(os.path.dirname(HERE), "plant.py")


def test_make_plant_settles_twice_and_writes_its_files(dcos_image, tmp_path):
    run = subprocess.run([sys.executable, LAUNCHER, "--image", dcos_image, "--seconds", "2", "--output", str(tmp_path)],
                         capture_output=True, text=True, timeout=900)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "set point now 3.000 V" in run.stdout
    assert "plant output from 1.5 s on: within" in run.stdout
    progress = [line for line in run.stdout.splitlines() if line.startswith("t=") and " pv " in line]
    assert len(progress) == 4, run.stdout
    with open(tmp_path / "trend.png", "rb") as trend:
        assert trend.read(8) == b"\x89PNG\r\n\x1a\n"
    bus = (tmp_path / "bus.log").read_text()
    # Both directions decoded: node 1's "pv" and node 2's "mv", whole pages.
    assert "DSM publication 1->all: publisher 0x000 part 3/3 page " in bus
    assert "DSM publication 2->all: publisher 0x000 part 3/3 page " in bus
    rows = (tmp_path / "plant.csv").read_text().splitlines()
    assert rows[0].startswith("time_ns,") and len(rows) > 150
