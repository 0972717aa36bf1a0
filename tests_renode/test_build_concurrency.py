"""Several builds of one tree at once must not break each other.

An engineer runs `make run` in one terminal while `make test` builds in
another, and the suite itself starts builds side by side; files a build
rewrites on every run (the flag stamps, the build revision) must never be
a shared temporary that one build removes under another.
"""

import glob
import os
import subprocess

from dcoslab.board import REPOSITORY

# The targets every build rewrites when their text changes, and checks on every run.
ALWAYS_CHECKED = ["build/fw486/flags.stamp", "build/fw486/generated/BuildRevision.cpp", "build/host/flags.stamp"]
BUILDS_AT_ONCE = 8
ROUNDS = 6


def test_builds_at_once_do_not_race_on_rewritten_files():
    for _ in range(ROUNDS):
        builds = [subprocess.Popen(["make", "--no-print-directory", "-C", REPOSITORY, *ALWAYS_CHECKED],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
                  for _ in range(BUILDS_AT_ONCE)]
        for build in builds:
            output, _ = build.communicate(timeout=300)
            assert build.returncode == 0, output
    leftovers = [path for target in ALWAYS_CHECKED for path in glob.glob(os.path.join(REPOSITORY, target) + ".new*")]
    assert leftovers == []
