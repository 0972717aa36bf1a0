// dcos-mon's trend plot: the PNG is what was asked (read back with cairo),
// each channel's line is drawn in its colour where its data say, the
// ticks are round numbers inside the range, and a size out of range or a
// file that cannot be written is refused with a reason.
#include <hostmon/TrendPlot.hpp>

#include <cairo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace {

std::string temporaryPng(const char* name) { return std::string(::testing::TempDir()) + name; }

struct Image {
    cairo_surface_t* surface = nullptr;
    explicit Image(const std::string& path) : surface(cairo_image_surface_create_from_png(path.c_str())) {}
    ~Image() { cairo_surface_destroy(surface); }
    bool ok() const { return cairo_surface_status(surface) == CAIRO_STATUS_SUCCESS; }
    int width() const { return cairo_image_surface_get_width(surface); }
    int height() const { return cairo_image_surface_get_height(surface); }
    uint32_t rgb(int x, int y) const
    {
        const unsigned char* data = cairo_image_surface_get_data(surface);
        const int stride = cairo_image_surface_get_stride(surface);
        uint32_t pixel;
        std::memcpy(&pixel, data + y * stride + x * 4, sizeof pixel);
        return pixel & 0xFFFFFF;
    }
    // Whether a pixel within @p radius of (x, y) has @p colour, give or
    // take the antialiasing's blend.
    bool near(double x, double y, uint32_t colour, int radius = 2) const
    {
        for (int dy = -radius; dy <= radius; ++dy) {
            for (int dx = -radius; dx <= radius; ++dx) {
                const int px = static_cast<int>(std::lround(x)) + dx;
                const int py = static_cast<int>(std::lround(y)) + dy;
                if (px < 0 || py < 0 || px >= width() || py >= height()) {
                    continue;
                }
                const uint32_t p = rgb(px, py);
                int distance = 0;
                for (int shift = 0; shift < 24; shift += 8) {
                    distance += std::abs(static_cast<int>((p >> shift) & 0xFF) -
                                         static_cast<int>((colour >> shift) & 0xFF));
                }
                if (distance < 40) {
                    return true;
                }
            }
        }
        return false;
    }
};

TEST(TrendPlot, WritesAPngOfTheAskedSizeWithEachLineWhereItsDataSay)
{
    hostmon::TrendSeries ramp{"ramp", {}};
    hostmon::TrendSeries wave{"wave", {}};
    for (int i = 0; i <= 50; ++i) {
        ramp.points.emplace_back(i * 0.1, i * 20.0);
        wave.points.emplace_back(i * 0.1, 500 + 400 * std::sin(i * 0.3));
    }
    const std::vector<hostmon::TrendSeries> series{ramp, wave};
    hostmon::PlotOptions options;
    options.width = 640;
    options.height = 400;
    options.title = "node 3";
    const std::string path = temporaryPng("trend.png");
    std::string why;
    ASSERT_TRUE(hostmon::writeTrendPlot(path, series, options, why)) << why;
    const Image image(path);
    ASSERT_TRUE(image.ok());
    EXPECT_EQ(image.width(), 640);
    EXPECT_EQ(image.height(), 400);

    const hostmon::PlotGeometry g = hostmon::plotGeometry(series, options);
    EXPECT_DOUBLE_EQ(g.xMin, 0.0);
    EXPECT_DOUBLE_EQ(g.xMax, 5.0);
    EXPECT_LT(g.yMin, 0.0);
    EXPECT_GT(g.yMax, 1000.0);
    // Samples of both lines, away from where they cross.
    for (const int i : {3, 10, 25, 40, 47}) {
        const auto& [x, y] = ramp.points[i];
        EXPECT_TRUE(image.near(g.xPixel(x), g.yPixel(y), hostmon::seriesColour(0))) << "ramp sample " << i;
    }
    for (const int i : {0, 5, 21, 36}) {
        const auto& [x, y] = wave.points[i];
        EXPECT_TRUE(image.near(g.xPixel(x), g.yPixel(y), hostmon::seriesColour(1))) << "wave sample " << i;
    }
    // Where no data are, no line: the corner of the plot area opposite the ramp.
    EXPECT_FALSE(image.near(g.xPixel(4.8), g.yPixel(30), hostmon::seriesColour(0), 4));
    EXPECT_EQ(image.rgb(g.left + 20, g.bottom - 3) & 0xFFFFFF, 0xFFFFFFu) << "the background is white";
    // The frame of the axes is drawn.
    EXPECT_LT(image.rgb(static_cast<int>(g.left), static_cast<int>((g.top + g.bottom) / 2)) & 0xFF, 0x80u);
    std::remove(path.c_str());
}

TEST(TrendPlot, AFlatLineAndNoDataStillMakeAPicture)
{
    const std::string path = temporaryPng("flat.png");
    std::string why;
    hostmon::PlotOptions options;
    ASSERT_TRUE(hostmon::writeTrendPlot(path, {{"still", {{0, 5}, {1, 5}}}}, options, why)) << why;
    const hostmon::PlotGeometry flat = hostmon::plotGeometry({{"still", {{0, 5}, {1, 5}}}}, options);
    EXPECT_LT(flat.yMin, 5.0);
    EXPECT_GT(flat.yMax, 5.0);
    ASSERT_TRUE(hostmon::writeTrendPlot(path, {{"none", {}}}, options, why)) << why;
    const Image image(path);
    EXPECT_TRUE(image.ok());
    EXPECT_EQ(image.width(), options.width);
    std::remove(path.c_str());
}

TEST(TrendPlot, RefusesASizeOutOfRangeAndAnUnwritableFile)
{
    std::string why;
    hostmon::PlotOptions options;
    options.width = 10;
    EXPECT_FALSE(hostmon::writeTrendPlot(temporaryPng("small.png"), {}, options, why));
    EXPECT_NE(why.find("pixels"), std::string::npos) << why;
    options.width = 800;
    why.clear();
    EXPECT_FALSE(hostmon::writeTrendPlot("/nonexistent-directory/plot.png", {}, options, why));
    EXPECT_NE(why.find("/nonexistent-directory/plot.png"), std::string::npos) << why;
}

TEST(TrendPlot, TicksAreRoundNumbersInsideTheRange)
{
    EXPECT_EQ(hostmon::niceTicks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
    EXPECT_EQ(hostmon::niceTicks(-3, 97, 5), (std::vector<double>{0, 20, 40, 60, 80}));
    const std::vector<double> fine = hostmon::niceTicks(0.01, 0.05, 4);
    ASSERT_FALSE(fine.empty());
    for (const double tick : fine) {
        EXPECT_GE(tick, 0.01 - 1e-12);
        EXPECT_LE(tick, 0.05 + 1e-12);
    }
    EXPECT_TRUE(hostmon::niceTicks(1, 1, 5).empty());
}

} // namespace
