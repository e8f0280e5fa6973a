// arcwheel roundness PROFILE.csv [--filter-upr K | --no-filter] [--association A] (formats.md
// section 8).

#include <fmt/core.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "characteristics/roundness.h"
#include "cli/columns_csv.h"
#include "cli/commands.h"
#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel::cli {
namespace {

constexpr const char* kRoundnessStage = "roundness";
// ISO 12181-2's default operator.
constexpr double kDefaultCutoffUpr = 50.0;

struct Trace {
  std::vector<double> angle_deg, radius_mm;
  std::vector<std::size_t> line;
};

// The trace as angles and radii about the instrument's axis, from either pair of columns.
Trace ReadTrace(const std::string& path) {
  TwoColumns columns = ReadTwoColumns(path, kRoundnessStage, {{"angle_deg", "radius_mm"}, {"x_mm", "y_mm"}});
  Trace trace;
  trace.line = std::move(columns.line);
  if (columns.first_name == "angle_deg") {
    trace.angle_deg = std::move(columns.first);
    trace.radius_mm = std::move(columns.second);
  } else {
    for (std::size_t i = 0; i < columns.first.size(); ++i) {
      trace.angle_deg.push_back(std::atan2(columns.second[i], columns.first[i]) * 180.0 / std::numbers::pi);
      trace.radius_mm.push_back(std::hypot(columns.first[i], columns.second[i]));
    }
  }
  for (std::size_t i = 0; i < trace.radius_mm.size(); ++i) {
    if (!(trace.radius_mm[i] > 0)) {
      throw Error(
          ErrorCode::kBadInput, kRoundnessStage,
          fmt::format("'{}' line {}: radius {} mm from the axis; a roundness trace needs radii above 0", path,
                      trace.line[i], trace.radius_mm[i]));
    }
  }
  return trace;
}

// Refuses what the evaluation cannot take, naming the file, line and option.
void CheckTrace(const std::string& path, const Trace& trace, std::optional<double> cutoff_upr) {
  const std::size_t n = trace.radius_mm.size();
  if (n < 8) {
    throw Error(ErrorCode::kBadInput, kRoundnessStage,
                fmt::format("'{}': a closed profile needs at least 8 points, got {}", path, n));
  }
  const characteristics::AngleSpacing spacing = characteristics::CheckAngleSpacing(trace.angle_deg);
  if (!spacing.equally_spaced) {
    const auto from = static_cast<std::size_t>(spacing.largest_gap_index);
    throw Error(
        ErrorCode::kBadInput, kRoundnessStage,
        fmt::format(
            "'{}': the angles are not equally spaced over one turn: the largest gap is {} deg, from line "
            "{} to line {}, where 360 / {} points is {} deg (the steps add up to {} deg)",
            path, spacing.largest_gap_deg, trace.line[from], trace.line[(from + 1) % n], n,
            spacing.expected_step_deg, spacing.turn_deg));
  }
  if (cutoff_upr && *cutoff_upr > 0.5 * static_cast<double>(n)) {
    throw Error(ErrorCode::kInvalidOption, kRoundnessStage,
                fmt::format("--filter-upr {} is above half the {} points of '{}' ({} UPR)", *cutoff_upr, n,
                            path, 0.5 * static_cast<double>(n)));
  }
}

nlohmann::json ToJson(const characteristics::RoundnessResult& result, std::size_t n) {
  nlohmann::json out;
  out["RONt_um"] = result.ront_um;
  out["RONp_um"] = result.ronp_um;
  out["RONv_um"] = result.ronv_um;
  out["RONq_um"] = result.ronq_um;
  out["center"] = {result.reference.center_x_mm, result.reference.center_y_mm};
  out["radius_mm"] = result.reference.radius_mm;
  if (result.op.association == characteristics::Association::kMinimumZone) {
    out["radius_inner_mm"] = result.reference.radius_inner_mm;
    out["radius_outer_mm"] = result.reference.radius_outer_mm;
  }
  out["filter"] = result.op.filter_cutoff_upr
                      ? nlohmann::json{{"type", "gaussian"}, {"cutoff_upr", *result.op.filter_cutoff_upr}}
                      : nlohmann::json{{"type", "none"}};
  out["association"] = characteristics::AssociationName(result.op.association);
  out["operator"] = result.op.Describe();
  if (result.op.association != characteristics::Association::kLeastSquares) {
    out["support_point_indices"] = result.reference.support_indices;
  }
  out["n"] = n;
  nlohmann::json harmonics = nlohmann::json::array();
  for (std::size_t k = 1; k <= result.harmonic_amplitude_um.size(); ++k) {
    harmonics.push_back({{"upr", k}, {"amplitude_um", result.harmonic_amplitude_um[k - 1]}});
  }
  out["harmonics"] = std::move(harmonics);
  return out;
}

}  // namespace

void AddRoundnessCommand(CLI::App& app) {
  CLI::App* command = app.add_subcommand(
      "roundness", "ISO 12181 roundness of a closed trace: RONt, RONp, RONv, RONq, spectrum (JSON)");
  auto path = std::make_shared<std::string>();
  auto cutoff_upr = std::make_shared<double>(kDefaultCutoffUpr);
  auto no_filter = std::make_shared<bool>(false);
  auto association = std::make_shared<std::string>("minimum-zone");
  command->add_option("PROFILE", *path, "CSV with columns angle_deg,radius_mm or x_mm,y_mm")->required();
  CLI::Option* filter =
      command
          ->add_option("--filter-upr", *cutoff_upr,
                       "Gaussian filter cut-off in undulations per revolution (ISO 16610-21)")
          ->capture_default_str();
  command->add_flag("--no-filter", *no_filter, "evaluate the trace unfiltered")->excludes(filter);
  command
      ->add_option(
          "--association", *association,
          "reference circle: least-squares, minimum-zone, maximum-inscribed or minimum-circumscribed")
      ->check(CLI::IsMember({"least-squares", "minimum-zone", "maximum-inscribed", "minimum-circumscribed"}))
      ->capture_default_str();
  command->footer(
      "Output: {\"RONt_um\", \"RONp_um\", \"RONv_um\", \"RONq_um\", \"center\", \"radius_mm\", \"filter\",\n"
      "\"association\", \"operator\", \"support_point_indices\", \"n\", \"harmonics\"}. "
      "docs/characteristics.md");
  command->callback([path, cutoff_upr, no_filter, association] {
    const std::optional<double> cutoff = *no_filter ? std::nullopt : std::optional<double>(*cutoff_upr);
    if (cutoff && !(*cutoff > 0)) {
      throw Error(ErrorCode::kInvalidOption, kRoundnessStage,
                  fmt::format("--filter-upr {} violates > 0", *cutoff));
    }
    const Trace trace = ReadTrace(*path);
    CheckTrace(*path, trace, cutoff);
    characteristics::RoundnessResult result;
    try {
      result = characteristics::EvaluateRoundness(
          trace.angle_deg, trace.radius_mm,
          {.filter_cutoff_upr = cutoff, .association = *characteristics::ParseAssociation(*association)});
    } catch (const Error& error) {
      throw Error(error.code(), kRoundnessStage, fmt::format("'{}': {}", *path, error.what()));
    }
    fmt::print("{}\n", JsonText(ToJson(result, trace.radius_mm.size())));
  });
}

}  // namespace arcwheel::cli
