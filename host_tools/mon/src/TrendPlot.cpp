#include <hostmon/TrendPlot.hpp>

#include <cairo.h>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hostmon {

namespace {

// Room for the tick labels, the axis names, the title and the legend.
constexpr double kLeftMargin = 90;
constexpr double kRightMargin = 30;
constexpr double kTopMargin = 70;
constexpr double kBottomMargin = 60;
constexpr double kFontSize = 13;

// Eight colours told apart on screen and on paper (the first ones of
// matplotlib's "tab10", which engineers know from their other plots).
constexpr uint32_t kPalette[] = {0x1F77B4, 0xD62728, 0x2CA02C, 0xFF7F0E, 0x9467BD, 0x8C564B, 0xE377C2, 0x17BECF};

void setColour(cairo_t* cr, uint32_t rgb)
{
    cairo_set_source_rgb(cr, ((rgb >> 16) & 0xFF) / 255.0, ((rgb >> 8) & 0xFF) / 255.0, (rgb & 0xFF) / 255.0);
}

// A tick's text: no more decimals than the step needs.
std::string tickText(double value, double step)
{
    const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
    if (std::fabs(value) < step * 1e-6) {
        value = 0;
    }
    if (std::fabs(value) >= 1e7) {
        return fmt::format("{:.3g}", value);
    }
    return fmt::format("{:.{}f}", value, decimals);
}

void showText(cairo_t* cr, double x, double y, const std::string& text, double alignX, double alignY)
{
    cairo_text_extents_t extents;
    cairo_text_extents(cr, text.c_str(), &extents);
    cairo_move_to(cr, x - extents.width * alignX - extents.x_bearing, y - extents.height * alignY - extents.y_bearing);
    cairo_show_text(cr, text.c_str());
}

} // namespace

uint32_t seriesColour(size_t index) { return kPalette[index % (sizeof kPalette / sizeof kPalette[0])]; }

std::vector<double> niceTicks(double low, double high, int wanted)
{
    std::vector<double> ticks;
    if (!(high > low) || wanted < 1 || !std::isfinite(low) || !std::isfinite(high)) {
        return ticks;
    }
    const double rough = (high - low) / wanted;
    const double power = std::pow(10.0, std::floor(std::log10(rough)));
    double step = power;
    for (const double factor : {1.0, 2.0, 5.0, 10.0}) {
        step = factor * power;
        if (step >= rough) {
            break;
        }
    }
    const double first = std::ceil(low / step - 1e-9) * step;
    for (int i = 0; i < 1000; ++i) {
        const double value = first + i * step;
        if (value > high + step * 1e-9) {
            break;
        }
        ticks.push_back(value);
    }
    return ticks;
}

PlotGeometry plotGeometry(const std::vector<TrendSeries>& series, const PlotOptions& options)
{
    PlotGeometry g;
    g.left = kLeftMargin;
    g.top = kTopMargin;
    g.right = options.width - kRightMargin;
    g.bottom = options.height - kBottomMargin;
    double xMin = std::numeric_limits<double>::infinity();
    double xMax = -xMin;
    double yMin = xMin;
    double yMax = -xMin;
    for (const TrendSeries& s : series) {
        for (const auto& [x, y] : s.points) {
            xMin = std::min(xMin, x);
            xMax = std::max(xMax, x);
            yMin = std::min(yMin, y);
            yMax = std::max(yMax, y);
        }
    }
    if (!std::isfinite(xMin)) {
        xMin = 0;
        xMax = 1;
        yMin = 0;
        yMax = 1;
    }
    if (xMax - xMin < 1e-9) {
        xMax = xMin + 1;
    }
    if (yMax - yMin < 1e-9) {
        yMin -= 1;
        yMax += 1;
    }
    // A little room above and below, so a line along the extreme values
    // does not vanish into the frame.
    const double margin = (yMax - yMin) * 0.05;
    g.xMin = xMin;
    g.xMax = xMax;
    g.yMin = yMin - margin;
    g.yMax = yMax + margin;
    return g;
}

bool writeTrendPlot(const std::string& path, const std::vector<TrendSeries>& series, const PlotOptions& options,
                    std::string& why)
{
    if (options.width < kMinPlotWidth || options.height < kMinPlotHeight || options.width > kMaxPlotSide ||
        options.height > kMaxPlotSide) {
        why = fmt::format("a plot is {}x{} to {}x{} pixels", kMinPlotWidth, kMinPlotHeight, kMaxPlotSide,
                          kMaxPlotSide);
        return false;
    }
    const PlotGeometry g = plotGeometry(series, options);
    cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, options.width, options.height);
    cairo_t* cr = cairo_create(surface);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, kFontSize);

    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);

    // Grid and ticks, then the frame over them.
    const std::vector<double> xTicks = niceTicks(g.xMin, g.xMax, std::max(2, options.width / 110));
    const std::vector<double> yTicks = niceTicks(g.yMin, g.yMax, std::max(2, options.height / 70));
    const double xStep = xTicks.size() > 1 ? xTicks[1] - xTicks[0] : 1;
    const double yStep = yTicks.size() > 1 ? yTicks[1] - yTicks[0] : 1;
    cairo_set_line_width(cr, 1);
    for (const double x : xTicks) {
        const double px = std::round(g.xPixel(x)) + 0.5;
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
        cairo_move_to(cr, px, g.top);
        cairo_line_to(cr, px, g.bottom);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, px, g.bottom);
        cairo_line_to(cr, px, g.bottom + 5);
        cairo_stroke(cr);
        showText(cr, px, g.bottom + 9, tickText(x, xStep), 0.5, 0);
    }
    for (const double y : yTicks) {
        const double py = std::round(g.yPixel(y)) + 0.5;
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
        cairo_move_to(cr, g.left, py);
        cairo_line_to(cr, g.right, py);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, g.left - 5, py);
        cairo_line_to(cr, g.left, py);
        cairo_stroke(cr);
        showText(cr, g.left - 8, py, tickText(y, yStep), 1, 0.5);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, g.left + 0.5, g.top + 0.5, g.right - g.left, g.bottom - g.top);
    cairo_stroke(cr);

    // Axis names and the title.
    showText(cr, (g.left + g.right) / 2, options.height - 12, "time (s)", 0.5, 1);
    cairo_save(cr);
    cairo_translate(cr, 18, (g.top + g.bottom) / 2);
    cairo_rotate(cr, -M_PI / 2);
    showText(cr, 0, 0, options.yLabel, 0.5, 0.5);
    cairo_restore(cr);
    if (!options.title.empty()) {
        cairo_set_font_size(cr, kFontSize + 2);
        showText(cr, (g.left + g.right) / 2, 10, options.title, 0.5, 0);
        cairo_set_font_size(cr, kFontSize);
    }

    // The lines, clipped to the plot area.
    cairo_save(cr);
    cairo_rectangle(cr, g.left, g.top, g.right - g.left, g.bottom - g.top);
    cairo_clip(cr);
    cairo_set_line_width(cr, 2);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (size_t i = 0; i < series.size(); ++i) {
        const TrendSeries& s = series[i];
        if (s.points.empty()) {
            continue;
        }
        setColour(cr, seriesColour(i));
        cairo_move_to(cr, g.xPixel(s.points[0].first), g.yPixel(s.points[0].second));
        for (const auto& [x, y] : s.points) {
            cairo_line_to(cr, g.xPixel(x), g.yPixel(y));
        }
        if (s.points.size() == 1) {
            // One sample is a dot, not nothing.
            cairo_arc(cr, g.xPixel(s.points[0].first), g.yPixel(s.points[0].second), 2, 0, 2 * M_PI);
            cairo_fill(cr);
        } else {
            cairo_stroke(cr);
        }
    }
    cairo_restore(cr);

    // The legend, one entry after the other in the band above the plot.
    double x = g.left;
    const double y = 45;
    for (size_t i = 0; i < series.size(); ++i) {
        setColour(cr, seriesColour(i));
        cairo_set_line_width(cr, 3);
        cairo_move_to(cr, x, y);
        cairo_line_to(cr, x + 24, y);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        showText(cr, x + 30, y, series[i].label, 0, 0.5);
        cairo_text_extents_t extents;
        cairo_text_extents(cr, series[i].label.c_str(), &extents);
        x += 30 + extents.x_advance + 24;
    }

    cairo_destroy(cr);
    cairo_surface_flush(surface);
    const cairo_status_t status = cairo_surface_write_to_png(surface, path.c_str());
    cairo_surface_destroy(surface);
    if (status != CAIRO_STATUS_SUCCESS) {
        why = fmt::format("cannot write {}: {}", path, cairo_status_to_string(status));
        return false;
    }
    return true;
}

} // namespace hostmon
