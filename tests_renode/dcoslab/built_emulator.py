"""Resolves a board's "emulator" to a program to run.

A board names its emulator either as a program on PATH or as
"built:<program>": the emulator built from Debian's QEMU source with our
device models (tests_renode/qemu/build_qemu.sh). Its binary lives in
build/qemu-<key>/, where <key> hashes the build script and the models; the
script itself says where (--print-path), so the key is computed in one place.
The build makes qemu-system-i386, which runs every board, and
qemu-system-x86_64, which runs the lab VM with one of our cards
(docs/guide/lab-vm.md). An installed DCOS carries a copy of
qemu-system-i386 only, in <prefix>/libexec/dcos/.
"""

import functools
import os
import subprocess

from . import layout

REPOSITORY = layout.ROOT

BUILD_SCRIPT = os.path.join(REPOSITORY, "tests_renode", "qemu", "build_qemu.sh")
BUILT_PREFIX = "built:"
BUILT_PROGRAMS = ("qemu-system-i386", "qemu-system-x86_64")
# What 'make install' copies (mk/install-sdk.sh): the boards' emulator.
INSTALLED_PROGRAMS = ("qemu-system-i386",)


class EmulatorNotBuilt(RuntimeError):
    """The board wants the built emulator and it is not there."""


@functools.lru_cache(maxsize=None)
def built_emulator_path(program="qemu-system-i386"):
    """Path of the built program for the current sources; raises if not built."""
    if program not in BUILT_PROGRAMS:
        raise EmulatorNotBuilt(f"'{BUILT_PREFIX}{program}': the build makes only {', '.join(BUILT_PROGRAMS)}")
    if layout.INSTALLED:
        if program not in INSTALLED_PROGRAMS:
            raise EmulatorNotBuilt(f"an installed DCOS carries only {', '.join(INSTALLED_PROGRAMS)}; "
                                   f"{program} is built in the source tree (tests_renode/qemu/build_qemu.sh)")
        candidate = os.path.join(layout.EMULATOR_DIRECTORY, program)
        if not os.access(candidate, os.X_OK):
            raise EmulatorNotBuilt(f"this installed DCOS has no {candidate}; reinstall it with 'make install'")
        return candidate
    try:
        result = subprocess.run([BUILD_SCRIPT, "--print-path"], capture_output=True, text=True, timeout=60, check=True)
    except (OSError, subprocess.SubprocessError) as error:
        raise EmulatorNotBuilt(f"cannot ask {BUILD_SCRIPT} where the emulator is: {error}") from None
    path = result.stdout.strip()
    directory = os.path.dirname(path)
    candidate = os.path.join(directory, program)
    if not os.access(candidate, os.X_OK):
        raise EmulatorNotBuilt(
            f"the emulator with the DCOS board models is not built for the current sources "
            f"(expected {candidate}); build it with 'make emulator' or {os.path.relpath(BUILD_SCRIPT, REPOSITORY)}"
        )
    return candidate


def resolve_emulator(name):
    """The program to run for a board's "emulator" entry."""
    if name.startswith(BUILT_PREFIX):
        return built_emulator_path(name[len(BUILT_PREFIX):])
    return name
