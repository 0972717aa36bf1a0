"""The bring-up tool's noise judgement, on many simulated boards (no emulator).

A board's noise used to be judged by the largest standard deviation of any
single DAC step, each from 8 conversions: over the 32 sweeps of a board (about
270 steps) the largest of so many small-sample deviations exceeds a 1.0 LSB
limit by chance on a board whose true noise is 0.6 LSB, which then failed most
bring-ups. The controller now pools each sweep's variance over its points
(docs/iobus/bringup-protocol.md) and the host fails a sweep only when the
chi-square lower confidence bound on sigma is above the limit.

The simulation here reproduces the controller's measurement step for step:
the DAC steps of drivers/iobus/src/Bringup.cpp for each gain, the model's
Gaussian noise rounded to whole ADC codes (tests_renode/models/isa_mfio.c),
and the controller's integer arithmetic for the pooled estimate. Each board
becomes a transcript that goes through the same parser and judge as a real
one.
"""

import math
import os
import random
import sys

import pytest

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPOSITORY, "host_tools", "bringup"))

import bringup_report as br  # noqa: E402

SAMPLES_PER_POINT = 8   # BringupSettings::samplesPerPoint
MAXIMUM_POINTS = 9      # BringupSettings::maximumPoints
MARGIN_CODES = 48       # BringupSettings::marginCodes


def dac_steps(gain):
    """The DAC codes the controller writes for one gain (measureChannel in Bringup.cpp)."""
    reach = (2048 - MARGIN_CODES) // gain
    points = max(2, min(MAXIMUM_POINTS, 16, 2 * reach + 1))
    steps = []
    for step in range(points):
        scaled = (2 * step - (points - 1)) * reach
        magnitude = (abs(scaled) + (points - 1) // 2) // (points - 1)
        steps.append(2048 + (magnitude if scaled >= 0 else -magnitude))
    return steps


def pooled_hundredths(points):
    """The controller's pooled deviation in hundredths and its degrees of freedom (pooledNoise in Bringup.cpp)."""
    squares = 0
    freedom = 0
    for n, total, total_squares in points:
        spread = n * total_squares - total * total
        squares += spread // n * 10000 + spread % n * 10000 // n
        freedom += n - 1
    variance = (squares + freedom // 2) // freedom
    root = math.isqrt(variance)
    if variance - root * root > root:
        root += 1
    return root, freedom


def largest_point_hundredths(points):
    """LinearityFit::noiseHundredths: the largest single point's deviation, as the report's noise_lsb."""
    largest = 0
    for n, total, total_squares in points:
        spread = n * total_squares - total * total
        largest = max(largest, math.isqrt(spread * 10000 // (n * (n - 1))))
    return largest


def adc_line(generator, channel, gain, sigma, pooled=True):
    codes = dac_steps(gain)
    points = []
    means = []
    ideals = []
    for code in codes:
        ideal = br.ideal_adc_code(code, gain)
        total = total_squares = 0
        for _ in range(SAMPLES_PER_POINT):
            value = min(max(round(ideal + sigma * generator.gauss(0.0, 1.0)), 0), 4095)
            total += value
            total_squares += value * value
        points.append((SAMPLES_PER_POINT, total, total_squares))
        means.append(total / SAMPLES_PER_POINT)
        ideals.append(ideal)
    # Least squares of the means on the ideal codes, as the controller fits them.
    count = len(ideals)
    mean_ideal, mean_measured = sum(ideals) / count, sum(means) / count
    slope = sum((i - mean_ideal) * (m - mean_measured) for i, m in zip(ideals, means)) / \
        sum((i - mean_ideal) ** 2 for i in ideals)
    offset = mean_measured + slope * (2048 - mean_ideal) - 2048
    deviation, freedom = pooled_hundredths(points)
    noise = f"noise_lsb={largest_point_hundredths(points) / 100:.2f}"
    if pooled:
        noise += f" noise_pooled_lsb={deviation / 100:.2f} noise_dof={freedom} samples={SAMPLES_PER_POINT}"
    return (f"BRINGUP ADC channel={channel} gain={gain} offset_lsb={offset:.2f} gain_error_pct={(slope - 1) * 100:.2f} "
            f"max_error_lsb={max(abs(m - i) for m, i in zip(means, ideals)):.2f} {noise} overrange=0 points="
            + ",".join(f"{code}:{mean:.1f}" for code, mean in zip(codes, means)))


def board_transcript(generator, sigma, pooled=True):
    lines = ["BRINGUP BEGIN base=0x300 irq=5", "BRINGUP PROBE ok id=4d46 revision=0100",
             "BRINGUP FIRMWARE version=0.1.0 revision=simulated",
             "BRINGUP DIO walking-ones ok", "BRINGUP DIO walking-zeros ok"]
    lines += [adc_line(generator, channel, gain, sigma, pooled) for channel in range(8) for gain in br.GAINS]
    lines += ["BRINGUP IRQ delivered=64 requested=64 latency_min_ns=1200 latency_max_ns=5000",
              "BRINGUP END failures=0"]
    return "\r\n".join(lines) + "\r\n"


def noise_failures(text):
    judgement = br.judge(br.parse_transcript(text), br.Limits())
    return judgement, [f for f in judgement.failures if f.metric in ("noise_pooled_lsb", "noise_lsb")]


def test_the_simulated_sweeps_are_the_controllers():
    # 9 steps at gains 1 to 100; 5 at gain 1000, whose +-2 DAC codes are all it can measure.
    assert dac_steps(1) == [48, 548, 1048, 1548, 2048, 2548, 3048, 3548, 4048]
    assert dac_steps(1000) == [2046, 2047, 2048, 2049, 2050]
    # Two points of 8 conversions, four 0s and four 2s, then four 1s and four 3s: each point's variance is
    # (8 x 16 - 8^2) / (8 x 7) = 8 / 7, and so is the pooled one, with 7 + 7 degrees of freedom.
    assert pooled_hundredths([(8, 8, 16), (8, 16, 40)]) == (round(100 * math.sqrt(8 / 7)), 14)


def test_the_chi_square_quantiles_are_exact():
    # Reference values from published tables (and scipy.stats.chi2.ppf).
    for probability, dof, expected in [(0.95, 1, 3.841458820694124), (0.95, 10, 18.307038053275146),
                                       (0.999, 35, 66.61882884370104), (0.999, 63, 103.44237731987324),
                                       (0.99, 2, 9.21034037197618), (0.5, 100, 99.33412923598846),
                                       (0.999, 5000, 5314.731358301196)]:
        assert br.chi_square_quantile(probability, dof) == pytest.approx(expected, rel=1e-5)


def test_boards_with_0_6_lsb_noise_pass_and_the_old_judgement_failed_most_of_them():
    generator = random.Random(20250610)
    boards = 600
    false_failures = 0
    old_failures = 0
    for _ in range(boards):
        state = generator.getstate()
        judgement, noisy = noise_failures(board_transcript(generator, 0.6))
        false_failures += bool(noisy) or judgement.verdict != "pass"
        # The same conversions as firmware before the pooled estimate reported them, judged as then.
        generator.setstate(state)
        _, old = noise_failures(board_transcript(generator, 0.6, pooled=False))
        old_failures += bool(old)
    # Each 0.6 LSB sweep would need its pooled deviation above ~1.3 LSB to fail: a chance far below 1e-12.
    assert false_failures == 0, f"{false_failures} of {boards} healthy boards failed"
    assert old_failures > boards // 2, f"the largest-point judgement failed only {old_failures} of {boards}"


def test_boards_with_1_5_lsb_noise_fail_on_their_noise():
    generator = random.Random(7)
    boards = 200
    for _ in range(boards):
        judgement, noisy = noise_failures(board_transcript(generator, 1.5))
        assert judgement.verdict == "fail" and noisy, br.format_report(br.Report(), judgement, br.Limits())
        # Most sweeps fail alone; every failure names its channel and gain and the bound above the limit.
        assert len(noisy) >= 16
        assert all(f.message.startswith(f"ADC channel {f.channel} gain {f.gain}: noise ") for f in noisy)


def test_at_the_limit_a_sweep_fails_as_often_as_the_confidence_allows():
    # A sweep whose noise is exactly the limit (1.0 LSB, 63 degrees of freedom): the one-sided test fails it
    # with probability 1 - confidence. Rounding to whole codes adds about 1/12 LSB^2, so a little more here.
    generator = random.Random(3)
    sweeps = 4000
    failed = 0
    limits = br.Limits(noise_confidence=0.95)
    for _ in range(sweeps):
        line = adc_line(generator, 0, 1, 1.0)
        report = br.parse_transcript(line)
        assert not report.garbled
        bound = br.noise_lower_bound(report.adc[0].noise_pooled_lsb, report.adc[0].noise_dof, 0.95)
        failed += bound > limits.max_noise_lsb
    assert 0.03 < failed / sweeps < 0.20
