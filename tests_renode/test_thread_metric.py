"""The Thread-Metric suite runs to completion on the bench image and reports every test.

Only completeness and sanity are checked here; the figures themselves belong
to `make bench` (docs/performance.md), never to a pass/fail test.
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "thread_metric"))

import run_thread_metric  # noqa: E402


def test_every_thread_metric_test_reports_a_figure():
    results = run_thread_metric.run("isa486")
    assert set(results) == set(run_thread_metric.EXPECTED)
    for name in run_thread_metric.EXPECTED:
        entry = results[name]
        assert entry["iterations"] == 2000
        # Every iteration does work: at least one instruction, and the total
        # is the per-iteration figure times the iterations.
        assert entry["instructions"] > entry["iterations"]
        assert abs(entry["instructions_per_iteration"] * entry["iterations"] - entry["instructions"]) < entry["iterations"]
