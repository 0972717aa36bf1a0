"""The emulator regression suite's fixtures come from the lab's pytest plugin
(dcoslab/pytest_plugin.py), the same one applications' own tests use."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

pytest_plugins = ["dcoslab.pytest_plugin"]
