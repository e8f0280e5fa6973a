#include "grinding/prediction.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/check.h"
#include "core/dense.h"
#include "core/error.h"
#include "core/parallel.h"
#include "grinding/toolpath.h"
#include "schema/grid_map.h"

namespace arcwheel::grinding {

using surfaces::Aperture;
using surfaces::Surface;
using surfaces::SurfacePoint;

namespace {

constexpr const char* kPredictionStage = "grinding.prediction";
constexpr int kRunoutTableSize = 4096;
// Samples of the wheel-centre offset per turn of the wheel in the ripple's minimum search.
constexpr double kSamplesPerTurn = 256.0;

// eps(phi) resampled on a uniform periodic table, mm, for fast lookup.
std::vector<double> RunoutTable(const PredictionOptions& o) {
  std::vector<double> table(kRunoutTableSize, 0.0);
  const size_t n = o.runout_phase_deg.size();
  if (n == 0) return table;
  for (int k = 0; k < kRunoutTableSize; ++k) {
    const double phi = 360.0 * k / kRunoutTableSize;
    // Bracketing samples, wrapping around 360 degrees.
    const auto upper = std::upper_bound(o.runout_phase_deg.begin(), o.runout_phase_deg.end(), phi);
    const size_t hi = static_cast<size_t>(upper - o.runout_phase_deg.begin()) % n;
    const size_t lo = (hi + n - 1) % n;
    double span = o.runout_phase_deg[hi] - o.runout_phase_deg[lo];
    double offset = phi - o.runout_phase_deg[lo];
    if (span <= 0.0) span += 360.0;
    if (offset < 0.0) offset += 360.0;
    const double t = n == 1 ? 0.0 : offset / span;
    table[static_cast<size_t>(k)] =
        1e-3 * (o.runout_radial_um[lo] + t * (o.runout_radial_um[hi] - o.runout_radial_um[lo]));
  }
  return table;
}

double LookUp(const std::vector<double>& table, double phi_deg) {
  double turns = phi_deg / 360.0;
  turns -= std::floor(turns);
  const double position = turns * kRunoutTableSize;
  const int k = std::min(static_cast<int>(position), kRunoutTableSize - 1);
  const double t = position - k;
  return table[static_cast<size_t>(k)] * (1.0 - t) +
         table[static_cast<size_t>((k + 1) % kRunoutTableSize)] * t;
}

struct NodeError {
  double low_order_mm;
  double ripple_mm;
};

class NodePredictor {
 public:
  NodePredictor(const Surface& surface, const Wheel& wheel, const PredictionOptions& options)
      : surface_(surface), wheel_(wheel), options_(options), runout_(RunoutTable(options)) {
    for (double e : runout_) max_runout_mm_ = std::max(max_runout_mm_, std::abs(e));
    if (options.spindle_rpm > 0.0) advance_per_turn_mm_ = options.feed_mm_per_min / options.spindle_rpm;
  }

  NodeError Predict(double x, double y) const {
    const double d_ra = options_.arc_radius_error_mm;
    const double d_rb = options_.keep_total_radius ? -d_ra : 0.0;
    // The ground point Q belonging to contact P sits beside P; find the P whose Q lies over the
    // node (the displacement changes slowly with P, so a few fixed-point steps converge to 1e-12).
    Eigen::Vector2d contact(x, y);
    Eigen::Vector3d q(x, y, 0.0);
    double n2 = 1.0;
    for (int iteration = 0; iteration < 8; ++iteration) {
      if (!surface_.InDomain(contact.x(), contact.y())) {
        throw Error(ErrorCode::kBadInput, kPredictionStage,
                    fmt::format("contact ({:.6f}, {:.6f}) mm grinding map node ({:.6f}, {:.6f}) mm "
                                "lies off the surface's domain",
                                contact.x(), contact.y(), x, y));
      }
      const SurfacePoint s = surface_.Evaluate(contact.x(), contact.y());
      const double n3 = std::sqrt(s.fx * s.fx + s.fy * s.fy + 1.0);
      n2 = std::sqrt(s.fx * s.fx + 1.0);
      const Eigen::Vector3d n(-s.fx / n3, -s.fy / n3, 1.0 / n3);
      const Eigen::Vector3d d(-s.fx / n2, 0.0, 1.0 / n2);
      const Eigen::Vector3d displacement = -d_ra * n - d_rb * d;
      q = Eigen::Vector3d(contact.x(), contact.y(), s.z_mm) + displacement;
      if (std::abs(q.x() - x) < 1e-12 && std::abs(q.y() - y) < 1e-12) break;
      contact = Eigen::Vector2d(x, y) - displacement.head<2>();
    }
    NodeError e{q.z() - surface_.Evaluate(x, y).z_mm, 0.0};
    if (max_runout_mm_ > 0.0 && advance_per_turn_mm_ > 0.0) e.ripple_mm = Ripple(x, y, n2);
    return e;
  }

 private:
  double Ripple(double x, double y, double n2) const {
    const ControlPoint p = ControlPointForContact(surface_, wheel_, x, y);
    const double clearance_xx = ClearanceHessian(surface_, wheel_, p)(0, 0);
    const double contact_per_centre = Eq5Jacobian(surface_, wheel_, x, y).inverse()(0, 0);
    const double k = clearance_xx * contact_per_centre * contact_per_centre;  // per mm of Xw^2
    // Beyond |s| = sqrt(4 max|eps| N2 / k) the parabola outweighs any runout; one turn suffices
    // when the wheel is flat against the surface.
    double reach = advance_per_turn_mm_;
    if (k > 0.0) reach = std::min(reach, std::sqrt(4.0 * max_runout_mm_ * n2 / k));
    const double step = advance_per_turn_mm_ / kSamplesPerTurn;
    const double xw = p.wheel_centre_mm.x();
    const double degrees_per_mm = 360.0 / advance_per_turn_mm_;
    double lowest = std::numeric_limits<double>::infinity();
    const int count = static_cast<int>(std::ceil(reach / step));
    for (int i = -count; i <= count; ++i) {
      const double offset = i * step;
      const double eps = LookUp(runout_, (xw + offset) * degrees_per_mm);
      lowest = std::min(lowest, 0.5 * k * offset * offset - eps * n2);
    }
    return lowest;
  }

  const Surface& surface_;
  const Wheel& wheel_;
  const PredictionOptions& options_;
  std::vector<double> runout_;
  double max_runout_mm_ = 0.0;
  double advance_per_turn_mm_ = 0.0;
};

struct Statistics {
  double pv_um, rms_um;
};

Statistics PvRms(const std::vector<double>& values_um) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0.0, sum2 = 0.0;
  size_t n = 0;
  for (double v : values_um) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
    ++n;
  }
  if (n == 0) return {0.0, 0.0};
  const double mean = sum / static_cast<double>(n);
  for (double v : values_um) {
    if (std::isfinite(v)) sum2 += (v - mean) * (v - mean);
  }
  return {hi - lo, std::sqrt(sum2 / static_cast<double>(n))};
}

std::vector<double> WithoutPlane(const FormPrediction& p) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  const size_t nx = p.x_mm.size();
  for (size_t k = 0; k < p.error_um.size(); ++k) {
    if (!std::isfinite(p.error_um[k])) continue;
    const Eigen::Vector3d basis(1.0, p.x_mm[k % nx], p.y_mm[k / nx]);
    normal += basis * basis.transpose();
    rhs += basis * p.error_um[k];
  }
  const Eigen::Vector3d plane = dense::LdltSolve(normal, rhs);
  std::vector<double> residual(p.error_um.size());
  for (size_t k = 0; k < p.error_um.size(); ++k) {
    residual[k] = p.error_um[k] - plane.dot(Eigen::Vector3d(1.0, p.x_mm[k % nx], p.y_mm[k / nx]));
  }
  return residual;
}

}  // namespace

std::vector<std::string> PredictionOptions::Problems() const {
  std::vector<std::string> problems;
  if (!std::isfinite(arc_radius_error_mm)) {
    problems.push_back(
        fmt::format("prediction.arc_radius_error_mm = {} violates finite", arc_radius_error_mm));
  }
  // The runout comes from the wheel's summary.json (its phases) or from prediction.runout_um.
  if (runout_phase_deg.size() != runout_radial_um.size()) {
    problems.push_back(fmt::format("prediction runout sizes phase_deg = {}, radial_um = {} violates equal",
                                   runout_phase_deg.size(), runout_radial_um.size()));
  }
  for (size_t i = 0; i < runout_phase_deg.size(); ++i) {
    if (!(runout_phase_deg[i] >= 0.0 && runout_phase_deg[i] < 360.0) ||
        (i > 0 && !(runout_phase_deg[i] > runout_phase_deg[i - 1]))) {
      problems.push_back(fmt::format(
          "prediction runout phase_deg[{}] = {} violates ascending within [0, 360)", i, runout_phase_deg[i]));
      break;
    }
  }
  if (!runout_phase_deg.empty() && !(spindle_rpm > 0.0)) {
    problems.push_back(
        fmt::format("prediction.spindle_rpm = {} violates > 0 (needed for runout)", spindle_rpm));
  }
  if (!(feed_mm_per_min > 0.0)) {
    problems.push_back(fmt::format("path.feed_mm_per_min = {} violates > 0", feed_mm_per_min));
  }
  if (nodes_x < 2 || nodes_y < 2) {
    problems.push_back(fmt::format("prediction.map_nodes = [{}, {}] violates >= 2 each", nodes_x, nodes_y));
  }
  if (threads < 0) problems.push_back(fmt::format("machine.threads = {} violates >= 0", threads));
  if (profile_u_mm.size() != profile_error_um.size()) {
    problems.push_back(fmt::format("prediction profile sizes u_mm = {}, error_um = {} violates equal",
                                   profile_u_mm.size(), profile_error_um.size()));
  }
  for (size_t k = 0; k < profile_u_mm.size() && k < profile_error_um.size(); ++k) {
    if (!std::isfinite(profile_u_mm[k]) || !std::isfinite(profile_error_um[k]) ||
        (k > 0 && !(profile_u_mm[k] > profile_u_mm[k - 1]))) {
      problems.push_back(
          fmt::format("prediction profile node {}: u_mm = {}, error_um = {} violates finite, "
                      "u_mm strictly increasing",
                      k, profile_u_mm[k], profile_error_um[k]));
      break;
    }
  }
  return problems;
}

void SetEccentricRunout(double total_indicated_runout_um, PredictionOptions& options) {
  options.runout_phase_deg.resize(360);
  options.runout_radial_um.resize(360);
  for (int k = 0; k < 360; ++k) {
    options.runout_phase_deg[static_cast<size_t>(k)] = k;
    options.runout_radial_um[static_cast<size_t>(k)] =
        0.5 * total_indicated_runout_um * std::cos(k * std::numbers::pi / 180.0);
  }
}

namespace {

// The height error (um) that a profile error the path does not follow prints at (x, y): -p(u) N3
// with u = Ra fy / N3, the contact's axial offset from the arc centre (eq. 5).
double ProfilePrintUm(const Surface& surface, const Wheel& wheel, const PredictionOptions& o, double x_mm,
                      double y_mm) {
  const std::vector<double>& u = o.profile_u_mm;
  if (u.empty()) return 0.0;
  const SurfacePoint s = surface.Evaluate(x_mm, y_mm);
  const double n3 = std::sqrt(s.fx * s.fx + s.fy * s.fy + 1.0);
  const double at = wheel.arc_radius_mm * s.fy / n3;
  const std::vector<double>& e = o.profile_error_um;
  if (u.size() == 1 || at <= u.front()) return -e.front() * n3;
  if (at >= u.back()) return -e.back() * n3;
  const size_t k = static_cast<size_t>(std::upper_bound(u.begin(), u.end(), at) - u.begin());
  const double t = (at - u[k - 1]) / (u[k] - u[k - 1]);
  return -(e[k - 1] + t * (e[k] - e[k - 1])) * n3;
}

}  // namespace

FormPrediction PredictFormError(const Surface& surface, const Aperture& aperture, const Wheel& wheel,
                                const PredictionOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kPredictionStage, options.Problems());
  FormPrediction p;
  const size_t nx = static_cast<size_t>(options.nodes_x), ny = static_cast<size_t>(options.nodes_y);
  for (int i = 0; i < options.nodes_x; ++i) {
    p.x_mm.push_back(aperture.HalfX() * (2.0 * i / (options.nodes_x - 1) - 1.0));
  }
  for (int j = 0; j < options.nodes_y; ++j) {
    p.y_mm.push_back(aperture.HalfY() * (2.0 * j / (options.nodes_y - 1) - 1.0));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  p.error_um.assign(nx * ny, nan);
  p.low_order_um.assign(nx * ny, nan);
  std::vector<double> ripple_um(nx * ny, nan);
  std::vector<double> profile_um(nx * ny, nan);
  const NodePredictor predictor(surface, wheel, options);
  const int workers = WorkerCount(options.threads);
  RunOnWorkers(workers, [&](int worker) {
    for (size_t j = static_cast<size_t>(worker); j < ny; j += static_cast<size_t>(workers)) {
      for (size_t i = 0; i < nx; ++i) {
        if (!aperture.Contains(p.x_mm[i], p.y_mm[j])) continue;
        const NodeError e = predictor.Predict(p.x_mm[i], p.y_mm[j]);
        const size_t k = j * nx + i;
        p.low_order_um[k] = 1e3 * e.low_order_mm;
        ripple_um[k] = 1e3 * e.ripple_mm;
        profile_um[k] = ProfilePrintUm(surface, wheel, options, p.x_mm[i], p.y_mm[j]);
        p.error_um[k] = 1e3 * (e.low_order_mm + e.ripple_mm) + profile_um[k];
      }
    }
  });
  const Statistics all = PvRms(p.error_um);
  const Statistics flat = PvRms(WithoutPlane(p));
  p.pv_um = all.pv_um;
  p.rms_um = all.rms_um;
  p.pv_after_tilt_um = flat.pv_um;
  p.rms_after_tilt_um = flat.rms_um;
  p.ripple_pv_um = PvRms(ripple_um).pv_um;
  if (!options.profile_u_mm.empty()) p.profile_pv_um = PvRms(profile_um).pv_um;
  return p;
}

void WritePredictionHdf5(const FormPrediction& prediction, const std::filesystem::path& path,
                         const std::string& surface_description, const std::string& wheel_description) {
  namespace layout = schema::grid_map;
  const size_t nx = prediction.x_mm.size(), ny = prediction.y_mm.size();
  ARCWHEEL_CHECK(nx >= 2 && ny >= 2) << "prediction map of " << nx << " x " << ny << " nodes";
  // PredictFormError lays the nodes evenly from the first to the last.
  layout::Content map{
      .x0_mm = prediction.x_mm.front(),
      .y0_mm = prediction.y_mm.front(),
      .dx_mm = (prediction.x_mm.back() - prediction.x_mm.front()) / static_cast<double>(nx - 1),
      .dy_mm = (prediction.y_mm.back() - prediction.y_mm.front()) / static_cast<double>(ny - 1),
      .nx = static_cast<int>(nx),
      .ny = static_cast<int>(ny),
      .error_um = prediction.error_um,
      .quantity = std::string(layout::kPredictedFormError)};
  map.layers = {{std::string(layout::kLowOrderUm), prediction.low_order_um}};
  map.figures = {{std::string(layout::kPvUmAttribute), prediction.pv_um},
                 {std::string(layout::kRmsUmAttribute), prediction.rms_um},
                 {"pv_after_tilt_um", prediction.pv_after_tilt_um},
                 {"rms_after_tilt_um", prediction.rms_after_tilt_um},
                 {"ripple_pv_um", prediction.ripple_pv_um},
                 {"profile_pv_um", prediction.profile_pv_um}};
  map.texts = {{"surface", surface_description}, {"wheel", wheel_description}};
  layout::WriteGridMap(map, path);
}

}  // namespace arcwheel::grinding
