#include "surfaces/surface_json.h"

#include <fmt/core.h>

#include <cmath>
#include <utility>

#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel::surfaces {
namespace {

std::shared_ptr<const Surface> ReadEvenAsphere(JsonSection& s) {
  EvenAsphereParameters p;
  p.vertex_radius_mm = s.RequiredNumber("vertex_radius_mm");
  if (!(p.vertex_radius_mm > 0.0)) s.Expected("vertex_radius_mm", "a radius > 0 (\"form\" gives the side)");
  p.conic = s.Number("conic", 0.0);
  if (s.Has("coefficients")) {
    s.Section("coefficients", false, [&p](JsonSection& c) {
      for (int order = 4; order <= 20; order += 2) {
        p.even_coefficients.push_back(c.Number(fmt::format("A{}", order), 0.0));
      }
    });
    while (!p.even_coefficients.empty() && p.even_coefficients.back() == 0.0) p.even_coefficients.pop_back();
  }
  const std::vector<double> off = s.Numbers("off_axis_mm", {0.0, 0.0});
  p.off_axis_x_mm = off[0];
  p.off_axis_y_mm = off[1];
  p.concave = s.Choice("form", {"concave", "convex"}) == "concave";
  try {
    return std::make_shared<EvenAsphere>(p);
  } catch (const Error& e) {
    s.Fail("off_axis_mm", fmt::format("is not usable: {}", e.what()));
  }
}

std::shared_ptr<const Surface> ReadXyPolynomial(JsonSection& s) {
  std::vector<XyPolynomialTerm> terms;
  s.Elements("terms", "{\"x_power\", \"y_power\", \"coefficient\"} objects", [&terms](JsonSection& t) {
    XyPolynomialTerm term;
    term.x_power = t.WholeNumber("x_power", 0, 0, 20);
    term.y_power = t.WholeNumber("y_power", 0, 0, 20);
    term.coefficient = t.RequiredNumber("coefficient");
    terms.push_back(term);
  });
  return std::make_shared<XyPolynomial>(std::move(terms));
}

std::shared_ptr<const Surface> ReadHeightGrid(JsonSection& s) {
  HeightGridParameters g;
  g.grid.x0_mm = s.RequiredNumber("x0_mm");
  g.grid.y0_mm = s.RequiredNumber("y0_mm");
  g.grid.dx_mm = s.RequiredNumber("dx_mm");
  if (!(g.grid.dx_mm > 0.0)) s.Expected("dx_mm", "a spacing > 0");
  g.grid.dy_mm = s.RequiredNumber("dy_mm");
  if (!(g.grid.dy_mm > 0.0)) s.Expected("dy_mm", "a spacing > 0");
  const std::string rows_expected = "an array of rows (one per y, each an array of heights along x)";
  if (!s.Has("heights_mm") || !s.Raw("heights_mm").is_array()) s.Expected("heights_mm", rows_expected);
  const nlohmann::json& rows = s.Raw("heights_mm");
  g.grid.ny = static_cast<int>(rows.size());
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const std::string key = fmt::format("heights_mm[{}]", j);
    if (!rows[j].is_array())
      s.Fail(key, fmt::format("expected an array of heights, got {}", JsonText(rows[j])));
    if (j == 0) g.grid.nx = static_cast<int>(rows[j].size());
    if (static_cast<int>(rows[j].size()) != g.grid.nx) {
      s.Fail(key, fmt::format("expected {} heights (as row 0), got {}", g.grid.nx, rows[j].size()));
    }
    for (const nlohmann::json& h : rows[j]) {
      if (!h.is_number() || !std::isfinite(h.get<double>())) {
        s.Fail(key, fmt::format("expected finite numbers only, got {}", JsonText(h)));
      }
      g.heights_mm.push_back(h.get<double>());
    }
  }
  try {
    return std::make_shared<HeightGrid>(std::move(g));
  } catch (const Error& e) {
    s.Fail("heights_mm", fmt::format("is not usable: {}", e.what()));
  }
}

}  // namespace

std::shared_ptr<const Surface> ReadSurface(JsonSection& section, const std::vector<std::string>& types) {
  const std::string type = section.Choice("type", types);
  if (type == "even_asphere") return ReadEvenAsphere(section);
  if (type == "xy_polynomial") return ReadXyPolynomial(section);
  return ReadHeightGrid(section);
}

Aperture ReadAperture(JsonSection& section) {
  const bool circle_keys = section.Has("diameter_mm");
  const bool rectangle_keys = section.Has("size_mm");
  if (circle_keys == rectangle_keys) {
    section.Fail("", fmt::format("expected diameter_mm (a circle) or size_mm (a rectangle), got {}",
                                 circle_keys ? "both" : "neither"));
  }
  // The keys imply the shape; an explicit "shape" must agree with them.
  const std::string implied = circle_keys ? "circle" : "rectangle";
  const std::string shape = section.Choice("shape", {implied, circle_keys ? "rectangle" : "circle"});
  if (shape != implied) {
    section.Fail("shape", fmt::format("expected \"{}\" (the aperture gives {}), got \"{}\"", implied,
                                      circle_keys ? "diameter_mm" : "size_mm", shape));
  }
  Aperture a;
  if (circle_keys) {
    a.shape = Aperture::Shape::kCircle;
    a.diameter_mm = section.RequiredNumber("diameter_mm");
    if (!(a.diameter_mm > 0.0)) section.Expected("diameter_mm", "a diameter > 0");
  } else {
    const std::vector<double> size = section.RequiredNumbers("size_mm", 2);
    if (!(size[0] > 0.0) || !(size[1] > 0.0)) section.Expected("size_mm", "two sizes > 0");
    a.width_x_mm = size[0];
    a.width_y_mm = size[1];
  }
  return a;
}

}  // namespace arcwheel::surfaces
