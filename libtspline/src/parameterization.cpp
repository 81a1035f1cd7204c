#include "tspline/parameterization.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "tspline/coons.h"
#include "tspline/corners.h"
#include "tspline/errors.h"
#include "tspline/polygon_validation.h"
#include "tspline/tmesh_submesh.h"
#include "tspline/tmesh_transfer.h"

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

double bbox_diagonal(const Polygon& p) {
  Eigen::Vector2d lo = p.vertices.front(), hi = p.vertices.front();
  for (const auto& v : p.vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  return (hi - lo).norm();
}

}  // namespace

namespace {

// Everything after the corners: adapted T-mesh, Coons start, nested optimization
// and repair. `clock` may be null (trial runs).
FrontResult optimize_front(BoundaryMap boundary, const ParameterizationOptions& opt, StageClock* clock_or_null) {
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };
  std::vector<StageTime> scratch_times;
  StageClock scratch(scratch_times);
  StageClock& clock = clock_or_null ? *clock_or_null : scratch;
  FrontResult r{std::move(boundary)};

  r.tolerance_is_relative = !opt.tolerance_absolute.has_value();
  const double diag = bbox_diagonal(r.boundary.polygon());
  r.tolerance_area = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * diag * diag;

  meshopt::SmoothingOptions sopt = opt.smoothing;
  if (!sopt.progress && opt.log) {
    sopt.progress = [&](int sweep, double move, std::size_t tangled) {
      if (sweep < 3 || sweep % 50 == 0) {
        std::ostringstream s;
        s << "  sweep " << sweep << ": max relative move " << move << ", tangled nodes " << tangled;
        opt.log(s.str());
      }
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
    log(s.str());
  };

  // Nested iteration: optimize on a coarse mesh, then refine, carry the
  // positions over and optimize again. Gauss-Seidel sweeps remove the local
  // errors quickly but the smooth, domain-wide ones slowly; on the coarse stages
  // those are cheap, so the finest stage starts close to its optimum.
  const Stages st = nested_stages(opt.initial_level, r.tolerance_area, diag, opt.nested_optimization);
  for (std::size_t k = 0; k < st.level.size(); ++k) {
    const bool last = k + 1 == st.level.size();
    TMesh coarse = k == 0 ? TMesh(st.level[0]) : r.mesh;
    if (k == 0) r.mesh = TMesh(st.level[0]);
    refine_below(r.mesh, st.level[k]);
    const BoundaryRefinementReport rep = refine_to_boundary(r.mesh, r.boundary, {st.tol[k], opt.max_level});
    refine_to_border_params(r.mesh, opt.border_params, opt.max_level);
    if (last) r.refinement = rep;
    clock.stop("tmesh");
    if (last) {
      std::ostringstream s;
      s << "t-mesh: " << r.mesh.num_cells() << " cells, " << r.mesh.num_vertices() << " vertices ("
        << r.mesh.num_hanging_vertices() << " hanging), max level " << r.mesh.max_level() << ", tolerance "
        << r.tolerance_area;
      log(s.str());
      if (rep.edges_over_tolerance > 0)
        log("warning: " + std::to_string(rep.edges_over_tolerance) +
            " boundary edges still exceed the tolerance at the maximum level " + std::to_string(opt.max_level));
      // The Coons start of the final T-mesh, for the report (and the start if not nested).
      r.coons = coons_positions(r.mesh, r.boundary);
      r.quality_coons = mesh_quality(r.mesh, r.coons);
      log("coons: " + std::to_string(r.quality_coons.inverted_cells) + " inverted cells");
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
    const TMesh coarse = r.mesh;
    std::size_t refined = 0;
    for (int c = 0; c < static_cast<int>(q.size()); ++c) {
      if (q[c].valid || coarse.cell_level(c) >= opt.max_level) continue;
      r.mesh.refine(coarse.cell_node(c));
      ++refined;
    }
    if (refined == 0) break;
    r.mesh.balance();
    r.mesh.build_topology();
    r.optimized = transfer_positions(coarse, r.optimized, r.mesh, r.boundary);
    r.repair_refined_cells.push_back(refined);
    log("repair round " + std::to_string(round + 1) + ": refined " + std::to_string(refined) +
        " inverted cells, now " + std::to_string(r.mesh.num_cells()) + " cells");
    optimize("repair " + std::to_string(round + 1));
    clock.stop("repair");
  }
  return r;
}

}  // namespace

FrontResult run_front(const Polygon& input, const ParameterizationOptions& opt) {
  auto log = [&](const std::string& s) {
    if (opt.log) opt.log(s);
  };
  if (opt.initial_level < 0 || opt.initial_level > 10)  // 2^10 x 2^10 = 10^6 cells, about 1 GB
    throw InputError("--init-level must be in [0, 10], got " + std::to_string(opt.initial_level));
  if (opt.max_level < std::max(1, opt.initial_level) || opt.max_level > TMesh::kMaxLevel)
    throw InputError("--max-level must be in [max(1, init-level), " + std::to_string(TMesh::kMaxLevel) + "]");
  if (opt.tolerance_absolute && !(*opt.tolerance_absolute > 0.0 && std::isfinite(*opt.tolerance_absolute)))
    throw InputError("--tol must be a positive finite area");
  if (!(opt.tolerance_relative > 0.0 && std::isfinite(opt.tolerance_relative)))
    throw InputError("--tol-rel must be a positive finite number");
  if (opt.max_repair_rounds < 0) throw InputError("the number of repair rounds must be >= 0");
  if (opt.corner_trials < 1) throw InputError("--corner-trials must be >= 1");

  std::vector<StageTime> times;
  StageClock clock(times);
  PolygonCleaning cleaning = clean_polygon(input);
  for (const std::string& note : cleaning.notes)
    if (opt.log) opt.log("note: " + note);
  Polygon poly = validate_polygon(std::move(cleaning.polygon));
  Corners corners;
  std::vector<CornerTrial> trials;
  if (opt.corners) {
    corners = corners_from_file_indices(poly, *opt.corners);
  } else {
    std::vector<Corners> cands = corner_candidates(poly, static_cast<std::size_t>(std::max(1, opt.corner_trials)));
    corners = cands.front();
    if (cands.size() > 1) {
      // Try the best few automatic choices (with the initial level capped at 5,
      // which is the full problem for the default options) and keep the one with
      // the fewest inverted cells, then the highest min + mean triangle quality
      // (the minimum guards validity margins, the mean the overall distortion).
      ParameterizationOptions topt = opt;
      topt.log = nullptr;
      topt.smoothing.progress = nullptr;
      topt.corner_trials = 1;
      // Trials at most at the default resolution (level <= 5, tolerance no finer
      // than the default 1e-5 diag^2): for the default options that is the run
      // itself; for fine user settings it keeps the trials cheap.
      topt.initial_level = std::min(opt.initial_level, 5);
      {
        const double d = bbox_diagonal(poly);
        const double tol = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * d * d;
        topt.tolerance_absolute = std::max(tol, 1e-5 * d * d);
      }
      std::size_t best = 0;
      for (std::size_t k = 0; k < cands.size(); ++k) {
        const FrontResult t = optimize_front(BoundaryMap(poly, cands[k]), topt, nullptr);
        trials.push_back({cands[k].index, t.quality_optimized.inverted_cells, t.quality_optimized.min_quality,
                          t.quality_optimized.mean_quality});
        const CornerTrial& a = trials[k];
        const CornerTrial& b = trials[best];
        if (a.inverted_cells < b.inverted_cells ||
            (a.inverted_cells == b.inverted_cells &&
             a.min_quality + a.mean_quality > b.min_quality + b.mean_quality))
          best = k;
      }
      corners = cands[best];
      corners.explanation += " Of the " + std::to_string(cands.size()) +
                             " best automatic choices, tried on the T-mesh, this one gave the fewest inverted "
                             "cells and the best min + mean triangle quality (choice " + std::to_string(best + 1) + ").";
      log("corners: tried " + std::to_string(cands.size()) + " automatic choices, kept choice " +
          std::to_string(best + 1));
    }
  }
  // A corner where the polygon is straight or reflex makes the corner cell
  // degenerate or folded whatever the interior does: reject it.
  for (int k = 0; k < 4; ++k) {
    const std::size_t n = poly.vertices.size(), i = corners.index[k];
    const Eigen::Vector2d a = poly.vertices[(i + n - 1) % n], b = poly.vertices[i], c = poly.vertices[(i + 1) % n];
    const Eigen::Vector2d u = b - a, w = c - b;
    if (!(u.x() * w.y() - u.y() * w.x() > 0.0)) {
      std::ostringstream s;
      s << "corner " << k << " (file vertex " << poly.file_index[i] << ") has an inner angle of "
        << corners.inner_angle_deg[k]
        << " degrees: corners must be convex vertices (inner angle below 180); pick another vertex, or omit "
           "--corners for the automatic choice";
      throw InputError(s.str());
    }
  }
  {
    std::ostringstream s;
    s << "boundary: " << poly.vertices.size() << " vertices, corners (file indices) "
      << poly.file_index[corners.index[0]] << "," << poly.file_index[corners.index[1]] << ","
      << poly.file_index[corners.index[2]] << "," << poly.file_index[corners.index[3]]
      << (opt.corners ? " (given)" : " (automatic)");
    log(s.str());
  }
  clock.stop("boundary");
  FrontResult r = optimize_front(BoundaryMap(std::move(poly), std::move(corners)), opt, &clock);
  r.removed_vertices = cleaning.removed_file_indices;
  r.cleaning_notes = cleaning.notes;
  r.corner_trials = std::move(trials);
  r.times = std::move(times);
  return r;
}

}  // namespace tspline
