#include "characteristics/association.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>

#include "core/check.h"
#include "core/dense.h"
#include "core/error.h"

namespace arcwheel::characteristics {
namespace {

constexpr std::string_view kAssociationStage = "characteristics.association";

struct NamedAssociation {
  Association association;
  std::string_view name;
  std::string_view abbreviation;
};
constexpr std::array<NamedAssociation, 4> kAssociationNames = {{
    {Association::kLeastSquares, "least-squares", "LS"},
    {Association::kMinimumZone, "minimum-zone", "MZ"},
    {Association::kMaximumInscribed, "maximum-inscribed", "MI"},
    {Association::kMinimumCircumscribed, "minimum-circumscribed", "MC"},
}};

const NamedAssociation& Named(Association association) {
  for (const NamedAssociation& named : kAssociationNames) {
    if (named.association == association) return named;
  }
  ARCWHEEL_CHECK(false) << "association " << static_cast<int>(association);
  return kAssociationNames[0];
}

// Rounding of a distance between points `scale` apart, with margin: the tolerance of the
// optimality conditions and of the simplex's pricing.
constexpr double kRelativeTolerance = 1e-12;

// The points about their centroid, so that far-off coordinates (1e4 mm) cost no digits.
struct Points {
  std::vector<double> x, y;
  double centroid_x = 0.0, centroid_y = 0.0;
  double scale_mm = 0.0;  // largest distance of a point from the centroid
  [[nodiscard]] int size() const { return static_cast<int>(x.size()); }
  [[nodiscard]] Eigen::Vector2d at(int i) const {
    return {x[static_cast<std::size_t>(i)], y[static_cast<std::size_t>(i)]};
  }
};

Points CentredPoints(std::span<const double> x_mm, std::span<const double> y_mm) {
  Points points;
  const std::size_t n = x_mm.size();
  for (std::size_t i = 0; i < n; ++i) {
    points.centroid_x += x_mm[i];
    points.centroid_y += y_mm[i];
  }
  points.centroid_x /= static_cast<double>(n);
  points.centroid_y /= static_cast<double>(n);
  points.x.resize(n);
  points.y.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    points.x[i] = x_mm[i] - points.centroid_x;
    points.y[i] = y_mm[i] - points.centroid_y;
    points.scale_mm = std::max(points.scale_mm, std::hypot(points.x[i], points.y[i]));
  }
  return points;
}

struct Circle {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double radius = 0.0;
};

// Kasa 1976: minimises sum (x^2 + y^2 + D x + E y + F)^2, linear in D, E, F. Only the start of
// the geometric fit. Coordinates are divided by the scale so that the normal equations hold O(1).
std::optional<Circle> AlgebraicCircle(const Points& points) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d p = points.at(i) / points.scale_mm;
    const Eigen::Vector3d row(p.x(), p.y(), 1.0);
    normal += row * row.transpose();
    rhs -= row * p.squaredNorm();
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(normal);
  if (!lu.isInvertible()) return std::nullopt;
  const Eigen::Vector3d def = lu.solve(rhs);
  Circle circle;
  circle.center = -0.5 * def.head<2>();
  const double radius_squared = circle.center.squaredNorm() - def(2);
  if (!(radius_squared > 0)) return std::nullopt;
  circle.center *= points.scale_mm;
  circle.radius = std::sqrt(radius_squared) * points.scale_mm;
  return circle;
}

// Gauss-Newton on the orthogonal distances d_i - r: converges in a few steps from the algebraic
// circle when the points are close to a circle, which is what a profile is.
Circle GeometricCircle(const Points& points, Circle circle) {
  constexpr int kMaxSteps = 50;
  double last_step = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxSteps; ++step) {
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
    for (int i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d offset = points.at(i) - circle.center;
      const double distance = offset.norm();
      const Eigen::Vector3d row(-offset.x() / distance, -offset.y() / distance, -1.0);
      normal += row * row.transpose();
      gradient += row * (distance - circle.radius);
    }
    const Eigen::Vector3d delta = -dense::LdltSolve(normal, gradient);
    circle.center += delta.head<2>();
    circle.radius += delta(2);
    const double size = delta.norm();
    // Stop when the steps stop shrinking: from there on they are rounding.
    if (size <= kRelativeTolerance * 1e-3 * points.scale_mm || !(size < 0.5 * last_step)) break;
    last_step = size;
  }
  return circle;
}

// ---- The linear programmes about a centre -------------------------------------------------------
// With u_i the unit vector from the centre c to point i and d_i its distance, moving the centre by
// delta changes d_i by -u_i . delta. Each association is then a linear programme in (R, delta)
// (and the zone half-width t), solved here as its dual: max cost . lambda subject to
// A lambda = b, lambda >= 0, whose columns are the points (twice for the zone: outer and inner).
// A basis is a set of support points; the primal solution y = B^-T cost_B gives R and delta.
//   circumscribed: min R      s.t. R + u_i.delta >= d_i           columns (1, u_i), cost d_i, b = (1, 0, 0)
//   inscribed:     max R      s.t. R + u_i.delta <= d_i           columns -(1, u_i), cost -d_i, b = -(1, 0,
//   0) zone:          min t      s.t. t +/- (R + u_i.delta - d_i) >= 0  columns (1, +/-1, +/-u_i), cost
//   +/-d_i, b = (1, 0, 0, 0)
using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;
using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4>;

class LinearProgramme {
 public:
  LinearProgramme(const Points& points, Association association, const Eigen::Vector2d& center)
      : association_(association), n_(points.size()) {
    distance_.resize(static_cast<std::size_t>(n_));
    direction_.resize(static_cast<std::size_t>(n_));
    for (int i = 0; i < n_; ++i) {
      const Eigen::Vector2d offset = points.at(i) - center;
      distance_[static_cast<std::size_t>(i)] = offset.norm();
      direction_[static_cast<std::size_t>(i)] = offset / offset.norm();
    }
  }
  [[nodiscard]] bool IsZone() const { return association_ == Association::kMinimumZone; }
  [[nodiscard]] int rows() const { return IsZone() ? 4 : 3; }
  [[nodiscard]] int columns() const { return IsZone() ? 2 * n_ : n_; }
  [[nodiscard]] int n() const { return n_; }
  [[nodiscard]] int PointOf(int column) const { return column % n_; }
  [[nodiscard]] bool IsOuter(int column) const { return !IsZone() || column < n_; }
  [[nodiscard]] double distance(int i) const { return distance_[static_cast<std::size_t>(i)]; }
  [[nodiscard]] const Eigen::Vector2d& direction(int i) const {
    return direction_[static_cast<std::size_t>(i)];
  }

  [[nodiscard]] Vector Column(int column) const {
    const int i = PointOf(column);
    const Eigen::Vector2d& u = direction(i);
    Vector a(rows());
    if (IsZone()) {
      const double sign = IsOuter(column) ? 1.0 : -1.0;
      a << 1.0, sign, sign * u.x(), sign * u.y();
    } else {
      const double sign = association_ == Association::kMaximumInscribed ? -1.0 : 1.0;
      a << sign, sign * u.x(), sign * u.y();
    }
    return a;
  }
  [[nodiscard]] double Cost(int column) const {
    const double d = distance(PointOf(column));
    if (IsZone()) return IsOuter(column) ? d : -d;
    return association_ == Association::kMaximumInscribed ? -d : d;
  }
  [[nodiscard]] Vector b() const {
    Vector b = Vector::Zero(rows());
    b(0) = association_ == Association::kMaximumInscribed ? -1.0 : 1.0;
    return b;
  }
  // How far the column's constraint is violated by the primal solution y (cost - a . y): the
  // column enters the basis when this is positive. One pass computes each point's deviation once.
  [[nodiscard]] std::pair<int, double> MostViolated(const Vector& y) const {
    const int offset = IsZone() ? 1 : 0;  // y = (t, R, delta) for the zone, (R, delta) otherwise
    const double radius = y(offset);
    const Eigen::Vector2d delta(y(offset + 1), y(offset + 2));
    int best = -1;
    double best_excess = 0.0;
    for (int i = 0; i < n_; ++i) {
      const double deviation = distance(i) - radius - direction(i).dot(delta);
      if (IsZone()) {
        const double excess = std::abs(deviation) - y(0);
        if (excess > best_excess) best_excess = excess, best = deviation > 0 ? i : i + n_;
      } else {
        const double excess = association_ == Association::kMaximumInscribed ? -deviation : deviation;
        if (excess > best_excess) best_excess = excess, best = i;
      }
    }
    return {best, best_excess};
  }
  [[nodiscard]] Eigen::Vector2d Delta(const Vector& y) const {
    const int offset = IsZone() ? 2 : 1;
    return {y(offset), y(offset + 1)};
  }

 private:
  Association association_;
  int n_;
  std::vector<double> distance_;
  std::vector<Eigen::Vector2d> direction_;
};

struct BasisSolution {
  Vector lambda;  // the dual variables of the basis columns (>= 0 when feasible)
  Vector y;       // the primal solution
  bool invertible = false;
};

BasisSolution SolveBasis(const LinearProgramme& lp, const std::vector<int>& basis) {
  const int m = lp.rows();
  Matrix matrix(m, m);
  Vector cost(m);
  for (int k = 0; k < m; ++k) {
    matrix.col(k) = lp.Column(basis[static_cast<std::size_t>(k)]);
    cost(k) = lp.Cost(basis[static_cast<std::size_t>(k)]);
  }
  BasisSolution solution;
  const Eigen::FullPivLU<Matrix> lu(matrix);
  if (!lu.isInvertible()) return solution;
  solution.invertible = true;
  solution.lambda = lu.solve(lp.b());
  solution.y = matrix.transpose().fullPivLu().solve(cost);
  return solution;
}

enum class SimplexOutcome { kOptimal, kUnbounded, kStalled };

// Primal simplex on the dual programme from a feasible basis; the basis and y are updated in place.
SimplexOutcome Simplex(const LinearProgramme& lp, std::vector<int>& basis, Vector& y, double tolerance_mm) {
  const int max_pivots = 100 + 2 * lp.columns();
  for (int pivot = 0; pivot < max_pivots; ++pivot) {
    const BasisSolution solution = SolveBasis(lp, basis);
    if (!solution.invertible) return SimplexOutcome::kStalled;
    y = solution.y;
    const auto [entering, excess] = lp.MostViolated(y);
    if (entering < 0 || excess <= tolerance_mm) return SimplexOutcome::kOptimal;
    const int m = lp.rows();
    Matrix matrix(m, m);
    for (int k = 0; k < m; ++k) matrix.col(k) = lp.Column(basis[static_cast<std::size_t>(k)]);
    const Vector w = matrix.fullPivLu().solve(lp.Column(entering));
    int leaving = -1;
    double ratio = std::numeric_limits<double>::infinity();
    for (int k = 0; k < m; ++k) {
      if (w(k) > 1e-12 && solution.lambda(k) / w(k) < ratio) ratio = solution.lambda(k) / w(k), leaving = k;
    }
    if (leaving < 0) return SimplexOutcome::kUnbounded;
    basis[static_cast<std::size_t>(leaving)] = entering;
  }
  return SimplexOutcome::kStalled;
}

// Point indices in order of their angle about the centre of the programme.
std::vector<int> ByAngle(const LinearProgramme& lp) {
  const auto n = static_cast<std::size_t>(lp.n());
  std::vector<double> angle(n);
  for (std::size_t i = 0; i < n; ++i) {
    angle[i] = std::atan2(lp.direction(static_cast<int>(i)).y(), lp.direction(static_cast<int>(i)).x());
  }
  std::vector<int> order(n);
  // Points given around the circle (a turn's, a section's) are in order from the smallest angle
  // on: with no two angles equal, that rotation is the one order the sort would find.
  const std::size_t first =
      static_cast<std::size_t>(std::min_element(angle.begin(), angle.end()) - angle.begin());
  bool rising = true;
  for (std::size_t k = 1; k < n && rising; ++k) rising = angle[(first + k - 1) % n] < angle[(first + k) % n];
  if (rising) {
    for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<int>((first + k) % n);
    return order;
  }
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return angle[static_cast<std::size_t>(a)] < angle[static_cast<std::size_t>(b)];
  });
  return order;
}

double AngleBetween(const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const double angle = std::atan2(from.x() * to.y() - from.y() * to.x(), from.dot(to));
  return angle < 0 ? angle + 2.0 * std::numbers::pi : angle;
}

// A feasible first basis. Zone: four points a quarter of the points apart in angle, alternately
// outer and inner (their chords cross, so the weights are positive). Inscribed and circumscribed:
// three points whose directions surround the centre, which exist only when no angular gap between
// neighbouring points exceeds half a turn; nullopt otherwise.
std::optional<std::vector<int>> FirstBasis(const LinearProgramme& lp) {
  const std::vector<int> order = ByAngle(lp);
  const int n = lp.n();
  if (lp.IsZone()) {
    const auto at = [&](int k) { return order[static_cast<std::size_t>(k * n / 4)]; };
    return std::vector<int>{at(0), at(1) + n, at(2), at(3) + n};
  }
  const int a = order[0];
  int b = -1;
  for (int k = 1; k < n; ++k) {
    const int i = order[static_cast<std::size_t>(k)];
    if (AngleBetween(lp.direction(a), lp.direction(i)) > std::numbers::pi) break;
    b = k;
  }
  if (b < 0 || b + 1 >= n) return std::nullopt;
  std::vector<int> basis{a, order[static_cast<std::size_t>(b)], order[static_cast<std::size_t>(b + 1)]};
  const BasisSolution solution = SolveBasis(lp, basis);
  if (!solution.invertible || solution.lambda.minCoeff() < -1e-9) return std::nullopt;
  return basis;
}

double LargestAngularGap(const LinearProgramme& lp) {
  const std::vector<int> order = ByAngle(lp);
  double largest = 0.0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const int from = order[k];
    const int to = order[(k + 1) % order.size()];
    const double gap =
        order.size() == 1 ? 2.0 * std::numbers::pi : AngleBetween(lp.direction(from), lp.direction(to));
    largest = std::max(largest, gap);
  }
  return largest;
}

std::optional<Eigen::Vector2d> Circumcentre(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                            const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a;
  const Eigen::Vector2d ac = c - a;
  const double twice_area = 2.0 * (ab.x() * ac.y() - ab.y() * ac.x());
  if (twice_area == 0.0) return std::nullopt;
  return Eigen::Vector2d(a.x() + (ac.y() * ab.squaredNorm() - ab.y() * ac.squaredNorm()) / twice_area,
                         a.y() + (ab.x() * ac.squaredNorm() - ac.x() * ab.squaredNorm()) / twice_area);
}

// The centre equidistant from the two outer points and from the two inner points: where the
// perpendicular bisectors of the two chords cross.
std::optional<Eigen::Vector2d> ZoneCentre(const Eigen::Vector2d& outer1, const Eigen::Vector2d& outer2,
                                          const Eigen::Vector2d& inner1, const Eigen::Vector2d& inner2) {
  Eigen::Matrix2d chords;
  chords.row(0) = (outer2 - outer1).transpose();
  chords.row(1) = (inner2 - inner1).transpose();
  const Eigen::Vector2d rhs(0.5 * (outer2 - outer1).squaredNorm(),
                            0.5 * ((inner2 - outer1).squaredNorm() - (inner1 - outer1).squaredNorm()));
  const double determinant = chords.determinant();
  if (determinant == 0.0) return std::nullopt;
  return Eigen::Vector2d(outer1 + chords.inverse() * rhs);
}

// The circle through the support points of the basis, exactly.
Eigen::Vector2d ExactCentre(const Points& points, const LinearProgramme& lp, const std::vector<int>& basis,
                            const Eigen::Vector2d& linearised) {
  std::vector<Eigen::Vector2d> outer, inner;
  for (const int column : basis)
    (lp.IsOuter(column) ? outer : inner).push_back(points.at(lp.PointOf(column)));
  std::optional<Eigen::Vector2d> centre;
  if (lp.IsZone() && outer.size() == 2 && inner.size() == 2)
    centre = ZoneCentre(outer[0], outer[1], inner[0], inner[1]);
  if (!lp.IsZone() && outer.size() == 3) centre = Circumcentre(outer[0], outer[1], outer[2]);
  return centre.value_or(linearised);
}

struct Certificate {
  bool certified = false;
  std::string why_not;
  double radius_inner = 0.0, radius_outer = 0.0;
  std::vector<int> support;
  std::vector<bool> on_outer;
};

// The optimality condition at the exact centre: every point on the right side of the circles and
// the support points' directions arranged as the condition needs.
Certificate Certify(const Points& points, Association association, const std::vector<int>& basis,
                    const Eigen::Vector2d& centre, double tolerance_mm) {
  const LinearProgramme lp(points, association, centre);
  Certificate certificate;
  double outer_sum = 0.0, inner_sum = 0.0;
  int outer_count = 0, inner_count = 0;
  for (const int column : basis) {
    const double d = lp.distance(lp.PointOf(column));
    if (lp.IsOuter(column))
      outer_sum += d, ++outer_count;
    else
      inner_sum += d, ++inner_count;
  }
  certificate.radius_outer = outer_count > 0 ? outer_sum / outer_count : 0.0;
  certificate.radius_inner = inner_count > 0 ? inner_sum / inner_count : certificate.radius_outer;
  if (association == Association::kMaximumInscribed) certificate.radius_inner = certificate.radius_outer;
  const double low = certificate.radius_inner - tolerance_mm;
  const double high = certificate.radius_outer + tolerance_mm;
  for (int i = 0; i < points.size(); ++i) {
    const double d = lp.distance(i);
    const bool outside_high = association != Association::kMaximumInscribed && d > high;
    const bool inside_low = association != Association::kMinimumCircumscribed && d < low;
    if (outside_high || inside_low) {
      certificate.why_not = fmt::format("point {} lies {:.3g} mm beyond the reference", i,
                                        outside_high ? d - high + tolerance_mm : low + tolerance_mm - d);
      return certificate;
    }
  }
  std::vector<int> columns = basis;
  std::sort(columns.begin(), columns.end(), [&](int a, int b) {
    const auto angle = [&](int column) {
      const Eigen::Vector2d& u = lp.direction(lp.PointOf(column));
      return std::atan2(u.y(), u.x());
    };
    return angle(a) < angle(b);
  });
  for (const int column : columns) {
    certificate.support.push_back(lp.PointOf(column));
    certificate.on_outer.push_back(lp.IsOuter(column));
  }
  if (lp.IsZone()) {
    for (std::size_t k = 0; k < columns.size(); ++k) {
      if (certificate.on_outer[k] == certificate.on_outer[(k + 1) % columns.size()]) {
        certificate.why_not = "the four support points do not alternate between the outer and inner circle";
        return certificate;
      }
    }
  } else if (SolveBasis(lp, basis).lambda.minCoeff() < -1e-9) {
    certificate.why_not = "the centre is not inside the triangle of the support points";
    return certificate;
  }
  certificate.certified = true;
  return certificate;
}

AssociatedCircle Failed(AssociatedCircle circle, AssociationStatus status, std::string message) {
  circle.status = status;
  circle.message = std::move(message);
  return circle;
}

void SetCentre(AssociatedCircle& circle, const Points& points, const Eigen::Vector2d& centre) {
  circle.center_x_mm = points.centroid_x + centre.x();
  circle.center_y_mm = points.centroid_y + centre.y();
}

AssociatedCircle ChebyshevCircle(const Points& points, AssociatedCircle result, const Circle& start,
                                 int max_relinearisations) {
  const double tolerance_mm = kRelativeTolerance * std::max(points.scale_mm, 1.0);
  Eigen::Vector2d centre = start.center;
  std::vector<int> basis;
  Certificate certificate;
  double last_move = std::numeric_limits<double>::infinity();
  for (int round = 0; round < max_relinearisations; ++round) {
    const LinearProgramme lp(points, result.association, centre);
    if (!lp.IsZone() && LargestAngularGap(lp) > std::numbers::pi) {
      return Failed(
          result, AssociationStatus::kNotDefined,
          fmt::format("the points leave a gap of {:.1f} deg about the centre: the {} circle is not "
                      "defined for points within half a turn (least-squares and minimum-zone are)",
                      LargestAngularGap(lp) * 180.0 / std::numbers::pi, AssociationName(result.association)));
    }
    if (basis.empty() || !SolveBasis(lp, basis).invertible ||
        SolveBasis(lp, basis).lambda.minCoeff() < -1e-9) {
      const std::optional<std::vector<int>> first = FirstBasis(lp);
      if (!first) return Failed(result, AssociationStatus::kNotCertified, "no first basis of support points");
      basis = *first;
    }
    Vector y;
    const SimplexOutcome outcome = Simplex(lp, basis, y, tolerance_mm);
    if (outcome == SimplexOutcome::kUnbounded) {
      return Failed(
          result, AssociationStatus::kNotDefined,
          fmt::format("the {} circle of these points is unbounded", AssociationName(result.association)));
    }
    if (outcome == SimplexOutcome::kStalled) {
      return Failed(result, AssociationStatus::kNotCertified, "the simplex method stalled");
    }
    const Eigen::Vector2d linearised = centre + lp.Delta(y);
    const double move = lp.Delta(y).norm();
    centre = linearised;
    // Relinearise while the centre still moves by more than rounding; then solve the support
    // points' circle exactly and check its optimality condition.
    if (move > tolerance_mm * 1e-2 && move < 0.5 * last_move) {
      last_move = move;
      continue;
    }
    centre = ExactCentre(points, lp, basis, linearised);
    certificate = Certify(points, result.association, basis, centre, tolerance_mm);
    if (certificate.certified) break;
    last_move = std::numeric_limits<double>::infinity();
  }
  if (!certificate.certified) {
    return Failed(
        result, AssociationStatus::kNotCertified,
        "optimality condition not met: " +
            (certificate.why_not.empty() ? std::string("the centre did not settle") : certificate.why_not));
  }
  SetCentre(result, points, centre);
  result.radius_inner_mm = certificate.radius_inner;
  result.radius_outer_mm = certificate.radius_outer;
  const LinearProgramme at_centre(points, result.association, centre);
  for (int i = 0; i < points.size(); ++i) {
    if (result.association != Association::kMinimumZone) {
      result.radius_inner_mm = std::min(result.radius_inner_mm, at_centre.distance(i));
      result.radius_outer_mm = std::max(result.radius_outer_mm, at_centre.distance(i));
    }
  }
  result.radius_mm = result.association == Association::kMinimumZone
                         ? 0.5 * (certificate.radius_inner + certificate.radius_outer)
                         : certificate.radius_outer;
  result.support_indices = certificate.support;
  result.support_on_outer = certificate.on_outer;
  result.status = AssociationStatus::kCertified;
  result.message = "certified by its optimality condition";
  return result;
}

}  // namespace

std::string_view AssociationName(Association association) { return Named(association).name; }

std::string_view AssociationAbbreviation(Association association) { return Named(association).abbreviation; }

std::optional<Association> ParseAssociation(std::string_view name) {
  for (const NamedAssociation& named : kAssociationNames) {
    if (named.name == name) return named.association;
  }
  return std::nullopt;
}

std::string AssociationNames() {
  return fmt::format("{}, {}, {} or {}", kAssociationNames[0].name, kAssociationNames[1].name,
                     kAssociationNames[2].name, kAssociationNames[3].name);
}

std::vector<std::string> AssociationOptions::Problems() const {
  std::vector<std::string> problems;
  if (max_relinearisations < 1) {
    problems.push_back(fmt::format("max_relinearisations = {} violates >= 1", max_relinearisations));
  }
  const int value = static_cast<int>(association);
  if (value < 0 || value >= static_cast<int>(kAssociationNames.size())) {
    problems.push_back(fmt::format("association = {} is none of {}", value, AssociationNames()));
  }
  return problems;
}

namespace {

// CircleDataProblem of points already centred (n >= 3).
std::string DataProblem(const Points& points) {
  const auto n = static_cast<std::size_t>(points.size());
  if (!(points.scale_mm > 0)) return fmt::format("all {} points coincide", n);
  // The principal direction of the points; collinear when no point leaves its line.
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (int i = 0; i < points.size(); ++i) scatter += points.at(i) * points.at(i).transpose();
  // The closed form of a 2 x 2 matrix's eigenvectors: the iterative solver's tridiagonalisation
  // compiled in seconds what this yes-or-no test does not need.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen;
  eigen.computeDirect(scatter);
  const Eigen::Vector2d normal = eigen.eigenvectors().col(0);
  double largest_offset = 0.0;
  for (int i = 0; i < points.size(); ++i)
    largest_offset = std::max(largest_offset, std::abs(points.at(i).dot(normal)));
  if (largest_offset <= kRelativeTolerance * points.scale_mm) {
    return fmt::format("all {} points lie on one line: no circle passes through them", n);
  }
  return "";
}

}  // namespace

std::string CircleDataProblem(std::span<const double> x_mm, std::span<const double> y_mm) {
  ARCWHEEL_CHECK(x_mm.size() == y_mm.size()) << x_mm.size() << " x, " << y_mm.size() << " y";
  const std::size_t n = x_mm.size();
  if (n < 3) return fmt::format("a circle needs at least 3 points, got {}", n);
  return DataProblem(CentredPoints(x_mm, y_mm));
}

AssociatedCircle AssociateCircle(std::span<const double> x_mm, std::span<const double> y_mm,
                                 const AssociationOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kAssociationStage, options.Problems());
  AssociatedCircle result;
  result.association = options.association;
  result.n = static_cast<int>(x_mm.size());
  ARCWHEEL_CHECK(x_mm.size() == y_mm.size()) << x_mm.size() << " x, " << y_mm.size() << " y";
  if (x_mm.size() < 3) return Failed(result, AssociationStatus::kDegenerate, CircleDataProblem(x_mm, y_mm));
  const Points points = CentredPoints(x_mm, y_mm);
  if (const std::string problem = DataProblem(points); !problem.empty()) {
    return Failed(result, AssociationStatus::kDegenerate, problem);
  }
  const std::optional<Circle> algebraic = AlgebraicCircle(points);
  if (!algebraic) return Failed(result, AssociationStatus::kDegenerate, "the points determine no circle");
  const Circle least_squares = GeometricCircle(points, *algebraic);
  if (options.association != Association::kLeastSquares) {
    return ChebyshevCircle(points, result, least_squares, options.max_relinearisations);
  }
  SetCentre(result, points, least_squares.center);
  result.radius_mm = least_squares.radius;
  result.radius_inner_mm = std::numeric_limits<double>::infinity();
  result.radius_outer_mm = 0.0;
  for (int i = 0; i < points.size(); ++i) {
    const double d = (points.at(i) - least_squares.center).norm();
    result.radius_inner_mm = std::min(result.radius_inner_mm, d);
    result.radius_outer_mm = std::max(result.radius_outer_mm, d);
  }
  result.status = AssociationStatus::kCertified;
  result.message = "converged";
  return result;
}

}  // namespace arcwheel::characteristics
