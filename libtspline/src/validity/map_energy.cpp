// The regularized distortion energy of a T-spline map; see map_energy.h.
#include "tspline/validity/map_energy.h"
#include "tspline/detail/quadrature.h"
#include "tspline/detail/simd_clones.h"
#include "tspline/detail/thread_pool.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>
#include "toolkit/errors.h"

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

// The sample terms of evaluate() on one element, point by point over arrays
// (branch-free, so that the compiler vectorizes the loop). Writes each
// sample's weighted term omega_q t_q^p into `term`, and with Grad the
// derivative of that with respect to J into G00..G11 (which may alias nothing
// read later). Returns the number of samples with det J <= 0.
enum class Power { One, Four, Eight, Other };

template <Power P, bool Grad>
std::size_t sample_terms(std::size_t n, const double* __restrict J00, const double* __restrict J01,
                         const double* __restrict J10, const double* __restrict J11, const double* __restrict weight,
                         double element_weight, double eps, double theta, double power, double* __restrict term,
                         double* __restrict G00, double* __restrict G01, double* __restrict G10,
                         double* __restrict G11) {
  const double e2 = eps * eps, ie2 = 1.0 / e2;
  std::size_t nonpos = 0;
  for (std::size_t q = 0; q < n; ++q) {
    const double j00 = J00[q], j01 = J01[q], j10 = J10[q], j11 = J11[q];
    const double omega = weight[q] * element_weight;
    const double D = j00 * j11 - j01 * j10;
    const double n2 = j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11;
    nonpos += static_cast<std::size_t>(!(D > 0.0));
    const double r = std::sqrt(e2 + D * D);
    const double ir = 1.0 / r;
    // 1 / chi = 2 / (D + r) = 2 (r - D) / eps^2 (regularized_det), each form
    // where it has no cancellation; both computed (a select, no branch).
    const double ic1_pos = 2.0 / (D + r), ic1_neg = 2.0 * (r - D) * ie2;
    const double ic1 = D > 0.0 ? ic1_pos : ic1_neg;
    const double c2 = 0.5 * (1.0 + D * ir);  // d chi / dD = (1 + D / r) / 2 = chi / r
    const double f = n2 * ic1, gA = (1.0 + D * D) * ic1;
    const double t = (1.0 - theta) * f + theta * gA;
    double tp, chain;  // t^p and omega p t^(p - 1)
    if constexpr (P == Power::One) {
      tp = t, chain = omega;
    } else if constexpr (P == Power::Four) {
      const double t2 = t * t;
      tp = t2 * t2, chain = 4.0 * omega * t2 * t;
    } else if constexpr (P == Power::Eight) {
      const double t2 = t * t, t4 = t2 * t2;
      tp = t4 * t4, chain = 8.0 * omega * t4 * t2 * t;
    } else {
      tp = std::pow(t, power), chain = omega * power * tp / t;
    }
    term[q] = omega * tp;
    if constexpr (Grad) {
      // dE/dJ = chain [(1-theta) (2 J - f c2 cof J) + theta (2 D - gA c2) cof J] / chi,
      // cof J = dD/dJ = [[J11, -J10], [-J01, J00]].
      const double a1 = chain * (1.0 - theta) * 2.0 * ic1;
      const double a2 = chain * (theta * (2.0 * D - gA * c2) - (1.0 - theta) * f * c2) * ic1;
      G00[q] = a1 * j00 + a2 * j11;
      G01[q] = a1 * j01 - a2 * j10;
      G10[q] = a1 * j10 - a2 * j01;
      G11[q] = a1 * j11 + a2 * j00;
    }
  }
  return nonpos;
}

template <bool Grad>
std::size_t sample_terms(std::size_t n, const double* J00, const double* J01, const double* J10, const double* J11,
                         const double* weight, double element_weight, double eps, double theta, double power,
                         double* term, double* G00, double* G01, double* G10, double* G11) {
  if (power == 1.0)
    return sample_terms<Power::One, Grad>(n, J00, J01, J10, J11, weight, element_weight, eps, theta, power, term,
                                          G00, G01, G10, G11);
  if (power == 4.0)
    return sample_terms<Power::Four, Grad>(n, J00, J01, J10, J11, weight, element_weight, eps, theta, power, term,
                                           G00, G01, G10, G11);
  if (power == 8.0)  // the pipeline's polish (AdaptiveOptions::polish_power)
    return sample_terms<Power::Eight, Grad>(n, J00, J01, J10, J11, weight, element_weight, eps, theta, power, term,
                                            G00, G01, G10, G11);
  return sample_terms<Power::Other, Grad>(n, J00, J01, J10, J11, weight, element_weight, eps, theta, power, term,
                                          G00, G01, G10, G11);
}

// The energy kernel is compiled for AVX2 and the baseline (simd_clones.h).

// What element_energy needs of one element, and its buffers (n samples each).
struct ElementKernel {
  const double* C;  // rows x 16, row-major: the extraction operator
  long rows;
  const int* functions;
  const int* variable_of;                // per function: its x variable, or -1
  const Eigen::Vector2d* normalized;     // per function: the fixed control point
  const double* W;                       // w's Bernstein coefficients, if rational
  bool rational;
  double hx, hy, weight;
  const detail::TensorGrid* grid;
  const double* point_weight;
};
struct KernelBuffers {
  double *x, *xs, *xt, *y, *ys, *yt, *rw, *rs, *rt, *J00, *J01, *J10, *J11, *term, *scratch;
};

// sum of a[0..n) in four interleaved partial sums (independent add chains).
inline double sum4(const double* a, std::size_t n) {
  double p[4] = {};
  std::size_t q = 0;
  for (; q + 4 <= n; q += 4)
    for (int l = 0; l < 4; ++l) p[l] += a[q + l];
  for (; q < n; ++q) p[0] += a[q];
  return (p[0] + p[1]) + (p[2] + p[3]);
}

template <int M>
inline void values(const detail::TensorGrid& g, const double* c, double* f, double* fs, double* ft, double* scratch) {
  detail::tensor_values_fixed<M>(g, c, f, fs, ft, scratch);
}

// J = [S_s / hx, S_t / hy] at the n samples from X, Y and their parametric
// derivatives. On a rational element S = X / w: S_s = (X_s - X w_s / w) / w,
// S_t alike; rw, rs, rt hold w, w_s, w_t there and become 1/w, w_s/w, w_t/w.
inline void sample_jacobians(std::size_t n, bool rational, double ihx, double ihy, const double* x, const double* y,
                             const double* xs, const double* xt, const double* ys, const double* yt, double* rw,
                             double* rs, double* rt, double* J00, double* J01, double* J10, double* J11) {
  if (!rational) {
    for (std::size_t q = 0; q < n; ++q) {
      J00[q] = xs[q] * ihx, J01[q] = xt[q] * ihy;
      J10[q] = ys[q] * ihx, J11[q] = yt[q] * ihy;
    }
    return;
  }
  for (std::size_t q = 0; q < n; ++q) {
    const double iw = 1.0 / rw[q];
    rw[q] = iw, rs[q] *= iw, rt[q] *= iw;
    J00[q] = (xs[q] - x[q] * rs[q]) * iw * ihx;
    J01[q] = (xt[q] - x[q] * rt[q]) * iw * ihy;
    J10[q] = (ys[q] - y[q] * rs[q]) * iw * ihx;
    J11[q] = (yt[q] - y[q] * rt[q]) * iw * ihy;
  }
}

// One element's share of evaluate(): adds its energy to F and, if g, its
// gradient to g; returns its samples with det J <= 0. The steps (each a loop
// over the samples or the 16 coefficients): the Bernstein coefficients of X
// and Y from the control points, X, Y and their derivatives at the samples
// (sum factorization, tensor_grid.h), J, the terms and dE/dJ, back through J
// to the coefficients (the transpose), and to the control points.
template <int M>
std::size_t element_energy_m(const ElementKernel& in, const double* xv, double eps, double theta, double power,
                             double* g, double& F, const KernelBuffers& s) {
  const detail::TensorGrid& grid = *in.grid;
  const std::size_t n = grid.size();
  double X[16] = {}, Y[16] = {};
  for (long r = 0; r < in.rows; ++r) {
    const int a = in.functions[r];
    const int v = in.variable_of[a];
    const double px = v >= 0 ? xv[v] : in.normalized[a].x();
    const double py = v >= 0 ? xv[v + 1] : in.normalized[a].y();
    const double* c = in.C + 16 * r;
    for (int i = 0; i < 16; ++i) X[i] += px * c[i], Y[i] += py * c[i];
  }
  values<M>(grid, X, s.x, s.xs, s.xt, s.scratch);
  values<M>(grid, Y, s.y, s.ys, s.yt, s.scratch);
  const double ihx = 1.0 / in.hx, ihy = 1.0 / in.hy;
  if (in.rational) values<M>(grid, in.W, s.rw, s.rs, s.rt, s.scratch);
  sample_jacobians(n, in.rational, ihx, ihy, s.x, s.y, s.xs, s.xt, s.ys, s.yt, s.rw, s.rs, s.rt, s.J00, s.J01, s.J10,
                   s.J11);
  // dE/dJ goes to (xs, xt, ys, yt): X and Y at the samples are not needed any more.
  const std::size_t nonpos =
      g ? sample_terms<true>(n, s.J00, s.J01, s.J10, s.J11, in.point_weight, in.weight, eps, theta, power, s.term, s.xs,
                             s.xt, s.ys, s.yt)
        : sample_terms<false>(n, s.J00, s.J01, s.J10, s.J11, in.point_weight, in.weight, eps, theta, power, s.term,
                              nullptr, nullptr, nullptr, nullptr);
  F += sum4(s.term, n);
  if (!g) return nonpos;
  // Back through J = [S_s / hx, S_t / hy] to dE/dX_s, dE/dX_t (and dE/dX for
  // a rational element), then to the Bernstein coefficients.
  double GX[16] = {}, GY[16] = {};
  if (!in.rational) {
    for (std::size_t q = 0; q < n; ++q) {
      s.xs[q] *= ihx, s.xt[q] *= ihy;
      s.ys[q] *= ihx, s.yt[q] *= ihy;
    }
    detail::tensor_values_transpose_fixed<M>(grid, nullptr, s.xs, s.xt, GX, s.scratch);
    detail::tensor_values_transpose_fixed<M>(grid, nullptr, s.ys, s.yt, GY, s.scratch);
  } else {
    for (std::size_t q = 0; q < n; ++q) {
      const double gsx = s.xs[q] * s.rw[q] * ihx, gtx = s.xt[q] * s.rw[q] * ihy;
      const double gsy = s.ys[q] * s.rw[q] * ihx, gty = s.yt[q] * s.rw[q] * ihy;
      s.xs[q] = gsx, s.xt[q] = gtx, s.x[q] = -(gsx * s.rs[q] + gtx * s.rt[q]);
      s.ys[q] = gsy, s.yt[q] = gty, s.y[q] = -(gsy * s.rs[q] + gty * s.rt[q]);
    }
    detail::tensor_values_transpose_fixed<M>(grid, s.x, s.xs, s.xt, GX, s.scratch);
    detail::tensor_values_transpose_fixed<M>(grid, s.y, s.ys, s.yt, GY, s.scratch);
  }
  for (long r = 0; r < in.rows; ++r) {
    const int v = in.variable_of[in.functions[r]];
    if (v < 0) continue;
    // Four partial sums each: one vector chain instead of 16 dependent adds.
    const double* c = in.C + 16 * r;
    double sx[4] = {}, sy[4] = {};
    for (int i = 0; i < 16; i += 4)
      for (int l = 0; l < 4; ++l) sx[l] += c[i + l] * GX[i + l], sy[l] += c[i + l] * GY[i + l];
    g[v] += (sx[0] + sx[1]) + (sx[2] + sx[3]);
    g[v + 1] += (sy[0] + sy[1]) + (sy[2] + sy[3]);
  }
  return nonpos;
}

TSPLINE_SIMD_CLONES
std::size_t element_energy(const ElementKernel& in, const double* xv, double eps, double theta, double power, double* g,
                           double& F, const KernelBuffers& s) {
  if (in.grid->m == 5) return element_energy_m<5>(in, xv, eps, theta, power, g, F, s);  // the default samples
  return element_energy_m<0>(in, xv, eps, theta, power, g, F, s);
}

}  // namespace

MapEnergy::Samples::Samples(const MapEnergy& energy, int level) {
  const detail::TensorGrid& grid = energy.levels_[static_cast<std::size_t>(level)].grid;
  const std::size_t n = grid.size();
  for (std::vector<double>* v : {&x, &xs, &xt, &y, &ys, &yt, &rw, &rs, &rt, &J00, &J01, &J10, &J11, &term})
    v->resize(n);
  scratch.resize(8 * static_cast<std::size_t>(grid.m));
}

MapEnergy::MapEnergy(const TSplineMap& map, const MapEnergyOptions& opt, const BezierExtraction* extraction)
    : options_(opt),
      own_extraction_(extraction ? std::nullopt
                                 : std::optional<BezierExtraction>(std::in_place, map.basis())),
      extraction_(extraction ? extraction : &*own_extraction_) {
  if (!opt.lobatto && (opt.gauss < 1 || opt.gauss > 6)) throw toolkit::InputError("MapEnergy: gauss must be in [1, 6]");
  if (opt.lobatto && (opt.gauss < 3 || opt.gauss > 5))
    throw toolkit::InputError("MapEnergy: Gauss-Lobatto points per direction must be in [3, 5]");
  if (!(opt.theta >= 0.0 && opt.theta < 1.0)) throw toolkit::InputError("MapEnergy: theta must be in [0, 1)");
  if (opt.max_sample_level < 0 || opt.max_sample_level > 4)
    throw toolkit::InputError("MapEnergy: max_sample_level must be in [0, 4]");
  if (options_.threads <= 0) options_.threads = static_cast<int>(detail::hardware_threads());
  options_.threads = std::min(options_.threads, 16);

  // Samples per level: the n points of the rule on each of the 2^l equal
  // sub-intervals, in s and in t (a tensor grid; Lobatto points on the
  // sub-intervals' common ends appear twice, once per sub-square).
  std::vector<double> gp, gw;
  if (opt.lobatto)
    lobatto_points_01(opt.gauss, gp, gw);
  else
    detail::gauss_points_01(opt.gauss, gp, gw);
  for (int l = 0; l <= opt.max_sample_level; ++l) {
    const int parts = 1 << l;
    const double h = 1.0 / parts;
    std::vector<double> points, weights;
    for (int part = 0; part < parts; ++part)
      for (std::size_t a = 0; a < gp.size(); ++a) {
        points.push_back((part + gp[a]) * h);
        weights.push_back(gw[a] * h);
      }
    Level level;
    level.grid.set(points, weights);
    const std::size_t m = weights.size();
    level.weight.resize(m * m);
    for (std::size_t r = 0; r < m; ++r)
      for (std::size_t p = 0; p < m; ++p) level.weight[p + m * r] = weights[p] * weights[r];
    levels_.push_back(std::move(level));
  }

  // Free functions and normalized control points.
  const TSplineBasis& basis = map.basis();
  variable_of_.assign(basis.size(), -1);
  if (!opt.movable.empty() && opt.movable.size() != basis.size())
    throw toolkit::InputError("MapEnergy: movable must have one flag per basis function");
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

  const auto& es = extraction_->elements();
  elements_.resize(es.size());
  for (std::size_t k = 0; k < es.size(); ++k) {
    const BezierElement& e = es[k];
    Element& d = elements_[k];
    for (Eigen::Index r = 0; r < e.C.rows(); ++r)
      for (int i = 0; i < 16; ++i) d.W[i] += e.C(r, i);
    // w = 1 exactly where the functions sum to 1 (then X_s / w = X_s: no chain rule through w).
    d.rational = false;
    for (int i = 0; i < 16; ++i) d.rational = d.rational || std::abs(d.W[i] - 1.0) > 1e-13;
    d.hx = e.hi.x() - e.lo.x();
    d.hy = e.hi.y() - e.lo.y();
    d.weight = opt.weighting == ElementWeighting::Area ? d.hx * d.hy : 1.0;
    d.active = false;
    for (int a : e.functions) d.active = d.active || variable_of_[a] >= 0;
    if (d.active) active_.push_back(static_cast<int>(k));
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
    const Level& level = levels_[0];
    Samples s(*this, 0);
    for (std::size_t k = 0; k < es.size(); ++k) {
      const Element& d = elements_[k];
      std::array<double, 16> X, Y;
      element_coefficients(k, x0.data(), X, Y);
      element_samples(k, X.data(), Y.data(), s);  // every element is at level 0 here
      for (std::size_t q = 0; q < level.weight.size(); ++q)
        area += level.weight[q] * d.hx * d.hy * (s.J00[q] * s.J11[q] - s.J01[q] * s.J10[q]);
    }
  }
  if (!(area > 0.0) || !std::isfinite(area))
    throw toolkit::InputError("MapEnergy: the map's domain has no positive area (boundary curve clockwise or degenerate)");
  L_ = std::sqrt(area);
  for (Eigen::Vector2d& p : normalized_) p /= L_;
}

void MapEnergy::element_coefficients(std::size_t k, const double* x, std::array<double, 16>& X,
                                     std::array<double, 16>& Y) const {
  const BezierElement& e = extraction_->elements()[k];
  double sx[16] = {}, sy[16] = {};  // locals: no aliasing with C
  for (Eigen::Index r = 0; r < e.C.rows(); ++r) {
    const int a = e.functions[r];
    const int v = variable_of_[a];
    const double px = v >= 0 ? x[v] : normalized_[a].x();
    const double py = v >= 0 ? x[v + 1] : normalized_[a].y();
    const double* c = e.C.row(r).data();
    for (int i = 0; i < 16; ++i) sx[i] += px * c[i], sy[i] += py * c[i];
  }
  std::copy(sx, sx + 16, X.begin());
  std::copy(sy, sy + 16, Y.begin());
}

void MapEnergy::element_samples(std::size_t k, const double* X, const double* Y, Samples& s) const {
  const Element& d = elements_[k];
  const detail::TensorGrid& g = levels_[d.level].grid;
  const std::size_t n = g.size();
  detail::tensor_values(g, X, s.x.data(), s.xs.data(), s.xt.data(), s.scratch.data());
  detail::tensor_values(g, Y, s.y.data(), s.ys.data(), s.yt.data(), s.scratch.data());
  if (d.rational) detail::tensor_values(g, d.W.data(), s.rw.data(), s.rs.data(), s.rt.data(), s.scratch.data());
  sample_jacobians(n, d.rational, 1.0 / d.hx, 1.0 / d.hy, s.x.data(), s.y.data(), s.xs.data(), s.xt.data(), s.ys.data(),
                   s.yt.data(), s.rw.data(), s.rs.data(), s.rt.data(), s.J00.data(), s.J01.data(), s.J10.data(),
                   s.J11.data());
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
    throw toolkit::InputError("MapEnergy::set_sample_level: level out of range");
  elements_[element].level = level;
  finest_level_ = std::max(finest_level_, level);
}

std::size_t MapEnergy::num_samples() const {
  std::size_t n = 0;
  for (const Element& e : elements_) n += levels_[e.level].weight.size();
  return n;
}

double MapEnergy::evaluate(const double* xv, double eps, double* gradient, std::size_t* nonpositive,
                           double power) const {
  const auto& es = extraction_->elements();
  const int threads = options_.threads;
  std::vector<double> energy(threads, 0.0);
  std::vector<std::size_t> folded(threads, 0);
  std::vector<std::vector<double>> grads(gradient ? threads - 1 : 0, std::vector<double>(num_variables(), 0.0));
  if (gradient) std::fill(gradient, gradient + num_variables(), 0.0);
  const double theta = options_.theta;
  const int finest = finest_active_level();
  detail::parallel_ranges(active_.size(), threads, [&](std::size_t b, std::size_t e_end, int slot) {
    double* g = gradient ? (slot == 0 ? gradient : grads[slot - 1].data()) : nullptr;
    Samples s(*this, finest);
    const KernelBuffers buffers{s.x.data(),   s.xs.data(),  s.xt.data(),  s.y.data(),    s.ys.data(),
                                s.yt.data(),  s.rw.data(),  s.rs.data(),  s.rt.data(),   s.J00.data(),
                                s.J01.data(), s.J10.data(), s.J11.data(), s.term.data(), s.scratch.data()};
    double F = 0.0;
    std::size_t nonpos = 0;
    for (std::size_t i = b; i < e_end; ++i) {
      const std::size_t k = static_cast<std::size_t>(active_[i]);
      const Element& d = elements_[k];
      const BezierElement& e = es[k];
      const Level& level = levels_[d.level];
      const ElementKernel in{e.C.data(), static_cast<long>(e.C.rows()), e.functions.data(), variable_of_.data(),
                             normalized_.data(), d.W.data(), d.rational, d.hx, d.hy, d.weight, &level.grid,
                             level.weight.data()};
      nonpos += element_energy(in, xv, eps, theta, power, g, F, buffers);
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
  SampleStats st;
  st.min_det = std::numeric_limits<double>::infinity();
  st.min_mean_ratio = std::numeric_limits<double>::infinity();
  double wsum = 0.0, jsum = 0.0;
  Samples s(*this, finest_active_level());
  for (const int ka : active_) {
    const std::size_t k = static_cast<std::size_t>(ka);
    const Element& d = elements_[k];
    const Level& level = levels_[d.level];
    std::array<double, 16> X, Y;
    element_coefficients(k, xv, X, Y);
    element_samples(k, X.data(), Y.data(), s);
    for (std::size_t q = 0; q < level.weight.size(); ++q) {
      const double D = s.J00[q] * s.J11[q] - s.J01[q] * s.J10[q];
      const double n2 = s.J00[q] * s.J00[q] + s.J01[q] * s.J01[q] + s.J10[q] * s.J10[q] + s.J11[q] * s.J11[q];
      const double jr = n2 > 0.0 ? 2.0 * D / n2 : 0.0;
      ++st.points;
      if (!(D > 0.0)) ++st.nonpositive;
      st.min_det = std::min(st.min_det, D);
      st.min_mean_ratio = std::min(st.min_mean_ratio, jr);
      const double omega = level.weight[q] * d.weight;
      wsum += omega, jsum += omega * jr;
    }
  }
  st.mean_mean_ratio = wsum > 0.0 ? jsum / wsum : 0.0;
  return st;
}

double MapEnergy::max_positive_step(const double* xv, const double* dv, double a_max, double safety) const {
  // The direction's own coefficients: element_coefficients is affine, so the
  // coefficients of x + t d are X + t (X(d) - X(0)) with the fixed points in X(0).
  const std::vector<double> zero(num_variables(), 0.0);
  std::vector<double> result(static_cast<std::size_t>(std::max(1, options_.threads)), a_max);
  const int finest = finest_active_level();
  detail::parallel_ranges(active_.size(), options_.threads, [&](std::size_t b, std::size_t e_end, int slot) {
    Samples s(*this, finest), sd(*this, finest);
    double best = a_max;
    for (std::size_t i = b; i < e_end; ++i) {
      const std::size_t k = static_cast<std::size_t>(active_[i]);
      const Element& d = elements_[k];
      std::array<double, 16> X, Y, DX, DY, X0, Y0;
      element_coefficients(k, xv, X, Y);
      element_coefficients(k, dv, DX, DY);
      element_coefficients(k, zero.data(), X0, Y0);
      for (int i = 0; i < 16; ++i) DX[i] -= X0[i], DY[i] -= Y0[i];
      element_samples(k, X.data(), Y.data(), s);
      element_samples(k, DX.data(), DY.data(), sd);
      for (std::size_t q = 0; q < levels_[d.level].weight.size(); ++q) {
        const double D0 = s.J00[q] * s.J11[q] - s.J01[q] * s.J10[q];
        if (!(D0 > 0.0)) continue;
        // det(J + t G) = D0 + t D1 + t^2 D2.
        const double D1 = s.J00[q] * sd.J11[q] + sd.J00[q] * s.J11[q] - s.J01[q] * sd.J10[q] - sd.J01[q] * s.J10[q];
        const double D2 = sd.J00[q] * sd.J11[q] - sd.J01[q] * sd.J10[q];
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
