"""Where the lab's files are: in the DCOS source tree, or in an installed DCOS.

`make install PREFIX=<path>` copies this package to
<path>/share/dcos/python/dcoslab/ and writes installed_layout.json beside this
file. Its paths are relative to this directory, so an installed DCOS can be
moved as a whole. Without the file the package runs from the source tree.
"""

import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
_MARKER = os.path.join(HERE, "installed_layout.json")

if os.path.exists(_MARKER):
    with open(_MARKER, encoding="utf-8") as _handle:
        _layout = json.load(_handle)
    INSTALLED = True
    # The installation prefix; board image paths are relative to it.
    ROOT = os.path.normpath(os.path.join(HERE, _layout["root"]))
    BOARDS_DIRECTORY = os.path.join(ROOT, _layout["boards"])
    # The emulator with the DCOS board models, copied by make install.
    EMULATOR_DIRECTORY = os.path.join(ROOT, _layout["emulator_dir"])
    # The plant simulator for the I/O board (host_tools/plant_simulator).
    PLANT_SIMULATOR = os.path.join(ROOT, "share", "dcos", "tools", "plant_simulator.py")
    # The host CAN tool (host_tools/can).
    DCOS_CAN = os.path.join(ROOT, "bin", "dcos-can")
else:
    INSTALLED = False
    # The repository; board image paths are relative to it.
    ROOT = os.path.dirname(os.path.dirname(HERE))
    BOARDS_DIRECTORY = os.path.join(ROOT, "tests_renode", "boards")
    EMULATOR_DIRECTORY = None
    PLANT_SIMULATOR = os.path.join(ROOT, "host_tools", "plant_simulator", "plant_simulator.py")
    DCOS_CAN = os.path.join(ROOT, "build", "host_tools", "bin", "dcos-can")
