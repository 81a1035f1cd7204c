// Certified validity of the T-spline map; see map_certification.h for the method.
#include "tspline/validity/map_certification.h"
#include "tspline/detail/thread_pool.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>

#include "tspline/detail/element_jacobian.h"
#include "tspline/detail/quadrature.h"
#include "toolkit/errors.h"
#include "toolkit/timing.h"

namespace tspline {

namespace {

using detail::BernsteinPoly;
using detail::bernstein_values;
using detail::ElementJacobian;
using detail::element_jacobian;

// Gauss-Legendre (5 points on [0,1]) nodes, weights and the Bernstein values of
// degrees 3 and 8 there, for the element mean of det J.
struct GaussBernstein {
  std::vector<double> p, w;
  double b3[5][4], b8[5][9];
};
const GaussBernstein& gauss_bernstein() {
  static const GaussBernstein g = [] {
    GaussBernstein t;
    detail::gauss_points_01(5, t.p, t.w);
    for (int a = 0; a < 5; ++a) {
      bernstein_values(3, t.p[a], t.b3[a]);
      bernstein_values(8, t.p[a], t.b8[a]);
    }
    return t;
  }();
  return g;
}

// p(s_a, t_b) at Gauss nodes a, b from tabulated basis values (bidegree (d, d)).
template <int d>
double at_gauss(const BernsteinPoly& p, const double (&bs)[d + 1], const double (&bt)[d + 1]) {
  double v = 0.0;
  for (int j = 0; j <= d; ++j) {
    double row = 0.0;
    for (int i = 0; i <= d; ++i) row += p.c[i + (d + 1) * j] * bs[i];
    v += row * bt[j];
  }
  return v;
}

}  // namespace

// ---------------------------------------------------------------------------
// Certification of one element
// ---------------------------------------------------------------------------
ElementCertificate certify_element(const BezierElement& e, const std::vector<Eigen::Vector2d>& P,
                                   const CertificationOptions& opt) {
  if (opt.max_depth < 0 || opt.max_depth > 20)
    throw toolkit::InputError("certify_element: max_depth out of range");
  const ElementJacobian J = element_jacobian(e, P);
  const double area = (e.hi.x() - e.lo.x()) * (e.hi.y() - e.lo.y());
  const double tol = opt.relative_tolerance * J.scale;
  const double w_min = J.weight.min_coefficient(), w_max = J.weight.max_abs_coefficient();
  ElementCertificate cert;

  // Mean of det J over the element: 5x5 Gauss (exact for D when w is constant).
  {
    const GaussBernstein& g = gauss_bernstein();
    double sum = 0.0;
    for (int a = 0; a < 5; ++a)
      for (int b = 0; b < 5; ++b) {
        const double w = at_gauss<3>(J.weight, g.b3[a], g.b3[b]);
        sum += g.w[a] * g.w[b] * at_gauss<8>(J.numerator, g.b8[a], g.b8[b]) / (w * w * w);
      }
    cert.det_mean = sum / area;
  }

  // Rigorous bound of D / w^3 from a lower bound d of D on a region.
  auto bound = [&](double d) {
    if (d >= 0.0) return d / (w_max * w_max * w_max);
    return w_min > 0.0 ? d / (w_min * w_min * w_min) : -std::numeric_limits<double>::infinity();
  };
  auto finish = [&](double d_low) {
    cert.det_lower_bound = bound(d_low) / area;
    cert.relative_lower_bound =
        cert.det_mean > 0.0 ? cert.det_lower_bound / cert.det_mean : -std::numeric_limits<double>::infinity();
    return cert;
  };

  const double d_root = J.numerator.min_coefficient();
  if (!(w_min > 0.0) || !(J.scale > 0.0) || !std::isfinite(J.scale)) {
    // w must be positive (it is a sum of B-splines covering the element); a
    // zero scale means D == 0 (a collapsed element). Neither can be certified.
    cert.status = ElementStatus::Undecided;
    return finish(std::min(d_root, 0.0));
  }

  struct Patch {
    BernsteinPoly d;
    int depth;
    double s0, t0, size;
  };
  std::deque<Patch> queue;  // breadth first: coarse corner samples first
  queue.push_back({J.numerator, 0, 0.0, 0.0, 1.0});
  double d_low = std::numeric_limits<double>::infinity();
  bool undecided = false;
  constexpr std::size_t kMaxPatches = 4096;  // bound on work for degenerate elements
  const int m = J.numerator.m, n = J.numerator.n;
  while (!queue.empty()) {
    Patch p = std::move(queue.front());
    queue.pop_front();
    ++cert.patches;
    cert.depth = std::max(cert.depth, p.depth);
    const double dmin = p.d.min_coefficient();
    if (dmin > tol) {
      d_low = std::min(d_low, dmin);
      continue;
    }
    // Corner coefficients are values: a negative one is a counterexample.
    const std::array<std::array<int, 2>, 4> corners = {{{0, 0}, {m, 0}, {0, n}, {m, n}}};
    for (const auto& [i, j] : corners) {
      const double v = p.d.at(i, j);
      if (v < -tol) {
        const double s = p.s0 + p.size * i / m, t = p.t0 + p.size * j / n;
        cert.status = ElementStatus::Invalid;
        cert.negative_at = {e.lo.x() + s * (e.hi.x() - e.lo.x()), e.lo.y() + t * (e.hi.y() - e.lo.y())};
        const double w = J.weight(s, t);
        cert.negative_det = v / (w * w * w * area);
        return finish(d_root);  // the search is incomplete: fall back to the root coefficients
      }
    }
    if (p.depth >= opt.max_depth || cert.patches + queue.size() >= kMaxPatches) {
      undecided = true;
      d_low = std::min(d_low, dmin);
      continue;
    }
    const std::array<BernsteinPoly, 4> q = bernstein_subdivide(p.d);
    const double h = 0.5 * p.size;
    queue.push_back({q[0], p.depth + 1, p.s0, p.t0, h});
    queue.push_back({q[1], p.depth + 1, p.s0 + h, p.t0, h});
    queue.push_back({q[2], p.depth + 1, p.s0, p.t0 + h, h});
    queue.push_back({q[3], p.depth + 1, p.s0 + h, p.t0 + h, h});
  }
  cert.status = undecided ? ElementStatus::Undecided : ElementStatus::Certified;
  return finish(d_low);
}

// ---------------------------------------------------------------------------
// The whole map
// ---------------------------------------------------------------------------
MapCertification certify_map(const TSplineMap& map, const CertificationOptions& opt) {
  return certify_map(BezierExtraction(map.basis()), map.mesh().num_cells(), map.control_points(), opt);
}

MapCertification certify_map(const BezierExtraction& extraction, std::size_t num_cells,
                             const std::vector<Eigen::Vector2d>& P, const CertificationOptions& opt,
                             const std::vector<char>* only) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<BezierElement>& es = extraction.elements();
  // One partial result per range of elements, merged in order (failures by element).
  std::vector<MapCertification> part(static_cast<std::size_t>(detail::pool_threads()));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> element_det(es.size(), nan), element_relative(es.size(), nan);
  detail::parallel_ranges(es.size(), detail::pool_threads(), [&](std::size_t b, std::size_t end, int slot) {
    MapCertification& r = part[slot];
    r.min_relative_lower_bound = std::numeric_limits<double>::infinity();
    r.min_det_lower_bound = std::numeric_limits<double>::infinity();
    for (std::size_t k = b; k < end; ++k) {
      if (only && !(*only)[k]) continue;
      const BezierElement& e = es[k];
      const ElementCertificate cert = certify_element(e, P, opt);
      element_det[k] = cert.det_lower_bound, element_relative[k] = cert.relative_lower_bound;
      ++r.elements;
      r.max_depth_used = std::max(r.max_depth_used, cert.depth);
      r.min_relative_lower_bound = std::min(r.min_relative_lower_bound, cert.relative_lower_bound);
      r.min_det_lower_bound = std::min(r.min_det_lower_bound, cert.det_lower_bound);
      switch (cert.status) {
        case ElementStatus::Certified:
          ++r.certified;
          continue;
        case ElementStatus::Invalid:
          ++r.invalid;
          break;
        case ElementStatus::Undecided:
          ++r.undecided;
          break;
      }
      r.failures.push_back({e.cell, k, e.lo, e.hi, cert});
    }
  }, 64);
  MapCertification r;
  r.cell_certified.assign(num_cells, 1);
  r.cell_det_lower_bound.assign(num_cells, nan), r.cell_relative_lower_bound.assign(num_cells, nan);
  for (std::size_t k = 0; k < es.size(); ++k) {
    if (std::isnan(element_det[k])) continue;
    double& d = r.cell_det_lower_bound[es[k].cell];
    double& q = r.cell_relative_lower_bound[es[k].cell];
    d = std::isnan(d) ? element_det[k] : std::min(d, element_det[k]);
    q = std::isnan(q) ? element_relative[k] : std::min(q, element_relative[k]);
  }
  r.min_relative_lower_bound = std::numeric_limits<double>::infinity();
  r.min_det_lower_bound = std::numeric_limits<double>::infinity();
  for (MapCertification& p : part) {
    if (p.elements == 0) continue;
    r.elements += p.elements;
    r.certified += p.certified;
    r.invalid += p.invalid;
    r.undecided += p.undecided;
    r.max_depth_used = std::max(r.max_depth_used, p.max_depth_used);
    r.min_relative_lower_bound = std::min(r.min_relative_lower_bound, p.min_relative_lower_bound);
    r.min_det_lower_bound = std::min(r.min_det_lower_bound, p.min_det_lower_bound);
    for (CertificationFailure& f : p.failures) {
      r.cell_certified[f.cell] = 0;
      r.failures.push_back(std::move(f));
    }
  }
  r.seconds = toolkit::seconds_since(t0);
  return r;
}

}  // namespace tspline
