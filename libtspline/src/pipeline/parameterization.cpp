#include "tspline/pipeline/parameterization.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>

#include "tspline/tmesh/coons.h"
#include "tspline/boundary/corners.h"
#include "tspline/errors.h"
#include "tspline/boundary/plane.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/tmesh/smoothing_problem.h"
#include "tspline/tmesh/tmesh_transfer.h"

namespace tspline {

namespace {

// Accumulates wall time per stage; stages may be entered several times.
class StageClock {
 public:
  explicit StageClock(std::vector<StageTime>& times) : times_(times) {}
  void stop(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    for (StageTime& t : times_)
      if (t.stage == stage) return void(t.seconds += dt);
    times_.push_back({stage, dt});
  }

 private:
  std::vector<StageTime>& times_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The nested sequence of meshes (coarse to fine) on which the optimization runs.
// Stage k has uniform level level[k] and boundary tolerance tol[k]; both are
// monotone, so every stage's tree refines the previous one, and the last stage
// is exactly the T-mesh of (initial_level, tolerance) built directly (the
// refinement criterion of a cell depends only on the cell, and the 2:1 balanced
// closure of a tree is unique).
struct Stages {
  std::vector<int> level;
  std::vector<double> tol;
};

Stages nested_stages(int initial_level, double tol, double diag, bool nested) {
  Stages st;
  if (!nested) return Stages{{initial_level}, {tol}};
  // Coarsest stage: level <= 2 and a tolerance of 1e-3 diag^2 (a handful of
  // boundary cells). Each stage halves the cell size: the uniform level grows by
  // one, and the area criterion, which scales like h^3 on a smooth boundary
  // (chord c, sagitta c^2/(8R): area ~ c^3/(16R)), tightens by 8.
  const int l0 = std::min(initial_level, 2);
  const double coarse_tol = 1e-3 * diag * diag;
  int k_tol = 0;
  while (tol * std::pow(8.0, k_tol) < coarse_tol && k_tol < 30) ++k_tol;
  const int stages = std::max(initial_level - l0, k_tol) + 1;
  for (int k = 0; k < stages; ++k) {
    const int remaining = stages - 1 - k;
    st.level.push_back(std::max(l0, initial_level - remaining));
    st.tol.push_back(tol * std::pow(8.0, std::min(remaining, k_tol)));
  }
  return st;
}

// Splits every leaf below `level` (one uniform step of the nested sequence).
void refine_below(TMesh& mesh, int level) {
  for (bool again = true; again;) {
    again = false;
    const std::size_t n = mesh.nodes().size();
    for (std::size_t i = 0; i < n; ++i) {
      if (mesh.node(static_cast<int>(i)).is_leaf() && mesh.node(static_cast<int>(i)).level < level) {
        mesh.refine(static_cast<int>(i));
        again = true;
      }
    }
  }
}


// Runs body(0), ..., body(n - 1) on up to hardware_concurrency threads; the
// first exception thrown by a body is rethrown here once the running bodies
// have finished (no body starts after one has thrown).
template <class Body>
void for_each_concurrently(std::size_t n, Body&& body) {
  const std::size_t threads = std::min<std::size_t>(n, std::max(1u, std::thread::hardware_concurrency()));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::vector<std::exception_ptr> errors(n);
  auto work = [&] {
    for (std::size_t k; !failed && (k = next.fetch_add(1)) < n;) {
      try {
        body(k);
      } catch (...) {
        errors[k] = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace

namespace {

// Everything after the corners: adapted T-mesh, Coons start, nested optimization
// and repair; the stage times go to the result's `times`.
FrontResult optimize_front(BoundaryMap boundary, const ParameterizationOptions& opt) {
  auto log = [&](const char* stage, const std::string& s) { report_step(opt.progress, stage, s); };
  FrontResult r{std::move(boundary)};
  StageClock clock(r.times);

  r.tolerance_is_relative = !opt.tolerance_absolute.has_value();
  const double diag = bounding_box_diagonal(r.boundary.polygon());
  r.tolerance_area = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * diag * diag;

  meshopt::SmoothingOptions sopt = opt.smoothing;
  if (!sopt.progress && opt.progress) {
    sopt.progress = [&](int sweep, double move, std::size_t tangled) {
      ProgressEvent e;
      e.kind = ProgressEvent::Kind::Sweep;
      e.stage = "optimization";
      e.count = sweep;
      e.value = move;
      e.defects = tangled;
      std::ostringstream s;
      s << "sweep " << sweep << ": max relative move " << move << ", tangled nodes " << tangled;
      e.text = s.str();
      opt.progress(e);
    };
  }
  auto optimize = [&](const std::string& what) {
    const meshopt::SmoothingProblem problem = build_smoothing_problem(r.mesh, true);
    r.smoothing = meshopt::smooth(r.optimized, problem, sopt);
    r.total_sweeps += r.smoothing.sweeps;
    r.node_visits += r.smoothing.node_visits;
    r.quality_optimized = mesh_quality(r.mesh, r.optimized);
    std::ostringstream s;
    s << "optimization (" << what << ", " << r.mesh.num_cells() << " cells): " << r.smoothing.sweeps << " sweeps"
      << (r.smoothing.converged ? "" : " (not converged)") << ", " << r.quality_optimized.inverted_cells
      << " inverted cells, min/mean quality " << r.quality_optimized.min_quality << " / "
      << r.quality_optimized.mean_quality;
    log("optimization", s.str());
  };

  // Nested iteration: optimize on a coarse mesh, then refine, carry the
  // positions over and optimize again. Gauss-Seidel sweeps remove the local
  // errors quickly but the smooth, domain-wide ones slowly; on the coarse stages
  // those are cheap, so the finest stage starts close to its optimum.
  const Stages st = nested_stages(opt.initial_level, r.tolerance_area, diag, opt.nested_optimization);
  // The last stage's T-mesh first (milliseconds: a test per cell), so that a
  // tolerance that needs more than max_cells fails at once (refine_to_boundary
  // throws), not after the optimization of every coarser stage.
  if (st.level.size() > 1) {
    TMesh last(opt.initial_level);
    refine_to_boundary(last, r.boundary, {r.tolerance_area, opt.max_level, opt.max_cells});
  }
  for (std::size_t k = 0; k < st.level.size(); ++k) {
    const bool last = k + 1 == st.level.size();
    TMesh coarse = k == 0 ? TMesh(st.level[0]) : r.mesh;
    if (k == 0) r.mesh = TMesh(st.level[0]);
    refine_below(r.mesh, st.level[k]);
    const BoundaryRefinementReport rep =
        refine_to_boundary(r.mesh, r.boundary, {st.tol[k], opt.max_level, opt.max_cells});
    refine_to_border_params(r.mesh, opt.border_params, opt.max_level);
    if (last) r.refinement = rep;
    clock.stop("tmesh");
    if (last) {
      std::ostringstream s;
      s << "t-mesh: " << r.mesh.num_cells() << " cells, " << r.mesh.num_vertices() << " vertices ("
        << r.mesh.num_hanging_vertices() << " hanging), max level " << r.mesh.max_level() << ", tolerance "
        << r.tolerance_area;
      log("tmesh", s.str());
      if (rep.edges_over_tolerance > 0)
        report_step(opt.progress, "tmesh",
                    "warning: " + std::to_string(rep.edges_over_tolerance) +
                        " boundary edges still exceed the tolerance at the maximum level " +
                        std::to_string(opt.max_level),
                    -1, ProgressEvent::Kind::Note);
      // The Coons start of the final T-mesh, for the report (and the start if not nested).
      r.coons = coons_positions(r.mesh, r.boundary);
      r.quality_coons = mesh_quality(r.mesh, r.coons);
      log("coons", "coons: " + std::to_string(r.quality_coons.inverted_cells) + " inverted cells");
      clock.stop("coons");
    }
    // Carry the previous stage over only if it was untangled: a coarse stage
    // can be impossible to untangle (its boundary too coarse for a thin part of
    // the domain), and then the Coons start of the finer mesh is the better start.
    const bool carry = k > 0 && r.quality_optimized.inverted_cells == 0;
    if (carry)
      r.optimized = transfer_positions(coarse, r.optimized, r.mesh, r.boundary);
    else
      r.optimized = last ? r.coons : coons_positions(r.mesh, r.boundary);
    // Intermediate stages only provide a start: a bounded number of sweeps.
    sopt.max_sweeps = last ? opt.smoothing.max_sweeps : std::min(opt.smoothing.max_sweeps, 100);
    optimize(last ? "final mesh" : "stage " + std::to_string(k + 1) + " of " + std::to_string(st.level.size()));
    clock.stop("optimization");
  }

  // Repair: cells that stay inverted lack interior freedom (typically thin
  // features of the domain). Refine them, place the new vertices in the current
  // physical mesh, re-balance and optimize again.
  sopt.max_sweeps = opt.smoothing.max_sweeps;
  for (int round = 0; round < opt.max_repair_rounds && r.quality_optimized.inverted_cells > 0; ++round) {
    const std::vector<CellQuality> q = cell_qualities(r.mesh, r.optimized);
    std::vector<int> inverted;
    for (int c = 0; c < static_cast<int>(q.size()); ++c)
      if (!q[c].valid && r.mesh.cell_level(c) < opt.max_level) inverted.push_back(c);
    if (inverted.empty()) {
      r.repair_stop_reason = "the " + std::to_string(r.quality_optimized.inverted_cells) +
                             " inverted cells are at `max_level` " + std::to_string(opt.max_level);
      log("repair", "repair stopped: " + r.repair_stop_reason);
      break;
    }
    const std::size_t refined = inverted.size();
    TMesh finer = refine_cells(r.mesh, inverted);
    if (finer.num_cells() > opt.max_cells) {
      // The domain needs a finer mesh than allowed (typically a long thin
      // part): say so and stop rather than go on with a tangled mesh.
      std::ostringstream s;
      s << "the polygon needs more than " << opt.max_cells << " cells (`max_cells`): after " << round
        << " repair round(s) " << r.quality_optimized.inverted_cells << " of " << r.mesh.num_cells()
        << " T-mesh cells are still inverted, and refining them makes " << finer.num_cells()
        << " cells; raise `max_cells`, or check the polygon for long thin parts (spikes, narrow channels)";
      throw InputError(s.str());
    }
    // The state before this round, restored if the round makes things worse.
    std::vector<Eigen::Vector2d> before = r.optimized;
    const MeshQualityStats quality_before = r.quality_optimized;
    const meshopt::SmoothingReport smoothing_before = r.smoothing;
    const TMesh coarse = std::exchange(r.mesh, std::move(finer));
    r.optimized = transfer_positions(coarse, r.optimized, r.mesh, r.boundary);
    r.repair_refined_cells.push_back(refined);
    log("repair", "repair round " + std::to_string(round + 1) + ": refined " + std::to_string(refined) +
        " inverted cells, now " + std::to_string(r.mesh.num_cells()) + " cells");
    optimize("repair " + std::to_string(round + 1));
    clock.stop("repair");
    if (r.quality_optimized.inverted_cells > quality_before.inverted_cells) {
      // Diverging (the inverted region grows with each round, as where a long
      // thin part needs far finer cells than its neighbourhood): more rounds
      // only multiply the cells. Keep the mesh before this round.
      r.repair_stop_reason = "repair round " + std::to_string(round + 1) + " left more inverted cells (" +
                             std::to_string(r.quality_optimized.inverted_cells) + ") than before it (" +
                             std::to_string(quality_before.inverted_cells) + "); kept the mesh before it";
      r.mesh = coarse;
      r.optimized = std::move(before);
      r.quality_optimized = quality_before;
      r.smoothing = smoothing_before;
      r.repair_refined_cells.pop_back();
      log("repair", "repair stopped: " + r.repair_stop_reason);
      break;
    }
  }
  return r;
}

}  // namespace

std::size_t best_corner_trial(const std::vector<CornerTrial>& trials) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < trials.size(); ++k) {
    const CornerTrial& a = trials[k];
    const CornerTrial& b = trials[best];
    if (a.inverted_cells < b.inverted_cells ||
        (a.inverted_cells == b.inverted_cells && a.min_quality + a.mean_quality > b.min_quality + b.mean_quality))
      best = k;
  }
  return best;
}

namespace {

// The input ring with needles narrower than the boundary tolerance's width
// (epsilon / diagonal) removed, validated; what was removed, for the report.
struct CleanBoundary {
  Polygon polygon;
  std::vector<std::size_t> removed_vertices;
  std::vector<std::string> notes;
};

CleanBoundary clean_boundary(const Polygon& input, const ParameterizationOptions& opt) {
  const double needle_width = needle_width_for_ring(input, opt.tolerance_absolute, opt.tolerance_relative);
  PolygonCleaning cleaning = clean_polygon(input, needle_width);
  if (!cleaning.notes.empty())
    report_step(opt.progress, "cleaning", "note: " + cleaning_summary("the boundary", cleaning), -1,
                ProgressEvent::Kind::Note);
  CleanBoundary out;
  out.removed_vertices = cleaning.removed_file_indices;
  out.notes = cleaning.notes;
  out.polygon = validate_cleaned_polygon(std::move(cleaning), needle_width);
  return out;
}

// The automatic corner choice tried on the T-mesh: the best few candidates'
// front halves run concurrently and the one with the fewest inverted cells,
// then the highest min + mean triangle quality, is kept.
struct CornerTrials {
  Corners corners;
  std::vector<CornerTrial> trials;
  std::optional<FrontResult> kept;  // the kept choice's front half, if the trials ran at the run's resolution
  std::vector<ProgressEvent> kept_events;  // its progress, replayed if it is the run's
};

// The front half of one trial, its steps and notes collected in `events`;
// sweeps of concurrent trials become heartbeats (the caller may stop the run).
FrontResult run_corner_trial(const Polygon& poly, const Corners& corners, ParameterizationOptions o,
                             const ProgressCallback& progress, std::size_t k, std::vector<ProgressEvent>& events,
                             std::mutex& report_mutex) {
  o.progress = nullptr;
  if (progress)
    o.progress = [&events, &report_mutex, &progress, k](const ProgressEvent& e) {
      if (e.kind == ProgressEvent::Kind::Step || e.kind == ProgressEvent::Kind::Note) {
        events.push_back(e);
        return;
      }
      ProgressEvent beat;
      beat.kind = ProgressEvent::Kind::Heartbeat;
      beat.stage = "corners";
      beat.text = "corner trial " + std::to_string(k + 1) + " working";
      const std::lock_guard<std::mutex> lock(report_mutex);
      progress(beat);
    };
  return optimize_front(BoundaryMap(poly, corners), o);
}

CornerTrials try_corners(const Polygon& poly, std::vector<Corners> cands, const ParameterizationOptions& opt) {
  // Trials at most at the default resolution (level <= 5, tolerance no finer
  // than the default 1e-5 diag^2): for the default options that is the run
  // itself; for fine user settings it keeps the trials cheap.
  ParameterizationOptions topt = opt;
  topt.smoothing.progress = nullptr;
  topt.corner_trials = 1;
  topt.initial_level = std::min(opt.initial_level, 5);
  const double d = bounding_box_diagonal(poly);
  const double tol = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * d * d;
  topt.tolerance_absolute = std::max(tol, 1e-5 * d * d);
  const bool trial_is_run = topt.initial_level == opt.initial_level && *topt.tolerance_absolute == tol;
  std::vector<std::optional<FrontResult>> results(cands.size());
  std::vector<std::vector<ProgressEvent>> events(cands.size());
  std::mutex report_mutex;
  std::size_t finished = 0;
  // A trial that needs more than max_cells with its corners (an InputError;
  // the options were validated) ranks last.
  std::vector<std::exception_ptr> over_budget(cands.size());
  auto report = [&](const std::string& text) {  // under report_mutex
    report_step(opt.progress, "corners",
                "corners: trial " + std::to_string(++finished) + " of " + std::to_string(cands.size()) + text);
  };
  for_each_concurrently(cands.size(), [&](std::size_t k) {
    try {
      results[k].emplace(run_corner_trial(poly, cands[k], topt, opt.progress, k, events[k], report_mutex));
    } catch (const InputError& e) {
      over_budget[k] = std::current_exception();
      const std::lock_guard<std::mutex> lock(report_mutex);
      if (opt.progress) report(" failed (choice " + std::to_string(k + 1) + "): " + e.what());
      return;
    }
    const FrontResult& t = *results[k];
    std::ostringstream s;
    s << " done (choice " << k + 1 << "): " << t.quality_optimized.inverted_cells
      << " inverted cells, min/mean quality " << t.quality_optimized.min_quality << " / "
      << t.quality_optimized.mean_quality;
    const std::lock_guard<std::mutex> lock(report_mutex);
    if (opt.progress) report(s.str());
  });
  CornerTrials out;
  for (std::size_t k = 0; k < cands.size(); ++k) {
    constexpr double kWorst = -std::numeric_limits<double>::infinity();
    if (!results[k]) {
      out.trials.push_back({cands[k].index, std::numeric_limits<std::size_t>::max(), kWorst, kWorst});
      continue;
    }
    const FrontResult& t = *results[k];
    out.trials.push_back({cands[k].index, t.quality_optimized.inverted_cells, t.quality_optimized.min_quality,
                          t.quality_optimized.mean_quality});
  }
  const std::size_t best = best_corner_trial(out.trials);
  if (!results[best]) std::rethrow_exception(over_budget[best]);  // every trial needed more cells
  if (trial_is_run) {
    out.kept = std::move(results[best]);
    out.kept->tolerance_is_relative = !opt.tolerance_absolute.has_value();
    out.kept_events = std::move(events[best]);
  }
  out.corners = std::move(cands[best]);
  out.corners.explanation += " Of the " + std::to_string(cands.size()) +
                             " best automatic choices, tried on the T-mesh, this one gave the fewest inverted "
                             "cells and the best min + mean triangle quality (choice " + std::to_string(best + 1) + ").";
  report_step(opt.progress, "corners",
              "corners: tried " + std::to_string(cands.size()) + " automatic choices, kept choice " +
                  std::to_string(best + 1));
  return out;
}

// A corner where the polygon is straight or reflex makes the corner cell
// degenerate or folded whatever the interior does: an input error.
void require_convex_corners(const Polygon& poly, const Corners& corners, bool given) {
  for (int k = 0; k < 4; ++k) {
    const std::size_t n = poly.vertices.size(), i = corners.index[k];
    const Eigen::Vector2d a = poly.vertices[(i + n - 1) % n], b = poly.vertices[i], c = poly.vertices[(i + 1) % n];
    if (cross(b - a, c - b) > 0.0) continue;
    std::ostringstream s;
    s << "corner " << k << " (file vertex " << poly.file_index[i] << ") has an inner angle of "
      << corners.inner_angle_deg[k] << " degrees: corners must be convex vertices (inner angle below 180); "
      << (given ? "pick another vertex, or leave `corners` unset for the automatic choice"
                : "the polygon has fewer than four strictly convex vertices: give `corners`");
    throw InputError(s.str());
  }
}

}  // namespace

FrontResult run_front(const Polygon& input, const ParameterizationOptions& opt) {
  validate_options(opt);
  std::vector<StageTime> times;
  StageClock clock(times);
  CleanBoundary boundary = clean_boundary(input, opt);
  Polygon& poly = boundary.polygon;
  clock.stop("boundary");
  CornerTrials chosen;
  if (opt.corners) {
    chosen.corners = corners_from_file_indices(poly, *opt.corners);
  } else {
    std::vector<Corners> cands = corner_candidates(poly, static_cast<std::size_t>(std::max(1, opt.corner_trials)));
    if (cands.size() > 1) {
      chosen = try_corners(poly, std::move(cands), opt);
      clock.stop("corner_trials");
    } else {
      chosen.corners = cands.front();
    }
  }
  const Corners& corners = chosen.corners;
  require_convex_corners(poly, corners, opt.corners.has_value());
  {
    std::ostringstream s;
    s << "boundary: " << poly.vertices.size() << " vertices, corners (file indices) "
      << poly.file_index[corners.index[0]] << "," << poly.file_index[corners.index[1]] << ","
      << poly.file_index[corners.index[2]] << "," << poly.file_index[corners.index[3]]
      << (opt.corners ? " (given)" : " (automatic)");
    report_step(opt.progress, "boundary", s.str());
  }
  clock.stop("boundary");
  FrontResult r = chosen.kept ? std::move(*chosen.kept) : optimize_front(BoundaryMap(std::move(poly), corners), opt);
  if (chosen.kept) {
    r.boundary = BoundaryMap(r.boundary.polygon(), corners);  // the same corners, with their explanation
    if (opt.progress)
      for (const ProgressEvent& e : chosen.kept_events) opt.progress(e);
    // The kept trial's stages were part of the trials' wall time.
    double kept = 0.0;
    for (const StageTime& t : r.times) kept += t.seconds;
    for (StageTime& t : times)
      if (t.stage == "corner_trials") t.seconds = std::max(0.0, t.seconds - kept);
  }
  times.insert(times.end(), r.times.begin(), r.times.end());
  r.removed_vertices = std::move(boundary.removed_vertices);
  r.cleaning_notes = std::move(boundary.notes);
  r.corner_trials = std::move(chosen.trials);
  r.times = std::move(times);
  return r;
}

}  // namespace tspline
