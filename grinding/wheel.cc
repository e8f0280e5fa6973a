#include "grinding/wheel.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"

namespace arcwheel::grinding {
namespace {

constexpr const char* kWheelStage = "grinding.wheel";
using nlohmann::json;
namespace key = schema::summary;

// "phases.arc_radius_mm" for messages.
std::string Dotted(std::string_view object, std::string_view name) {
  return fmt::format("{}.{}", object, name);
}

[[noreturn]] void Bad(const std::filesystem::path& path, std::string_view key, const std::string& what) {
  throw Error(ErrorCode::kBadInput, kWheelStage, fmt::format("'{}': key '{}' {}", path.string(), key, what));
}

double RequiredNumber(const json& object, const std::filesystem::path& path, std::string_view key) {
  if (!object.contains(key)) Bad(path, key, "is missing");
  if (!object.at(key).is_number()) Bad(path, key, "must be a number");
  return object.at(key).get<double>();
}

std::vector<double> NumberArray(const json& object, const std::filesystem::path& path, std::string_view key,
                                const std::string& full_key) {
  if (!object.contains(key) || !object.at(key).is_array()) Bad(path, full_key, "must be an array");
  std::vector<double> values;
  for (const json& v : object.at(key)) {
    values.push_back(v.is_number() ? v.get<double>() : std::nan(""));  // null -> NaN
  }
  return values;
}

void ReadPhases(const json& root, const std::filesystem::path& path, WheelSummary& s) {
  if (!root.contains(key::kPhases) || !root.at(key::kPhases).is_object()) return;
  const json& phases = root.at(key::kPhases);
  const auto array = [&](std::string_view name) {
    return NumberArray(phases, path, name, Dotted(key::kPhases, name));
  };
  const std::vector<double> phase = array(key::phases::kPhaseDeg);
  const std::vector<double> ra = array(key::phases::kArcRadiusMm);
  const std::vector<double> rb = array(key::phases::kCenterRadialMm);
  if (ra.size() != phase.size() || rb.size() != phase.size()) {
    Bad(path, key::kPhases, "arrays differ in length");
  }
  std::vector<bool> usable(phase.size(), true);
  if (phases.contains(key::phases::kUsable) && phases.at(key::phases::kUsable).is_array() &&
      phases.at(key::phases::kUsable).size() == phase.size()) {
    for (size_t i = 0; i < phase.size(); ++i) usable[i] = phases.at(key::phases::kUsable)[i] == true;
  }
  for (size_t i = 0; i < phase.size(); ++i) {
    if (!usable[i] || !std::isfinite(phase[i]) || !std::isfinite(ra[i]) || !std::isfinite(rb[i])) {
      continue;
    }
    s.phase_deg.push_back(phase[i]);
    s.arc_radius_mm.push_back(ra[i]);
    s.center_radial_mm.push_back(rb[i]);
  }
}

// A file without schema_version was written before versions were recorded: read it as 1.0.
void CheckSchemaVersion(const json& root, const std::filesystem::path& path) {
  std::optional<std::string> version;
  if (const auto it = root.find(key::kSchemaVersion); it != root.end()) {
    if (!it->is_string()) Bad(path, key::kSchemaVersion, "must be a string such as \"1.0\"");
    version = it->get<std::string>();
  }
  schema::CheckVersion(version, key::kVersion, path.string(), fmt::format("key '{}'", key::kSchemaVersion),
                       kWheelStage);
}

}  // namespace

double Wheel::ArcRadiusAt(double u_mm) const {
  if (!HasProfile()) return arc_radius_mm;
  const auto upper = std::upper_bound(profile_u_mm.begin(), profile_u_mm.end(), u_mm);
  const size_t k =
      std::clamp<size_t>(static_cast<size_t>(upper - profile_u_mm.begin()), 1, profile_u_mm.size() - 1);
  const double t = (u_mm - profile_u_mm[k - 1]) / (profile_u_mm[k] - profile_u_mm[k - 1]);
  const double error_um = profile_error_um[k - 1] + t * (profile_error_um[k] - profile_error_um[k - 1]);
  return arc_radius_mm + 1e-3 * error_um;
}

bool Wheel::Reaches(double u_mm) const {
  if (HasProfile() && (u_mm < profile_u_mm.front() || u_mm > profile_u_mm.back())) return false;
  return std::abs(u_mm) <= half_width_mm;
}

std::vector<std::string> Wheel::Problems() const {
  std::vector<std::string> problems;
  if (!(arc_radius_mm > 0.0)) {
    problems.push_back(fmt::format("wheel.arc_radius_mm = {} violates > 0", arc_radius_mm));
  }
  // The job gives the total radius; the base radius is what is left of it below the arc.
  if (!(base_radius_mm >= 0.0)) {
    problems.push_back(fmt::format("wheel.total_radius_mm = {} violates >= wheel.arc_radius_mm = {}",
                                   TotalRadius(), arc_radius_mm));
  }
  if (!(half_width_mm > 0.0) || half_width_mm > arc_radius_mm) {
    problems.push_back(
        fmt::format("wheel.width_mm = {} violates 0 < width_mm <= 2 * wheel.arc_radius_mm = {}",
                    2.0 * half_width_mm, 2.0 * arc_radius_mm));
  }
  // The mean profile comes from the wheel's summary.json.
  if (profile_u_mm.size() != profile_error_um.size() || profile_u_mm.size() == 1) {
    problems.push_back(
        fmt::format("wheel profile sizes u_mm = {}, error_um = {} violates equal, and 0 or >= 2",
                    profile_u_mm.size(), profile_error_um.size()));
  }
  for (size_t i = 0; i < profile_u_mm.size(); ++i) {
    const double error_um = i < profile_error_um.size() ? profile_error_um[i] : 0.0;
    if (!std::isfinite(profile_u_mm[i]) || !std::isfinite(error_um) ||
        (i > 0 && !(profile_u_mm[i] > profile_u_mm[i - 1]))) {
      problems.push_back(fmt::format(
          "wheel profile node {}: u_mm = {}, error_um = {} violates finite, u_mm strictly increasing", i,
          profile_u_mm[i], error_um));
      break;
    }
  }
  return problems;
}

WheelSummary ReadWheelSummary(const std::filesystem::path& path) {
  const json root = ReadJsonFile(path, kWheelStage);
  if (!root.is_object()) Bad(path, "(root)", "must be a JSON object");
  CheckSchemaVersion(root, path);
  WheelSummary s;
  s.mean_arc_radius_mm = RequiredNumber(root, path, key::kMeanArcRadiusMm);
  if (!(s.mean_arc_radius_mm > 0.0)) Bad(path, key::kMeanArcRadiusMm, "must be > 0");
  s.mean_arc_radius_sigma_mm = RequiredNumber(root, path, key::kMeanArcRadiusSigmaMm);
  if (root.contains(key::kMaxRunoutUm) && root.at(key::kMaxRunoutUm).is_number()) {
    s.max_runout_um = root.at(key::kMaxRunoutUm).get<double>();
  }
  if (root.contains(key::kScan) && root.at(key::kScan).is_object()) {
    const json& scan = root.at(key::kScan);
    if (scan.contains(key::scan::kWheelDiameterMm) && scan.at(key::scan::kWheelDiameterMm).is_number()) {
      s.wheel_diameter_mm = scan.at(key::scan::kWheelDiameterMm).get<double>();
    }
    if (scan.contains(key::scan::kWheelId) && scan.at(key::scan::kWheelId).is_string()) {
      s.wheel_id = scan.at(key::scan::kWheelId).get<std::string>();
    }
  }
  if (root.contains(key::kArcwheelVersion) && root.at(key::kArcwheelVersion).is_string()) {
    s.arcwheel_version = root.at(key::kArcwheelVersion).get<std::string>();
  }
  if (root.contains(key::kMeanProfile) && root.at(key::kMeanProfile).is_object()) {
    const json& profile = root.at(key::kMeanProfile);
    s.profile_u_mm = NumberArray(profile, path, key::mean_profile::kUMm,
                                 Dotted(key::kMeanProfile, key::mean_profile::kUMm));
    s.profile_error_um = NumberArray(profile, path, key::mean_profile::kErrorUm,
                                     Dotted(key::kMeanProfile, key::mean_profile::kErrorUm));
    if (s.profile_u_mm.size() != s.profile_error_um.size()) {
      Bad(path, key::kMeanProfile,
          fmt::format("{} and {} differ in length", key::mean_profile::kUMm, key::mean_profile::kErrorUm));
    }
  }
  ReadPhases(root, path, s);
  if (root.contains(key::kModel) && root.at(key::kModel).is_object()) {
    const json& model = root.at(key::kModel);
    if (model.contains(key::model::kMeanArcRadiusMm) && model.at(key::model::kMeanArcRadiusMm).is_number())
      s.model_mean_arc_radius_mm = model.at(key::model::kMeanArcRadiusMm).get<double>();
    if (model.contains(key::model::kMeanArcRadiusSigmaMm) &&
        model.at(key::model::kMeanArcRadiusSigmaMm).is_number())
      s.model_mean_arc_radius_sigma_mm = model.at(key::model::kMeanArcRadiusSigmaMm).get<double>();
  }
  return s;
}

ProfileError ReadModelProfile(const std::filesystem::path& wheel_map) {
  namespace map = schema::wheel_map;
  const auto read = [&wheel_map] {
    const hdf5::File file = hdf5::File::OpenReadOnly(wheel_map);
    for (const std::string_view dataset : {map::kModelProfileUMm, map::kModelProfileErrorUm}) {
      if (!file.HasObject(std::string(dataset))) {
        Bad(wheel_map, dataset,
            "is missing: the wheel was processed without its model (--no-model), or the "
            "model could not be fitted (see summary.json's warnings)");
      }
    }
    const std::vector<double> u = file.ReadDoubles(std::string(map::kModelProfileUMm));
    const std::vector<double> e = file.ReadDoubles(std::string(map::kModelProfileErrorUm));
    if (u.size() != e.size())
      Bad(wheel_map, map::kModelProfileErrorUm, "differs in length from profile_u_mm");
    ProfileError p;
    for (size_t k = 0; k < u.size(); ++k) {
      if (!std::isfinite(u[k]) || !std::isfinite(e[k])) continue;
      if (!p.u_mm.empty() && !(u[k] > p.u_mm.back()))
        Bad(wheel_map, map::kModelProfileUMm, "is not increasing");
      p.u_mm.push_back(u[k]);
      p.error_um.push_back(e[k]);
    }
    if (p.u_mm.size() < 2) Bad(wheel_map, map::kModelProfileErrorUm, "has fewer than 2 finite nodes");
    return p;
  };
  // A damaged file is read first in a child process, as every HDF5 reader here (core/hdf5.h).
  hdf5::ReadFirstInChildProcess(wheel_map, [&read] { (void)read(); });
  return read();
}

}  // namespace arcwheel::grinding
