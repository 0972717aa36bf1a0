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
else:
    INSTALLED = False
    # The repository; board image paths are relative to it.
    ROOT = os.path.dirname(os.path.dirname(HERE))
    BOARDS_DIRECTORY = os.path.join(ROOT, "tests_renode", "boards")
    EMULATOR_DIRECTORY = None
