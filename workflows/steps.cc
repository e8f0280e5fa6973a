#include "workflows/steps.h"

#include <fmt/core.h>

#include <chrono>
#include <string>

#include "core/number_format.h"
#include "core/progress.h"
#include "workflows/process_pipeline.h"

namespace arcwheel::workflows {
namespace {

double StepSecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void RunProcessStep(const std::filesystem::path& scan, const std::filesystem::path& output,
                    const ProcessStepInput& input) {
  // The pipeline `arcwheel process -q SCAN -o OUTPUT` runs, with its default options.
  Progress quiet(false);
  ProcessPipelineOptions options;
  options.scan_settings_path = input.scan_settings;
  options.scan_format = input.format;
  options.columns = input.columns;
  (void)RunProcessPipeline(scan.string(), output, std::move(options), quiet);
}

ToolpathStepResult RunToolpathStep(const std::filesystem::path& job_path,
                                   const std::optional<std::filesystem::path>& wheel_summary,
                                   double max_wheel_change_mm, const std::filesystem::path& output,
                                   grinding::WheelProfileSource wheel_profile) {
  const auto start = std::chrono::steady_clock::now();
  ToolpathStepResult result{
      .job = grinding::ReadJob(job_path, wheel_summary, max_wheel_change_mm, wheel_profile), .report = {}};
  const grinding::Job& job = result.job;
  result.report = grinding::RunToolpathJob(job, output);
  const grinding::ToolpathSummary& t = result.report.toolpath;
  if (job.wheel_change) fmt::print("{}\n", ShowNumbersIn(grinding::ArcRadiusLine(*job.wheel_change)));
  fmt::print(
      "{} control points in {} pass(es) of {} rows; rows straight to {:.2e} mm; "
      "{} gouge checks, smallest gap {:.3f} um\n",
      t.control_points, t.passes, t.rows_per_pass, Shown(t.max_row_deviation_mm), t.gouge_checks,
      Shown(1e3 * t.min_gouge_gap_mm));
  if (result.report.predicted) {
    const grinding::FormPrediction& p = result.report.prediction;
    fmt::print(
        "predicted form error (arc radius error {:.2g} mm: {}{}): PV {:.3f} um, RMS {:.3f} um; "
        "after tilt PV {:.3f} um, RMS {:.3f} um; runout ripple PV {:.3f} um{}\n",
        Shown(job.prediction.arc_radius_error_mm), job.arc_radius_error_source,
        job.prediction.runout_radial_um.empty() ? ", no runout" : ", with runout", Shown(p.pv_um),
        Shown(p.rms_um), Shown(p.pv_after_tilt_um), Shown(p.rms_after_tilt_um), Shown(p.ripple_pv_um),
        job.prediction.profile_u_mm.empty()
            ? ""
            : fmt::format("; profile error p(u) PV {:.3f} um", Shown(p.profile_pv_um)));
  }
  fmt::print("wrote {} in {:.2f} s\n", output.string(), Shown(StepSecondsSince(start)));
  return result;
}

polishing::PolishRunReport RunPolishStep(const std::filesystem::path& job_path,
                                         const std::optional<std::filesystem::path>& error_map,
                                         const std::filesystem::path& output) {
  const auto start = std::chrono::steady_clock::now();
  const polishing::PolishJob job = polishing::ReadPolishJob(job_path, error_map);
  const polishing::PolishRunReport report = polishing::RunPolishJob(job, output);
  const polishing::DwellSolution& d = report.dwell;
  fmt::print(
      "{} dwell points; error PV {:.4f} um, RMS {:.4f} um -> predicted residual PV {:.4f} um, "
      "RMS {:.4f} um over {} aperture nodes\n",
      report.points, Shown(d.before.pv_um), Shown(d.before.rms_um), Shown(d.after.pv_um),
      Shown(d.after.rms_um), d.before.nodes);
  fmt::print("total dwell {:.1f} s; speeds {:.3f} .. {:.3f} mm/s, up to {:.1f} mm/s^2; {} iterations{}\n",
             Shown(d.total_time_s), Shown(report.min_speed_mm_s), Shown(report.max_speed_mm_s),
             Shown(d.max_acceleration_mm_s2), d.iterations, d.converged ? "" : " (iteration limit reached)");
  fmt::print("wrote {} in {:.2f} s\n", output.string(), Shown(StepSecondsSince(start)));
  return report;
}

}  // namespace arcwheel::workflows
