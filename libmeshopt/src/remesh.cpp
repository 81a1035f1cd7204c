// Algorithms 1-3 of Dassi, Mola & Si 2014 (SAMPLING, OPTIMIZING, RE-MESHING).
#include "meshopt/remesh.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>

#include "remesher.h"
#include "toolkit/errors.h"
#include "toolkit/timing.h"

namespace meshopt {
namespace {

using detail::Remesher;

using toolkit::seconds_since;

void validate(const RemeshOptions& o) {
  auto bad = [](const std::string& what) { throw toolkit::InputError("meshopt::remesh: " + what); };
  if (!(o.length > 0.0) || !std::isfinite(o.length)) bad("the length L must be positive and finite");
  if (!(o.anisotropy >= 0.0) || !std::isfinite(o.anisotropy)) bad("the anisotropy s must be finite and >= 0");
  if (!(o.min_angle >= 0.0) || !(o.min_angle < std::numbers::pi / 3.0)) bad("theta_min must be in [0, 60) degrees");
  if (o.rounds < 0 || o.outer < 0 || o.inner < 0) bad("K, I and J must be >= 0");
  if (!(o.smooth_fraction >= 0.0) || !(o.smooth_fraction <= 1.0)) bad("the smoothed fraction must be in [0, 1]");
  if (!(o.inversion_angle > 0.0) || !(o.inversion_angle <= std::numbers::pi)) bad("alpha must be in (0, pi]");
  if (!(o.max_deviation >= 0.0) || !std::isfinite(o.max_deviation)) bad("the maximum deviation must be finite and >= 0");
  if (o.max_flip_passes < 1) bad("max_flip_passes must be >= 1");
}

std::deque<int> all_triangles(const RemeshMesh& m) {
  std::deque<int> q;
  for (std::size_t t = 0; t < m.triangles.size(); ++t)
    if (m.triangles[t].alive) q.push_back(static_cast<int>(t));
  return q;
}

/// Algorithm 1.
void sampling(Remesher& r, const RemeshOptions& o) {
  RemeshMesh& m = r.mesh();
  std::deque<int> q = all_triangles(m);
  // Each split adds a vertex; the cap only guards against a model that never
  // lets edges shrink (e.g. projections that fail).
  const std::size_t max_splits = 20 * m.triangles.size() + 1000000;
  std::size_t splits = 0;
  while (!q.empty() && splits < max_splits) {
    const int f = q.front();
    q.pop_front();
    if (!m.triangles[f].alive) continue;
    auto [a, b] = r.extreme_edge(f, true);
    if (!(r.length(a, b) > 1.5 * o.length)) {
      // The accuracy cap: split the most curved chord (each half has about a
      // quarter of its II(e, e), chordal_estimate.h).
      if (!r.too_deviant(f)) continue;
      const detail::Edge e = r.most_curved_edge(f);
      a = e[0];
      b = e[1];
    }
    const int c = r.split(a, b);
    if (c < 0) continue;
    ++splits;
    for (int t : m.triangles_of(c)) q.push_back(t);
  }
  r.improve_all_by_flips();
  q = all_triangles(m);
  while (!q.empty()) {
    const int f = q.front();
    q.pop_front();
    if (!m.triangles[f].alive) continue;
    const auto [a, b] = r.extreme_edge(f, false);
    if (!(r.length(a, b) < 0.5 * o.length)) continue;
    const int kept = r.collapse(a, b, 1.5 * o.length);
    if (kept < 0) continue;
    for (int t : m.triangles_of(kept)) q.push_back(t);
  }
  r.improve_all_by_flips();
}

/// Algorithm 2, line 6: collapse the shortest edge of triangles with a 6D angle below theta_min.
void collapse_small_angles(Remesher& r, const RemeshOptions& o) {
  RemeshMesh& m = r.mesh();
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    if (!m.triangles[t].alive || !(r.min_angle(static_cast<int>(t)) < o.min_angle)) continue;
    const auto [a, b] = r.extreme_edge(static_cast<int>(t), false);
    r.collapse(a, b, 1.5 * o.length);
  }
}

/// Algorithm 2.
void optimizing(Remesher& r, const RemeshOptions& o) {
  for (int i = 0; i < o.outer; ++i) {
    for (int j = 0; j < o.inner; ++j) {
      r.smooth(o.smooth_fraction);
      r.improve_all_by_flips();
    }
    collapse_small_angles(r, o);
    r.improve_all_by_flips();
  }
}

}  // namespace

RemeshReport remesh(RemeshMesh& mesh, const RemeshGeometry& geometry, const RemeshOptions& options) {
  validate(options);
  RemeshReport report;
  Remesher r(mesh, geometry, options, report);
  for (int k = 0; k < options.rounds; ++k) {  // Algorithm 3
    if (options.progress) options.progress(k, "sampling");
    auto t0 = std::chrono::steady_clock::now();
    sampling(r, options);
    report.seconds_sampling += seconds_since(t0);
    if (options.progress) options.progress(k, "optimizing");
    t0 = std::chrono::steady_clock::now();
    optimizing(r, options);
    report.seconds_optimizing += seconds_since(t0);
  }
  mesh.compact();
  return report;
}

}  // namespace meshopt
