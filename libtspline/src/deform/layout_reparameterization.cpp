#include "tspline/deform/layout_reparameterization.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <string>
#include <thread>

#include "tspline/boundary/polygon_validation.h"
#include "tspline/deform/reparameterization.h"
#include "tspline/errors.h"

namespace tspline {
namespace {

std::vector<const Polygon*> rings_of(const Domain& d) {
  std::vector<const Polygon*> r = {&d.outer};
  for (const Polygon& h : d.holes) r.push_back(&h);
  return r;
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
  // Inside: the affine part and Shepard's inverse-distance average (power 2)
  // of the rings' residuals, a smooth field that equals them at the rings.
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double w = 0.0;
  for (std::size_t k = 0; k < old_.size(); ++k) {
    const double d2 = (x - old_[k]).squaredNorm();
    sum += global_.residual[k] / d2;
    w += 1.0 / d2;
  }
  return global_.affine(x) + sum / w;
}

MultiPatchResult reparameterize_layout(const PreviousLayout& old, const Domain& moved_in,
                                       const ParameterizationOptions& options, const AdaptiveOptions& adaptive,
                                       const MultiPatchOptions& multi, const PatchCallback& on_patch) {
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
  std::vector<BoundaryDeformation> per_patch(P);
  for (std::size_t p = 0; p < P; ++p) {
    Patch patch;
    patch.polygon = old.polygons[p];
    patch.corners = old.corners[p];
    per_patch[p].A = motion.deformation().A;
    per_patch[p].b = motion.deformation().b;
    for (Eigen::Vector2d& v : patch.polygon.vertices) {
      const Eigen::Vector2d to = motion(v);
      per_patch[p].residual.push_back(to - per_patch[p].affine(v));
      v = to;
    }
    try {
      const Polygon checked = validate_polygon(patch.polygon);
      if (checked.vertices != patch.polygon.vertices) throw InputError("it turned over");
    } catch (const InputError& e) {
      const Eigen::Vector2d at = patch.polygon.vertices.front();
      throw InputError("the motion is too large for the previous layout: patch " + std::to_string(p) + " near (" +
                       std::to_string(at.x()) + ", " + std::to_string(at.y()) + ") folds (" + e.what() +
                       "); map the moved domain from scratch, or move it in smaller steps");
    }
    R.layout.patches.push_back(std::move(patch));
  }
  for (const Interface& f : R.layout.interfaces) {
    R.layout.patches[f.patch_a].side_cut[f.side_a] = static_cast<int>(f.cut);
    R.layout.patches[f.patch_b].side_cut[f.side_b] = static_cast<int>(f.cut);
  }
  {
    Eigen::Vector2d lo = moved.outer.vertices.front(), hi = lo;
    for (const auto& v : moved.outer.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    R.diameter = (hi - lo).norm();
  }
  R.domain_area = domain_area(R.domain);
  report_step(options.progress, "patches",
              "warm start: " + std::to_string(P) + " patches of the previous layout moved with the domain");

  // The patches, each from its previous map, on `threads` threads.
  std::mutex progress_mutex;
  ParameterizationOptions shared = options;
  if (options.progress)
    shared.progress = [cb = options.progress, &progress_mutex](const ProgressEvent& e) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      cb(e);
    };
  std::vector<std::optional<ParameterizationResult>> runs(P);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&]() {
    for (std::size_t p; !failed && (p = next++) < P;) {
      try {
        if (on_patch) {
          std::lock_guard<std::mutex> lock(progress_mutex);
          on_patch(p, 0);
        }
        ParameterizationOptions po = shared;
        if (shared.progress)
          po.progress = [cb = shared.progress, p](const ProgressEvent& e) {
            ProgressEvent f = e;
            f.text = "patch " + std::to_string(p) + ": " + e.text;
            cb(f);
          };
        runs[p].emplace(reparameterize(*old.maps[p], old.polygons[p], old.corners[p], R.layout.patches[p].polygon,
                                       per_patch[p], po, adaptive));
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  const unsigned threads =
      multi.threads > 0 ? static_cast<unsigned>(multi.threads) : std::max(1u, std::thread::hardware_concurrency());
  const unsigned n = static_cast<unsigned>(std::min<std::size_t>(threads, P));
  if (n <= 1) work();
  else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < n; ++t) pool.emplace_back(work);
    for (std::thread& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
  R.patches.reserve(P);
  for (auto& r : runs) R.patches.push_back(std::move(*r));
  finish_multipatch_result(R, adaptive, options.max_level);
  return R;
}

}  // namespace tspline
