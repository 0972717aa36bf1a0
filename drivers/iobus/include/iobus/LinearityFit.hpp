// DAC-to-ADC linearity figures for the bring-up report, in integer arithmetic.
//
// The bring-up (docs/iobus/bringup-protocol.md, `BRINGUP ADC`) steps a DAC
// over a range, converts each step several times, and reports the offset,
// the gain error, the largest deviation from the ideal transfer and the
// noise. The firmware has no floating point, so every figure here is an
// integer in hundredths (of an LSB, or of a percent); the caller prints it
// with two decimals.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace iobus {

/// Accumulates the points of one channel at one gain and fits a line.
class LinearityFit {
public:
    /// The most points one fit holds.
    static constexpr size_t kMaximumPoints = 16;

    /// One step: the ideal ADC code and the sums of the conversions read.
    struct Point {
        uint16_t output;     ///< The DAC code written.
        int32_t ideal;       ///< The ideal ADC code for it.
        uint32_t samples;    ///< Conversions read.
        uint32_t sum;        ///< Sum of the codes read.
        uint64_t sumSquares; ///< Sum of the squares of the codes read.
    };

    /// Empties the fit.
    void clear() { count_ = 0; }

    /// Starts a new point for DAC code @p output with ideal ADC code @p ideal;
    /// false when the fit is full.
    bool beginPoint(uint16_t output, int32_t ideal);

    /// Adds one conversion result (a 12-bit code) to the current point.
    void addSample(uint16_t code);

    /// The number of points.
    size_t count() const { return count_; }

    /// Point @p index (0 to count() - 1).
    const Point& point(size_t index) const { return points_[index]; }

    /// The mean of point @p index in tenths of an LSB, rounded.
    int32_t meanTenths(size_t index) const;

    /// The fitted line's error at 0 V (ideal code 2048), in hundredths of an LSB.
    int32_t offsetHundredths() const;

    /// (fitted slope / ideal slope - 1) x 100, in hundredths of a percent.
    int32_t gainErrorHundredthsPercent() const;

    /// The largest |mean - ideal| over the points, in hundredths of an LSB.
    int32_t maximumErrorHundredths() const;

    /// The largest sample standard deviation over the points, in hundredths of an LSB.
    int32_t noiseHundredths() const;

    /// The span of the means (largest minus smallest), in hundredths of an LSB.
    int32_t measuredSpanHundredths() const;

    /// The span of the ideal codes, in LSB.
    int32_t idealSpan() const;

private:
    // Least squares over the points; see LinearityFit.cpp.
    bool fit(int64_t& numerator, int64_t& denominator, int64_t& offsetScaled, int64_t& scale) const;

    Point points_[kMaximumPoints] = {};
    size_t count_ = 0;
};

/// The integer square root of @p value (the largest r with r * r <= value), in bounded time.
uint64_t integerSquareRoot(uint64_t value);

} // namespace iobus
