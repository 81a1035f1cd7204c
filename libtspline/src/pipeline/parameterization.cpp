#include "tspline/pipeline/parameterization.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <utility>

#include "tspline/boundary/corners.h"
#include "tspline/boundary/plane.h"
#include "tspline/boundary/polygon_validation.h"
#include "tspline/detail/stage_clock.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/errors.h"
#include "tspline/pipeline/front_optimization.h"

namespace tspline {

namespace {

// Runs body(0), ..., body(n - 1) on up to hardware_concurrency threads; the
// first exception thrown by a body is rethrown here once the running bodies
// have finished (no body starts after one has thrown).
template <class Body>
void for_each_concurrently(std::size_t n, Body&& body) {
  const std::size_t threads = std::min<std::size_t>(n, detail::hardware_threads());
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::vector<std::exception_ptr> errors(n);
  // The extra threads take no item while a core is lent to the quad mesher
  // and one is left (detail::LentCore): the calling thread goes on alone.
  // The items are independent, so neither matters to the results.
  auto work = [&](bool extra) {
    for (std::size_t k;;) {
      if (extra) detail::wait_while_one_core_left([&] { return failed || next >= n; });
      if (failed || (k = next.fetch_add(1)) >= n) break;
      try {
        body(k);
      } catch (...) {
        errors[k] = std::current_exception();
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(work, true);
  work(false);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace

std::size_t best_corner_trial(const std::vector<CornerTrial>& trials) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < trials.size(); ++k) {
    const CornerTrial& a = trials[k];
    const CornerTrial& b = trials[best];
    if (a.inverted_cells < b.inverted_cells ||
        (a.inverted_cells == b.inverted_cells && a.min_mean_ratio + a.mean_mean_ratio > b.min_mean_ratio + b.mean_mean_ratio))
      best = k;
  }
  return best;
}

double run_needle_width(const Polygon& ring, const ParameterizationOptions& opt) {
  return opt.needle_width ? *opt.needle_width
                          : needle_width_for_ring(ring, opt.tolerance_absolute, opt.tolerance_relative);
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
  const double needle_width = run_needle_width(input, opt);
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

// The front half of one trial up to the end of its nested stages (FrontRun:
// the repair rounds come with finish()), its steps and notes collected in
// `events`; sweeps of concurrent trials become heartbeats (the caller may stop
// the run).
FrontRun start_corner_trial(const Polygon& poly, const Corners& corners, ParameterizationOptions o,
                            const ProgressCallback& progress, std::size_t k,
                            std::vector<ProgressEvent>& events, std::mutex& report_mutex) {
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
  return FrontRun(BoundaryMap(poly, corners), o);
}

// The options of a corner trial: at most the default resolution (level <= 5,
// tolerance no finer than the default 1e-5 diag^2): for the default options
// that is the run itself (`trial_is_run`); for fine user settings it keeps the
// trials cheap.
ParameterizationOptions trial_options(const Polygon& poly, const ParameterizationOptions& opt, bool& trial_is_run) {
  ParameterizationOptions topt = opt;
  topt.smoothing.progress = nullptr;
  topt.corner_trials = 1;
  topt.initial_level = std::min(opt.initial_level, 5);
  const double d = bounding_box_diagonal(poly);
  const double tol = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * d * d;
  topt.tolerance_absolute = std::max(tol, 1e-5 * d * d);
  trial_is_run = topt.initial_level == opt.initial_level && *topt.tolerance_absolute == tol;
  return topt;
}

// One row per candidate: its corners and its front's figures; a trial that
// failed (needed more than max_cells) ranks last.
std::vector<CornerTrial> trial_rows(const std::vector<Corners>& cands,
                                    const std::vector<std::optional<FrontResult>>& results) {
  std::vector<CornerTrial> rows;
  for (std::size_t k = 0; k < cands.size(); ++k) {
    constexpr double kWorst = -std::numeric_limits<double>::infinity();
    if (!results[k]) {
      rows.push_back({cands[k].index, std::numeric_limits<std::size_t>::max(), kWorst, kWorst});
      continue;
    }
    const FrontResult& t = *results[k];
    rows.push_back({cands[k].index, t.quality_optimized.inverted_cells, t.quality_optimized.min_mean_ratio,
                    t.quality_optimized.mean_mean_ratio});
  }
  return rows;
}

CornerTrials try_corners(const Polygon& poly, std::vector<Corners> cands, const ParameterizationOptions& opt) {
  bool trial_is_run = false;
  const ParameterizationOptions topt = trial_options(poly, opt, trial_is_run);
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
  // Under stop_when_tangled a trial whose T-mesh is tangled after its nested
  // stages waits there, before its repair rounds, until some trial's is not:
  // then every waiting trial goes on as it would have (FrontRun), and the
  // choice is the one without the option; if none is, the run stops.
  const bool wait = topt.stop_when_tangled;
  std::vector<std::optional<FrontRun>> runs(cands.size());
  std::atomic<bool> untangled{false};
  auto finish = [&](std::size_t k) {
    try {
      results[k].emplace(runs[k]->finish());
      runs[k].reset();
    } catch (const InputError& e) {
      over_budget[k] = std::current_exception();
      runs[k].reset();
      const std::lock_guard<std::mutex> lock(report_mutex);
      if (opt.progress) report(" failed (choice " + std::to_string(k + 1) + "): " + e.what());
      return;
    }
    const FrontResult& t = *results[k];
    std::ostringstream s;
    s << " done (choice " << k + 1 << "): " << t.quality_optimized.inverted_cells
      << " inverted cells, min/mean quality " << t.quality_optimized.min_mean_ratio << " / "
      << t.quality_optimized.mean_mean_ratio;
    const std::lock_guard<std::mutex> lock(report_mutex);
    if (opt.progress) report(s.str());
  };
  for_each_concurrently(cands.size(), [&](std::size_t k) {
    try {
      runs[k].emplace(start_corner_trial(poly, cands[k], topt, opt.progress, k, events[k], report_mutex));
    } catch (const InputError& e) {
      over_budget[k] = std::current_exception();
      const std::lock_guard<std::mutex> lock(report_mutex);
      if (opt.progress) report(" failed (choice " + std::to_string(k + 1) + "): " + e.what());
      return;
    }
    if (runs[k]->inverted_cells() == 0) untangled = true;
    if (wait && !untangled) return;  // waits
    finish(k);
  });
  std::vector<std::size_t> waiting;
  for (std::size_t k = 0; k < cands.size(); ++k)
    if (runs[k]) waiting.push_back(k);
  if (!waiting.empty() && !untangled) {
    std::ostringstream s;
    s << "every corner trial's T-mesh is tangled after its nested stages, at most " << kIntermediateStageSweeps
      << " sweeps into the final one (inverted cells:";
    for (std::size_t i = 0; i < waiting.size(); ++i)
      s << (i ? ", " : " ") << runs[waiting[i]]->inverted_cells() << " of " << runs[waiting[i]]->cells();
    s << ")";
    throw FrontTangled(s.str());
  }
  for_each_concurrently(waiting.size(), [&](std::size_t i) { finish(waiting[i]); });
  CornerTrials out;
  out.trials = trial_rows(cands, results);
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
  detail::StageClock clock(times);
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
