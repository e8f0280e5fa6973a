// arcwheel.toolpath, polish, compare and history: the library calls the `toolpath`, `polish`,
// `compare` and `history` commands make (grinding/toolpath_writer.h, polishing/job.h,
// reports/compare.h, reports/history.h, store/queries.h), with their results as dicts and numpy
// arrays. The toolpath and polish stages write their files (into a folder the caller names or a
// temporary one) and arcwheel/__init__.py reads their tables back.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/hdf5.h"
#include "core/json_text.h"
#include "grinding/job.h"
#include "grinding/toolpath_writer.h"
#include "polishing/job.h"
#include "python/src/bindings.h"
#include "reports/compare.h"
#include "reports/history.h"
#include "schema/grid_map.h"
#include "schema/polish_outputs.h"
#include "schema/toolpath_outputs.h"
#include "store/queries.h"
#include "store/store.h"

namespace arcwheel::python {
namespace {

namespace fs = std::filesystem;

py::object JsonFile(const fs::path& path, const char* stage) {
  return ParseJson(ReadJsonFile(path, stage).dump());
}

// `arcwheel toolpath JOB [--wheel SUMMARY] -o OUTDIR`: its files, and toolpath_summary.json.
py::dict Toolpath(const fs::path& job_path, const std::optional<fs::path>& wheel, const fs::path& output_dir,
                  double max_wheel_change_mm, const std::string& wheel_profile) {
  if (wheel_profile != "mean" && wheel_profile != "model") {
    throw Error(ErrorCode::kInvalidOption, "toolpath",
                "wheel_profile '" + wheel_profile + "' is not one of: mean, model");
  }
  RunReleased([&] {
    const grinding::Job job =
        grinding::ReadJob(job_path, wheel, max_wheel_change_mm,
                          wheel_profile == "model" ? grinding::WheelProfileSource::kModel
                                                   : grinding::WheelProfileSource::kMeanProfile);
    return grinding::RunToolpathJob(job, output_dir);
  });
  py::dict d;
  d["summary"] = JsonFile(output_dir / schema::toolpath::kSummaryFileName, "toolpath");
  return d;
}

// `arcwheel polish JOB -o OUTDIR`, `error_map` replacing the job's: its files, and
// polish_summary.json.
py::dict Polish(const fs::path& job_path, const std::optional<fs::path>& error_map,
                const fs::path& output_dir) {
  RunReleased([&] {
    const polishing::PolishJob job = polishing::ReadPolishJob(job_path, error_map);
    return polishing::RunPolishJob(job, output_dir);
  });
  py::dict d;
  d["summary"] = JsonFile(output_dir / schema::polish::kSummaryFileName, "polish");
  return d;
}

// A grid map (prediction.h5, residual_map.h5, an HDF5 error map) as its nodes and values.
py::dict ReadGridMap(const fs::path& path) {
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  const schema::grid_map::Location where = schema::grid_map::LocateGridMap(file, "grid_map");
  std::vector<double> x_mm, y_mm;
  for (int i = 0; i < where.nx; ++i) x_mm.push_back(where.x0_mm + i * where.dx_mm);
  for (int j = 0; j < where.ny; ++j) y_mm.push_back(where.y0_mm + j * where.dy_mm);
  py::dict d;
  d["x_mm"] = ToNumpy(std::move(x_mm));
  d["y_mm"] = ToNumpy(std::move(y_mm));
  d["error_um"] = ToNumpy(file.ReadDoubles(where.error_dataset), {where.ny, where.nx});
  return d;
}

// `arcwheel compare BEFORE AFTER`: compare.json as a dict, and the map difference as arrays.
py::dict Compare(const fs::path& before, const fs::path& after) {
  reports::Comparison comparison = RunReleased([&] {
    return reports::CompareScans(reports::ReadReportInputs(before), reports::ReadReportInputs(after));
  });
  comparison.before_dir = before;
  comparison.after_dir = after;
  py::dict d;
  d["comparison"] = ParseJson(reports::ComparisonJson(comparison).dump());
  reports::MapDifference& map = comparison.map;
  const auto n_phase = static_cast<py::ssize_t>(map.phase_deg.size());
  const auto n_y = static_cast<py::ssize_t>(map.y_mm.size());
  py::dict arrays;
  arrays["phase_deg"] = ToNumpy(std::move(map.phase_deg));
  arrays["y_mm"] = ToNumpy(std::move(map.y_mm));
  arrays["difference_um"] = ToNumpy(std::move(map.difference_um), {n_phase, n_y});
  d["map"] = arrays;
  return d;
}

// `arcwheel history DIR...` or `history --wheel ID [--since DATE] [--db STORE]`.
py::dict History(const std::vector<fs::path>& folders, const std::string& wheel, const std::string& since,
                 const std::string& db, const std::vector<std::string>& dressings) {
  if (folders.empty() == wheel.empty()) {
    throw Error(ErrorCode::kInvalidOption, "reports.history",
                "give the folders of the scans or wheel= (from the results store), not both");
  }
  std::vector<double> dressing_times_s;
  for (const std::string& dressing : dressings) {
    dressing_times_s.push_back(reports::ParseTimestamp_s(dressing, "dressing"));
  }
  const reports::History h = RunReleased([&] {
    if (wheel.empty()) return reports::BuildHistory(folders, dressing_times_s, dressings);
    std::optional<double> since_s;
    if (!since.empty()) since_s = store::ParseSince_s(since, "since");
    store::Store results = store::Store::Open(store::StoreLocation(db));
    return store::HistoryFromStore(results, wheel, since_s, dressing_times_s, dressings);
  });
  py::dict d;
  d["wheel_id"] = h.wheel_id;
  std::vector<double> time_s, radius_mm, sigma_mm, runout_um, arc_error_um;
  std::vector<int> segment;
  py::list timestamps, scan_folders;
  for (const reports::HistoryScan& scan : h.scans) {
    time_s.push_back(scan.time_s);
    segment.push_back(scan.segment);
    radius_mm.push_back(scan.summary.mean_arc_radius_mm);
    sigma_mm.push_back(scan.summary.mean_arc_radius_sigma_mm);
    runout_um.push_back(scan.summary.max_runout_um);
    arc_error_um.push_back(scan.summary.max_arc_error_um);
    timestamps.append(scan.timestamp);
    scan_folders.append(scan.folder.string());
  }
  d["timestamp"] = timestamps;
  d["folder"] = scan_folders;
  d["time_s"] = ToNumpy(std::move(time_s));
  d["segment"] = ToNumpy(std::move(segment));
  d["mean_arc_radius_mm"] = ToNumpy(std::move(radius_mm));
  d["mean_arc_radius_sigma_mm"] = ToNumpy(std::move(sigma_mm));
  d["max_runout_um"] = ToNumpy(std::move(runout_um));
  d["max_arc_error_um"] = ToNumpy(std::move(arc_error_um));
  py::list wear;
  for (const reports::WearRate& w : h.wear) {
    py::dict rate;
    rate["segment"] = w.segment;
    rate["scans"] = w.scans;
    rate["rate_um_per_h"] = w.rate_um_per_h;
    rate["sigma_um_per_h"] = w.sigma_um_per_h;
    rate["chi2_per_dof"] = w.chi2_per_dof;
    rate["intercept_mm"] = w.intercept_mm;
    rate["first_time_s"] = w.first_time_s;
    rate["last_time_s"] = w.last_time_s;
    wear.append(rate);
  }
  d["wear"] = wear;
  d["csv"] = reports::HistoryCsv(h);
  return d;
}

}  // namespace

void BindStages(py::module_& module) {
  module.def("_toolpath", &Toolpath, py::arg("job"), py::arg("wheel"), py::arg("output_dir"),
             py::arg("max_wheel_change_mm"), py::arg("wheel_profile"));
  module.attr("DEFAULT_MAX_WHEEL_CHANGE_MM") = grinding::kDefaultMaxWheelChangeMm;
  module.def("_polish", &Polish, py::arg("job"), py::arg("error_map"), py::arg("output_dir"));
  module.def("read_grid_map", &ReadGridMap, py::arg("path"),
             "A grid map file (prediction.h5, residual_map.h5, an HDF5 error map): {x_mm [nx], y_mm [ny], "
             "error_um [ny, nx]}.");
  module.def("_compare", &Compare, py::arg("before"), py::arg("after"));
  module.def("_history", &History, py::arg("folders"), py::arg("wheel"), py::arg("since"), py::arg("db"),
             py::arg("dressings"));
}

}  // namespace arcwheel::python
