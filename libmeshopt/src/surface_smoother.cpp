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

// The largest stretch of D phi at u: the square root of the largest
// eigenvalue of D phi^T D phi.
double largest_stretch(const ParametricSurface& surface, const Eigen::Vector2d& u) {
  const SurfacePoint p = surface.evaluate(u, 1);
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(p.d.transpose() * p.d, Eigen::EigenvaluesOnly)
                       .eigenvalues()
                       .maxCoeff());
}

// One run of smooth_surface: Gauss-Seidel sweeps over the free nodes, each
// moved within its face to the minimum of its submesh's objective. Holds the
// corner normals and node sizes as the nodes move.
class SurfaceSmoothing {
 public:
  SurfaceSmoothing(SurfaceMesh& m, const SurfaceSmoothingOptions& opt)
      : m_(m),
        opt_(opt),
        normals_(corner_normals(m)),
        node_size_(node_sizes(m, opt.size)),
        corners_(node_corners(m)),
        active_(m.x.size(), 1) {}

  SurfaceSmoothingReport run() {
    rep_.tangled_before = tangled();
    double F = objective();
    for (int sweep = 0; sweep < opt_.max_sweeps; ++sweep) {
      const Sweep s = sweep_nodes();
      const double F_new = objective();
      const double r_f = std::isfinite(F) && std::isfinite(F_new) && F_new > 0.0 ? std::abs(F - F_new) / F_new : kInf;
      F = F_new;
      rep_.sweeps = sweep + 1;
      rep_.last_relative_move = s.r_x;
      rep_.last_relative_objective = r_f;
      if (opt_.progress) opt_.progress(sweep, s.r_x, r_f, tangled());
      if ((s.r_x < opt_.tol_x && r_f < opt_.tol_f) || s.visited == 0) {
        rep_.converged = true;
        break;
      }
    }
    rep_.objective = F;
    rep_.tangled_after = tangled();
    rep_.newton_steps = cnt_.newton;
    rep_.gradient_fallbacks = cnt_.gradient;
    return rep_;
  }

 private:
  struct Sweep {
    double r_x = 0.0;  // the largest move relative to the node's submesh
    std::size_t visited = 0;
  };

  std::size_t tangled() const { return element_qualities(m_, normals_, opt_.measure, node_size_).tangled; }
  double objective() const { return global_objective(m_, normals_, opt_.measure, node_size_); }

  // One sweep over the active free nodes.
  Sweep sweep_nodes() {
    Sweep s;
    for (std::size_t i = 0; i < m_.x.size(); ++i) {
      if (m_.free_face[i] < 0 || corners_[i].empty() || !active_[i]) continue;
      active_[i] = 0;
      ++s.visited;
      s.r_x = std::max(s.r_x, visit(i));
    }
    return s;
  }

  // Free node i moved to the minimum of its submesh's objective, if it may go
  // there. Returns its move relative to the largest submesh edge (0: it stays).
  double visit(std::size_t i) {
    const ParametricSurface& surface = *m_.faces[m_.free_face[i]];
    const double max_edge = build_terms(m_, corners_[i], normals_, node_size_, terms_);
    if (terms_.empty() || !(max_edge > 0.0)) return 0.0;
    ++rep_.node_visits;
    // Parametric length scale for the step cap: the submesh size divided by the
    // largest stretch of D phi (a step of this length moves x by <= max_edge).
    const double stretch = largest_stretch(surface, m_.u[i]);
    if (!(stretch > 0.0) || !std::isfinite(stretch)) return 0.0;
    const SurfaceNodeObjective obj{surface, terms_, opt_.measure};
    if (!(obj.min_sigma(m_.u[i]) > 0.0)) active_[i] = 1;  // tangled: keep visiting
    const Eigen::Vector2d un = descend(m_.u[i], obj, max_edge / stretch);
    if (un == m_.u[i] || !may_move_to(m_, corners_[i], surface, un)) return 0.0;
    const SurfacePoint q = surface.evaluate(un, 1);
    const Eigen::Vector3d n = unit_normal(q);
    if (n.isZero()) return 0.0;  // never move a node onto a degenerate point
    const double move = (q.x - m_.x[i]).norm() / max_edge;
    if (move >= 0.1 * opt_.tol_x) activate_star(i);
    place(i, un, q.x, n);
    return move;
  }

  // Newton descent from u with steps of at most step_cap.
  Eigen::Vector2d descend(const Eigen::Vector2d& u, const SurfaceNodeObjective& obj, double step_cap) {
    Eigen::Vector2d un = detail::newton_descent(u, obj, opt_.newton, step_cap, cnt_);
    // Nonlinear over-relaxation (as in smooth()): taken only if the submesh stays
    // valid and the node inside its face there.
    if (opt_.newton.over_relaxation != 1.0) {
      const Eigen::Vector2d ur = u + opt_.newton.over_relaxation * (un - u);
      if (obj.min_sigma(un) > 0.0 && obj.min_sigma(ur) > 0.0) un = ur;
    }
    return un;
  }

  void activate_star(std::size_t i) {
    for (const Corner& c : corners_[i])
      for (int k = 0; k < m_.elements[c.element].nv; ++k) active_[m_.elements[c.element].v[k]] = 1;
  }

  // Node i at uv point un of its face (x there, unit normal n).
  void place(std::size_t i, const Eigen::Vector2d& un, const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
    m_.u[i] = un;
    m_.x[i] = x;
    for (const Corner& c : corners_[i]) normals_[4 * static_cast<std::size_t>(c.element) + c.local] = n;
    if (opt_.size) {
      node_size_[i] = opt_.size(x);
      if (!(node_size_[i] > 0.0) || !std::isfinite(node_size_[i]))
        throw toolkit::InputError("meshopt::smooth_surface: the size field is not positive and finite at node " +
                                    std::to_string(i) + " after it moved");
    }
  }

  SurfaceMesh& m_;
  const SurfaceSmoothingOptions& opt_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<double> node_size_;
  const std::vector<std::vector<Corner>> corners_;
  // Active nodes: a node is visited again only if it or a neighbour moved by more
  // than tol_x / 10 (relative) at their last visit, or its submesh is tangled.
  std::vector<char> active_;
  std::vector<SurfaceTerm> terms_;  // node i's, rebuilt at each visit
  detail::Counters cnt_;
  SurfaceSmoothingReport rep_;
};

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
  return SurfaceSmoothing(m, opt).run();
}

}  // namespace meshopt
