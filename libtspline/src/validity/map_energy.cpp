// The regularized distortion energy of a T-spline map; see map_energy.h.
#include "tspline/validity/map_energy.h"
#include "tspline/detail/quadrature.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include "tspline/validity/map_quality.h"

namespace tspline {

double regularized_det(double D, double eps) {
  const double r = std::sqrt(eps * eps + D * D);
  if (D > 0.0) return 0.5 * (D + r);
  // (D + r) / 2 = eps^2 / (2 (r - D)): no cancellation when D << 0.
  return 0.5 * eps * eps / (r - D);
}

namespace {

// Gauss-Lobatto nodes and weights on [0,1] (n = 3, 4, 5): the end points are
// nodes, so the samples include every element's corners and edges, where maps
// fold first (thin slivers along the border).
void lobatto_points_01(int n, std::vector<double>& p, std::vector<double>& w) {
  p.clear(), w.clear();
  if (n == 3) {
    p = {0.0, 0.5, 1.0};
    w = {1.0 / 6, 4.0 / 6, 1.0 / 6};
  } else if (n == 4) {
    const double a = 0.5 / std::sqrt(5.0);
    p = {0.0, 0.5 - a, 0.5 + a, 1.0};
    w = {1.0 / 12, 5.0 / 12, 5.0 / 12, 1.0 / 12};
  } else {
    const double a = 0.5 * std::sqrt(3.0 / 7.0);
    p = {0.0, 0.5 - a, 0.5, 0.5 + a, 1.0};
    w = {1.0 / 20, 49.0 / 180, 16.0 / 45, 49.0 / 180, 1.0 / 20};
  }
}

// Derivative of B_i^3 at s.
std::array<double, 4> bernstein3_derivative(double s) {
  const double r = 1.0 - s;
  return {-3.0 * r * r, 3.0 * r * r - 6.0 * s * r, 6.0 * s * r - 3.0 * s * s, 3.0 * s * s};
}

// Runs body(begin, end, slot) on `threads` contiguous ranges of [0, n).
template <class Body>
void parallel_ranges(std::size_t n, int threads, Body&& body) {
  if (threads <= 1 || n < 256) {
    body(std::size_t{0}, n, 0);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (n + threads - 1) / threads;
  for (int t = 1; t < threads; ++t) {
    const std::size_t b = std::min(n, t * chunk), e = std::min(n, (t + 1) * chunk);
    pool.emplace_back([&body, b, e, t] { body(b, e, t); });
  }
  body(0, std::min(n, chunk), 0);
  for (std::thread& th : pool) th.join();
}

}  // namespace

namespace {

// The sample's Jacobian J = dS/d(xi, eta) in normalized coordinates and what
// the gradient needs, from the element's Bernstein coefficients.
struct SampleJacobian {
  double J00, J01, J10, J11;   // [dS/dxi dS/deta], rows x, y
  double x, y, w, ws, wt;      // X and w and w's derivatives (local coordinates)
};

inline SampleJacobian sample_jacobian(const std::array<double, 16>& X, const std::array<double, 16>& Y,
                                      const std::array<double, 16>& W, const std::array<double, 16>& B,
                                      const std::array<double, 16>& Bs, const std::array<double, 16>& Bt, double hx,
                                      double hy) {
  double x = 0, y = 0, xs = 0, ys = 0, xt = 0, yt = 0, w = 0, ws = 0, wt = 0;
  for (int i = 0; i < 16; ++i) {
    x += X[i] * B[i], y += Y[i] * B[i];
    xs += X[i] * Bs[i], ys += Y[i] * Bs[i];
    xt += X[i] * Bt[i], yt += Y[i] * Bt[i];
    w += W[i] * B[i], ws += W[i] * Bs[i], wt += W[i] * Bt[i];
  }
  const double iw = 1.0 / w;
  // S = X / w: S_s = (X_s - S w_s) / w, S_t = (X_t - S w_t) / w.
  SampleJacobian r;
  r.J00 = (xs - x * iw * ws) * iw / hx;
  r.J10 = (ys - y * iw * ws) * iw / hx;
  r.J01 = (xt - x * iw * wt) * iw / hy;
  r.J11 = (yt - y * iw * wt) * iw / hy;
  r.x = x, r.y = y, r.w = w, r.ws = ws, r.wt = wt;
  return r;
}

}  // namespace

MapEnergy::MapEnergy(const TSplineMap& map, const MapEnergyOptions& opt)
    : options_(opt), extraction_(map.basis()) {
  if (!opt.lobatto && (opt.gauss < 1 || opt.gauss > 6)) throw std::invalid_argument("MapEnergy: gauss must be in [1, 6]");
  if (opt.lobatto && (opt.gauss < 3 || opt.gauss > 5))
    throw std::invalid_argument("MapEnergy: Gauss-Lobatto points per direction must be in [3, 5]");
  if (!(opt.theta >= 0.0 && opt.theta < 1.0)) throw std::invalid_argument("MapEnergy: theta must be in [0, 1)");
  if (opt.max_sample_level < 0 || opt.max_sample_level > 4)
    throw std::invalid_argument("MapEnergy: max_sample_level must be in [0, 4]");
  if (options_.threads <= 0) options_.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options_.threads = std::min(options_.threads, 16);

  // Sample patterns per level.
  std::vector<double> gp, gw;
  if (opt.lobatto)
    lobatto_points_01(opt.gauss, gp, gw);
  else
    detail::gauss_points_01(opt.gauss, gp, gw);
  for (int l = 0; l <= opt.max_sample_level; ++l) {
    Pattern p;
    const int m = 1 << l;
    const double h = 1.0 / m;
    for (int bj = 0; bj < m; ++bj)
      for (int bi = 0; bi < m; ++bi)
        for (std::size_t b = 0; b < gp.size(); ++b)
          for (std::size_t a = 0; a < gp.size(); ++a) {
            const double s = (bi + gp[a]) * h, t = (bj + gp[b]) * h;
            const std::array<double, 4> us = bernstein3(s), ut = bernstein3(t);
            const std::array<double, 4> ds = bernstein3_derivative(s), dt = bernstein3_derivative(t);
            std::array<double, 16> B, Bs, Bt;
            for (int j = 0; j < 4; ++j)
              for (int i = 0; i < 4; ++i) {
                B[i + 4 * j] = us[i] * ut[j];
                Bs[i + 4 * j] = ds[i] * ut[j];
                Bt[i + 4 * j] = us[i] * dt[j];
              }
            p.weight.push_back(gw[a] * gw[b] * h * h);
            p.B.push_back(B), p.Bs.push_back(Bs), p.Bt.push_back(Bt);
          }
    patterns_.push_back(std::move(p));
  }

  // Free functions and normalized control points.
  const TSplineBasis& basis = map.basis();
  variable_of_.assign(basis.size(), -1);
  if (!opt.movable.empty() && opt.movable.size() != basis.size())
    throw std::invalid_argument("MapEnergy: movable must have one flag per basis function");
  for (int a = 0; a < static_cast<int>(basis.size()); ++a)
    if (!touches_border(basis.function(a)) && (opt.movable.empty() || opt.movable[a])) {
      variable_of_[a] = static_cast<int>(2 * free_functions_.size());
      free_functions_.push_back(a);
    }
  const std::vector<Eigen::Vector2d>& P = map.control_points();
  Eigen::Vector2d lo = P.front(), hi = lo;
  for (const Eigen::Vector2d& p : P) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  centre_ = 0.5 * (lo + hi);
  original_ = P;

  const auto& es = extraction_.elements();
  elements_.resize(es.size());
  for (std::size_t k = 0; k < es.size(); ++k) {
    const BezierElement& e = es[k];
    Element& d = elements_[k];
    for (Eigen::Index r = 0; r < e.C.rows(); ++r)
      for (int i = 0; i < 16; ++i) d.W[i] += e.C(r, i);
    d.hx = e.hi.x() - e.lo.x();
    d.hy = e.hi.y() - e.lo.y();
    d.weight = opt.weighting == ElementWeighting::Area ? d.hx * d.hy : 1.0;
    d.active = false;
    for (int a : e.functions) d.active = d.active || variable_of_[a] >= 0;
  }

  // L^2 = area of the domain = integral of det J over the square (exact up to
  // the quadrature of the rational factor; the boundary curve is fixed, so
  // this is the area it encloses whatever the interior control points).
  L_ = 1.0;
  normalized_.resize(P.size());
  for (std::size_t a = 0; a < P.size(); ++a) normalized_[a] = P[a] - centre_;
  double area = 0.0;
  {
    // Integrate det J with area weights regardless of the weighting option.
    const Eigen::VectorXd x0 = variables(map);
    const Pattern& pat = patterns_[0];
    for (std::size_t k = 0; k < es.size(); ++k) {
      const Element& d = elements_[k];
      std::array<double, 16> X, Y;
      element_coefficients(k, x0.data(), X, Y);
      for (std::size_t q = 0; q < pat.weight.size(); ++q) {
        const SampleJacobian j = sample_jacobian(X, Y, d.W, pat.B[q], pat.Bs[q], pat.Bt[q], d.hx, d.hy);
        area += pat.weight[q] * d.hx * d.hy * (j.J00 * j.J11 - j.J01 * j.J10);
      }
    }
  }
  if (!(area > 0.0) || !std::isfinite(area))
    throw std::invalid_argument("MapEnergy: the map's domain has no positive area (boundary curve clockwise or degenerate)");
  L_ = std::sqrt(area);
  for (Eigen::Vector2d& p : normalized_) p /= L_;
}

void MapEnergy::element_coefficients(std::size_t k, const double* x, std::array<double, 16>& X,
                                     std::array<double, 16>& Y) const {
  const BezierElement& e = extraction_.elements()[k];
  X.fill(0.0), Y.fill(0.0);
  for (Eigen::Index r = 0; r < e.C.rows(); ++r) {
    const int a = e.functions[r];
    const int v = variable_of_[a];
    const double px = v >= 0 ? x[v] : normalized_[a].x();
    const double py = v >= 0 ? x[v + 1] : normalized_[a].y();
    for (int i = 0; i < 16; ++i) X[i] += px * e.C(r, i), Y[i] += py * e.C(r, i);
  }
}

Eigen::VectorXd MapEnergy::variables(const TSplineMap& map) const {
  Eigen::VectorXd x(num_variables());
  for (std::size_t i = 0; i < free_functions_.size(); ++i) {
    const Eigen::Vector2d p = (map.control_points()[free_functions_[i]] - centre_) / L_;
    x[2 * i] = p.x(), x[2 * i + 1] = p.y();
  }
  return x;
}

std::vector<Eigen::Vector2d> MapEnergy::control_points(const double* x) const {
  std::vector<Eigen::Vector2d> P(normalized_.size());
  for (std::size_t a = 0; a < P.size(); ++a) {
    const int v = variable_of_[a];
    P[a] = v >= 0 ? Eigen::Vector2d(centre_ + L_ * Eigen::Vector2d(x[v], x[v + 1])) : original_[a];
  }
  return P;
}

void MapEnergy::set_sample_level(std::size_t element, int level) {
  if (level < 0 || level > options_.max_sample_level)
    throw std::invalid_argument("MapEnergy::set_sample_level: level out of range");
  elements_[element].level = level;
}

std::size_t MapEnergy::num_samples() const {
  std::size_t n = 0;
  for (const Element& e : elements_) n += patterns_[e.level].weight.size();
  return n;
}


double MapEnergy::evaluate(const double* xv, double eps, double* gradient, std::size_t* nonpositive,
                           double power) const {
  const auto& es = extraction_.elements();
  const int threads = options_.threads;
  std::vector<double> energy(threads, 0.0);
  std::vector<std::size_t> folded(threads, 0);
  std::vector<std::vector<double>> grads(gradient ? threads - 1 : 0, std::vector<double>(num_variables(), 0.0));
  if (gradient) std::fill(gradient, gradient + num_variables(), 0.0);
  const double theta = options_.theta;
  parallel_ranges(es.size(), threads, [&](std::size_t b, std::size_t e_end, int slot) {
    double* g = gradient ? (slot == 0 ? gradient : grads[slot - 1].data()) : nullptr;
    double F = 0.0;
    std::size_t nonpos = 0;
    for (std::size_t k = b; k < e_end; ++k) {
      const BezierElement& e = es[k];
      const Element& d = elements_[k];
      if (!d.active) continue;
      const Pattern& pat = patterns_[d.level];
      const Eigen::Index nf = e.C.rows();
      std::array<double, 16> X, Y;
      element_coefficients(k, xv, X, Y);
      std::array<double, 16> GX{}, GY{};
      for (std::size_t q = 0; q < pat.weight.size(); ++q) {
        const SampleJacobian s = sample_jacobian(X, Y, d.W, pat.B[q], pat.Bs[q], pat.Bt[q], d.hx, d.hy);
        const double omega = pat.weight[q] * d.weight;
        const double D = s.J00 * s.J11 - s.J01 * s.J10;
        const double n2 = s.J00 * s.J00 + s.J01 * s.J01 + s.J10 * s.J10 + s.J11 * s.J11;
        nonpos += !(D > 0.0);
        const double r = std::sqrt(eps * eps + D * D);
        const double c1 = regularized_det(D, eps);
        const double c2 = c1 / r;  // d chi / dD = (1 + D / r) / 2 = chi / r
        const double f = n2 / c1, gA = (1.0 + D * D) / c1;
        const double term = (1.0 - theta) * f + theta * gA;
        // With a power p: omega term^p, so dE = p term^(p-1) omega d(term).
        const double tp = power == 1.0 ? term : power == 4.0 ? (term * term) * (term * term) : std::pow(term, power);
        F += omega * tp;
        if (!g) continue;
        const double chain = power == 1.0 ? 1.0 : power * tp / term;
        // dE/dJ = omega [(1-theta) (2 J - f c2 cof J) + theta (2 D - g c2) cof J] / c1,
        // cof J = dD/dJ = [[J11, -J10], [-J01, J00]].
        const double a1 = chain * omega * (1.0 - theta) * 2.0 / c1;
        const double a2 = chain * omega * ((theta * (2.0 * D - gA * c2)) - (1.0 - theta) * f * c2) / c1;
        const double G00 = a1 * s.J00 + a2 * s.J11, G01 = a1 * s.J01 - a2 * s.J10;
        const double G10 = a1 * s.J10 - a2 * s.J01, G11 = a1 * s.J11 + a2 * s.J00;
        // Back to dS/ds (= J col 0 * hx) and dS/dt, then to X, X_s, X_t.
        const double iw = 1.0 / s.w;
        const double gsx = G00 / d.hx * iw, gsy = G10 / d.hx * iw;  // dE/dX_s
        const double gtx = G01 / d.hy * iw, gty = G11 / d.hy * iw;  // dE/dX_t
        const double gx = -(gsx * s.ws + gtx * s.wt) * iw, gy = -(gsy * s.ws + gty * s.wt) * iw;  // dE/dX
        const auto& B = pat.B[q];
        const auto& Bs = pat.Bs[q];
        const auto& Bt = pat.Bt[q];
        for (int i = 0; i < 16; ++i) {
          GX[i] += gx * B[i] + gsx * Bs[i] + gtx * Bt[i];
          GY[i] += gy * B[i] + gsy * Bs[i] + gty * Bt[i];
        }
      }
      if (!g) continue;
      for (Eigen::Index r = 0; r < nf; ++r) {
        const int v = variable_of_[e.functions[r]];
        if (v < 0) continue;
        double sx = 0.0, sy = 0.0;
        for (int i = 0; i < 16; ++i) sx += e.C(r, i) * GX[i], sy += e.C(r, i) * GY[i];
        g[v] += sx, g[v + 1] += sy;
      }
    }
    energy[slot] = F;
    folded[slot] = nonpos;
  });
  if (nonpositive) {
    *nonpositive = 0;
    for (std::size_t v : folded) *nonpositive += v;
  }
  double E = 0.0;
  for (double v : energy) E += v;
  for (const auto& gl : grads)
    for (std::size_t i = 0; i < gl.size(); ++i) gradient[i] += gl[i];
  return E;
}

SampleStats MapEnergy::stats(const double* xv) const {
  const auto& es = extraction_.elements();
  SampleStats st;
  st.min_det = std::numeric_limits<double>::infinity();
  st.min_mean_ratio = std::numeric_limits<double>::infinity();
  double wsum = 0.0, jsum = 0.0;
  for (std::size_t k = 0; k < es.size(); ++k) {
    const Element& d = elements_[k];
    if (!d.active) continue;
    const Pattern& pat = patterns_[d.level];
    std::array<double, 16> X, Y;
    element_coefficients(k, xv, X, Y);
    for (std::size_t q = 0; q < pat.weight.size(); ++q) {
      const SampleJacobian s = sample_jacobian(X, Y, d.W, pat.B[q], pat.Bs[q], pat.Bt[q], d.hx, d.hy);
      const double D = s.J00 * s.J11 - s.J01 * s.J10;
      const double n2 = s.J00 * s.J00 + s.J01 * s.J01 + s.J10 * s.J10 + s.J11 * s.J11;
      const double jr = n2 > 0.0 ? 2.0 * D / n2 : 0.0;
      ++st.points;
      if (!(D > 0.0)) ++st.nonpositive;
      st.min_det = std::min(st.min_det, D);
      st.min_mean_ratio = std::min(st.min_mean_ratio, jr);
      const double omega = pat.weight[q] * d.weight;
      wsum += omega, jsum += omega * jr;
    }
  }
  st.mean_mean_ratio = wsum > 0.0 ? jsum / wsum : 0.0;
  return st;
}

}  // namespace tspline
