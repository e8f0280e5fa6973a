#include "surfaces/surface.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "core/error.h"

namespace arcwheel::surfaces {
namespace {

constexpr const char* kSurfaceStage = "grinding.surface";
constexpr int kMaxEvenTerms = 9;  // A4 .. A20

// Slopes of the clamped cubic spline through equally spaced values; the end slopes are those of
// the cubic through the four end values, so cubic data are reproduced exactly.
std::vector<double> SplineSlopes(const std::vector<double>& f, double h) {
  const size_t n = f.size();
  std::vector<double> m(n, 0.0);
  m[0] = (-11.0 * f[0] + 18.0 * f[1] - 9.0 * f[2] + 2.0 * f[3]) / (6.0 * h);
  m[n - 1] = (11.0 * f[n - 1] - 18.0 * f[n - 2] + 9.0 * f[n - 3] - 2.0 * f[n - 4]) / (6.0 * h);
  // Thomas algorithm on m[i-1] + 4 m[i] + m[i+1] = 3 (f[i+1] - f[i-1]) / h, i = 1 .. n-2.
  const size_t interior = n - 2;
  std::vector<double> diag(interior, 4.0);
  std::vector<double> rhs(interior);
  for (size_t k = 0; k < interior; ++k) rhs[k] = 3.0 * (f[k + 2] - f[k]) / h;
  rhs[0] -= m[0];
  rhs[interior - 1] -= m[n - 1];
  for (size_t k = 1; k < interior; ++k) {
    const double w = 1.0 / diag[k - 1];
    diag[k] -= w;
    rhs[k] -= w * rhs[k - 1];
  }
  m[interior] = rhs[interior - 1] / diag[interior - 1];
  for (size_t k = interior - 1; k-- > 0;) m[k + 1] = (rhs[k] - m[k + 2]) / diag[k];
  return m;
}

// Cubic Hermite basis on [0, 1] and its first two derivatives with respect to t:
// [value at 0, value at 1, slope at 0, slope at 1].
struct HermiteBasis {
  std::array<double, 4> b, d1, d2;
};
HermiteBasis Hermite(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {{2 * t3 - 3 * t2 + 1, -2 * t3 + 3 * t2, t3 - 2 * t2 + t, t3 - t2},
          {6 * t2 - 6 * t, -6 * t2 + 6 * t, 3 * t2 - 4 * t + 1, 3 * t2 - 2 * t},
          {12 * t - 6, -12 * t + 6, 6 * t - 4, 6 * t - 2}};
}

}  // namespace

// ---------------------------------------------------------------------------------------------
EvenAsphere::EvenAsphere(const EvenAsphereParameters& parameters) : parameters_(parameters) {
  if (!(parameters.vertex_radius_mm > 0.0) || !std::isfinite(parameters.vertex_radius_mm)) {
    throw Error(
        ErrorCode::kBadInput, kSurfaceStage,
        fmt::format("vertex_radius_mm = {} must be a finite number > 0", parameters.vertex_radius_mm));
  }
  if (parameters.even_coefficients.size() > kMaxEvenTerms) {
    throw Error(ErrorCode::kBadInput, kSurfaceStage,
                fmt::format("{} even coefficients given; at most {} (A4 .. A20)",
                            parameters.even_coefficients.size(), kMaxEvenTerms));
  }
  curvature_per_mm_ = 1.0 / parameters.vertex_radius_mm;
  sign_ = parameters.concave ? 1.0 : -1.0;
  sag_at_origin_mm_ = 0.0;
  if (!InDomain(0.0, 0.0)) {
    throw Error(ErrorCode::kBadInput, kSurfaceStage,
                fmt::format("off-axis origin ({}, {}) mm lies outside the asphere's domain",
                            parameters.off_axis_x_mm, parameters.off_axis_y_mm));
  }
  const double x0 = parameters.off_axis_x_mm, y0 = parameters.off_axis_y_mm;
  sag_at_origin_mm_ = SagOfRadiusSquared(x0 * x0 + y0 * y0).sag_mm;
}

EvenAsphere::SagOfU EvenAsphere::SagOfRadiusSquared(double u) const {
  const double c = curvature_per_mm_;
  const double conic_factor = 1.0 + parameters_.conic;
  const double q = std::sqrt(1.0 - conic_factor * c * c * u);
  // c u / (1 + q) avoids the cancellation of (1 - q) / ((1 + k) c) and holds for k = -1.
  SagOfU s{c * u / (1.0 + q), c / (2.0 * q), conic_factor * c * c * c / (4.0 * q * q * q)};
  const std::vector<double>& a = parameters_.even_coefficients;
  // Horner in u for sum_i A_2i u^i (i = 2 .. 10) and its derivatives.
  double p = 0.0, dp = 0.0, d2p = 0.0;
  for (size_t m = a.size(); m-- > 0;) {
    const double i = static_cast<double>(m + 2);
    p = p * u + a[m];
    dp = dp * u + i * a[m];
    d2p = d2p * u + i * (i - 1.0) * a[m];
  }
  // p holds sum A u^(i-2), dp sum i A u^(i-2), d2p sum i(i-1) A u^(i-2).
  s.sag_mm += p * u * u;
  s.dsag_du += dp * u;
  s.d2sag_du2 += d2p;
  return s;
}

SurfacePoint EvenAsphere::Evaluate(double x_mm, double y_mm) const {
  const double px = x_mm + parameters_.off_axis_x_mm;
  const double py = y_mm + parameters_.off_axis_y_mm;
  const SagOfU s = SagOfRadiusSquared(px * px + py * py);
  // Chain rule through u = X^2 + Y^2.
  SurfacePoint p;
  p.z_mm = sign_ * (s.sag_mm - sag_at_origin_mm_);
  p.fx = sign_ * 2.0 * px * s.dsag_du;
  p.fy = sign_ * 2.0 * py * s.dsag_du;
  p.fxx_per_mm = sign_ * (2.0 * s.dsag_du + 4.0 * px * px * s.d2sag_du2);
  p.fxy_per_mm = sign_ * 4.0 * px * py * s.d2sag_du2;
  p.fyy_per_mm = sign_ * (2.0 * s.dsag_du + 4.0 * py * py * s.d2sag_du2);
  return p;
}

bool EvenAsphere::InDomain(double x_mm, double y_mm) const {
  const double px = x_mm + parameters_.off_axis_x_mm;
  const double py = y_mm + parameters_.off_axis_y_mm;
  const double c = curvature_per_mm_;
  return 1.0 - (1.0 + parameters_.conic) * c * c * (px * px + py * py) > 0.0;
}

std::string EvenAsphere::Describe() const {
  std::string text =
      fmt::format("even asphere, {}, R0 = {} mm, k = {}, local origin at ({}, {}) mm off the parent axis",
                  parameters_.concave ? "concave" : "convex", parameters_.vertex_radius_mm, parameters_.conic,
                  parameters_.off_axis_x_mm, parameters_.off_axis_y_mm);
  for (size_t m = 0; m < parameters_.even_coefficients.size(); ++m) {
    if (parameters_.even_coefficients[m] != 0.0) {
      text += fmt::format(", A{} = {}", 2 * m + 4, parameters_.even_coefficients[m]);
    }
  }
  return text;
}

// ---------------------------------------------------------------------------------------------
XyPolynomial::XyPolynomial(std::vector<XyPolynomialTerm> terms) : terms_(std::move(terms)) {
  for (const XyPolynomialTerm& t : terms_) {
    if (t.x_power < 0 || t.y_power < 0 || t.x_power > 20 || t.y_power > 20) {
      throw Error(ErrorCode::kBadInput, kSurfaceStage,
                  fmt::format("term x^{} y^{}: powers must be within 0 .. 20", t.x_power, t.y_power));
    }
    max_x_power_ = std::max(max_x_power_, t.x_power);
    max_y_power_ = std::max(max_y_power_, t.y_power);
  }
}

SurfacePoint XyPolynomial::Evaluate(double x_mm, double y_mm) const {
  // Powers x^0 .. x^max once, then each term and its derivatives from them.
  std::array<double, 21> xp{}, yp{};
  xp[0] = yp[0] = 1.0;
  for (int i = 1; i <= max_x_power_; ++i) xp[i] = xp[i - 1] * x_mm;
  for (int j = 1; j <= max_y_power_; ++j) yp[j] = yp[j - 1] * y_mm;
  SurfacePoint p;
  for (const XyPolynomialTerm& t : terms_) {
    const int i = t.x_power, j = t.y_power;
    const double c = t.coefficient;
    p.z_mm += c * xp[i] * yp[j];
    if (i >= 1) p.fx += c * i * xp[i - 1] * yp[j];
    if (j >= 1) p.fy += c * j * xp[i] * yp[j - 1];
    if (i >= 2) p.fxx_per_mm += c * i * (i - 1) * xp[i - 2] * yp[j];
    if (i >= 1 && j >= 1) p.fxy_per_mm += c * i * j * xp[i - 1] * yp[j - 1];
    if (j >= 2) p.fyy_per_mm += c * j * (j - 1) * xp[i] * yp[j - 2];
  }
  return p;
}

std::string XyPolynomial::Describe() const {
  std::string text = "XY polynomial, z =";
  for (const XyPolynomialTerm& t : terms_) {
    text += fmt::format(" + {} x^{} y^{}", t.coefficient, t.x_power, t.y_power);
  }
  return text;
}

// ---------------------------------------------------------------------------------------------
HeightGrid::HeightGrid(HeightGridParameters parameters) : p_(std::move(parameters)) {
  if (p_.grid.nx < 4 || p_.grid.ny < 4) {
    throw Error(ErrorCode::kBadInput, kSurfaceStage,
                fmt::format("height grid of {} x {} nodes: at least 4 x 4 needed", p_.grid.nx, p_.grid.ny));
  }
  if (!(p_.grid.dx_mm > 0.0) || !(p_.grid.dy_mm > 0.0)) {
    throw Error(ErrorCode::kBadInput, kSurfaceStage,
                fmt::format("height grid spacing ({}, {}) mm must be > 0", p_.grid.dx_mm, p_.grid.dy_mm));
  }
  const size_t nx = static_cast<size_t>(p_.grid.nx), ny = static_cast<size_t>(p_.grid.ny);
  if (p_.heights_mm.size() != nx * ny) {
    throw Error(ErrorCode::kBadInput, kSurfaceStage,
                fmt::format("height grid holds {} heights, {} x {} = {} expected", p_.heights_mm.size(), nx,
                            ny, nx * ny));
  }
  for (size_t k = 0; k < p_.heights_mm.size(); ++k) {
    if (!std::isfinite(p_.heights_mm[k])) {
      throw Error(ErrorCode::kBadInput, kSurfaceStage,
                  fmt::format("height at node (i = {}, j = {}) is not finite", k % nx, k / nx));
    }
  }
  slope_x_.resize(nx * ny);
  slope_y_.resize(nx * ny);
  slope_xy_.resize(nx * ny);
  std::vector<double> line;
  for (size_t j = 0; j < ny; ++j) {
    line.assign(p_.heights_mm.begin() + static_cast<std::ptrdiff_t>(j * nx),
                p_.heights_mm.begin() + static_cast<std::ptrdiff_t>((j + 1) * nx));
    const std::vector<double> m = SplineSlopes(line, p_.grid.dx_mm);
    std::copy(m.begin(), m.end(), slope_x_.begin() + static_cast<std::ptrdiff_t>(j * nx));
  }
  line.resize(ny);
  for (size_t i = 0; i < nx; ++i) {
    for (size_t j = 0; j < ny; ++j) line[j] = p_.heights_mm[j * nx + i];
    const std::vector<double> my = SplineSlopes(line, p_.grid.dy_mm);
    for (size_t j = 0; j < ny; ++j) line[j] = slope_x_[j * nx + i];
    const std::vector<double> mxy = SplineSlopes(line, p_.grid.dy_mm);
    for (size_t j = 0; j < ny; ++j) {
      slope_y_[j * nx + i] = my[j];
      slope_xy_[j * nx + i] = mxy[j];
    }
  }
}

bool HeightGrid::InDomain(double x_mm, double y_mm) const {
  const double x_end = p_.grid.x0_mm + (p_.grid.nx - 1) * p_.grid.dx_mm;
  const double y_end = p_.grid.y0_mm + (p_.grid.ny - 1) * p_.grid.dy_mm;
  return x_mm >= p_.grid.x0_mm && x_mm <= x_end && y_mm >= p_.grid.y0_mm && y_mm <= y_end;
}

SurfacePoint HeightGrid::Evaluate(double x_mm, double y_mm) const {
  const double gx = (x_mm - p_.grid.x0_mm) / p_.grid.dx_mm;
  const double gy = (y_mm - p_.grid.y0_mm) / p_.grid.dy_mm;
  const int i = std::clamp(static_cast<int>(std::floor(gx)), 0, p_.grid.nx - 2);
  const int j = std::clamp(static_cast<int>(std::floor(gy)), 0, p_.grid.ny - 2);
  const HermiteBasis bx = Hermite(gx - i);
  const HermiteBasis by = Hermite(gy - j);
  const double hx = p_.grid.dx_mm, hy = p_.grid.dy_mm;
  SurfacePoint p;
  // Corner a (0 or 1) in x and b in y; Hermite slots: 0/1 values, 2/3 slopes.
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const size_t k = static_cast<size_t>((j + b) * p_.grid.nx + (i + a));
      const double v = p_.heights_mm[k], sx = slope_x_[k] * hx, sy = slope_y_[k] * hy,
                   sxy = slope_xy_[k] * hx * hy;
      const auto combine = [&](const std::array<double, 4>& ux, const std::array<double, 4>& uy) {
        return v * ux[a] * uy[b] + sx * ux[2 + a] * uy[b] + sy * ux[a] * uy[2 + b] +
               sxy * ux[2 + a] * uy[2 + b];
      };
      p.z_mm += combine(bx.b, by.b);
      p.fx += combine(bx.d1, by.b) / hx;
      p.fy += combine(bx.b, by.d1) / hy;
      p.fxx_per_mm += combine(bx.d2, by.b) / (hx * hx);
      p.fxy_per_mm += combine(bx.d1, by.d1) / (hx * hy);
      p.fyy_per_mm += combine(bx.b, by.d2) / (hy * hy);
    }
  }
  return p;
}

std::string HeightGrid::Describe() const {
  return fmt::format("height grid, {} x {} nodes from ({}, {}) mm, spacing ({}, {}) mm, bicubic spline",
                     p_.grid.nx, p_.grid.ny, p_.grid.x0_mm, p_.grid.y0_mm, p_.grid.dx_mm, p_.grid.dy_mm);
}

// ---------------------------------------------------------------------------------------------
double Aperture::HalfX() const { return shape == Shape::kCircle ? diameter_mm / 2.0 : width_x_mm / 2.0; }
double Aperture::HalfY() const { return shape == Shape::kCircle ? diameter_mm / 2.0 : width_y_mm / 2.0; }
bool Aperture::Contains(double x_mm, double y_mm) const {
  if (shape == Shape::kCircle) return std::hypot(x_mm, y_mm) <= diameter_mm / 2.0;
  return std::abs(x_mm) <= HalfX() && std::abs(y_mm) <= HalfY();
}
double Aperture::HalfChordAt(double y_mm) const {
  // Rows are laid over the rectangle's whole y range; a row whose middle contact strays a hair
  // past the edge still grinds the full width.
  if (shape == Shape::kRectangle) return HalfX();
  const double r = diameter_mm / 2.0;
  return std::abs(y_mm) < r ? std::sqrt(r * r - y_mm * y_mm) : 0.0;
}
std::string Aperture::Describe() const {
  if (shape == Shape::kCircle) return fmt::format("circular aperture, diameter {} mm", diameter_mm);
  return fmt::format("rectangular aperture {} x {} mm", width_x_mm, width_y_mm);
}

void CheckApertureInDomain(const Surface& surface, const Aperture& aperture, double margin_x_mm,
                           double margin_y_mm) {
  // The domains we have are convex (a disc, a rectangle, the plane): a fine grid over the grown
  // aperture's bounding box, clipped to the grown aperture, finds any point off them.
  constexpr int kSamples = 64;
  const double hx = aperture.HalfX() + margin_x_mm, hy = aperture.HalfY() + margin_y_mm;
  for (int j = 0; j <= kSamples; ++j) {
    for (int i = 0; i <= kSamples; ++i) {
      const double x = -hx + 2.0 * hx * i / kSamples, y = -hy + 2.0 * hy * j / kSamples;
      if (aperture.shape == Aperture::Shape::kCircle && std::hypot(x / hx, y / hy) > 1.0) continue;
      if (!surface.InDomain(x, y)) {
        throw Error(ErrorCode::kBadInput, kSurfaceStage,
                    fmt::format("point ({:.3f}, {:.3f}) mm of the {} (with {} / {} mm lead and "
                                "reach margins) lies outside the surface's domain ({})",
                                x, y, aperture.Describe(), margin_x_mm, margin_y_mm, surface.Describe()));
      }
    }
  }
}

}  // namespace arcwheel::surfaces
