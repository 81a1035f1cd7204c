// Algorithm 2 of Gargallo-Peiro et al. on parameterized surfaces.
#include "meshopt/surface_smoother.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "meshopt/parametric_star.h"
#include "meshopt/surface_objective.h"
#include "meshopt/triangle_measure.h"
#include "newton_descent.h"
#include "toolkit/errors.h"

namespace meshopt {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The surface objective in the form detail::newton_descent expects (x = u).
struct SurfaceNodeObjective {
  const ParametricSurface& surface;
  std::span<const SurfaceTerm> terms;
  SurfaceMeasure measure;
  // A submesh whose smallest sigma is positive but numerically flat (below 1e-10 of
  // the mean |sigma|, e.g. a free node on a straight boundary between two fixed ones)
  // counts as sigma* = 0: the regularized measure (delta > 0) then moves it, where
  // Newton on the barrier 1/sigma would only multiply sigma by 1.5 per step.
  double min_sigma(const Eigen::Vector2d& u) const {
    if (!surface.contains(u)) return -kInf;
    const double m = surface_min_sigma(surface.value(u), terms);
    return m > 0.0 && m < 1e-10 * mean_abs_sigma(u) ? 0.0 : m;
  }
  double mean_abs_sigma(const Eigen::Vector2d& u) const {
    const Eigen::Vector3d x = surface.value(u);
    double s = 0.0;
    for (const SurfaceTerm& t : terms)
      s += std::abs(triangle_invariants(x, t.xa, t.xb, t.ideal_inv, t.normal, true).sigma);
    return s / static_cast<double>(terms.size());
  }
  ObjectiveValue full(const Eigen::Vector2d& u, double delta) const {
    return surface_objective(u, surface, terms, measure, delta);
  }
  double value(const Eigen::Vector2d& u, double delta) const {
    return surface_objective_value(u, surface, terms, measure, delta);
  }
};

struct Corner {
  int element;
  int local;
};

// For every node, the element corners at which it sits.
std::vector<std::vector<Corner>> node_corners(const SurfaceMesh& m) {
  std::vector<std::vector<Corner>> out(m.x.size());
  for (std::size_t e = 0; e < m.elements.size(); ++e)
    for (int i = 0; i < m.elements[e].nv; ++i) out[m.elements[e].v[i]].push_back({static_cast<int>(e), i});
  return out;
}

double element_size(const SurfaceElement& el, const std::vector<double>& node_size) {
  double h = 0.0;
  for (int i = 0; i < el.nv; ++i) h += node_size[el.v[i]];
  return h / el.nv;
}

// SETIDEALELEMENTS: the corner triangles of node i's submesh that contain it, each
// rotated so that the free node comes first. Returns the largest submesh edge.
double build_terms(const SurfaceMesh& m, const std::vector<Corner>& corners, const std::vector<Eigen::Vector3d>& normals,
                   const std::vector<double>& node_size, std::vector<SurfaceTerm>& terms) {
  terms.clear();
  double max_edge = 0.0;
  for (const Corner& c : corners) {
    const SurfaceElement& el = m.elements[c.element];
    for (int i = 0; i < el.nv; ++i) max_edge = std::max(max_edge, (m.x[el.v[(i + 1) % el.nv]] - m.x[el.v[i]]).norm());
    for (const CornerTriangle& ct : corner_triangles(el.nv, element_size(el, node_size))) {
      const auto it = std::find(ct.local.begin(), ct.local.end(), c.local);
      if (it == ct.local.end()) continue;  // constant term (Eq. 17)
      const int j = static_cast<int>(it - ct.local.begin());
      const int la = ct.local[(j + 1) % 3], lb = ct.local[(j + 2) % 3];
      SurfaceTerm t;
      t.xa = m.x[el.v[la]];
      t.xb = m.x[el.v[lb]];
      t.ideal_inv = ideal_inverse(ct.ideal[j], ct.ideal[(j + 1) % 3], ct.ideal[(j + 2) % 3]);
      const std::size_t base = 4 * static_cast<std::size_t>(c.element);
      t.normal = (normals[base + c.local] + normals[base + la] + normals[base + lb]).normalized();
      t.weight = ct.weight;
      terms.push_back(t);
    }
  }
  return max_edge;
}

// F = sum over elements of their distortion (delta = 0); infinity if any is tangled.
double global_objective(const SurfaceMesh& m, const std::vector<Eigen::Vector3d>& normals, SurfaceMeasure measure,
                        const std::vector<double>& node_size) {
  double F = 0.0;
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const SurfaceElement& el = m.elements[e];
    for (const CornerTriangle& ct : corner_triangles(el.nv, element_size(el, node_size))) {
      const auto [i0, i1, i2] = ct.local;
      const TriangleInvariants t = triangle_invariants(
          m.x[el.v[i0]], m.x[el.v[i1]], m.x[el.v[i2]], ideal_inverse(ct.ideal[0], ct.ideal[1], ct.ideal[2]),
          normals[4 * e + i0] + normals[4 * e + i1] + normals[4 * e + i2]);
      F += ct.weight * distortion(measure, t.f, t.sigma, 0.0).value;
    }
  }
  return F;
}

// Whether a free node may move to uv point `un` of its face. The exact test of a
// trimmed face (gmsh::model::isInside, 10-100 us per call on OCC faces) is
// skipped when `un` lies in one of the node's elements in parameter space and is
// not near one of their edges between two fixed nodes. Such an element has its
// corners in the face, and the face's trimming curves pass through the mesh
// only along chains of edges between fixed nodes, from which they deviate by a
// sagitta: within kTrimmingMargin of such an edge isInside decides.
bool may_move_to(const SurfaceMesh& m, const std::vector<Corner>& corners, const ParametricSurface& surface,
                 const Eigen::Vector2d& un) {
  if (!surface.contains(un)) return false;
  bool in_star = false;
  std::array<Eigen::Vector2d, 4> uv;
  for (const Corner& c : corners) {
    const SurfaceElement& el = m.elements[c.element];
    for (int k = 0; k < el.nv; ++k) {
      const int v = el.v[k];
      uv[k] = m.free_face[v] >= 0 || m.corner_uv.empty() ? m.u[v] : m.corner_uv[4 * static_cast<std::size_t>(c.element) + k];
    }
    for (int k = 0; k < el.nv; ++k) {
      const int l = (k + 1) % el.nv;
      if (m.free_face[el.v[k]] < 0 && m.free_face[el.v[l]] < 0 &&
          segment_distance(un, uv[k], uv[l]) < kTrimmingMargin * (uv[l] - uv[k]).norm())
        return surface.contains_exactly(un);
    }
    for (int k = 1; k + 1 < el.nv && !in_star; ++k) in_star = in_triangle(un, uv[0], uv[k], uv[k + 1]);
  }
  return in_star || surface.contains_exactly(un);
}

void validate_surface_options(const SurfaceSmoothingOptions& o) {
  detail::validate_options(o.newton);
  auto bad = [](const std::string& what) { throw toolkit::InputError("meshopt::smooth_surface: " + what); };
  if (o.max_sweeps < 0) bad("max_sweeps must be >= 0");
  if (!(o.tol_x >= 0.0) || !std::isfinite(o.tol_x)) bad("tol_x must be finite and >= 0");
  if (!(o.tol_f >= 0.0) || !std::isfinite(o.tol_f)) bad("tol_f must be finite and >= 0");
}

}  // namespace

ElementQualities surface_mesh_quality(const SurfaceMesh& mesh, SurfaceMeasure measure, const SizeField& size) {
  validate_surface_mesh(mesh, false);  // measuring needs no trimmed-face test
  const std::vector<Eigen::Vector3d> normals = corner_normals(mesh);
  const std::vector<double> h = node_sizes(mesh, size);
  return element_qualities(mesh, normals, measure, h);
}

SurfaceSmoothingReport smooth_surface(SurfaceMesh& m, const SurfaceSmoothingOptions& opt) {
  validate_surface_options(opt);
  validate_surface_mesh(m);
  std::vector<Eigen::Vector3d> normals = corner_normals(m);
  std::vector<double> node_size = node_sizes(m, opt.size);
  const std::vector<std::vector<Corner>> corners = node_corners(m);

  SurfaceSmoothingReport rep;
  rep.tangled_before = element_qualities(m, normals, opt.measure, node_size).tangled;
  double F = global_objective(m, normals, opt.measure, node_size);
  detail::Counters cnt;
  std::vector<SurfaceTerm> terms;
  // Active nodes: a node is visited again only if it or a neighbour moved by more
  // than tol_x / 10 (relative) at their last visit, or its submesh is tangled.
  std::vector<char> active(m.x.size(), 1);
  auto activate_star = [&](std::size_t i) {
    for (const Corner& c : corners[i])
      for (int k = 0; k < m.elements[c.element].nv; ++k) active[m.elements[c.element].v[k]] = 1;
  };
  for (int sweep = 0; sweep < opt.max_sweeps; ++sweep) {
    double r_x = 0.0;
    std::size_t visited = 0;
    for (std::size_t i = 0; i < m.x.size(); ++i) {
      const int face = m.free_face[i];
      if (face < 0 || corners[i].empty() || !active[i]) continue;
      active[i] = 0;
      ++visited;
      const ParametricSurface& surface = *m.faces[face];
      const double max_edge = build_terms(m, corners[i], normals, node_size, terms);
      if (terms.empty() || !(max_edge > 0.0)) continue;
      ++rep.node_visits;
      // Parametric length scale for the step cap: the submesh size divided by the
      // largest stretch of D phi (a step of this length moves x by <= max_edge).
      const SurfacePoint p = surface.evaluate(m.u[i], 1);
      const double stretch = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(
                                           p.d.transpose() * p.d, Eigen::EigenvaluesOnly)
                                           .eigenvalues()
                                           .maxCoeff());
      if (!(stretch > 0.0) || !std::isfinite(stretch)) continue;
      const SurfaceNodeObjective obj{surface, terms, opt.measure};
      if (!(obj.min_sigma(m.u[i]) > 0.0)) active[i] = 1;  // tangled: keep visiting
      Eigen::Vector2d un = detail::newton_descent(m.u[i], obj, opt.newton, max_edge / stretch, cnt);
      // Nonlinear over-relaxation (as in smooth()): taken only if the submesh stays
      // valid and the node inside its face there.
      if (opt.newton.over_relaxation != 1.0) {
        const Eigen::Vector2d ur = m.u[i] + opt.newton.over_relaxation * (un - m.u[i]);
        if (obj.min_sigma(un) > 0.0 && obj.min_sigma(ur) > 0.0) un = ur;
      }
      if (un == m.u[i] || !may_move_to(m, corners[i], surface, un)) continue;
      const SurfacePoint q = surface.evaluate(un, 1);
      const Eigen::Vector3d n = unit_normal(q);
      if (n.isZero()) continue;  // never move a node onto a degenerate point
      const double move = (q.x - m.x[i]).norm() / max_edge;
      r_x = std::max(r_x, move);
      if (move >= 0.1 * opt.tol_x) activate_star(i);
      m.u[i] = un;
      m.x[i] = q.x;
      for (const Corner& c : corners[i]) normals[4 * static_cast<std::size_t>(c.element) + c.local] = n;
      if (opt.size) {
        node_size[i] = opt.size(q.x);
        if (!(node_size[i] > 0.0) || !std::isfinite(node_size[i]))
          throw toolkit::InputError("meshopt::smooth_surface: the size field is not positive and finite at node " +
                                      std::to_string(i) + " after it moved");
      }
    }
    const double F_new = global_objective(m, normals, opt.measure, node_size);
    const double r_f = std::isfinite(F) && std::isfinite(F_new) && F_new > 0.0 ? std::abs(F - F_new) / F_new : kInf;
    F = F_new;
    rep.sweeps = sweep + 1;
    rep.last_relative_move = r_x;
    rep.last_relative_objective = r_f;
    if (opt.progress)
      opt.progress(sweep, r_x, r_f, element_qualities(m, normals, opt.measure, node_size).tangled);
    if ((r_x < opt.tol_x && r_f < opt.tol_f) || visited == 0) {
      rep.converged = true;
      break;
    }
  }
  rep.objective = F;
  rep.tangled_after = element_qualities(m, normals, opt.measure, node_size).tangled;
  rep.newton_steps = cnt.newton;
  rep.gradient_fallbacks = cnt.gradient;
  return rep;
}

}  // namespace meshopt
