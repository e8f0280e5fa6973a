#include "surfaces/surface_json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace arcwheel::surfaces {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

const JsonJobContext kContext{.file = "job.json", .stage = "test.job", .docs_page = "docs/test.md"};

struct ReadResult {
  Aperture aperture;
  json resolved;
  std::string error;  // empty when accepted
};

ReadResult ReadApertureText(const std::string& text) {
  const json document = json::parse(R"({"aperture": )" + text + "}");
  JsonSection root(document, kContext);
  ReadResult result;
  try {
    root.Section("aperture", true, [&result](JsonSection& s) { result.aperture = ReadAperture(s); });
    result.resolved = root.resolved()["aperture"];
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput) << e.what();
    result.error = e.what();
  }
  return result;
}

TEST(ReadAperture, TakesTheShapeFromTheKeysWhenItIsLeftOut) {
  const ReadResult circle = ReadApertureText(R"({"diameter_mm": 60})");
  ASSERT_EQ(circle.error, "");
  EXPECT_EQ(circle.aperture.shape, Aperture::Shape::kCircle);
  EXPECT_EQ(circle.aperture.diameter_mm, 60.0);
  EXPECT_EQ(circle.resolved["shape"], "circle");  // recorded, as if given

  const ReadResult rectangle = ReadApertureText(R"({"size_mm": [40, 30]})");
  ASSERT_EQ(rectangle.error, "");
  EXPECT_EQ(rectangle.aperture.shape, Aperture::Shape::kRectangle);
  EXPECT_EQ(rectangle.aperture.width_x_mm, 40.0);
  EXPECT_EQ(rectangle.aperture.width_y_mm, 30.0);
  EXPECT_EQ(rectangle.resolved["shape"], "rectangle");

  const ReadResult given = ReadApertureText(R"({"shape": "circle", "diameter_mm": 25})");
  ASSERT_EQ(given.error, "");
  EXPECT_EQ(given.aperture.shape, Aperture::Shape::kCircle);
}

TEST(ReadAperture, RefusesNeitherOrBothSizeKeysAndAShapeThatContradictsThem) {
  EXPECT_THAT(
      ReadApertureText(R"({"shape": "circle"})").error,
      HasSubstr("key 'aperture' expected diameter_mm (a circle) or size_mm (a rectangle), got neither"));
  EXPECT_THAT(ReadApertureText(R"({"diameter_mm": 60, "size_mm": [40, 30]})").error,
              HasSubstr("key 'aperture' expected diameter_mm (a circle) or size_mm (a rectangle), got both"));
  EXPECT_THAT(ReadApertureText(R"({"shape": "rectangle", "diameter_mm": 60})").error,
              HasSubstr("key 'aperture.shape' expected \"circle\" (the aperture gives diameter_mm), got "
                        "\"rectangle\""));
  EXPECT_THAT(
      ReadApertureText(R"({"shape": "circle", "size_mm": [4, 3]})").error,
      HasSubstr("key 'aperture.shape' expected \"rectangle\" (the aperture gives size_mm), got \"circle\""));
  EXPECT_THAT(ReadApertureText(R"({"shape": "oval", "size_mm": [4, 3]})").error,
              HasSubstr("key 'aperture.shape' expected one of \"rectangle\", \"circle\", got \"oval\""));
  EXPECT_THAT(ReadApertureText(R"({"diameter_mm": -5})").error,
              HasSubstr("key 'aperture.diameter_mm' expected a diameter > 0, got -5"));
  EXPECT_THAT(ReadApertureText(R"({"size_mm": [4]})").error,
              HasSubstr("key 'aperture.size_mm' expected an array of 2 finite numbers, got [4]"));
}

std::string SurfaceError(const std::string& text, const std::vector<std::string>& types) {
  const json document = json::parse(R"({"surface": )" + text + "}");
  JsonSection root(document, kContext);
  try {
    root.Section("surface", true, [&types](JsonSection& s) { (void)ReadSurface(s, types); });
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ReadSurface, ReadsAFreeformWhosePowersAreWholeNumbersWithinZeroToTwenty) {
  const json document = json::parse(
      R"({"type": "xy_polynomial", "terms": [{"x_power": 2, "coefficient": 0.5}, {"x_power": 1.0, "y_power": 3, "coefficient": -2}]})");
  JsonSection section(document, kContext);
  const auto surface = ReadSurface(section, {"even_asphere", "xy_polynomial"});
  // z = 0.5 x^2 - 2 x y^3 at (2, -1): 2 + 4.
  EXPECT_DOUBLE_EQ(surface->Evaluate(2.0, -1.0).z_mm, 6.0);
  const std::vector<std::string> types = {"even_asphere", "xy_polynomial"};
  EXPECT_THAT(
      SurfaceError(R"({"type": "xy_polynomial", "terms": [{"x_power": 2.5, "coefficient": 1}]})", types),
      HasSubstr("key 'surface.terms[0].x_power' expected a whole number within 0 .. 20, got 2.5"));
  EXPECT_THAT(
      SurfaceError(R"({"type": "xy_polynomial", "terms": [{"y_power": 21, "coefficient": 1}]})", types),
      HasSubstr("key 'surface.terms[0].y_power' expected a whole number within 0 .. 20, got 21"));
  EXPECT_THAT(SurfaceError(R"({"type": "height_grid"})", types),
              HasSubstr("key 'surface.type' expected one of \"even_asphere\", \"xy_polynomial\", got "
                        "\"height_grid\""));
  EXPECT_THAT(SurfaceError(R"({"type": "even_asphere", "vertex_radius_mm": -400})", types),
              HasSubstr("key 'surface.vertex_radius_mm' expected a radius > 0"));
}

}  // namespace
}  // namespace arcwheel::surfaces
