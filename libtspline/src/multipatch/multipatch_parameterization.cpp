#include "tspline/multipatch/multipatch_parameterization.h"

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>
#include <mutex>
#include <numeric>
#include <set>
#include <thread>

#include "tspline/boundary/border_knots.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/errors.h"
#include "tspline/multipatch/automatic_cuts.h"
#include "tspline/spline/bezier_extraction.h"
#include "tspline/spline/map_side.h"
#include "tspline/spline/tspline_fit.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"

namespace tspline {

Eigen::Vector2d side_point_uv(int side, double t) {
  switch (static_cast<Side>(side)) {
    case Side::Bottom: return {t, 0.0};
    case Side::Right: return {1.0, t};
    case Side::Top: return {1.0 - t, 1.0};
    case Side::Left: return {0.0, 1.0 - t};
  }
  return {0.0, 0.0};
}

double map_area(const TSplineMap& map) {
  // Green's theorem: the integral of det J over [0,1]^2 is the integral of
  // x dy along the image of the square's border, counter-clockwise (any
  // piecewise C1 map). On the border the functions that do not vanish sum to 1,
  // so between two border knots x(t) is a cubic polynomial and x y'(t) one of
  // degree 5: 3 Gauss points per span integrate it exactly (4 are used).
  static const double g[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  static const Eigen::Vector2d direction[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};  // d uv / dt per side
  const double x0 = map.point({0.0, 0.0}).x();  // the integral of x0 dy around a closed curve is 0
  double area = 0.0;
  for (int side = 0; side < 4; ++side) {
    std::vector<double> t = border_params(map.mesh(), static_cast<Side>(side));
    t.push_back(0.0), t.push_back(1.0);
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end()), t.end());
    for (std::size_t k = 0; k + 1 < t.size(); ++k) {
      const double a = t[k], h = t[k + 1] - t[k];
      for (int i = 0; i < 4; ++i) {
        const double s = a + 0.5 * h * (1.0 + g[i]);
        const MapDerivatives d = map.derivatives(side_point_uv(side, s), 1);
        const double dy = (d.J * direction[side]).y();
        area += 0.5 * h * w[i] * (d.x.x() - x0) * dy;
      }
    }
  }
  return area;
}

double interface_gap(const TSplineMap& a, int side_a, const TSplineMap& b, int side_b) {
  std::vector<double> t = border_params(a.mesh(), static_cast<Side>(side_a));
  for (double s : border_params(b.mesh(), static_cast<Side>(side_b))) t.push_back(reversed_param(s));
  for (int k = 0; k <= 64; ++k) t.push_back(k / 64.0);
  // Both sides' points as TSplineMap::point gives them (map_side.h).
  const MapSide sa(a, side_a), sb(b, side_b);
  double gap = 0.0;
  for (double s : t) gap = std::max(gap, (sa.at(s) - sb.at(reversed_param(s))).norm());
  return gap;
}

double MultiPatchResult::max_gap() const {
  double g = 0.0;
  for (const InterfaceReport& i : interfaces) g = std::max(g, i.max_gap);
  return g;
}

bool MultiPatchResult::valid() const {
  return std::all_of(patches.begin(), patches.end(), [](const ParameterizationResult& r) { return r.valid(); });
}

namespace {

// The least sine of the patch polygon's angles at its four corners (negative
// at a reflex corner; -1 where a corner has a zero-length edge).
double worst_corner_sine(const Patch& patch) {
  const std::vector<Eigen::Vector2d>& v = patch.polygon.vertices;
  const std::size_t n = v.size();
  double worst = 1.0;
  for (const std::size_t c : patch.corners) {
    const Eigen::Vector2d a = v[(c + 1) % n] - v[c], b = v[(c + n - 1) % n] - v[c];
    const double l = a.norm() * b.norm();
    worst = std::min(worst, l > 0.0 ? (a.x() * b.y() - a.y() * b.x()) / l : -1.0);
  }
  return worst;
}

/// The least of value(r) over the patches' results (+infinity for none).
template <class Value>
double min_over_patches(const std::vector<ParameterizationResult>& patches, Value value) {
  double m = std::numeric_limits<double>::infinity();
  for (const ParameterizationResult& r : patches) m = std::min(m, value(r));
  return m;
}

}  // namespace

bool MultiPatchResult::certified_valid() const {
  return std::all_of(patches.begin(), patches.end(),
                     [](const ParameterizationResult& r) { return r.certified_valid(); });
}

double MultiPatchResult::min_relative_det_bound() const {
  return min_over_patches(patches,
                          [](const ParameterizationResult& r) { return r.certification.min_relative_lower_bound; });
}

double MultiPatchResult::min_mean_ratio_dense() const {
  return min_over_patches(patches, [](const ParameterizationResult& r) { return r.dense_quality.min_mean_ratio; });
}

double MultiPatchResult::min_scaled_jacobian_dense() const {
  return min_over_patches(patches, [](const ParameterizationResult& r) { return r.dense_quality.min_scaled; });
}

double MultiPatchResult::min_mean_ratio_gauss() const {
  return min_over_patches(patches, [](const ParameterizationResult& r) { return r.quality.min_mean_ratio; });
}

namespace {

// Knots of both sides of interface f (patch a's parameters; b's mirrored).
std::set<double> interface_knots(const MultiPatchResult& R, const Interface& f) {
  std::set<double> u;
  for (double t : border_params(R.patches[f.patch_a].map->mesh(), static_cast<Side>(f.side_a))) u.insert(t);
  for (double t : border_params(R.patches[f.patch_b].map->mesh(), static_cast<Side>(f.side_b)))
    u.insert(reversed_param(t));
  return u;
}

InterfaceReport measure_interface(const MultiPatchResult& R, const Interface& f) {
  const TSplineMap& a = *R.patches[f.patch_a].map;
  const TSplineMap& b = *R.patches[f.patch_b].map;
  InterfaceReport rep;
  rep.max_gap = interface_gap(a, f.side_a, b, f.side_b);
  const std::vector<double> ka = border_params(a.mesh(), static_cast<Side>(f.side_a));
  std::vector<double> kb = border_params(b.mesh(), static_cast<Side>(f.side_b));
  rep.knots_a = ka.size();
  rep.knots_b = kb.size();
  for (double& t : kb) t = reversed_param(t);
  std::sort(kb.begin(), kb.end());
  rep.same_knots = ka == kb;
  return rep;
}

// Every interface of R measured (R.interfaces), on the pool's threads.
void measure_interfaces(MultiPatchResult& R) {
  R.interfaces.assign(R.layout.interfaces.size(), {});
  detail::parallel_items(
      R.layout.interfaces.size(), detail::pool_threads(),
      [&](std::size_t i) { R.interfaces[i] = measure_interface(R, R.layout.interfaces[i]); }, 16);
}

// Once the boundary curves agree, the later adaptive rounds may still have
// refined one side of an interface and not the other. Each patch is refined to
// the union of the knots of its interfaces and its map carried over
// (transfer_map reproduces the boundary curve exactly; inside it is the
// interpolant of the old map), then checked again: the new map replaces the
// old one only if it is still certified (or the old one was not either).
// Returns the number of patches refined (0: every interface has one set of knots).
std::size_t equalize_interface_knots(MultiPatchResult& R, const AdaptiveOptions& ad, int max_level) {
  std::vector<BorderParams> want(R.patches.size());
  for (const Interface& f : R.layout.interfaces) {
    const std::set<double> u = interface_knots(R, f);
    for (double t : u) {
      want[f.patch_a][f.side_a].push_back(t);
      want[f.patch_b][f.side_b].push_back(reversed_param(t));
    }
  }
  // Each patch on its own (want is read only): on the pool's threads.
  std::atomic<std::size_t> count{0};
  detail::parallel_items(R.patches.size(), detail::pool_threads(), [&](std::size_t p) {
    ParameterizationResult& r = R.patches[p];
    TMesh mesh = r.map->mesh();
    if (refine_to_border_params(mesh, want[p], max_level) == 0) return;
    TSplineMap map = transfer_map(*r.map, std::move(mesh));
    const BezierExtraction extraction(map.basis());  // (one for the three checks)
    MapCertification cert =
        ad.certify ? certify_map(extraction, map.mesh().num_cells(), map.control_points(), ad.certification)
                   : MapCertification{};
    if (ad.certify && r.certified_valid() && !cert.certified_valid()) return;
    ++count;
    std::vector<CellMapQuality> cells;
    r.quality = map_quality(map, extraction, ad.gauss, &cells);
    r.cell_quality = std::move(cells);
    r.dense_quality = dense_map_quality(extraction, map.control_points(), ad.dense_samples);
    r.certification = std::move(cert);
    r.front.mesh = map.mesh();
    r.front.optimized.assign(r.front.mesh.num_vertices(), Eigen::Vector2d::Zero());
    for (int v = 0; v < static_cast<int>(r.front.mesh.num_vertices()); ++v)
      r.front.optimized[v] = map.point(r.front.mesh.vertex_param(v));
    r.map.emplace(std::move(map));
  });
  return count;
}

}  // namespace

MultiPatchResult run_multipatch_parameterization(const Domain& input, const std::optional<std::vector<Cut>>& cuts,
                                                 const ParameterizationOptions& options,
                                                 const AdaptiveOptions& adaptive, const MultiPatchOptions& multi,
                                                 const PatchCallback& on_patch) {
  const Domain domain = validate_domain(input);
  if (cuts) return run_multipatch_parameterization(domain, build_patch_layout(domain, *cuts), "given", options,
                                                   adaptive, multi, on_patch);
  AutomaticCuts a = automatic_cuts(domain);
  PatchLayout layout = build_patch_layout(domain, std::move(a.cuts));
  return run_multipatch_parameterization(domain, std::move(layout), "automatic: " + a.explanation, options, adaptive,
                                         multi, on_patch);
}

MultiPatchResult run_multipatch_parameterization(const Domain& domain, PatchLayout layout,
                                                 const std::string& explanation,
                                                 const ParameterizationOptions& options,
                                                 const AdaptiveOptions& adaptive, const MultiPatchOptions& multi,
                                                 const PatchCallback& on_patch) {
  if (multi.max_sync_rounds < 0) throw InputError("the number of interface rounds must be >= 0");
  if (multi.threads < 0) throw InputError("the number of threads must be >= 0");
  auto log = [&](const std::string& s) { report_step(options.progress, "patches", s); };
  MultiPatchResult R;
  R.domain = domain;
  R.layout = std::move(layout);
  R.cuts_explanation = explanation;
  R.diameter = bounding_box_diagonal(R.domain.outer);
  R.domain_area = domain_area(R.domain);
  const std::size_t P = R.layout.patches.size();
  log("patches: " + std::to_string(P) + " four-sided patches, " + std::to_string(R.layout.cuts.size()) + " cuts (" +
      R.cuts_explanation + ")");
  // Progress events of concurrent patches go through one lock.
  std::mutex progress_mutex;
  ParameterizationOptions shared = options;
  shared.progress = locked_progress(options.progress, progress_mutex);
  const unsigned threads = patch_threads(multi.threads);

  std::vector<BorderParams> required(P);
  std::vector<char> stale(P, 1);
  R.patches.reserve(P);
  auto check_cancel = [&multi] {
    if (multi.cancel && multi.cancel->load(std::memory_order_relaxed)) throw MultiPatchCancelled();
  };
  for (int round = 0;; ++round) {
    check_cancel();
    std::vector<std::size_t> todo;
    for (std::size_t p = 0; p < P; ++p)
      if (stale[p]) todo.push_back(p);
    std::vector<std::optional<ParameterizationResult>> runs(todo.size());
    // The order the patches are run in (their results keep the patches'
    // order). Where a patch below the thresholds stops the run, those most
    // likely to be below go first: the ones with the sharpest polygon corner
    // (the map's scaled Jacobian at a patch corner is the sine of the angle
    // between the fitted sides there, corner_quality.h). Newfoundland's first
    // layout stopped at patch 1,005 of 5,645 in index order.
    std::vector<std::size_t> order(todo.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    if (round == 0 && multi.stop_when) {
      std::vector<double> sine(todo.size());
      for (std::size_t i = 0; i < todo.size(); ++i) sine[i] = worst_corner_sine(R.layout.patches[todo[i]]);
      std::stable_sort(order.begin(), order.end(),
                       [&sine](std::size_t a, std::size_t b) { return sine[a] < sine[b]; });
    }
    for_each_patch(todo.size(), threads, [&](std::size_t k) {
      check_cancel();
      const std::size_t i = order[k];
      const std::size_t p = todo[i];
      if (on_patch) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        on_patch(p, round);
      }
      ParameterizationOptions po = shared;
      const Patch& patch = R.layout.patches[p];
      po.corners = std::array<long long, 4>{};
      for (int k = 0; k < 4; ++k) (*po.corners)[k] = static_cast<long long>(patch.corners[k]);
      po.corner_trials = 1;
      // A patch is fitted at least as closely as alone (tolerance_relative of
      // its own diagonal), however large an absolute tolerance: an area near
      // a small patch's own would let its fit drop the patch's corners.
      if (po.tolerance_absolute) {
        const double d = bounding_box_diagonal(patch.polygon);
        po.tolerance_absolute = std::min(*po.tolerance_absolute, po.tolerance_relative * d * d);
      }
      // Its ring was cleaned with the domain: nothing more is removed from it
      // (ParameterizationOptions::needle_width).
      po.needle_width = 0.0;
      po.border_params = required[p];
      po.progress = patch_progress(shared.progress, p);
      try {
        runs[i].emplace(run_parameterization(patch.polygon, po, adaptive));
      } catch (const InputError& e) {  // (its corners and polygon come from the layout: say which patch)
        throw InputError("patch " + std::to_string(p) + " of the layout: " + e.what());
      }
      if (!runs[i]->map) throw NumericalError("patch " + std::to_string(p) + ": no map was produced");
      if (round == 0 && multi.stop_when)
        if (const std::string why = multi.stop_when(p, *runs[i]); !why.empty())
          throw MultiPatchStopped("patch " + std::to_string(p) + " " + why);
    });
    for (std::size_t i = 0; i < todo.size(); ++i) {
      const std::size_t p = todo[i];
      if (round == 0) R.patches.push_back(std::move(*runs[i]));  // round 0 runs every patch, in order
      else R.patches[p] = std::move(*runs[i]);
      stale[p] = 0;
    }
    // Interfaces: gaps and knots.
    measure_interfaces(R);
    bool all_conform = true;
    for (std::size_t i = 0; i < R.layout.interfaces.size(); ++i) {
      const Interface& f = R.layout.interfaces[i];
      const InterfaceReport& rep = R.interfaces[i];
      if (rep.max_gap <= multi.gap_tolerance * R.diameter) continue;
      all_conform = false;
      if (round >= multi.max_sync_rounds) continue;
      // Both sides get the union of the knots, mirrored for patch b.
      std::set<double> u = interface_knots(R, f);
      u.insert(required[f.patch_a][f.side_a].begin(), required[f.patch_a][f.side_a].end());
      for (double t : required[f.patch_b][f.side_b]) u.insert(reversed_param(t));
      required[f.patch_a][f.side_a].assign(u.begin(), u.end());
      required[f.patch_b][f.side_b].clear();
      for (double t : u) required[f.patch_b][f.side_b].push_back(reversed_param(t));
      stale[f.patch_a] = stale[f.patch_b] = 1;
    }
    if (all_conform || round >= multi.max_sync_rounds) {
      R.sync_rounds = round;
      break;
    }
    log("interfaces: re-running " + std::to_string(std::count(stale.begin(), stale.end(), 1)) +
        " patches with the union of the knots of their interfaces");
  }
  finish_multipatch_result(R, adaptive, options.max_level, options.progress);
  return R;
}

void for_each_patch(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& task) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&]() {
    for (std::size_t i; !failed && (i = next++) < n;) {
      try {
        task(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  const unsigned k = static_cast<unsigned>(std::min<std::size_t>(threads, n));
  if (k <= 1) work();
  else {
    std::vector<std::thread> pool;
    // The patches keep the cores busy: a patch's own parallel calls run their
    // ranges in its thread (the same results) instead of waking pool workers.
    for (unsigned t = 0; t < k; ++t) pool.emplace_back([&work] {
        const detail::SerialRanges serial;
        work();
      });
    for (std::thread& t : pool) t.join();
  }
  if (error) std::rethrow_exception(error);
}

unsigned patch_threads(int requested) {
  return requested > 0 ? static_cast<unsigned>(requested) : detail::hardware_threads();
}

ProgressCallback locked_progress(const ProgressCallback& progress, std::mutex& lock) {
  if (!progress) return {};
  return [progress, &lock](const ProgressEvent& e) {
    std::lock_guard<std::mutex> hold(lock);
    progress(e);
  };
}

ProgressCallback patch_progress(const ProgressCallback& progress, std::size_t p) {
  if (!progress) return {};
  return [progress, p](const ProgressEvent& e) {
    ProgressEvent f = e;
    f.text = "patch " + std::to_string(p) + ": " + e.text;
    progress(f);
  };
}

void finish_multipatch_result(MultiPatchResult& R, const AdaptiveOptions& adaptive, int max_level,
                              const ProgressCallback& progress) {
  // Refining a patch to the knots of one interface can refine its others (the
  // T-mesh stays balanced): repeat until every interface has one set of knots.
  // (A large layout spends seconds here: the user is told.)
  report_step(progress, "interfaces",
              "interfaces: one set of knots on every interface (each patch refined to the knots of all its "
              "interfaces, " + std::to_string(R.patches.size()) + " patches), then the gaps measured");
  std::size_t refined = 0;
  for (int round = 0; round < 16; ++round) {
    const std::size_t n = equalize_interface_knots(R, adaptive, max_level);
    if (n == 0) break;
    refined += n;
  }
  measure_interfaces(R);
  report_step(progress, "interfaces",
              "interfaces: " + std::to_string(refined) + " patch refinement(s) to their interfaces' knots, " +
                  std::to_string(R.interfaces.size()) + " interfaces measured");
  // The patches' areas on the pool's threads, summed in patch order.
  const std::size_t P = R.patches.size();
  std::vector<double> areas(P);
  detail::parallel_items(P, detail::pool_threads(),
                         [&](std::size_t p) { areas[p] = map_area(*R.patches[p].map); });
  R.map_area = std::accumulate(areas.begin(), areas.end(), 0.0);
}

}  // namespace tspline
