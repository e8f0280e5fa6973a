#include "grinding/toolpath_writer.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/version.h"
#include "schema/toolpath_outputs.h"

namespace arcwheel::grinding {
namespace {

constexpr const char* kToolpathWriterStage = "grinding.output";
enum Stream { kCsv = 0, kGcode = 1, kPmac = 2 };

std::ofstream OpenStaged(const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw Error(ErrorCode::kIo, kToolpathWriterStage,
                fmt::format("cannot create '{}': {}", path.string(), std::strerror(errno)));
  }
  return out;
}

void CloseChecked(std::ofstream& out, const std::filesystem::path& final_path) {
  out.flush();
  if (!out) {
    throw Error(ErrorCode::kIo, kToolpathWriterStage,
                fmt::format("cannot write '{}' (disk full?): {}", final_path.string(), std::strerror(errno)));
  }
  out.close();
}

// G-code comments end at the first ')': keep descriptions free of parentheses.
std::string GcodeComment(std::string text) {
  std::replace(text.begin(), text.end(), '(', '[');
  std::replace(text.begin(), text.end(), ')', ']');
  return "(" + text + ")\n";
}

// Formats each row in a worker thread and writes rows, with the moves that link them, in order.
class ProgramWriter {
 public:
  ProgramWriter(const Job& job, std::ofstream* csv, std::ofstream* gcode, std::ofstream* pmac)
      : job_(job), csv_(csv), gcode_(gcode), pmac_(pmac) {}

  void Prepare(ToolpathRow& row) const {
    row.text.resize(3);
    const int d = job_.machine.decimals;
    const double feed = job_.path.feed_mm_per_min;
    if (csv_ != nullptr) AppendCsvLines(row, feed, row.text[kCsv]);
    if (gcode_ != nullptr) {
      auto out = std::back_inserter(row.text[kGcode]);
      fmt::format_to(out, "(pass {} row {})\n", row.pass, row.row);
      for (size_t i = 0; i < row.points.size(); ++i) {
        const auto& w = row.points[i].wheel_centre_mm;
        fmt::format_to(out, "G01 X{:.{}f} Y{:.{}f} Z{:.{}f}", w.x(), d, w.y(), d, w.z(), d);
        if (i == 0) fmt::format_to(out, " F{}", feed);
        fmt::format_to(out, "\n");
      }
    }
    if (pmac_ != nullptr) {
      auto out = std::back_inserter(row.text[kPmac]);
      fmt::format_to(out, "; pass {} row {}\nF{}\n", row.pass, row.row, feed);
      for (const ControlPoint& p : row.points) {
        const auto& w = p.wheel_centre_mm;
        fmt::format_to(out, "X{:.{}f} Y{:.{}f} Z{:.{}f}\n", w.x(), d, w.y(), d, w.z(), d);
      }
    }
  }

  void Consume(const ToolpathRow& row) {
    const Eigen::Vector3d start = row.points.front().wheel_centre_mm;
    const bool linked_directly = has_previous_ && job_.path.zigzag && row.pass == previous_pass_;
    if (!linked_directly) Approach(start);
    if (csv_ != nullptr) *csv_ << row.text[kCsv];
    if (gcode_ != nullptr) *gcode_ << row.text[kGcode];
    if (pmac_ != nullptr) *pmac_ << row.text[kPmac];
    previous_end_ = row.points.back().wheel_centre_mm;
    previous_pass_ = row.pass;
    has_previous_ = true;
  }

  void Finish() {
    const int d = job_.machine.decimals;
    if (has_previous_) {
      const double safe_z = previous_end_.z() + job_.machine.retract_mm;
      if (gcode_ != nullptr) *gcode_ << fmt::format("G00 Z{:.{}f}\n", safe_z, d);
      if (pmac_ != nullptr) *pmac_ << fmt::format("RAPID\nZ{:.{}f}\n", safe_z, d);
    }
    if (gcode_ != nullptr) *gcode_ << "M30\n";
    if (pmac_ != nullptr) *pmac_ << "CLOSE\n";
  }

 private:
  // Lift (if at the surface), rapid over the next row's start, feed down onto it.
  void Approach(const Eigen::Vector3d& start) {
    const int d = job_.machine.decimals;
    const double retract = job_.machine.retract_mm;
    const double safe_z = std::max(start.z(), has_previous_ ? previous_end_.z() : start.z()) + retract;
    const double feed = job_.path.feed_mm_per_min;
    if (gcode_ != nullptr) {
      if (has_previous_) *gcode_ << fmt::format("G01 Z{:.{}f} F{}\n", safe_z, d, feed);
      *gcode_ << fmt::format("G00 X{:.{}f} Y{:.{}f} Z{:.{}f}\n", start.x(), d, start.y(), d, safe_z, d);
    }
    if (pmac_ != nullptr) {
      if (has_previous_) *pmac_ << fmt::format("F{}\nZ{:.{}f}\n", feed, safe_z, d);
      *pmac_ << fmt::format("RAPID\nX{:.{}f} Y{:.{}f} Z{:.{}f}\nLINEAR\n", start.x(), d, start.y(), d, safe_z,
                            d);
    }
  }

  const Job& job_;
  std::ofstream* csv_;
  std::ofstream* gcode_;
  std::ofstream* pmac_;
  bool has_previous_ = false;
  int previous_pass_ = -1;
  Eigen::Vector3d previous_end_ = Eigen::Vector3d::Zero();
};

void WriteHeaders(const Job& job, std::ofstream* csv, std::ofstream* gcode, std::ofstream* pmac) {
  const std::vector<std::string> lines = ToolpathHeaderLines(job);
  const int d = job.machine.decimals;
  const std::string rounding = fmt::format(
      "wheel-centre coordinates in mm, rounded to {} decimals; feed in mm/min; the CSV keeps full precision",
      d);
  if (csv != nullptr) {
    for (const std::string& line : lines) *csv << "# " << line << "\n";
    *csv << "xw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min,row,pass\n";
  }
  if (gcode != nullptr) {
    for (const std::string& line : lines) *gcode << GcodeComment(line);
    *gcode << GcodeComment(rounding) << "G90 G21\n";
  }
  if (pmac != nullptr) {
    for (const std::string& line : lines) *pmac << "; " << line << "\n";
    *pmac << "; " << rounding << "\n"
          << "; F is in mm/min: set the coordinate system's feed time unit Isx90 = 60000 (ms)\n"
          << "CLOSE\n"
          << fmt::format("OPEN PROG {} CLEAR\n", job.machine.pmac_program) << "ABS\nLINEAR\n";
  }
}

// The nominal and the measured arc radius side by side (docs/grinding.md, toolpath_summary.json).
nlohmann::json ArcRadiusJson(const WheelChange& c) {
  namespace key = schema::toolpath::summary::arc_radius;
  nlohmann::json j;
  j[key::kNominalMm] = c.nominal_arc_radius_mm ? nlohmann::json(*c.nominal_arc_radius_mm) : nlohmann::json();
  j[key::kMeasuredMm] = c.measured_arc_radius_mm;
  j[key::kMeasuredSigmaMm] = c.measured_sigma_mm;
  j[key::kDifferenceMm] = c.nominal_arc_radius_mm ? nlohmann::json(c.DifferenceMm()) : nlohmann::json();
  j[key::kMaxChangeMm] = c.max_change_mm;
  j[key::kUsed] = "measured";
  return j;
}

nlohmann::json SummaryJson(const Job& job, const ToolpathRunReport& report,
                           const std::vector<std::string>& files) {
  namespace key = schema::toolpath::summary;
  nlohmann::json j;
  j[key::kArcwheelVersion] = kVersion;
  j[key::kJob] = ParseJsonText(job.resolved_json, "the resolved job", kToolpathWriterStage);
  j[key::kJobPath] = job.source.string();
  j[key::kSurface] = job.surface->Describe();
  j[key::kWheel] = job.wheel.description;
  if (job.wheel_change) j[key::kArcRadius] = ArcRadiusJson(*job.wheel_change);
  if (job.wheel_summary)
    j[key::kWheelProfile] = job.wheel_profile == WheelProfileSource::kModel ? "model" : "mean";
  const ToolpathSummary& t = report.toolpath;
  namespace path = key::toolpath;
  j[key::kToolpath] = {{path::kPasses, t.passes},
                       {path::kRowsPerPass, t.rows_per_pass},
                       {path::kControlPoints, t.control_points},
                       {path::kFirstRowYwMm, t.first_row_yw_mm},
                       {path::kRowPitchMm, t.row_pitch_mm},
                       {path::kMaxRowDeviationMm, t.max_row_deviation_mm},
                       {path::kGougeChecks, t.gouge_checks},
                       {path::kMinGougeGapUm, 1e3 * t.min_gouge_gap_mm},
                       {path::kMinClearanceCurvaturePerMm, t.min_local_clearance_per_mm}};
  if (report.predicted) {
    const FormPrediction& p = report.prediction;
    namespace prediction = key::prediction;
    j[key::kPrediction] = {{prediction::kArcRadiusErrorMm, job.prediction.arc_radius_error_mm},
                           {prediction::kArcRadiusErrorSource, job.arc_radius_error_source},
                           {prediction::kKeepTotalRadius, job.prediction.keep_total_radius},
                           {prediction::kPvUm, p.pv_um},
                           {prediction::kRmsUm, p.rms_um},
                           {prediction::kPvAfterTiltUm, p.pv_after_tilt_um},
                           {prediction::kRmsAfterTiltUm, p.rms_after_tilt_um},
                           {prediction::kRipplePvUm, p.ripple_pv_um},
                           {prediction::kProfilePvUm, p.profile_pv_um}};
  }
  j[key::kFiles] = files;
  return j;
}

}  // namespace

void AppendCsvLines(const ToolpathRow& row, double feed_mm_per_min, std::string& out) {
  // std::to_chars gives the shortest round-trip text, several times faster than a stream.
  std::array<char, 512> line;
  for (const ControlPoint& p : row.points) {
    char* end = line.data();
    char* const stop = line.data() + line.size();
    // 12 numbers of at most 24 characters fit the line; the check documents that.
    const auto put = [&end, stop](auto value, char separator) {
      const std::to_chars_result result = std::to_chars(end, stop - 1, value);
      ARCWHEEL_CHECK(result.ec == std::errc()) << "CSV line buffer too short";
      end = result.ptr;
      *end++ = separator;
    };
    const Eigen::Vector3d& w = p.wheel_centre_mm;
    const Eigen::Vector3d& c = p.contact_mm;
    const Eigen::Vector3d& n = p.normal;
    for (double v : {w.x(), w.y(), w.z(), c.x(), c.y(), c.z(), n.x(), n.y(), n.z(), feed_mm_per_min})
      put(v, ',');
    put(row.row, ',');
    put(row.pass, '\n');
    out.append(line.data(), end);
  }
}

std::string ArcRadiusLine(const WheelChange& c) {
  const std::string measured =
      fmt::format("measured {} mm (1-sigma {:.2g} mm)", c.measured_arc_radius_mm, c.measured_sigma_mm);
  if (!c.nominal_arc_radius_mm)
    return fmt::format("arc radius: {}, used; the job gives no nominal", measured);
  return fmt::format("arc radius: {}, used; nominal {} mm (job); difference {:+.4f} mm (limit +-{} mm)",
                     measured, *c.nominal_arc_radius_mm, c.DifferenceMm(), c.max_change_mm);
}

std::vector<std::string> ToolpathHeaderLines(const Job& job) {
  const ToolpathOptions& o = job.path;
  std::vector<std::string> lines = {
      fmt::format("arcwheel {} parallel-grinding toolpath (method.md A.8, eq. 5), job '{}'", kVersion,
                  job.name),
      "surface: " + job.surface->Describe(),
      "aperture: " + job.aperture.Describe(),
      "wheel: " + job.wheel.description,
      fmt::format(
          "path: wheel axis along Y, rows along X at constant wheel-centre Y; step-over {} mm, "
          "spacing {} mm{}, feed {} mm/min, {} pass(es) of {} um, lead-in {} mm, lead-out {} mm, {}",
          o.step_over_mm, o.point_spacing_mm,
          o.chordal_tolerance_um > 0 ? fmt::format(" (chordal tolerance {} um)", o.chordal_tolerance_um) : "",
          o.feed_mm_per_min, o.passes, o.depth_per_pass_um, o.lead_in_mm, o.lead_out_mm,
          o.zigzag ? "zigzag" : "one way"),
  };
  if (job.wheel_change) lines.insert(lines.begin() + 4, ArcRadiusLine(*job.wheel_change));
  return lines;
}

ToolpathRunReport RunToolpathJob(const Job& job, const std::filesystem::path& output_folder) {
  OutputSet outputs;
  outputs.CreateFolder(output_folder);
  std::vector<std::string> files;
  const auto stage = [&](const std::string& name, bool wanted) -> std::optional<std::filesystem::path> {
    if (!wanted) return std::nullopt;
    files.push_back(name);
    return outputs.Stage(output_folder / name);
  };
  const auto csv_path = stage("toolpath.csv", job.outputs.csv);
  const auto gcode_path = stage("toolpath.nc", job.outputs.gcode);
  const auto pmac_path = stage("toolpath.pmc", job.outputs.pmac);
  std::ofstream csv, gcode, pmac;
  if (csv_path) csv = OpenStaged(*csv_path);
  if (gcode_path) gcode = OpenStaged(*gcode_path);
  if (pmac_path) pmac = OpenStaged(*pmac_path);
  std::ofstream* csv_out = csv_path ? &csv : nullptr;
  std::ofstream* gcode_out = gcode_path ? &gcode : nullptr;
  std::ofstream* pmac_out = pmac_path ? &pmac : nullptr;

  WriteHeaders(job, csv_out, gcode_out, pmac_out);
  ProgramWriter writer(job, csv_out, gcode_out, pmac_out);
  ToolpathRunReport report;
  report.toolpath = GenerateToolpath(*job.surface, job.aperture, job.wheel, job.path,
                                     {.prepare = [&writer](ToolpathRow& row) { writer.Prepare(row); },
                                      .consume = [&writer](ToolpathRow& row) { writer.Consume(row); }});
  writer.Finish();
  if (csv_path) CloseChecked(csv, output_folder / "toolpath.csv");
  if (gcode_path) CloseChecked(gcode, output_folder / "toolpath.nc");
  if (pmac_path) CloseChecked(pmac, output_folder / "toolpath.pmc");

  if (job.predict) {
    report.prediction = PredictFormError(*job.surface, job.aperture, job.wheel, job.prediction);
    report.predicted = true;
    const auto h5_path = stage(std::string(schema::toolpath::kPredictionFileName), true);
    WritePredictionHdf5(report.prediction, *h5_path, job.surface->Describe(), job.wheel.description);
  }
  files.emplace_back(schema::toolpath::kSummaryFileName);
  const std::filesystem::path summary_path =
      outputs.Stage(output_folder / schema::toolpath::kSummaryFileName);
  {
    std::ofstream summary = OpenStaged(summary_path);
    summary << JsonText(SummaryJson(job, report, files), 2) << "\n";
    CloseChecked(summary, output_folder / schema::toolpath::kSummaryFileName);
  }
  outputs.Commit();
  return report;
}

}  // namespace arcwheel::grinding
