#include "reports/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <regex>
#include <set>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::reports::plot {
namespace {

// Decodes PNG bytes with cairo's own reader and counts pixels by colour (0xRRGGBB).
std::map<std::uint32_t, int> PixelHistogram(const std::string& png) {
  struct Reader {
    const std::string* bytes;
    std::size_t offset = 0;
  } reader{&png};
  cairo_surface_t* image = cairo_image_surface_create_from_png_stream(
      [](void* closure, unsigned char* data, unsigned int length) {
        auto* r = static_cast<Reader*>(closure);
        if (r->offset + length > r->bytes->size()) return CAIRO_STATUS_READ_ERROR;
        std::copy_n(r->bytes->data() + r->offset, length, data);
        r->offset += length;
        return CAIRO_STATUS_SUCCESS;
      },
      &reader);
  EXPECT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  std::map<std::uint32_t, int> histogram;
  const int width = cairo_image_surface_get_width(image);
  const int height = cairo_image_surface_get_height(image);
  const int stride = cairo_image_surface_get_stride(image);
  const unsigned char* data = cairo_image_surface_get_data(image);
  for (int row = 0; row < height; ++row) {
    const auto* line = reinterpret_cast<const std::uint32_t*>(data + row * stride);
    for (int column = 0; column < width; ++column) ++histogram[line[column] & 0xFFFFFFu];
  }
  cairo_surface_destroy(image);
  return histogram;
}

std::uint32_t Packed(const Rgb& c) {
  auto byte = [](double v) { return static_cast<std::uint32_t>(std::lround(v * 255.0)); };
  return (byte(c.r) << 16) | (byte(c.g) << 8) | byte(c.b);
}

void ExpectTicks(const std::vector<double>& actual, const std::vector<double>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) EXPECT_NEAR(actual[i], expected[i], 1e-9) << "tick " << i;
}

TEST(NiceTicks, FallOnRoundNumbersForKnownRanges) {
  ExpectTicks(NiceTicks(0.0, 1.0, 6), {0.0, 0.2, 0.4, 0.6, 0.8, 1.0});
  ExpectTicks(NiceTicks(0.0, 360.0, 8), {0, 50, 100, 150, 200, 250, 300, 350});
  ExpectTicks(NiceTicks(-3.2, 7.9, 6), {-2, 0, 2, 4, 6});
  ExpectTicks(NiceTicks(74.9961, 75.0039, 5), {74.998, 75.0, 75.002});
  EXPECT_DOUBLE_EQ(NiceStep(74.9961, 75.0039, 5), 0.002);
}

TEST(NiceTicks, StepIsOneTwoOrFiveTimesAPowerOfTenAndTicksFitTheRange) {
  for (double low : {-1234.5, -0.0371, 0.0, 2.5e-4, 74.99}) {
    for (double span : {1e-5, 0.003, 0.9, 7.0, 360.0, 12345.0}) {
      for (int max_ticks : {2, 4, 7, 11}) {
        const double high = low + span;
        const double step = NiceStep(low, high, max_ticks);
        const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-12));
        EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
                    std::abs(mantissa - 5) < 1e-9)
            << "step " << step;
        const std::vector<double> ticks = NiceTicks(low, high, max_ticks);
        EXPECT_LE(static_cast<int>(ticks.size()), max_ticks);
        EXPECT_GE(ticks.size(), 1u) << low << " " << high << " " << max_ticks;
        for (double t : ticks) {
          EXPECT_GE(t, low - 1e-9 * span);
          EXPECT_LE(t, high + 1e-9 * span);
          EXPECT_NEAR(t / step, std::round(t / step), 1e-6);
        }
      }
    }
  }
}

TEST(FormatTick, UsesAsManyDecimalsAsTheStepNeeds) {
  EXPECT_EQ(FormatTick(0.6000000000000001, 0.2), "0.6");
  EXPECT_EQ(FormatTick(75.002, 0.002), "75.002");
  EXPECT_EQ(FormatTick(150.0, 50.0), "150");
  EXPECT_EQ(FormatTick(-1e-17, 0.5), "0.0");
}

TEST(FormatTick, WritesNegativeValuesWithTheMinusSign) {
  EXPECT_EQ(FormatTick(-0.25, 0.05), "−0.25");
  EXPECT_EQ(FormatTick(-150.0, 50.0), "−150");
}

TEST(Viridis, MatchesThePublishedEndAndMiddleColours) {
  EXPECT_EQ(Packed(Viridis(0.0)), 0x440154u);
  EXPECT_EQ(Packed(Viridis(1.0)), 0xFDE725u);
  EXPECT_EQ(Packed(Viridis(5.0 / 9.0)), 0x1F9E89u);
  EXPECT_EQ(Packed(Viridis(-3.0)), 0x440154u) << "clamped below";
  EXPECT_EQ(Packed(Viridis(7.0)), 0xFDE725u) << "clamped above";
}

TEST(Viridis, LightnessRisesMonotonically) {
  // Perceptual maps rise in lightness; Rec. 709 luma is a close enough proxy for this check.
  double previous = -1.0;
  for (int k = 0; k <= 100; ++k) {
    const Rgb c = Viridis(k / 100.0);
    const double luma = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    EXPECT_GT(luma, previous) << "t = " << k / 100.0;
    previous = luma;
  }
}

// A heat map on the nodes x = 0 .. n_x - 1, y = 0 .. n_y - 1, coloured over [0, 1]; no values yet.
HeatMap IntegerNodeMap(std::size_t n_x, std::size_t n_y) {
  HeatMap map;
  map.n_x = n_x;
  map.n_y = n_y;
  for (std::size_t i = 0; i < n_x; ++i) map.x_nodes.push_back(static_cast<double>(i));
  for (std::size_t j = 0; j < n_y; ++j) map.y_nodes.push_back(static_cast<double>(j));
  map.colour_min = 0.0;
  map.colour_max = 1.0;
  return map;
}

TEST(HeatMap, PaintsTwoEqualHalvesInTheColoursOfTheirValues) {
  HeatMap map = IntegerNodeMap(10, 4);
  for (std::size_t i = 0; i < map.n_x; ++i) {
    for (std::size_t j = 0; j < map.n_y; ++j) map.values.push_back(i < 5 ? 0.0 : 1.0);
  }
  map.x.label = "x (mm)";
  map.y.label = "y (mm)";
  map.colour_bar_label = "v (um)";
  const auto histogram = PixelHistogram(RenderPng(map, 400.0, 300.0, 1.0));
  const int low = histogram.count(Packed(Viridis(0.0))) ? histogram.at(Packed(Viridis(0.0))) : 0;
  const int high = histogram.count(Packed(Viridis(1.0))) ? histogram.at(Packed(Viridis(1.0))) : 0;
  EXPECT_GT(low, 10000) << "the left half is painted in viridis(0)";
  EXPECT_NEAR(static_cast<double>(high) / low, 1.0, 0.03) << "the halves are equal";
}

TEST(HeatMap, KeepsEqualScalesOnBothAxesWhenAsked) {
  // Cells span 10 x 5 units. The plot area of a 400 x 300 pt figure leaves 270 x 252 pt for the
  // map (50 pt left, 80 right for the colour bar, 18 top, 30 bottom), so at equal scales the map
  // is 270 pt wide and 135 pt high.
  HeatMap map = IntegerNodeMap(10, 5);
  map.values.assign(map.n_x * map.n_y, 1.0);
  map.equal_aspect = true;
  const auto histogram = PixelHistogram(RenderPng(map, 400.0, 300.0, 1.0));
  const auto yellow = histogram.find(Packed(Viridis(1.0)));
  ASSERT_NE(yellow, histogram.end());
  EXPECT_NEAR(yellow->second, 270.0 * 135.0, 0.03 * 270.0 * 135.0);
}

TEST(PathMap, ColoursEachSegmentByTheValueAtItsEnd) {
  // Two segments of equal length: into point 1 (value 1, yellow) and into point 2 (value 0, purple).
  PathMap path;
  path.x.label = "x (mm)";
  path.y.label = "y (mm)";
  path.x_points = {0.0, 10.0, 10.0};
  path.y_points = {0.0, 0.0, 10.0};
  path.values = {0.5, 1.0, 0.0};
  path.colour_min = 0.0;
  path.colour_max = 1.0;
  const auto histogram = PixelHistogram(RenderPng(path, 300.0, 300.0, 2.0));
  auto count = [&](double t) {
    const auto it = histogram.find(Packed(Viridis(t)));
    return it == histogram.end() ? 0 : it->second;
  };
  EXPECT_GT(count(1.0), 300) << "the first segment";
  EXPECT_GT(count(0.0), 300) << "the second segment";
  EXPECT_NEAR(static_cast<double>(count(1.0)) / count(0.0), 1.0, 0.2) << "segments of equal length";
}

TEST(PathMap, RefusesSizesThatDoNotMatch) {
  PathMap path;
  path.x_points = {0.0, 1.0};
  path.y_points = {0.0, 1.0};
  path.values = {1.0};
  try {
    (void)RenderPng(path, 200.0, 200.0, 1.0);
    ADD_FAILURE() << "mismatched sizes were drawn";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kInternal);
  }
}

TEST(LinePlot, DrawsEachSeriesInItsColour) {
  LinePlot plot;
  plot.x.label = "phase (deg)";
  plot.y.label = "value (um)";
  for (int s = 0; s < 2; ++s) {
    Series series;
    series.label = "series " + std::to_string(s);
    series.colour = SeriesColour(s);
    for (int i = 0; i <= 100; ++i) {
      series.x.push_back(i);
      series.y.push_back(s + std::sin(i / 10.0));
    }
    plot.series.push_back(series);
  }
  const auto histogram = PixelHistogram(RenderPng(plot, 400.0, 250.0, 2.0));
  for (int s = 0; s < 2; ++s) {
    EXPECT_GT(histogram.count(Packed(SeriesColour(s))) ? histogram.at(Packed(SeriesColour(s))) : 0, 200)
        << "series " << s;
  }
}

TEST(RenderSvg, PrefixesEveryIdAndReferenceSoFiguresCanShareAPage) {
  LinePlot plot;
  plot.title = "t";
  plot.x.label = "x (mm)";
  plot.y.label = "y (mm)";
  plot.series.push_back({"s", {0, 1, 2}, {0, 1, 0}, {}, {}, SeriesColour(0)});
  const std::string svg = RenderSvg(plot, 300.0, 200.0, "f7-");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u) << "no XML prolog";
  const std::regex id(R"re(id="([^"]*)")re");
  int ids = 0;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), id); it != std::sregex_iterator();
       ++it, ++ids) {
    EXPECT_EQ((*it)[1].str().rfind("f7-", 0), 0u) << (*it)[1].str();
  }
  EXPECT_GT(ids, 0) << "cairo draws text as glyph symbols referenced by id";
  const std::regex reference(R"re((?:href="#|url\(#)([^")]*))re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), reference); it != std::sregex_iterator();
       ++it) {
    EXPECT_EQ((*it)[1].str().rfind("f7-", 0), 0u) << (*it)[1].str();
  }
}

}  // namespace
}  // namespace arcwheel::reports::plot
