// arcwheel transform fit PAIRS.csv --model MODEL (formats.md section 5) and
// arcwheel transform apply TRANSFORM.json FILE (toolpath CSV, G-code or PMAC program).

#include <fmt/core.h>
#include <unistd.h>

#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/output.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "frames/csv_table.h"
#include "frames/program_transform.h"
#include "frames/transform_fit.h"
#include "frames/transform_json.h"

namespace arcwheel::cli {
namespace {

constexpr const char* kTransformFitStage = "transform.fit";
constexpr const char* kApplyStage = "transform.apply";

std::vector<frames::PointPair> ReadPairs(const std::string& path, frames::TransformModel model) {
  const frames::CsvTable table = frames::ReadCsvTable(path, kTransformFitStage);
  const int d = frames::ModelDimension(model);
  const char* names[2][3] = {{"xs_mm", "ys_mm", "zs_mm"}, {"xt_mm", "yt_mm", "zt_mm"}};
  std::vector<size_t> columns;
  for (const auto& side : names) {
    for (int k = 0; k < d; ++k) columns.push_back(table.Require(side[k], kTransformFitStage));
  }
  std::vector<frames::PointPair> pairs(table.cells.size());
  for (size_t row = 0; row < table.cells.size(); ++row) {
    for (int k = 0; k < d; ++k) {
      pairs[row].source_mm(k) = table.Number(row, columns[k], kTransformFitStage);
      pairs[row].target_mm(k) = table.Number(row, columns[d + k], kTransformFitStage);
    }
  }
  return pairs;
}

// The fit does not know the file; bad geometry is reported against it.
frames::TransformFit FitNamingFile(const std::vector<frames::PointPair>& pairs, frames::TransformModel model,
                                   const frames::TransformFitOptions& options, const std::string& path) {
  try {
    return frames::FitTransform(pairs, model, options);
  } catch (const Error& error) {
    if (error.code() != ErrorCode::kBadInput && error.code() != ErrorCode::kFitFailed) throw;
    throw Error(error.code(), kTransformFitStage, fmt::format("'{}': {}", path, error.what()));
  }
}

std::string ReadText(const std::string& path, const char* stage) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, stage, fmt::format("cannot open '{}'", path));
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::kIo, stage, fmt::format("cannot read '{}'", path));
  return buffer.str();
}

nlohmann::json ReadJson(const std::string& path, const char* stage) {
  return ParseJsonText(ReadText(path, stage), path, stage);
}

std::string FitSummary(const frames::TransformFit& fit) {
  std::string text = fmt::format("{}: {} of {} pairs used, rms residual {:.6f} mm, max {:.6f} mm\n",
                                 frames::ModelName(fit.transform.model), fit.pairs_used,
                                 fit.residuals_mm.size(), fit.rms_residual_mm, fit.max_residual_mm);
  for (size_t k = 0; k < fit.parameter_names.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    text += fmt::format("  {:<10} {:>16.9f}", fit.parameter_names[k], fit.parameters(i));
    if (fit.covariance) text += fmt::format("  +- {:.3g}", std::sqrt((*fit.covariance)(i, i)));
    text += "\n";
  }
  for (size_t i = 0; i < fit.is_outlier.size(); ++i) {
    if (fit.is_outlier[i]) {
      text += fmt::format("  pair {} flagged as an outlier (residual {:.6f} mm{})\n", i + 1,
                          fit.residuals_mm[i].norm(), fit.used[i] ? "" : ", dropped");
    }
  }
  return text;
}

void AddFit(CLI::App& transform) {
  CLI::App* fit =
      transform.add_subcommand("fit", "best-fit transform from corresponding points (JSON on stdout)");
  struct Args {
    std::string pairs, model, output;
    frames::TransformFitOptions options;
  };
  auto args = std::make_shared<Args>();
  fit->add_option("PAIRS", args->pairs, "CSV with header xs_mm,ys_mm,zs_mm,xt_mm,yt_mm,zt_mm (2D: no z)")
      ->required();
  fit->add_option("--model", args->model, "rigid3d, similarity3d (7-parameter Helmert), rigid2d or affine2d")
      ->required();
  fit->add_option("--outlier-threshold", args->options.outlier_threshold,
                  "flag a pair whose leave-one-out residual exceeds this many sigma (per coordinate)")
      ->capture_default_str();
  fit->add_flag("--drop-outliers", args->options.drop_outliers,
                "refit without the flagged pairs, worst first");
  fit->add_option("-o,--output", args->output, "write the JSON here instead of stdout");
  fit->footer(
      "Output: formats.md section 5 keys (model, rotation_matrix or matrix, scale, translation, convention,\n"
      "rms_residual_mm, residuals_mm) plus parameters, sigmas, covariance and outlier flags "
      "(docs/frames.md).");
  fit->callback([args] {
    const frames::TransformModel model = frames::ParseModel(args->model);
    const std::vector<frames::PointPair> pairs = ReadPairs(args->pairs, model);
    const frames::TransformFit result = FitNamingFile(pairs, model, args->options, args->pairs);
    nlohmann::json out = frames::TransformFitToJson(result);
    out["input"] = args->pairs;
    EmitText(JsonText(out, 2) + "\n", args->output);
    SummariseOnTerminal(FitSummary(result));
  });
}

void AddApply(CLI::App& transform) {
  CLI::App* apply = transform.add_subcommand(
      "apply", "apply a frame or transform JSON to a toolpath CSV, G-code or PMAC file");
  struct Args {
    std::string transform, input, output, format = "auto";
    bool inverse = false;
    frames::ProgramTransformOptions options;
  };
  auto args = std::make_shared<Args>();
  apply
      ->add_option("TRANSFORM", args->transform,
                   "JSON from `arcwheel frame`, `transform fit` or `headcenter calibrate`")
      ->required();
  apply->add_option("INPUT", args->input, "toolpath CSV, G-code or PMAC program")->required();
  apply->add_option("-o,--output", args->output, "write the result here (atomically) instead of stdout");
  apply->add_flag("--inverse", args->inverse, "apply target -> source instead of source -> target");
  apply->add_option("--format", args->format, "auto, csv, gcode or pmac")->capture_default_str();
  apply
      ->add_option("--decimals", args->options.decimals,
                   "digits after the point in G-code and PMAC numbers (-1: as many as the input has)")
      ->capture_default_str();
  apply->callback([args] {
    const frames::Transform forward =
        frames::TransformFromJson(ReadJson(args->transform, kApplyStage), args->transform);
    const frames::Transform chosen = args->inverse ? forward.Inverse() : forward;
    const std::string text = ReadText(args->input, kApplyStage);
    const frames::ProgramKind kind = args->format == "auto" ? frames::DetectProgramKind(args->input, text)
                                                            : frames::ParseProgramKind(args->format);
    const frames::ProgramTransformResult result =
        frames::TransformProgram(text, kind, chosen, args->input, args->options);
    EmitText(result.text, args->output);
    SummariseOnTerminal(fmt::format("{}: {} points in {} lines rewritten ({})\n", args->input,
                                    result.points_transformed, result.lines_changed,
                                    args->inverse ? "inverse" : "forward"));
  });
}

}  // namespace

void AddTransformCommand(CLI::App& app) {
  CLI::App* transform =
      app.add_subcommand("transform", "best-fit transforms between frames, and whole-file transforms");
  transform->require_subcommand(1);
  AddFit(*transform);
  AddApply(*transform);
}

}  // namespace arcwheel::cli
