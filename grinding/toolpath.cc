#include "grinding/toolpath.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/parallel.h"

namespace arcwheel::grinding {

using surfaces::Aperture;
using surfaces::Surface;
using surfaces::SurfacePoint;

namespace {

constexpr const char* kToolpathStage = "grinding.toolpath";
constexpr double kNewtonTolerance_mm = 1e-11;
constexpr int kNewtonMaxIterations = 40;
// Rounding noise of the clearance curvature is ~1e-15 / mm; anything below this is a real cut.
constexpr double kLocalClearanceTolerance_per_mm = -1e-12;

// Eq. 5 at one contact, with the surface point and the arc radius it used.
struct Eq5 {
  ControlPoint point;
  SurfacePoint surface;
  double arc_radius_mm = 0.0;
};

Eq5 EvaluateEq5(const Surface& surface, const Wheel& wheel, double x, double y) {
  Eq5 e;
  const SurfacePoint& s = e.surface = surface.Evaluate(x, y);
  const double n3 = std::sqrt(s.fx * s.fx + s.fy * s.fy + 1.0);
  const double n2 = std::sqrt(s.fx * s.fx + 1.0);
  const double ra =
      wheel.HasProfile() ? wheel.ArcRadiusAt(wheel.arc_radius_mm * s.fy / n3) : wheel.arc_radius_mm;
  const double rb = wheel.base_radius_mm;
  e.arc_radius_mm = ra;
  e.point.contact_mm = {x, y, s.z_mm};
  e.point.normal = Eigen::Vector3d(-s.fx, -s.fy, 1.0) / n3;
  e.point.wheel_centre_mm = {x - ra * s.fx / n3 - rb * s.fx / n2, y - ra * s.fy / n3,
                             s.z_mm + ra / n3 + rb / n2};
  return e;
}

// d(Xw, Yw)/d(X, Y): d(fx/N3, fy/N3)/d(fx, fy) times the Hessian, and d(fx/N2)/dfx = 1/N2^3
// (a measured profile's own slope is left out: it only slows Newton's convergence, not its answer).
Eigen::Matrix2d JacobianOf(const Eq5& e, double rb) {
  const SurfacePoint& s = e.surface;
  const double n3 = std::sqrt(s.fx * s.fx + s.fy * s.fy + 1.0);
  const double n2 = std::sqrt(s.fx * s.fx + 1.0);
  Eigen::Matrix2d unit_normal_slope;
  unit_normal_slope << 1.0 + s.fy * s.fy, -s.fx * s.fy, -s.fx * s.fy, 1.0 + s.fx * s.fx;
  unit_normal_slope /= n3 * n3 * n3;
  Eigen::Matrix2d hessian;
  hessian << s.fxx_per_mm, s.fxy_per_mm, s.fxy_per_mm, s.fyy_per_mm;
  Eigen::Matrix2d jacobian = Eigen::Matrix2d::Identity() - e.arc_radius_mm * unit_normal_slope * hessian;
  jacobian.row(0) -= rb / (n2 * n2 * n2) * hessian.row(0);
  return jacobian;
}

// Newton on eq. 5. fix_contact_x: the first equation is X = target_x, else Xw = target_x.
Eq5 SolveEq5(const Surface& surface, const Wheel& wheel, bool fix_contact_x, double target_x,
             double target_yw, Eigen::Vector2d xy) {
  for (int iteration = 0; iteration < kNewtonMaxIterations; ++iteration) {
    if (!std::isfinite(xy.x()) || !std::isfinite(xy.y()) || !surface.InDomain(xy.x(), xy.y())) break;
    const Eq5 e = EvaluateEq5(surface, wheel, xy.x(), xy.y());
    const Eigen::Vector3d& c = e.point.wheel_centre_mm;
    const Eigen::Vector2d residual(fix_contact_x ? xy.x() - target_x : c.x() - target_x, c.y() - target_yw);
    if (residual.cwiseAbs().maxCoeff() < kNewtonTolerance_mm) return e;
    Eigen::Matrix2d jacobian = JacobianOf(e, wheel.base_radius_mm);
    if (fix_contact_x) jacobian.row(0) << 1.0, 0.0;
    const double det = jacobian.determinant();
    if (!(std::abs(det) > 1e-12)) break;
    xy -= jacobian.inverse() * residual;
  }
  throw Error(
      ErrorCode::kBadInput, kToolpathStage,
      fmt::format("cannot place the wheel at {} = {:.6f} mm, wheel-centre Y = {:.6f} mm: "
                  "eq. 5 has no solution there (last contact tried ({:.6f}, {:.6f}) mm); "
                  "the wheel cannot follow the surface at that point",
                  fix_contact_x ? "contact X" : "wheel-centre X", target_x, target_yw, xy.x(), xy.y()));
}

// Hessian of W(x, y) = Zw - sqrt(R(y)^2 - (x - Xw)^2), R(y) = Rb + sqrt(Ra^2 - (y - Yw)^2), the
// wheel's lower surface, minus the surface's Hessian, at the contact.
Eigen::Matrix2d ClearanceHessianOf(const Eq5& e, const Wheel& wheel) {
  const ControlPoint& p = e.point;
  const Eigen::Vector3d& c = p.wheel_centre_mm;
  const double ra = e.arc_radius_mm;
  const double t = p.contact_mm.y() - c.y();
  const double q = std::sqrt(ra * ra - t * t);
  const double rim = wheel.base_radius_mm + q;
  const double a = p.contact_mm.x() - c.x();
  const double root = std::sqrt(rim * rim - a * a);
  const double root3 = root * root * root;
  const double dr = -t / q, d2r = -ra * ra / (q * q * q);
  Eigen::Matrix2d difference;
  difference(0, 0) = rim * rim / root3 - e.surface.fxx_per_mm;
  difference(0, 1) = -a * rim * dr / root3 - e.surface.fxy_per_mm;
  difference(1, 1) = -(dr * dr + rim * d2r) / root + rim * rim * dr * dr / root3 - e.surface.fyy_per_mm;
  difference(1, 0) = difference(0, 1);
  return difference;
}

double SmallestEigenvalue(const Eigen::Matrix2d& m) {
  const double mean = 0.5 * (m(0, 0) + m(1, 1));
  const double half_diff = 0.5 * (m(0, 0) - m(1, 1));
  return mean - std::sqrt(half_diff * half_diff + m(0, 1) * m(0, 1));
}

struct RowStats {
  double max_row_deviation_mm = 0.0;
  long long gouge_checks = 0;
  double min_gouge_gap_mm = std::numeric_limits<double>::infinity();
  double min_local_clearance_per_mm = std::numeric_limits<double>::infinity();
  void Merge(const RowStats& o) {
    max_row_deviation_mm = std::max(max_row_deviation_mm, o.max_row_deviation_mm);
    gouge_checks += o.gouge_checks;
    min_gouge_gap_mm = std::min(min_gouge_gap_mm, o.min_gouge_gap_mm);
    min_local_clearance_per_mm = std::min(min_local_clearance_per_mm, o.min_local_clearance_per_mm);
  }
};

class RowBuilder {
 public:
  RowBuilder(const Surface& surface, const Aperture& aperture, const Wheel& wheel,
             const ToolpathOptions& options, int rows_count)
      : surface_(surface), aperture_(aperture), wheel_(wheel), options_(options), rows_count_(rows_count) {}

  // Control points of the row at wheel-centre Y = yw, in +X order; empty if the row misses a
  // circular aperture. Every point gets the local checks as it is solved.
  std::vector<ControlPoint> Build(int row, double yw, bool reversed, RowStats& stats) const {
    const Eq5 middle = SolveEq5(surface_, wheel_, true, 0.0, yw, {0.0, yw});
    const double half = aperture_.HalfChordAt(middle.point.contact_mm.y());
    if (half <= 0.0) return {};
    const double lead_low = reversed ? options_.lead_out_mm : options_.lead_in_mm;
    const double lead_high = reversed ? options_.lead_in_mm : options_.lead_out_mm;
    const Eigen::Vector2d mid_xy = middle.point.contact_mm.head<2>();
    const Eq5 first =
        SolveEq5(surface_, wheel_, true, -half - lead_low, yw, mid_xy - Eigen::Vector2d(half, 0));
    const Eq5 last =
        SolveEq5(surface_, wheel_, true, half + lead_high, yw, mid_xy + Eigen::Vector2d(half, 0));
    const RowContext context{row, yw, &stats};
    std::vector<ControlPoint> points =
        options_.chordal_tolerance_um > 0.0 ? Adaptive(first, last, context) : Uniform(first, last, context);
    // Global checks on a grid about gouge_check_spacing_mm wide: every few rows (and the last),
    // along the row every spacing of wheel-centre travel and at both ends.
    const int row_stride =
        std::max(1, static_cast<int>(std::lround(options_.gouge_check_spacing_mm / options_.step_over_mm)));
    if (row % row_stride != 0 && row != rows_count_ - 1) return points;
    double last_checked_xw = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < points.size(); ++i) {
      const double xw = points[i].wheel_centre_mm.x();
      if (i == 0 || i + 1 == points.size() ||
          xw - last_checked_xw >= options_.gouge_check_spacing_mm - 1e-9) {
        GlobalGougeCheck(row, static_cast<int>(i), points[i], stats);
        last_checked_xw = xw;
      }
    }
    return points;
  }

 private:
  struct RowContext {
    int row;
    double yw;
    RowStats* stats;
  };

  std::vector<ControlPoint> Uniform(const Eq5& first, const Eq5& last, const RowContext& context) const {
    const double xw0 = first.point.wheel_centre_mm.x(), xw1 = last.point.wheel_centre_mm.x();
    const long long n = std::max<long long>(
        1, static_cast<long long>(std::ceil((xw1 - xw0) / options_.point_spacing_mm - 1e-9)));
    const double step = (xw1 - xw0) / static_cast<double>(n);
    std::vector<ControlPoint> points;
    points.reserve(static_cast<size_t>(n + 1));
    Accept(first, context, points);
    for (long long i = 1; i < n; ++i) {
      Accept(SolveEq5(surface_, wheel_, false, xw0 + static_cast<double>(i) * step, context.yw,
                      NextGuess(points, step)),
             context, points);
    }
    Accept(last, context, points);
    return points;
  }

  // Steps as long as the midpoint of the straight move stays within the chordal tolerance of the
  // true wheel-centre curve (checked by solving the midpoint, not estimated).
  std::vector<ControlPoint> Adaptive(const Eq5& first, const Eq5& last, const RowContext& context) const {
    const double tolerance_mm = options_.chordal_tolerance_um * 1e-3;
    const double xw1 = last.point.wheel_centre_mm.x();
    std::vector<ControlPoint> points;
    Accept(first, context, points);
    double step = options_.point_spacing_mm;
    while (xw1 - points.back().wheel_centre_mm.x() > 1e-9) {
      const ControlPoint a = points.back();
      const Eigen::Vector2d a_xy = a.contact_mm.head<2>();
      step = std::min(options_.point_spacing_mm, 2.0 * step);
      for (;;) {
        const bool to_end = a.wheel_centre_mm.x() + step >= xw1 - 1e-9;
        const double xb = to_end ? xw1 : a.wheel_centre_mm.x() + step;
        const double h = xb - a.wheel_centre_mm.x();
        const Eq5 b =
            to_end ? last : SolveEq5(surface_, wheel_, false, xb, context.yw, a_xy + Eigen::Vector2d(h, 0));
        const Eq5 mid = SolveEq5(surface_, wheel_, false, a.wheel_centre_mm.x() + 0.5 * h, context.yw,
                                 a_xy + Eigen::Vector2d(0.5 * h, 0));
        const double chord_mm = std::abs(mid.point.wheel_centre_mm.z() -
                                         0.5 * (a.wheel_centre_mm.z() + b.point.wheel_centre_mm.z()));
        if (chord_mm <= tolerance_mm || h < 1e-6) {
          Accept(b, context, points);
          step = h;
          break;
        }
        step = 0.5 * h;
      }
    }
    return points;
  }

  // Linear extrapolation of the last two contacts: Newton then needs one step.
  static Eigen::Vector2d NextGuess(const std::vector<ControlPoint>& points, double step) {
    const Eigen::Vector2d last = points.back().contact_mm.head<2>();
    if (points.size() < 2) return last + Eigen::Vector2d(step, 0.0);
    return 2.0 * last - points[points.size() - 2].contact_mm.head<2>();
  }

  // Local checks (row straightness, reach, curvature) of a solved point, then keeps it.
  void Accept(const Eq5& e, const RowContext& context, std::vector<ControlPoint>& points) const {
    const ControlPoint& p = e.point;
    const int index = static_cast<int>(points.size());
    const Eigen::Vector3d& c = p.wheel_centre_mm;
    RowStats& stats = *context.stats;
    stats.max_row_deviation_mm = std::max(stats.max_row_deviation_mm, std::abs(c.y() - context.yw));
    const double u = p.contact_mm.y() - c.y();
    if (!wheel_.Reaches(u)) {
      throw Error(ErrorCode::kBadInput, kToolpathStage,
                  fmt::format("row {} point {}: contact ({:.6f}, {:.6f}) mm lies {:.4f} mm from the "
                              "arc centre along the wheel axis, beyond the wheel's usable arc "
                              "(half width {} mm{}); the surface is too steep across the feed",
                              context.row, index, p.contact_mm.x(), p.contact_mm.y(), u, wheel_.half_width_mm,
                              wheel_.HasProfile() ? " and measured profile" : ""));
    }
    const double clearance = SmallestEigenvalue(ClearanceHessianOf(e, wheel_));
    stats.min_local_clearance_per_mm = std::min(stats.min_local_clearance_per_mm, clearance);
    if (clearance < kLocalClearanceTolerance_per_mm) {
      throw Error(ErrorCode::kBadInput, kToolpathStage,
                  fmt::format("row {} point {}: the wheel (Ra = {} mm, total radius {} mm) cannot "
                              "reach the curvature at contact ({:.6f}, {:.6f}) mm: the concave "
                              "surface is more curved than the wheel there (clearance curvature "
                              "{:.3e} / mm), so the wheel would gouge beside the contact",
                              context.row, index, wheel_.arc_radius_mm, wheel_.TotalRadius(),
                              p.contact_mm.x(), p.contact_mm.y(), clearance));
    }
    points.push_back(p);
  }

  void GlobalGougeCheck(int row, int index, const ControlPoint& p, RowStats& stats) const {
    const GougeProbe probe = ProbeGouge(surface_, aperture_, wheel_, p, options_.gouge_samples);
    ++stats.gouge_checks;
    stats.min_gouge_gap_mm = std::min(stats.min_gouge_gap_mm, probe.min_gap_mm);
    if (probe.min_gap_mm < -options_.gouge_tolerance_mm) {
      const Eigen::Vector3d& c = p.wheel_centre_mm;
      throw Error(ErrorCode::kBadInput, kToolpathStage,
                  fmt::format("row {} point {}: gouge: with the wheel centre at ({:.6f}, {:.6f}, "
                              "{:.6f}) mm for contact ({:.6f}, {:.6f}) mm the wheel cuts {:.3f} um "
                              "below the surface at ({:.6f}, {:.6f}) mm",
                              row, index, c.x(), c.y(), c.z(), p.contact_mm.x(), p.contact_mm.y(),
                              -probe.min_gap_mm * 1e3, probe.x_mm, probe.y_mm));
    }
  }

  const Surface& surface_;
  const Aperture& aperture_;
  const Wheel& wheel_;
  const ToolpathOptions& options_;
  int rows_count_;
};

std::vector<double> PlanRows(const Surface& surface, const Aperture& aperture, const Wheel& wheel,
                             double step_over_mm) {
  // Wheel-centre Y of the contacts over the aperture: the rows must cover all of them.
  constexpr int kSamples = 64;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int j = 0; j <= kSamples; ++j) {
    for (int i = 0; i <= kSamples; ++i) {
      const double x = aperture.HalfX() * (2.0 * i / kSamples - 1.0);
      const double y = aperture.HalfY() * (2.0 * j / kSamples - 1.0);
      if (aperture.shape == Aperture::Shape::kCircle && std::hypot(x, y) > aperture.HalfX() * (1 + 1e-12)) {
        continue;
      }
      const double yw = ControlPointForContact(surface, wheel, x, y).wheel_centre_mm.y();
      lo = std::min(lo, yw);
      hi = std::max(hi, yw);
    }
  }
  const int intervals = std::max(1, static_cast<int>(std::ceil((hi - lo) / step_over_mm - 1e-9)));
  std::vector<double> rows(static_cast<size_t>(intervals) + 1);
  for (int k = 0; k <= intervals; ++k) rows[static_cast<size_t>(k)] = lo + (hi - lo) * k / intervals;
  return rows;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
ControlPoint ControlPointForContact(const Surface& surface, const Wheel& wheel, double x_mm, double y_mm) {
  return EvaluateEq5(surface, wheel, x_mm, y_mm).point;
}

double WheelBottomZ(const Wheel& wheel, const Eigen::Vector3d& c, double x_mm, double y_mm,
                    double extra_arc_radius_mm, double extra_base_radius_mm) {
  const double ra = wheel.arc_radius_mm + extra_arc_radius_mm;
  const double t = y_mm - c.y();
  if (std::abs(t) > std::min(wheel.half_width_mm, ra)) return std::numeric_limits<double>::infinity();
  const double rim = wheel.base_radius_mm + extra_base_radius_mm + std::sqrt(ra * ra - t * t);
  const double a = x_mm - c.x();
  if (std::abs(a) >= rim) return std::numeric_limits<double>::infinity();
  return c.z() - std::sqrt(rim * rim - a * a);
}

double DistanceToTorus(const Wheel& wheel, const Eigen::Vector3d& c, const Eigen::Vector3d& p) {
  const double rho = std::hypot(p.x() - c.x(), p.z() - c.z());
  return std::hypot(rho - wheel.base_radius_mm, p.y() - c.y()) - wheel.arc_radius_mm;
}

GougeProbe ProbeGouge(const Surface& surface, const Aperture& aperture, const Wheel& wheel,
                      const ControlPoint& p, int samples) {
  const Eigen::Vector3d& c = p.wheel_centre_mm;
  const int n = std::max(samples / 2, 1);
  const double reach_x = std::min(wheel.TotalRadius(), 2.0 * aperture.HalfX());
  const double half_w = std::min(wheel.half_width_mm, wheel.arc_radius_mm);
  // With a measured profile the wheel is treated as the torus of the profile's radius at the
  // contact: the profile's own shape is already accounted for in the control point.
  const double extra_ra = wheel.ArcRadiusAt(p.contact_mm.y() - c.y()) - wheel.arc_radius_mm;
  GougeProbe probe{std::numeric_limits<double>::infinity(), p.contact_mm.x(), p.contact_mm.y()};
  // The y lines run through the contact so that the contact itself is one of the samples.
  for (int j = -2 * n; j <= 2 * n; ++j) {
    const double y = p.contact_mm.y() + half_w * j / n;
    if (std::abs(y - c.y()) > half_w) continue;
    for (int i = -n; i <= n; ++i) {
      const double r = static_cast<double>(i) / n;
      const double x = p.contact_mm.x() + reach_x * r * std::abs(r);
      if (!aperture.Contains(x, y) || !surface.InDomain(x, y)) continue;
      const double gap = WheelBottomZ(wheel, c, x, y, extra_ra) - surface.Evaluate(x, y).z_mm;
      if (gap < probe.min_gap_mm) probe = {gap, x, y};
    }
  }
  return probe;
}

ControlPoint SolveContactForWheelCentre(const Surface& surface, const Wheel& wheel, double xw_mm,
                                        double yw_mm, Eigen::Vector2d guess_mm) {
  return SolveEq5(surface, wheel, false, xw_mm, yw_mm, guess_mm).point;
}

ControlPoint SolveContactOnRow(const Surface& surface, const Wheel& wheel, double contact_x_mm, double yw_mm,
                               Eigen::Vector2d guess_mm) {
  return SolveEq5(surface, wheel, true, contact_x_mm, yw_mm, guess_mm).point;
}

Eigen::Matrix2d Eq5Jacobian(const Surface& surface, const Wheel& wheel, double x_mm, double y_mm) {
  return JacobianOf(EvaluateEq5(surface, wheel, x_mm, y_mm), wheel.base_radius_mm);
}

double LocalClearanceCurvature(const Surface& surface, const Wheel& wheel, const ControlPoint& p) {
  return SmallestEigenvalue(ClearanceHessian(surface, wheel, p));
}

Eigen::Matrix2d ClearanceHessian(const Surface& surface, const Wheel& wheel, const ControlPoint& p) {
  // The torus through this contact: the profile's radius where eq. 5 took it.
  Eq5 e = EvaluateEq5(surface, wheel, p.contact_mm.x(), p.contact_mm.y());
  e.point = p;
  return ClearanceHessianOf(e, wheel);
}
std::vector<std::string> ToolpathOptions::Problems() const {
  std::vector<std::string> problems;
  const auto require = [&problems](bool ok, const std::string& text) {
    if (!ok) problems.push_back(text);
  };
  require(step_over_mm > 0.0, fmt::format("path.step_over_mm = {} violates > 0", step_over_mm));
  require(point_spacing_mm > 0.0, fmt::format("path.point_spacing_mm = {} violates > 0", point_spacing_mm));
  require(chordal_tolerance_um >= 0.0,
          fmt::format("path.chordal_tolerance_um = {} violates >= 0", chordal_tolerance_um));
  require(feed_mm_per_min > 0.0, fmt::format("path.feed_mm_per_min = {} violates > 0", feed_mm_per_min));
  require(depth_per_pass_um >= 0.0,
          fmt::format("path.depth_per_pass_um = {} violates >= 0", depth_per_pass_um));
  require(passes >= 1, fmt::format("path.passes = {} violates >= 1", passes));
  require(lead_in_mm >= 0.0, fmt::format("path.lead_in_mm = {} violates >= 0", lead_in_mm));
  require(lead_out_mm >= 0.0, fmt::format("path.lead_out_mm = {} violates >= 0", lead_out_mm));
  require(gouge_check_spacing_mm > 0.0,
          fmt::format("gouge_check.spacing_mm = {} violates > 0", gouge_check_spacing_mm));
  require(gouge_samples >= 3, fmt::format("gouge_check.samples = {} violates >= 3", gouge_samples));
  require(gouge_tolerance_mm >= 0.0,
          fmt::format("gouge_check.tolerance_um = {} violates >= 0", gouge_tolerance_mm * 1e3));
  require(threads >= 0, fmt::format("machine.threads = {} violates >= 0", threads));
  return problems;
}

ToolpathSummary GenerateToolpath(const Surface& surface, const Aperture& aperture, const Wheel& wheel,
                                 const ToolpathOptions& options, const RowSink& sink) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kToolpathStage, options.Problems());
  ThrowIfProblems(ErrorCode::kBadInput, kToolpathStage, wheel.Problems());
  const std::vector<double> rows = PlanRows(surface, aperture, wheel, options.step_over_mm);
  const RowBuilder builder(surface, aperture, wheel, options, static_cast<int>(rows.size()));
  const int threads = WorkerCount(options.threads);
  const int block = kRowsInFlightPerWorker * threads;
  ToolpathSummary summary;
  summary.passes = options.passes;
  summary.rows_per_pass = static_cast<int>(rows.size());
  summary.first_row_yw_mm = rows.front();
  summary.row_pitch_mm = rows.size() > 1 ? rows[1] - rows[0] : 0.0;
  RowStats total;
  std::vector<ToolpathRow> batch;
  for (int pass = 0; pass < options.passes; ++pass) {
    const double z_offset_mm = (options.passes - 1 - pass) * options.depth_per_pass_um * 1e-3;
    for (size_t first = 0; first < rows.size(); first += static_cast<size_t>(block)) {
      ThrowIfInterrupted();
      const size_t count = std::min(rows.size() - first, static_cast<size_t>(block));
      // Rows are reused block after block so that their text buffers keep their capacity.
      batch.resize(count);
      std::vector<std::exception_ptr> errors(count);
      std::vector<RowStats> stats(static_cast<size_t>(threads));
      // Each row keeps its own error, so that the first failing row is the one reported.
      RunOnWorkers(threads, [&](int worker) {
        for (size_t k = static_cast<size_t>(worker); k < count; k += static_cast<size_t>(threads)) {
          try {
            ToolpathRow& row = batch[k];
            row.pass = pass;
            row.row = static_cast<int>(first + k);
            row.reversed = options.zigzag && row.row % 2 == 1;
            row.z_offset_mm = z_offset_mm;
            for (std::string& text : row.text) text.clear();
            row.points =
                builder.Build(row.row, rows[first + k], row.reversed, stats[static_cast<size_t>(worker)]);
            if (row.reversed) std::reverse(row.points.begin(), row.points.end());
            for (ControlPoint& p : row.points) {
              p.wheel_centre_mm.z() += z_offset_mm;
              p.contact_mm.z() += z_offset_mm;
            }
            if (sink.prepare) sink.prepare(row);
          } catch (...) {
            errors[k] = std::current_exception();
          }
        }
      });
      for (const std::exception_ptr& e : errors) {
        if (e) std::rethrow_exception(e);
      }
      for (const RowStats& s : stats) total.Merge(s);
      for (ToolpathRow& row : batch) {
        if (row.points.empty()) continue;  // a row that misses a circular aperture
        summary.control_points += static_cast<long long>(row.points.size());
        if (sink.consume) sink.consume(row);
      }
    }
  }
  summary.max_row_deviation_mm = total.max_row_deviation_mm;
  summary.gouge_checks = total.gouge_checks;
  summary.min_gouge_gap_mm = total.min_gouge_gap_mm;
  summary.min_local_clearance_per_mm = total.min_local_clearance_per_mm;
  return summary;
}

}  // namespace arcwheel::grinding
