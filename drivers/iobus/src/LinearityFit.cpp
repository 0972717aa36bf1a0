#include <iobus/LinearityFit.hpp>

#include <iobus/MfioRegisters.hpp>

namespace iobus {

namespace {

constexpr int64_t kZeroCode = mfio::kCodeZero;

int64_t divideRounded(int64_t numerator, int64_t denominator)
{
    if (denominator < 0) {
        numerator = -numerator;
        denominator = -denominator;
    }
    if (numerator >= 0) {
        return (numerator + denominator / 2) / denominator;
    }
    return -((-numerator + denominator / 2) / denominator);
}

int64_t absolute(int64_t value) { return value < 0 ? -value : value; }

} // namespace

uint64_t integerSquareRoot(uint64_t value)
{
    // Bit-by-bit method: 32 iterations for a 64-bit argument.
    uint64_t result = 0;
    uint64_t bit = uint64_t{1} << 62;
    while (bit > value) {
        bit >>= 2;
    }
    while (bit != 0) {
        if (value >= result + bit) {
            value -= result + bit;
            result = (result >> 1) + bit;
        } else {
            result >>= 1;
        }
        bit >>= 2;
    }
    return result;
}

bool LinearityFit::beginPoint(uint16_t output, int32_t ideal)
{
    if (count_ == kMaximumPoints) {
        return false;
    }
    points_[count_++] = Point{output, ideal, 0, 0, 0};
    return true;
}

void LinearityFit::addSample(uint16_t code)
{
    if (count_ == 0) {
        return;
    }
    Point& p = points_[count_ - 1];
    ++p.samples;
    p.sum += code;
    p.sumSquares += uint64_t{code} * code;
}

int32_t LinearityFit::meanTenths(size_t index) const
{
    const Point& p = points_[index];
    if (p.samples == 0) {
        return 0;
    }
    return static_cast<int32_t>(divideRounded(int64_t{p.sum} * 10, p.samples));
}

// Least squares of mean = a + b x u over the points with samples, where
// u = ideal - 2048. Means are used in hundredths of an LSB (m = 100 x mean,
// rounded), which keeps every product inside 64 bits. Gives b as
// numerator / denominator and a - 2048 in hundredths of an LSB.
bool LinearityFit::fit(int64_t& numerator, int64_t& denominator, int64_t& offsetScaled, int64_t& scale) const
{
    int64_t n = 0, su = 0, suu = 0, sm = 0, sum = 0;
    for (size_t i = 0; i < count_; ++i) {
        const Point& p = points_[i];
        if (p.samples == 0) {
            continue;
        }
        const int64_t u = p.ideal - kZeroCode;
        const int64_t m = divideRounded(int64_t{p.sum} * 100, p.samples) - kZeroCode * 100;
        ++n;
        su += u;
        suu += u * u;
        sm += m;
        sum += u * m;
    }
    scale = 100;
    const int64_t d = n * suu - su * su;
    if (n < 2 || d == 0) {
        numerator = 0;
        denominator = 0;
        offsetScaled = n > 0 ? divideRounded(sm, n) : 0;
        return false;
    }
    numerator = n * sum - su * sm; // slope x 100 x d
    denominator = d * 100;
    // a = (sm - b x su) / n, in hundredths.
    offsetScaled = divideRounded(sm * d - (n * sum - su * sm) * su, n * d);
    return true;
}

int32_t LinearityFit::offsetHundredths() const
{
    int64_t numerator, denominator, offset, scale;
    fit(numerator, denominator, offset, scale);
    return static_cast<int32_t>(offset);
}

int32_t LinearityFit::gainErrorHundredthsPercent() const
{
    int64_t numerator, denominator, offset, scale;
    if (!fit(numerator, denominator, offset, scale)) {
        return 0;
    }
    // (b - 1) x 100 % in hundredths: (numerator - denominator) x 10000 / denominator.
    return static_cast<int32_t>(divideRounded((numerator - denominator) * 10000, denominator));
}

int32_t LinearityFit::maximumErrorHundredths() const
{
    int64_t largest = 0;
    for (size_t i = 0; i < count_; ++i) {
        const Point& p = points_[i];
        if (p.samples == 0) {
            continue;
        }
        const int64_t error = divideRounded((int64_t{p.sum} - int64_t{p.ideal} * p.samples) * 100, p.samples);
        if (absolute(error) > largest) {
            largest = absolute(error);
        }
    }
    return static_cast<int32_t>(largest);
}

int32_t LinearityFit::noiseHundredths() const
{
    uint64_t largest = 0;
    for (size_t i = 0; i < count_; ++i) {
        const Point& p = points_[i];
        if (p.samples < 2) {
            continue;
        }
        // Sample variance = (n x sum(x^2) - sum(x)^2) / (n x (n - 1)); times 10^4 for hundredths.
        const uint64_t n = p.samples;
        const uint64_t spread = n * p.sumSquares - uint64_t{p.sum} * p.sum;
        const uint64_t variance = spread * 10000u / (n * (n - 1u));
        const uint64_t deviation = integerSquareRoot(variance);
        if (deviation > largest) {
            largest = deviation;
        }
    }
    return static_cast<int32_t>(largest);
}

int32_t LinearityFit::measuredSpanHundredths() const
{
    bool any = false;
    int64_t lowest = 0, highest = 0;
    for (size_t i = 0; i < count_; ++i) {
        const Point& p = points_[i];
        if (p.samples == 0) {
            continue;
        }
        const int64_t mean = divideRounded(int64_t{p.sum} * 100, p.samples);
        if (!any || mean < lowest) {
            lowest = mean;
        }
        if (!any || mean > highest) {
            highest = mean;
        }
        any = true;
    }
    return static_cast<int32_t>(highest - lowest);
}

int32_t LinearityFit::idealSpan() const
{
    if (count_ == 0) {
        return 0;
    }
    int32_t lowest = points_[0].ideal, highest = points_[0].ideal;
    for (size_t i = 1; i < count_; ++i) {
        lowest = points_[i].ideal < lowest ? points_[i].ideal : lowest;
        highest = points_[i].ideal > highest ? points_[i].ideal : highest;
    }
    return highest - lowest;
}

} // namespace iobus
