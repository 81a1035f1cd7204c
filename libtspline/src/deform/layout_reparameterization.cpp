#include "tspline/deform/layout_reparameterization.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <mutex>
#include <string>
#include <thread>

#include "tspline/boundary/polygon_validation.h"
#include "tspline/deform/reparameterization.h"
#include "tspline/errors.h"
#include "tspline/layout/layout_optimizer.h"
#include "tspline/layout/layout_quality.h"

namespace tspline {
namespace {

std::vector<const Polygon*> rings_of(const Domain& d) {
  std::vector<const Polygon*> r = {&d.outer};
  for (const Polygon& h : d.holes) r.push_back(&h);
  return r;
}

// The inner nodes of a quad layout (patch corners inside the domain) moved to
// raise its worst corners on the moved rings (layout_optimizer.h), the ring
// nodes kept where the motion put them (material points of the coast), the
// topology kept: a layout carried through many steps would otherwise keep
// angles that the moving coast has closed. Only for layouts whose patch sides
// along cuts are straight segments (quad layouts); others are left as moved.
// Returns the number of inner nodes.
std::size_t reoptimize_inner_nodes(PatchLayout& layout, const Domain& moved, int max_sweeps) {
  for (const Cut& c : layout.cuts)
    if (c.size() != 2) return 0;
  std::vector<RingCurve> curves;
  for (const Polygon* r : rings_of(moved)) curves.emplace_back(r->vertices);
  const RingGeometry geometry = RingGeometry::of_rings(curves);
  const double tol = 1e-9 * bounding_box_diagonal(moved.outer);
  // Nodes: the patch corners, one per position.
  LayoutMesh m;
  std::map<std::pair<double, double>, int> id;
  auto node = [&](const Eigen::Vector2d& x) {
    const auto [it, added] = id.try_emplace({x.x(), x.y()}, static_cast<int>(m.x.size()));
    if (added) {
      m.x.push_back(x);
      int ring = -1;
      double arc = 0.0;
      const int e = geometry.nearest(x);
      if (e >= 0 && segment_distance(x, geometry.edge(e).a, geometry.edge(e).b) <= tol) {
        const RingGeometry::Edge& edge = geometry.edge(e);
        ring = edge.ring;
        arc = curves[ring].arc(edge.index) + (x - edge.a).norm();
      }
      m.ring.push_back(ring);
      m.arc.push_back(arc);
    }
    return it->second;
  };
  for (const Patch& p : layout.patches) {
    std::array<int, 4> q;
    for (int k = 0; k < 4; ++k) q[k] = node(p.polygon.vertices[p.corners[k]]);
    m.quads.push_back(q);
  }
  // A side along a cut must be the straight segment between its corners.
  for (const Patch& p : layout.patches)
    for (int k = 0; k < 4; ++k) {
      const std::size_t n = p.polygon.vertices.size(), a = p.corners[k], b = p.corners[(k + 1) % 4];
      if (p.side_cut[k] >= 0 && (a + 1) % n != b) return 0;
    }
  std::vector<int> inner;
  for (std::size_t n = 0; n < m.size(); ++n)
    if (m.ring[n] < 0) inner.push_back(static_cast<int>(n));
  if (inner.empty()) return 0;
  LayoutRings rings;
  rings.curves = curves;
  const LayoutQuality quality(rings);
  const LayoutAdmissible admissible = admissible_in(geometry, tol);
  LayoutOptimizationOptions o;
  o.max_sweeps = max_sweeps;
  const std::vector<Eigen::Vector2d> before = m.x;
  optimize_layout_nodes(m, quality, admissible, inner, o);
  // The patches' corners and the cuts' ends where their nodes went.
  for (Patch& p : layout.patches)
    for (int k = 0; k < 4; ++k) {
      Eigen::Vector2d& v = p.polygon.vertices[p.corners[k]];
      v = m.x[id.at({v.x(), v.y()})];
    }
  for (Cut& c : layout.cuts)
    for (Eigen::Vector2d& v : c) {
      const auto it = id.find({v.x(), v.y()});
      if (it != id.end()) v = m.x[it->second];
    }
  return inner.size();
}

}  // namespace

LayoutMotion::LayoutMotion(const Domain& old, const Domain& moved) {
  const auto a = rings_of(old), b = rings_of(moved);
  std::vector<RingCurve> curves;
  for (std::size_t r = 0; r < a.size(); ++r) {
    ring_start_.push_back(old_.size());
    old_.insert(old_.end(), a[r]->vertices.begin(), a[r]->vertices.end());
    new_.insert(new_.end(), b[r]->vertices.begin(), b[r]->vertices.end());
    curves.emplace_back(a[r]->vertices);
  }
  ring_start_.push_back(old_.size());
  global_ = fit_boundary_deformation(old_, new_);
  Eigen::Vector2d lo = old_.front(), hi = lo;
  for (const Eigen::Vector2d& v : old_) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  tolerance_ = 1e-9 * (hi - lo).norm();
  rings_.emplace(RingGeometry::of_rings(curves));
}

Eigen::Vector2d LayoutMotion::operator()(const Eigen::Vector2d& x) const {
  // On a ring: with the edge it lies on (a vertex is an end of its edges).
  const int e = rings_->nearest(x);
  if (e >= 0) {
    const RingGeometry::Edge& edge = rings_->edge(e);
    if (segment_distance(x, edge.a, edge.b) <= tolerance_) {
      const std::size_t first = ring_start_[edge.ring], n = ring_start_[edge.ring + 1] - first;
      const std::size_t i = first + edge.index, j = first + (edge.index + 1) % n;
      const Eigen::Vector2d ab = edge.b - edge.a;
      const double t = std::clamp((x - edge.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      if (x == edge.a) return new_[i];
      if (x == edge.b) return new_[j];
      return (1.0 - t) * new_[i] + t * new_[j];
    }
  }
  // Inside: the affine part and the mean value interpolant of the rings'
  // residuals (Floater 2003; Hormann & Floater 2006 for polygons with holes:
  // signed angles, every ring oriented with the domain on its left, i.e. holes
  // clockwise). It reproduces the residual's piecewise linear values on the
  // ring edges (so a point near the coast moves as the coast next to it) and
  // linear functions.
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double w = 0.0;
  for (std::size_t r = 0; r + 1 < ring_start_.size(); ++r) {
    const std::size_t first = ring_start_[r], n = ring_start_[r + 1] - first;
    const bool reverse = r > 0;  // validated holes run counter-clockwise
    auto vertex = [&](std::size_t k) { return first + (reverse ? (n - k) % n : k % n); };
    // tan(alpha_k / 2) of the signed angle at x from vertex k to vertex k + 1.
    auto half_tan = [&](std::size_t k) {
      const Eigen::Vector2d a = old_[vertex(k)] - x, b = old_[vertex(k + 1)] - x;
      return (a.x() * b.y() - a.y() * b.x()) / (a.norm() * b.norm() + a.dot(b));
    };
    double t_prev = half_tan(n - 1);
    for (std::size_t k = 0; k < n; ++k) {
      const double t = half_tan(k);
      const std::size_t i = vertex(k);
      const double wk = (t_prev + t) / (old_[i] - x).norm();
      sum += wk * global_.residual[i];
      w += wk;
      t_prev = t;
    }
  }
  return global_.affine(x) + sum / w;
}

MultiPatchResult reparameterize_layout(const PreviousLayout& old, const Domain& moved_in,
                                       const ParameterizationOptions& options, const AdaptiveOptions& adaptive,
                                       const MultiPatchOptions& multi, const PatchCallback& on_patch,
                                       int layout_sweeps) {
  const std::size_t P = old.maps.size();
  if (P == 0 || old.polygons.size() != P || old.corners.size() != P)
    throw InputError("the previous layout has no patches, or not one polygon and corners per patch");
  const auto a = rings_of(old.domain), b = rings_of(moved_in);
  if (a.size() != b.size())
    throw InputError("the moved domain has " + std::to_string(b.size()) + " rings, the previous map's " +
                     std::to_string(a.size()) + " (ring k moves to ring k)");
  for (std::size_t r = 0; r < a.size(); ++r)
    if (a[r]->vertices.size() != b[r]->vertices.size())
      throw InputError(ring_name(r) + " of the moved domain has " + std::to_string(b[r]->vertices.size()) +
                       " vertices, the previous map's " + std::to_string(a[r]->vertices.size()));
  // Simple rings that do not cross; nothing removed (the counts must stay) and
  // the same orientation (validate_domain turns every ring counter-clockwise).
  DomainCleaningOptions keep;
  keep.needle_width = 0.0;
  const Domain moved = validate_domain(moved_in, keep);
  const auto c = rings_of(moved);
  if (c.size() != a.size()) throw InputError("the moved domain lost a hole when it was validated");
  for (std::size_t r = 0; r < c.size(); ++r)
    if (c[r]->vertices != b[r]->vertices)
      throw InputError(ring_name(r) + " of the moved domain runs the other way round or lost a vertex when it was "
                                      "validated (a reflection, or a spike of zero width)");

  const LayoutMotion motion(old.domain, moved);
  MultiPatchResult R;
  R.domain = moved;
  R.cuts_explanation = "warm start: the previous layout moved with the domain";
  for (const Cut& cut : old.cuts) {
    Cut m;
    for (const Eigen::Vector2d& p : cut) m.push_back(motion(p));
    R.layout.cuts.push_back(std::move(m));
  }
  R.layout.interfaces = old.interfaces;
  for (std::size_t p = 0; p < P; ++p) {
    Patch patch;
    patch.polygon = old.polygons[p];
    patch.corners = old.corners[p];
    for (Eigen::Vector2d& v : patch.polygon.vertices) v = motion(v);
    R.layout.patches.push_back(std::move(patch));
  }
  for (const Interface& f : R.layout.interfaces) {
    R.layout.patches[f.patch_a].side_cut[f.side_a] = static_cast<int>(f.cut);
    R.layout.patches[f.patch_b].side_cut[f.side_b] = static_cast<int>(f.cut);
  }
  if (layout_sweeps > 0) reoptimize_inner_nodes(R.layout, moved, layout_sweeps);
  std::vector<BoundaryDeformation> per_patch(P);
  for (std::size_t p = 0; p < P; ++p) {
    const Patch& patch = R.layout.patches[p];
    per_patch[p].A = motion.deformation().A;
    per_patch[p].b = motion.deformation().b;
    for (std::size_t k = 0; k < patch.polygon.vertices.size(); ++k)
      per_patch[p].residual.push_back(patch.polygon.vertices[k] - per_patch[p].affine(old.polygons[p].vertices[k]));
    try {
      const Polygon checked = validate_polygon(patch.polygon);
      if (checked.vertices != patch.polygon.vertices) throw InputError("it turned over");
    } catch (const InputError& e) {
      const Eigen::Vector2d at = patch.polygon.vertices.front();
      throw InputError("the motion is too large for the previous layout: patch " + std::to_string(p) + " near (" +
                       std::to_string(at.x()) + ", " + std::to_string(at.y()) + ") folds (" + e.what() +
                       "); map the moved domain from scratch, or move it in smaller steps");
    }
  }
  R.diameter = bounding_box_diagonal(moved.outer);
  R.domain_area = domain_area(R.domain);
  report_step(options.progress, "patches",
              "warm start: " + std::to_string(P) + " patches of the previous layout moved with the domain");

  // The patches, each from its previous map, on `threads` threads.
  std::mutex progress_mutex;
  ParameterizationOptions shared = options;
  shared.progress = locked_progress(options.progress, progress_mutex);
  std::vector<std::optional<ParameterizationResult>> runs(P);
  const unsigned threads = patch_threads(multi.threads);
  for_each_patch(P, threads, [&](std::size_t p) {
    if (on_patch) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      on_patch(p, 0);
    }
    ParameterizationOptions po = shared;
    po.progress = patch_progress(shared.progress, p);
    runs[p].emplace(reparameterize(*old.maps[p], old.polygons[p], old.corners[p], R.layout.patches[p].polygon,
                                   per_patch[p], po, adaptive,
                                   old.reference_mean_ratio.size() == P
                                       ? std::optional<double>(old.reference_mean_ratio[p])
                                       : std::nullopt));
  });
  R.patches.reserve(P);
  for (auto& r : runs) R.patches.push_back(std::move(*r));
  finish_multipatch_result(R, adaptive, options.max_level, options.progress);
  return R;
}

}  // namespace tspline
