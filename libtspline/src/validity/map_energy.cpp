// The regularized distortion energy of a T-spline map; see map_energy.h.
#include "tspline/validity/map_energy.h"
#include "tspline/detail/quadrature.h"
#include "tspline/detail/thread_pool.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

#include <Eigen/Dense>

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
  detail::parallel_ranges(es.size(), threads, [&](std::size_t b, std::size_t e_end, int slot) {
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


SampleTerm sample_term(const Eigen::Matrix2d& J, double eps, double theta, double power, bool project) {
  constexpr double s2 = 0.70710678118654752440;  // 1 / sqrt(2)
  // Conformal (z) and anticonformal (w) coordinates of J in the orthonormal
  // basis e1..e4 of map_energy.h: vec J = E (z1, z2, w1, w2).
  const Eigen::Vector2d z(s2 * (J(0, 0) + J(1, 1)), s2 * (J(1, 0) - J(0, 1)));
  const Eigen::Vector2d w(s2 * (J(0, 0) - J(1, 1)), s2 * (J(0, 1) + J(1, 0)));
  const double P = z.squaredNorm(), Q = w.squaredNorm();
  const double D = J.determinant();  // = (P - Q) / 2, without the cancellation
  const double I = J.squaredNorm();  // = P + Q
  // t(I, D) = N / chi, N = (1 - theta) I + theta (D^2 + 1) (Garanzha et al. 2021, Eqs. 2-4);
  // chi' = chi / r, chi'' = eps^2 / (2 r^3), r = sqrt(eps^2 + D^2).
  const double r = std::sqrt(eps * eps + D * D);
  const double chi = regularized_det(D, eps);
  const double c1 = chi / r, c2 = eps * eps / (2.0 * r * r * r);
  const double N = (1.0 - theta) * I + theta * (D * D + 1.0);
  const double t = N / chi;
  const double tI = (1.0 - theta) / chi;
  const double tD = (2.0 * theta * D - t * c1) / chi;
  const double tID = -(1.0 - theta) * c1 / (chi * chi);
  const double tDD = (2.0 * theta - 4.0 * theta * D * c1 / chi - t * c2 + 2.0 * t * c1 * c1 / chi) / chi;
  // phi = t^p: phi_a = p t^(p-1) t_a, phi_ab = p t^(p-1) t_ab + p (p-1) t^(p-2) t_a t_b.
  const double tp1 = power == 1.0 ? 1.0 : std::pow(t, power - 1.0);
  const double d1 = power * tp1, d2 = power == 1.0 ? 0.0 : power * (power - 1.0) * tp1 / t;
  const double fI = d1 * tI, fD = d1 * tD;
  const double fII = d2 * tI * tI, fID = d1 * tID + d2 * tI * tD, fDD = d1 * tDD + d2 * tD * tD;
  // To (P, Q): I = P + Q, D = (P - Q) / 2.
  const double fP = fI + 0.5 * fD, fQ = fI - 0.5 * fD;
  const double fPP = fII + fID + 0.25 * fDD, fQQ = fII - fID + 0.25 * fDD, fPQ = fII - 0.25 * fDD;

  SampleTerm out;
  out.value = power == 1.0 ? t : tp1 * t;
  // Gradient: d phi / dz = 2 phi_P z, d phi / dw = 2 phi_Q w, then vec J = E (z, w).
  const Eigen::Vector2d gz = 2.0 * fP * z, gw = 2.0 * fQ * w;
  out.gradient << s2 * (gz[0] + gw[0]), s2 * (-gz[1] + gw[1]), s2 * (gz[1] + gw[1]), s2 * (gz[0] - gw[0]);

  // Eigensystem of H_zw: unit directions (any, where z or w vanishes).
  const double nz = std::sqrt(P), nw = std::sqrt(Q);
  const Eigen::Vector2d zh = nz > 0.0 ? Eigen::Vector2d(z / nz) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d wh = nw > 0.0 ? Eigen::Vector2d(w / nw) : Eigen::Vector2d(1.0, 0.0);
  const Eigen::Vector2d zp(-zh[1], zh[0]), wp(-wh[1], wh[0]);
  double lz = 2.0 * fP, lw = 2.0 * fQ;                      // twist (z-perp), flip (w-perp)
  double a = 2.0 * fP + 4.0 * fPP * P, c = 2.0 * fQ + 4.0 * fQQ * Q;  // scalings: [[a, b], [b, c]]
  double b = 4.0 * fPQ * nz * nw;                            //   on (zh, 0), (0, wh)
  if (project) {
    lz = std::max(lz, 0.0), lw = std::max(lw, 0.0);
    const double m = 0.5 * (a + c), h = std::hypot(0.5 * (a - c), b);
    const double lp = m + h, lm = m - h;
    if (lp <= 0.0) {
      a = b = c = 0.0;
    } else if (lm < 0.0) {
      // Keep the positive eigenpair only: v v^T lp, v the better conditioned
      // of the two (equivalent) eigenvector formulas.
      Eigen::Vector2d v1(b, lp - a), v2(lp - c, b);
      Eigen::Vector2d v = v1.squaredNorm() >= v2.squaredNorm() ? v1 : v2;
      const double n2 = v.squaredNorm();
      if (n2 > 0.0) {
        v /= std::sqrt(n2);
      } else {
        v = a >= c ? Eigen::Vector2d(1.0, 0.0) : Eigen::Vector2d(0.0, 1.0);
      }
      a = lp * v[0] * v[0], b = lp * v[0] * v[1], c = lp * v[1] * v[1];
    }
  }
  // H_zw in the (z1, z2, w1, w2) coordinates.
  Eigen::Matrix4d Hzw = Eigen::Matrix4d::Zero();
  Hzw.topLeftCorner<2, 2>() = lz * zp * zp.transpose() + a * zh * zh.transpose();
  Hzw.bottomRightCorner<2, 2>() = lw * wp * wp.transpose() + c * wh * wh.transpose();
  Hzw.topRightCorner<2, 2>() = b * zh * wh.transpose();
  Hzw.bottomLeftCorner<2, 2>() = Hzw.topRightCorner<2, 2>().transpose();
  Eigen::Matrix4d E;  // columns e1..e4 in vec J = (J00, J01, J10, J11)
  E << s2, 0, s2, 0,  //
      0, -s2, 0, s2,  //
      0, s2, 0, s2,   //
      s2, 0, -s2, 0;
  out.hessian = E * Hzw * E.transpose();
  return out;
}

void MapEnergy::build_hessian_pattern() const {
  HessianPattern& hp = hpattern_;
  const auto& es = extraction_.elements();
  const std::size_t nodes = free_functions_.size();
  // Node adjacency, lower part (rows i >= column j).
  std::vector<std::vector<int>> col(nodes);
  std::vector<int> fn;
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (!elements_[k].active) continue;
    fn.clear();
    for (int a : es[k].functions)
      if (variable_of_[a] >= 0) fn.push_back(variable_of_[a] / 2);
    for (int j : fn)
      for (int i : fn)
        if (i >= j) col[j].push_back(i);
  }
  for (std::vector<int>& c : col) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
  }
  // Scalar structure: columns 2j and 2j+1 both hold rows 2i, 2i+1, i in col[j].
  const Eigen::Index n = static_cast<Eigen::Index>(2 * nodes);
  std::size_t nnz = 0;
  for (const std::vector<int>& c : col) nnz += 4 * c.size();
  hp.H = Eigen::SparseMatrix<double>(n, n);
  hp.H.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  int* outer = hp.H.outerIndexPtr();
  int* inner = hp.H.innerIndexPtr();
  double* val = hp.H.valuePtr();
  std::size_t pos = 0;
  for (std::size_t j = 0; j < nodes; ++j)
    for (int d = 0; d < 2; ++d) {
      outer[2 * j + d] = static_cast<int>(pos);
      for (int i : col[j]) {
        inner[pos] = 2 * i, val[pos++] = 0.0;
        inner[pos] = 2 * i + 1, val[pos++] = 0.0;
      }
    }
  outer[n] = static_cast<int>(pos);
  // Slots per element.
  hp.slot_offset.assign(es.size() + 1, 0);
  for (std::size_t k = 0; k < es.size(); ++k) {
    const std::size_t m = es[k].functions.size();
    hp.slot_offset[k + 1] = hp.slot_offset[k] + (elements_[k].active ? m * m : 0);
  }
  hp.slots.assign(hp.slot_offset.back(), -1);
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (!elements_[k].active) continue;
    const std::vector<int>& f = es[k].functions;
    const std::size_t m = f.size();
    for (std::size_t c = 0; c < m; ++c) {
      if (variable_of_[f[c]] < 0) continue;
      const int j = variable_of_[f[c]] / 2;
      for (std::size_t r = 0; r < m; ++r) {
        if (variable_of_[f[r]] < 0) continue;
        const int i = variable_of_[f[r]] / 2;
        if (i < j) continue;
        const auto it = std::lower_bound(col[j].begin(), col[j].end(), i);
        hp.slots[hp.slot_offset[k] + r * m + c] = static_cast<int>(it - col[j].begin());
      }
    }
  }
  // Greedy colouring: elements of one colour share no free function, so that
  // they can be assembled in parallel without conflicts.
  std::vector<std::vector<int>> support(nodes);
  for (std::size_t k = 0; k < es.size(); ++k)
    if (elements_[k].active)
      for (int a : es[k].functions)
        if (variable_of_[a] >= 0) support[variable_of_[a] / 2].push_back(static_cast<int>(k));
  std::vector<int> color(es.size(), -1);
  std::vector<char> used;
  hp.colors.clear();
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (!elements_[k].active) continue;
    used.assign(hp.colors.size() + 1, 0);
    for (int a : es[k].functions)
      if (variable_of_[a] >= 0)
        for (int o : support[variable_of_[a] / 2])
          if (color[o] >= 0) used[color[o]] = 1;
    int cc = 0;
    while (used[cc]) ++cc;
    color[k] = cc;
    if (cc == static_cast<int>(hp.colors.size())) hp.colors.emplace_back();
    hp.colors[cc].push_back(static_cast<int>(k));
  }
  hp.built = true;
}

void MapEnergy::hessian(const double* xv, double eps, Eigen::SparseMatrix<double>& H, double power,
                        bool project) const {
  if (!hpattern_.built) build_hessian_pattern();
  const HessianPattern& hp = hpattern_;
  if (H.rows() != hp.H.rows() || H.nonZeros() != hp.H.nonZeros() || !H.isCompressed())
    H = hp.H;
  else
    std::fill(H.valuePtr(), H.valuePtr() + H.nonZeros(), 0.0);
  const auto& es = extraction_.elements();
  const double theta = options_.theta;
  const int* outer = H.outerIndexPtr();
  double* val = H.valuePtr();
  using Mat16 = Eigen::Matrix<double, 16, 16>;
  using MatA = Eigen::Matrix<double, 16, Eigen::Dynamic>;
  for (const std::vector<int>& group : hp.colors) {
    detail::parallel_ranges(group.size(), options_.threads, [&](std::size_t b, std::size_t e_end, int) {
      MatA A, Mxx, Mxy, Myy;
      Eigen::MatrixXd Cf, Kxx, Kxy, Kyy;
      std::vector<int> rows;
      for (std::size_t gi = b; gi < e_end; ++gi) {
        const std::size_t k = static_cast<std::size_t>(group[gi]);
        const BezierElement& e = es[k];
        const Element& d = elements_[k];
        const Pattern& pat = patterns_[d.level];
        const Eigen::Index nq = static_cast<Eigen::Index>(pat.weight.size());
        std::array<double, 16> X, Y;
        element_coefficients(k, xv, X, Y);
        A.resize(16, 2 * nq), Mxx.resize(16, 2 * nq), Mxy.resize(16, 2 * nq), Myy.resize(16, 2 * nq);
        for (Eigen::Index q = 0; q < nq; ++q) {
          const SampleJacobian s = sample_jacobian(X, Y, d.W, pat.B[q], pat.Bs[q], pat.Bt[q], d.hx, d.hy);
          Eigen::Matrix2d J;
          J << s.J00, s.J01, s.J10, s.J11;
          const SampleTerm st = sample_term(J, eps, theta, power, project);
          const Eigen::Matrix4d Hq = (pat.weight[q] * d.weight) * st.hessian;
          // J00 = as . X, J01 = at . X, J10 = as . Y, J11 = at . Y (sample_jacobian).
          const double iw = 1.0 / s.w;
          const auto& Bq = pat.B[q];
          const auto& Bs = pat.Bs[q];
          const auto& Bt = pat.Bt[q];
          for (int i = 0; i < 16; ++i) {
            A(i, 2 * q) = (Bs[i] - Bq[i] * s.ws * iw) * iw / d.hx;
            A(i, 2 * q + 1) = (Bt[i] - Bq[i] * s.wt * iw) * iw / d.hy;
          }
          Mxx.middleCols<2>(2 * q) = A.middleCols<2>(2 * q) * Hq.topLeftCorner<2, 2>();
          Mxy.middleCols<2>(2 * q) = A.middleCols<2>(2 * q) * Hq.topRightCorner<2, 2>();
          Myy.middleCols<2>(2 * q) = A.middleCols<2>(2 * q) * Hq.bottomRightCorner<2, 2>();
        }
        // Bernstein-coefficient blocks (sum over samples of A_q H_q A_q^T).
        const Mat16 Bxx = Mxx * A.transpose(), Bxy = Mxy * A.transpose(), Byy = Myy * A.transpose();
        // To the element's free control points: K = C_f B C_f^T.
        rows.clear();
        for (Eigen::Index r = 0; r < e.C.rows(); ++r)
          if (variable_of_[e.functions[r]] >= 0) rows.push_back(static_cast<int>(r));
        const Eigen::Index nf = static_cast<Eigen::Index>(rows.size());
        Cf.resize(nf, 16);
        for (Eigen::Index r = 0; r < nf; ++r) Cf.row(r) = e.C.row(rows[r]);
        Kxx.noalias() = Cf * Bxx * Cf.transpose();
        Kxy.noalias() = Cf * Bxy * Cf.transpose();
        Kyy.noalias() = Cf * Byy * Cf.transpose();
        const std::size_t m = e.functions.size();
        const int* slot = &hp.slots[hp.slot_offset[k]];
        for (Eigen::Index c = 0; c < nf; ++c) {
          const int j = variable_of_[e.functions[rows[c]]] / 2;
          for (Eigen::Index r = 0; r < nf; ++r) {
            const int sl = slot[rows[r] * m + rows[c]];
            if (sl < 0) continue;
            double* c0 = val + outer[2 * j] + 2 * sl;
            double* c1 = val + outer[2 * j + 1] + 2 * sl;
            c0[0] += Kxx(r, c);  // (x_i, x_j)
            c0[1] += Kxy(c, r);  // (y_i, x_j) = (x_j, y_i)
            c1[0] += Kxy(r, c);  // (x_i, y_j)
            c1[1] += Kyy(r, c);  // (y_i, y_j)
          }
        }
      }
    }, 8);
  }
}

double MapEnergy::max_positive_step(const double* xv, const double* dv, double a_max, double safety) const {
  const auto& es = extraction_.elements();
  // The direction's own coefficients: element_coefficients is linear, so the
  // coefficients of x + t d are X + t (X(d) - X(0)) with the fixed points in X(0).
  const std::vector<double> zero(num_variables(), 0.0);
  std::vector<double> result(static_cast<std::size_t>(std::max(1, options_.threads)), a_max);
  detail::parallel_ranges(es.size(), options_.threads, [&](std::size_t b, std::size_t e_end, int slot) {
    double best = a_max;
    for (std::size_t k = b; k < e_end; ++k) {
      const Element& d = elements_[k];
      if (!d.active) continue;
      const Pattern& pat = patterns_[d.level];
      std::array<double, 16> X, Y, DX, DY, X0, Y0;
      element_coefficients(k, xv, X, Y);
      element_coefficients(k, dv, DX, DY);
      element_coefficients(k, zero.data(), X0, Y0);
      for (int i = 0; i < 16; ++i) DX[i] -= X0[i], DY[i] -= Y0[i];
      for (std::size_t q = 0; q < pat.weight.size(); ++q) {
        const SampleJacobian s = sample_jacobian(X, Y, d.W, pat.B[q], pat.Bs[q], pat.Bt[q], d.hx, d.hy);
        const double D0 = s.J00 * s.J11 - s.J01 * s.J10;
        if (!(D0 > 0.0)) continue;
        const SampleJacobian g = sample_jacobian(DX, DY, d.W, pat.B[q], pat.Bs[q], pat.Bt[q], d.hx, d.hy);
        // det(J + t G) = D0 + t D1 + t^2 D2.
        const double D1 = s.J00 * g.J11 + g.J00 * s.J11 - s.J01 * g.J10 - g.J01 * s.J10;
        const double D2 = g.J00 * g.J11 - g.J01 * g.J10;
        // Smallest positive root, if any, by the stable quadratic formula.
        double root = std::numeric_limits<double>::infinity();
        if (D2 == 0.0) {
          if (D1 < 0.0) root = -D0 / D1;
        } else {
          const double disc = D1 * D1 - 4.0 * D2 * D0;
          if (disc >= 0.0) {
            const double sq = std::sqrt(disc);
            const double qq = -0.5 * (D1 + (D1 >= 0.0 ? sq : -sq));
            const double r1 = qq / D2, r2 = qq != 0.0 ? D0 / qq : std::numeric_limits<double>::infinity();
            for (double rt : {r1, r2})
              if (rt > 0.0) root = std::min(root, rt);
          }
        }
        best = std::min(best, safety * root);
      }
    }
    result[slot] = best;
  });
  double a = a_max;
  for (double v : result) a = std::min(a, v);
  return a;
}

}  // namespace tspline
