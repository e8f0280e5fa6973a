// arcwheel fit circle POINTS.csv [--association A] (formats.md section 4).

#include <fmt/core.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "characteristics/association.h"
#include "cli/columns_csv.h"
#include "cli/commands.h"
#include "core/error.h"
#include "core/json_text.h"
#include "fitting/circle_fit.h"

namespace arcwheel::cli {
namespace {

constexpr const char* kCircleFitStage = "fit.circle";

// The geometric least-squares circle with its sigmas (the contract's first output, unchanged).
nlohmann::json LeastSquaresCircle(const std::string& path, const TwoColumns& points) {
  const fitting::CircleFit result = fitting::FitCircle(points.first, points.second, {}, {});
  if (!result.IsUsable()) {
    throw Error(ErrorCode::kFitFailed, kCircleFitStage, "'" + path + "': " + result.message);
  }
  nlohmann::json out;
  out["center"] = {result.center_mm.x(), result.center_mm.y()};
  out["radius"] = result.radius_mm;
  out["n"] = result.n;
  out["rms_residual_mm"] = result.rms_residual_mm;
  out["pv_residual_mm"] = result.pv_residual_mm;
  out["radius_sigma_mm"] = result.radius_sigma_mm();
  out["center_sigma_mm"] = {std::sqrt(result.covariance(0, 0)), std::sqrt(result.covariance(1, 1))};
  return out;
}

// Minimum zone, maximum inscribed or minimum circumscribed, with its support points.
nlohmann::json ChebyshevCircle(const std::string& path, const TwoColumns& points,
                               characteristics::Association association) {
  const characteristics::AssociatedCircle circle =
      characteristics::AssociateCircle(points.first, points.second, {.association = association});
  if (circle.status == characteristics::AssociationStatus::kNotDefined) {
    throw Error(ErrorCode::kBadInput, kCircleFitStage, "'" + path + "': " + circle.message);
  }
  if (!circle.IsCertified()) {
    throw Error(ErrorCode::kFitFailed, kCircleFitStage, "'" + path + "': " + circle.message);
  }
  nlohmann::json out;
  out["center"] = {circle.center_x_mm, circle.center_y_mm};
  if (association == characteristics::Association::kMinimumZone) {
    out["radius_inner_mm"] = circle.radius_inner_mm;
    out["radius_outer_mm"] = circle.radius_outer_mm;
    out["zone_width_mm"] = circle.zone_width_mm();
  } else {
    out["radius"] = circle.radius_mm;
  }
  out["n"] = circle.n;
  out["association"] = characteristics::AssociationName(association);
  out["support_point_indices"] = circle.support_indices;
  return out;
}

}  // namespace

void AddFitCommand(CLI::App& app) {
  CLI::App* fit = app.add_subcommand("fit", "least-squares fits of point sets");
  fit->require_subcommand(1);
  CLI::App* circle = fit->add_subcommand("circle", "reference circle through 2D points (JSON on stdout)");
  auto path = std::make_shared<std::string>();
  auto columns = std::make_shared<std::vector<std::string>>(std::vector<std::string>{"x_mm", "y_mm"});
  auto association = std::make_shared<std::string>("least-squares");
  circle->add_option("POINTS", *path, "CSV with a header naming the columns")->required();
  circle->add_option("--columns", *columns, "the two column names to use")
      ->expected(2)
      ->capture_default_str();
  circle
      ->add_option("--association", *association,
                   "least-squares, minimum-zone (Chebyshev), maximum-inscribed or minimum-circumscribed")
      ->check(CLI::IsMember({"least-squares", "minimum-zone", "maximum-inscribed", "minimum-circumscribed"}))
      ->capture_default_str();
  circle->footer(
      "Output (least-squares): {\"center\": [a, b], \"radius\": r, \"n\": N, \"rms_residual_mm\", "
      "\"pv_residual_mm\",\n"
      "\"radius_sigma_mm\", \"center_sigma_mm\"}; sigmas from the residual scatter (unknown noise).\n"
      "Other associations: \"center\", \"n\", \"association\", \"support_point_indices\" (0-based data rows) "
      "and\n"
      "\"radius_inner_mm\", \"radius_outer_mm\", \"zone_width_mm\" (minimum-zone) or \"radius\". "
      "docs/characteristics.md");
  circle->callback([path, columns, association] {
    const TwoColumns points = ReadTwoColumns(*path, kCircleFitStage, {{(*columns)[0], (*columns)[1]}});
    if (const std::string problem = characteristics::CircleDataProblem(points.first, points.second);
        !problem.empty()) {
      throw Error(ErrorCode::kBadInput, kCircleFitStage, "'" + *path + "': " + problem);
    }
    const characteristics::Association chosen = *characteristics::ParseAssociation(*association);
    const nlohmann::json out = chosen == characteristics::Association::kLeastSquares
                                   ? LeastSquaresCircle(*path, points)
                                   : ChebyshevCircle(*path, points, chosen);
    // 17 significant digits: the numbers round-trip exactly.
    fmt::print("{}\n", JsonText(out));
  });
}

}  // namespace arcwheel::cli
