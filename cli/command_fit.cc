// arcwheel fit circle POINTS.csv (formats.md section 4).

#include <fmt/core.h>

#include <charconv>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"
#include "fitting/circle_fit.h"

namespace arcwheel::cli {
namespace {

constexpr const char* kCircleFitStage = "fit.circle";

struct Points {
  std::vector<double> x, y;
};

std::vector<std::string> SplitCells(const std::string& line) {
  const char separator = line.find(',') != std::string::npos   ? ','
                         : line.find(';') != std::string::npos ? ';'
                                                               : '\t';
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, separator)) {
    const auto begin = cell.find_first_not_of(" \t\r");
    const auto end = cell.find_last_not_of(" \t\r");
    cells.push_back(begin == std::string::npos ? "" : cell.substr(begin, end - begin + 1));
  }
  return cells;
}

Points ReadPoints(const std::string& path, const std::string& x_name, const std::string& y_name) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::kIo, kCircleFitStage, "cannot open '" + path + "'");
  std::string line;
  std::size_t number = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    header = SplitCells(line);
    break;
  }
  const auto find = [&](const std::string& name) {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    throw Error(ErrorCode::kBadInput, kCircleFitStage,
                "'" + path + "': the header has no column '" + name + "'");
  };
  const std::size_t ix = find(x_name);
  const std::size_t iy = find(y_name);
  Points points;
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> cells = SplitCells(line);
    if (cells.size() != header.size()) {
      throw Error(ErrorCode::kBadInput, kCircleFitStage,
                  fmt::format("'{}' line {}: {} cells, the header names {}", path, number, cells.size(),
                              header.size()));
    }
    for (const std::size_t column : {ix, iy}) {
      double value = 0;
      const std::string& cell = cells[column];
      const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
      if (error != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value)) {
        throw Error(
            ErrorCode::kBadInput, kCircleFitStage,
            fmt::format("'{}' line {}: cannot read {} value '{}'", path, number, header[column], cell));
      }
      (column == ix ? points.x : points.y).push_back(value);
    }
  }
  return points;
}

}  // namespace

void AddFitCommand(CLI::App& app) {
  CLI::App* fit = app.add_subcommand("fit", "least-squares fits of point sets");
  fit->require_subcommand(1);
  CLI::App* circle =
      fit->add_subcommand("circle", "geometric least-squares circle through 2D points (JSON on stdout)");
  auto path = std::make_shared<std::string>();
  auto columns = std::make_shared<std::vector<std::string>>(std::vector<std::string>{"x_mm", "y_mm"});
  circle->add_option("POINTS", *path, "CSV with a header naming the columns")->required();
  circle->add_option("--columns", *columns, "the two column names to use")
      ->expected(2)
      ->capture_default_str();
  circle->footer(
      "Output: {\"center\": [a, b], \"radius\": r, \"n\": N, \"rms_residual_mm\", \"pv_residual_mm\",\n"
      "\"radius_sigma_mm\", \"center_sigma_mm\"}; sigmas from the residual scatter (unknown noise).");
  circle->callback([path, columns] {
    const Points points = ReadPoints(*path, (*columns)[0], (*columns)[1]);
    const fitting::CircleFit result = fitting::FitCircle(points.x, points.y, {}, {});
    if (!result.IsUsable()) {
      throw Error(ErrorCode::kFitFailed, kCircleFitStage, "'" + *path + "': " + result.message);
    }
    nlohmann::json out;
    out["center"] = {result.center_mm.x(), result.center_mm.y()};
    out["radius"] = result.radius_mm;
    out["n"] = result.n;
    out["rms_residual_mm"] = result.rms_residual_mm;
    out["pv_residual_mm"] = result.pv_residual_mm;
    out["radius_sigma_mm"] = result.radius_sigma_mm();
    out["center_sigma_mm"] = {std::sqrt(result.covariance(0, 0)), std::sqrt(result.covariance(1, 1))};
    // 17 significant digits: the numbers round-trip exactly.
    fmt::print("{}\n", out.dump(-1, ' ', false, nlohmann::json::error_handler_t::strict));
  });
}

}  // namespace arcwheel::cli
