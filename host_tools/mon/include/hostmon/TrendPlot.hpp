// dcos-mon's trend plot: the samples of every channel over the node's time,
// as a PNG drawn with Debian's cairo: axes with ticks and labels, one line
// per channel in its own colour, a legend naming them, time in seconds on
// x. The geometry is a value of its own, so a test can say where a data
// point must have been drawn and look at that pixel.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hostmon {

struct TrendSeries {
    std::string label;
    /// (seconds, value) in the order they came.
    std::vector<std::pair<double, double>> points;
};

struct PlotOptions {
    int width = 1000;
    int height = 600;
    std::string title;
    std::string yLabel = "value";
};

/// The size limits writeTrendPlot takes.
constexpr int kMinPlotWidth = 200;
constexpr int kMinPlotHeight = 150;
constexpr int kMaxPlotSide = 10000;

/// Where the data goes in the picture.
struct PlotGeometry {
    /// The plot area in pixels: x grows to the right, y downwards.
    double left = 0, top = 0, right = 0, bottom = 0;
    /// The data range the area shows.
    double xMin = 0, xMax = 1, yMin = 0, yMax = 1;

    double xPixel(double seconds) const { return left + (seconds - xMin) / (xMax - xMin) * (right - left); }
    double yPixel(double value) const { return bottom - (value - yMin) / (yMax - yMin) * (bottom - top); }
};

/// The geometry writeTrendPlot uses for @p series at @p options' size.
PlotGeometry plotGeometry(const std::vector<TrendSeries>& series, const PlotOptions& options);

/// The colour of the @p index-th series, as 0xRRGGBB.
uint32_t seriesColour(size_t index);

/// Tick values for [@p low, @p high]: steps of 1, 2 or 5 times a power of
/// ten, about @p wanted of them, every one inside the range.
std::vector<double> niceTicks(double low, double high, int wanted);

/// Draws @p series into a PNG at @p path; false with @p why when the size
/// is out of range or cairo cannot write the file.
bool writeTrendPlot(const std::string& path, const std::vector<TrendSeries>& series, const PlotOptions& options,
                    std::string& why);

} // namespace hostmon
