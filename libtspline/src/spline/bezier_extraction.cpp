// Bezier extraction of the cubic T-spline basis; see bezier_extraction.h.
#include "tspline/spline/bezier_extraction.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <utility>
#include <vector>

#include "tspline/detail/quadrature.h"
#include "tspline/validity/map_quality.h"

namespace tspline {

namespace {

// Interpolation nodes inside (0, 1) for the univariate conversion: a cubic is
// determined by 4 values; interior nodes avoid evaluating a B-spline exactly on
// a knot, where cubic_bspline takes the right-hand piece.
constexpr double kNodes[4] = {0.125, 0.375, 0.625, 0.875};

// Inverse of the Bernstein collocation matrix M(r, i) = B_i^3(kNodes[r]);
// its condition number is about 13, so the conversion loses < 2 digits.
const Eigen::Matrix4d& collocation_inverse() {
  static const Eigen::Matrix4d inv = [] {
    Eigen::Matrix4d M;
    for (int r = 0; r < 4; ++r) {
      const std::array<double, 4> b = bernstein3(kNodes[r]);
      for (int i = 0; i < 4; ++i) M(r, i) = b[i];
    }
    return Eigen::Matrix4d(M.inverse());
  }();
  return inv;
}

void add_breaks(const std::array<double, 5>& knots, double lo, double hi, std::vector<double>& out) {
  for (double k : knots)
    if (k > lo && k < hi) out.push_back(k);
}

void sort_unique(std::vector<double>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

}  // namespace

std::array<double, 4> bernstein3(double s) {
  const double r = 1.0 - s;
  return {r * r * r, 3.0 * s * r * r, 3.0 * s * s * r, s * s * s};
}

std::array<double, 4> bspline_bernstein(const std::array<double, 5>& knots, double a, double b) {
  const Eigen::Matrix4d& inv = collocation_inverse();
  Eigen::Vector4d v;
  for (int r = 0; r < 4; ++r) v[r] = cubic_bspline(knots, a + kNodes[r] * (b - a));
  const Eigen::Vector4d c = inv * v;
  return {c[0], c[1], c[2], c[3]};
}

void cell_element_breaks(const TSplineBasis& basis, int c, std::vector<double>& xb, std::vector<double>& yb) {
  const Eigen::Vector2d lo = basis.mesh().cell_min(c), hi = basis.mesh().cell_max(c);
  xb.assign({lo.x(), hi.x()});
  yb.assign({lo.y(), hi.y()});
  // Knots are exact dyadic doubles (integer coordinate / 2^30), so equal knot
  // lines compare equal.
  for (int a : basis.functions_on_cell(c)) {
    const BlendingFunction& f = basis.function(a);
    add_breaks(f.knots_xi, lo.x(), hi.x(), xb);
    add_breaks(f.knots_eta, lo.y(), hi.y(), yb);
  }
  sort_unique(xb);
  sort_unique(yb);
}

namespace {

// The univariate Bernstein coefficients (bspline_bernstein) of the knot
// vectors met in one extraction, by knot vector and interval: the cells of a
// column share their intervals and most of their knot vectors, so each pair
// is computed once per extraction instead of once per element (a third of
// the extraction's time). Values are those bspline_bernstein gives.
class UnivariateCache {
 public:
  using Knots = std::array<double, 5>;

  // (The reference holds until the next call.)
  const std::array<double, 4>& get(const Knots& k, double a, double b) {
    if (4 * (used_ + 1) > 3 * slots_.size()) grow();
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(k, a, b) & mask;; i = (i + 1) & mask) {
      Slot& s = slots_[i];
      if (!s.full) {
        s = {k, a, b, bspline_bernstein(k, a, b), true};
        ++used_;
        return s.value;
      }
      if (s.knots == k && s.a == a && s.b == b) return s.value;
    }
  }

 private:
  struct Slot {
    Knots knots;
    double a, b;
    std::array<double, 4> value;
    bool full;
  };

  static std::size_t hash(const Knots& k, double a, double b) {
    std::uint64_t h = 0x9e3779b97f4a7c15ULL;
    auto mix = [&h](double v) {
      h ^= std::bit_cast<std::uint64_t>(v) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    };
    for (const double v : k) mix(v);
    mix(a);
    mix(b);
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    return static_cast<std::size_t>(h);
  }

  void grow() {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(std::max<std::size_t>(64, 2 * old.size()), Slot{});
    used_ = 0;
    const std::size_t mask = slots_.size() - 1;
    for (const Slot& s : old) {
      if (!s.full) continue;
      std::size_t i = hash(s.knots, s.a, s.b) & mask;
      while (slots_[i].full) i = (i + 1) & mask;
      slots_[i] = s;
      ++used_;
    }
  }

  std::vector<Slot> slots_;
  std::size_t used_ = 0;
};

// The Bezier elements of cell c appended to out (extract_cell).
void extract_cell_into(const TSplineBasis& basis, int c, UnivariateCache& cache, std::vector<double>& xb,
                       std::vector<double>& yb, std::vector<BezierElement>& out) {
  cell_element_breaks(basis, c, xb, yb);
  const std::vector<int>& fs = basis.functions_on_cell(c);
  for (std::size_t j = 0; j + 1 < yb.size(); ++j)
    for (std::size_t i = 0; i + 1 < xb.size(); ++i) {
      BezierElement e;
      e.cell = c;
      e.lo = {xb[i], yb[j]};
      e.hi = {xb[i + 1], yb[j + 1]};
      e.functions.reserve(fs.size());
      for (int a : fs) {
        const BlendingFunction& f = basis.function(a);
        // Open support (k0, k4) x (l0, l4) meets the open element.
        if (f.knots_xi[0] < e.hi.x() && f.knots_xi[4] > e.lo.x() && f.knots_eta[0] < e.hi.y() &&
            f.knots_eta[4] > e.lo.y())
          e.functions.push_back(a);
      }
      e.C.resize(static_cast<Eigen::Index>(e.functions.size()), 16);
      for (std::size_t r = 0; r < e.functions.size(); ++r) {
        const BlendingFunction& f = basis.function(e.functions[r]);
        // Tensor product: the coefficients are products of the univariate ones.
        const std::array<double, 4> bx = cache.get(f.knots_xi, e.lo.x(), e.hi.x());
        const std::array<double, 4> by = cache.get(f.knots_eta, e.lo.y(), e.hi.y());
        for (int q = 0; q < 4; ++q)
          for (int p = 0; p < 4; ++p) e.C(static_cast<Eigen::Index>(r), p + 4 * q) = bx[p] * by[q];
      }
      out.push_back(std::move(e));
    }
}

}  // namespace

std::vector<BezierElement> extract_cell(const TSplineBasis& basis, int c) {
  UnivariateCache cache;
  std::vector<double> xb, yb;
  std::vector<BezierElement> out;
  extract_cell_into(basis, c, cache, xb, yb, out);
  return out;
}

namespace {

/// Adds the breaks of the geometry's cell g strictly inside [lo, hi].
void add_geometry_breaks(const TSplineBasis& geometry, int g, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                         std::vector<double>& xb, std::vector<double>& yb) {
  thread_local std::vector<double> gx, gy;
  cell_element_breaks(geometry, g, gx, gy);
  for (double x : gx)
    if (x > lo.x() && x < hi.x()) xb.push_back(x);
  for (double y : gy)
    if (y > lo.y() && y < hi.y()) yb.push_back(y);
  sort_unique(xb);
  sort_unique(yb);
}

void tensor_gauss(const std::vector<double>& xb, const std::vector<double>& yb, int n,
                  std::vector<QuadraturePoint>& out) {
  thread_local std::vector<double> gp, gw;
  detail::gauss_points_01(n, gp, gw);
  out.clear();
  out.reserve((xb.size() - 1) * (yb.size() - 1) * gp.size() * gp.size());
  for (std::size_t j = 0; j + 1 < yb.size(); ++j)
    for (std::size_t i = 0; i + 1 < xb.size(); ++i) {
      const double hx = xb[i + 1] - xb[i], hy = yb[j + 1] - yb[j];
      for (std::size_t b = 0; b < gp.size(); ++b)
        for (std::size_t a = 0; a < gp.size(); ++a)
          out.push_back({{xb[i] + gp[a] * hx, yb[j] + gp[b] * hy}, gw[a] * gw[b] * hx * hy});
    }
}

}  // namespace

void cell_quadrature(const TSplineBasis& basis, int c, int n, std::vector<QuadraturePoint>& out,
                     const TSplineBasis* geometry, int g) {
  std::vector<double> xb, yb;
  cell_element_breaks(basis, c, xb, yb);
  if (geometry) add_geometry_breaks(*geometry, g, basis.mesh().cell_min(c), basis.mesh().cell_max(c), xb, yb);
  tensor_gauss(xb, yb, n, out);
}

void box_quadrature(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int n, std::vector<QuadraturePoint>& out,
                    const TSplineBasis& geometry, int g) {
  thread_local std::vector<double> xb, yb;
  xb.assign({lo.x(), hi.x()});
  yb.assign({lo.y(), hi.y()});
  add_geometry_breaks(geometry, g, lo, hi, xb, yb);
  tensor_gauss(xb, yb, n, out);
}

BezierExtraction::BezierExtraction(const TSplineBasis& basis) {
  const int nc = static_cast<int>(basis.mesh().num_cells());
  cell_begin_.reserve(nc + 1);
  elements_.reserve(static_cast<std::size_t>(nc));
  UnivariateCache cache;
  std::vector<double> xb, yb;
  for (int c = 0; c < nc; ++c) {
    cell_begin_.push_back(elements_.size());
    extract_cell_into(basis, c, cache, xb, yb, elements_);
  }
  cell_begin_.push_back(elements_.size());
}

Eigen::Matrix<double, 16, 3> homogeneous_bezier_points(const BezierElement& e,
                                                       const std::vector<Eigen::Vector2d>& P) {
  Eigen::Matrix<double, 16, 3> H = Eigen::Matrix<double, 16, 3>::Zero();
  for (std::size_t r = 0; r < e.functions.size(); ++r) {
    const Eigen::Vector2d& p = P[e.functions[r]];
    H += e.C.row(static_cast<Eigen::Index>(r)).transpose() * Eigen::RowVector3d(p.x(), p.y(), 1.0);
  }
  return H;
}

}  // namespace tspline
