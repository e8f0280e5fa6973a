#pragma once
// Helpers shared by polishing's tests.

#include <fmt/core.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "core/testing/testing.h"
#include "polishing/removal_function.h"
#include "polishing/robot_kinematics.h"
#include "polishing/robot_model.h"

namespace arcwheel::polishing::testing {

inline constexpr double kDeg = std::numbers::pi / 180.0;  // radians in a degree

// The built-in ABB IRB 4600-40/2.55 with its own URDF.
inline const RobotKinematics& Irb4600Kinematics() {
  static const RobotKinematics k(*FindRobotModel("ABB IRB 4600-40/2.55"),
                                 std::string(FindRobotModel("ABB IRB 4600-40/2.55")->urdf), "built in");
  return k;
}

// Writes `job` to dir/job.json and runs `arcwheel polish` on it into dir/out, with `flags`.
inline arcwheel::testing::CommandResult PolishJob(const arcwheel::testing::TempDir& dir,
                                                  const nlohmann::json& job, const std::string& flags = "") {
  arcwheel::testing::WriteText(dir / "job.json", job.dump(2));
  return arcwheel::testing::RunArcwheel(
      fmt::format("polish {} -o {} {}", (dir / "job.json").string(), (dir / "out").string(), flags));
}

// An axis-aligned elliptic Gaussian of known parameters (peak rate, centre cx, cy and sigmas sx, sy
// in mm) sampled on an nx x ny grid of tool offsets from (x0, y0) in steps of h mm.
inline TabulatedRemovalFunction SampledGaussian(double peak, double cx, double cy, double sx, double sy,
                                                double x0, double y0, double h, int nx, int ny) {
  TabulatedRemovalFunction t{.x0_mm = x0, .y0_mm = y0, .dx_mm = h, .dy_mm = h, .nx = nx, .ny = ny};
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = x0 + i * h - cx, y = y0 + j * h - cy;
      t.rate_um_per_s.push_back(peak * std::exp(-0.5 * (x * x / (sx * sx) + y * y / (sy * sy))));
    }
  }
  return t;
}

// The rows of a CSV the program wrote: "# " comment lines, then a header line (returned in
// `header`), then rows of numbers.
inline std::vector<std::vector<double>> ParseCsvRows(const std::string& text, std::string& header) {
  std::istringstream in(text);
  std::string line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.rfind("# ", 0) == 0) continue;
    if (header.empty()) {
      header = line;
      continue;
    }
    std::vector<double> row;
    std::stringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace arcwheel::polishing::testing
