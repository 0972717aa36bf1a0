"""The emulator regression suite's fixtures come from the lab's pytest plugin
(dcoslab/pytest_plugin.py), the same one applications' own tests use."""

import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

pytest_plugins = ["dcoslab.pytest_plugin"]


def pytest_collection_modifyitems(config, items):
    """Refuses a module whose tests share a module-scoped fixture (a lab VM,
    booted once) unless it is one xdist group: with plain load balancing,
    `-n 2` splits such a module over two workers, each boots its own fixture,
    and tests that follow one VM script in phases wait for a phase their
    worker's VM never reaches."""
    problems = set()
    for item in items:
        info = getattr(item, "_fixtureinfo", None)
        if info is None:
            continue
        shared = [name for name, definitions in info.name2fixturedefs.items()
                  if definitions and definitions[-1].scope == "module"
                  and definitions[-1].baseid.endswith(".py")]
        if shared and item.get_closest_marker("xdist_group") is None:
            problems.add(f"{item.module.__name__}: tests share module-scoped {', '.join(sorted(shared))} "
                         f"but the module has no pytestmark = pytest.mark.xdist_group(...)")
    if problems:
        raise pytest.UsageError("\n".join(sorted(problems)))
