#include "tspline/pipeline/front_optimization.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tspline/boundary/polygon_validation.h"
#include "tspline/detail/stage_clock.h"
#include "tspline/errors.h"
#include "tspline/tmesh/coons.h"
#include "tspline/tmesh/smoothing_problem.h"
#include "tspline/tmesh/tmesh_transfer.h"

namespace tspline {
namespace {

using detail::StageClock;

// The nested sequence of meshes (coarse to fine) on which the optimization runs.
// Stage k has uniform level level[k] and boundary tolerance tol[k]; both are
// monotone, so every stage's tree refines the previous one, and the last stage
// is exactly the T-mesh of (initial_level, tolerance) built directly (the
// refinement criterion of a cell depends only on the cell, and the 2:1 balanced
// closure of a tree is unique).
struct Stages {
  std::vector<int> level;
  std::vector<double> tol;
  std::size_t size() const { return level.size(); }
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

}  // namespace

// One run of optimize_front: the result it builds and the options it reads
// (its own copy: a FrontRun outlives its caller's options).
class FrontOptimizer {
 public:
  FrontOptimizer(BoundaryMap boundary, const ParameterizationOptions& opt);
  FrontOptimizer(const FrontOptimizer&) = delete;
  FrontOptimizer& operator=(const FrontOptimizer&) = delete;

  void run_nested_stages();
  /// The rest of a final stage paused by run_nested_stages (none: nothing).
  void resume();
  void repair();
  void stop_if_tangled() const;
  /// Of the optimized T-mesh: at the pause, if paused.
  std::size_t inverted_cells() const {
    return paused_ ? paused_inverted_ : r_.quality_optimized.inverted_cells;
  }
  const FrontResult& result() const { return r_; }
  FrontResult take_result() { return std::move(r_); }

 private:
  void log(const char* stage, const std::string& text) const { report_step(opt_.progress, stage, text); }
  void optimize(const std::string& what);
  // optimize() in parts: the problem of the current mesh; sweeps until
  // `sweeps` in all (meshopt::smooth_until); the figures and the log line.
  void begin_optimize();
  void advance_optimize(int sweeps);
  void end_optimize(const std::string& what);
  void end_stage(FrontStage stage);
  void report_final_tmesh(const BoundaryRefinementReport& rep);
  bool repair_round(int round);

  const ParameterizationOptions opt_;
  FrontResult r_;
  StageClock clock_;
  double diag_ = 0.0;
  meshopt::SmoothingOptions sopt_;
  meshopt::SmoothingProblem problem_;
  meshopt::SmoothingRun run_;
  // stop_when_tangled: the final stage paused kIntermediateStageSweeps in,
  // tangled (its record, and its inverted cells then).
  std::optional<FrontStage> paused_;
  std::size_t paused_inverted_ = 0;
};

FrontOptimizer::FrontOptimizer(BoundaryMap boundary, const ParameterizationOptions& opt)
    : opt_(opt), r_{std::move(boundary)}, clock_(r_.times), sopt_(opt.smoothing) {
  r_.tolerance_is_relative = !opt.tolerance_absolute.has_value();
  diag_ = bounding_box_diagonal(r_.boundary.polygon());
  r_.tolerance_area = opt.tolerance_absolute ? *opt.tolerance_absolute : opt.tolerance_relative * diag_ * diag_;
  if (!sopt_.progress && opt.progress) {
    sopt_.progress = [this](int sweep, double move, std::size_t tangled) {
      ProgressEvent e;
      e.kind = ProgressEvent::Kind::Sweep;
      e.stage = "optimization";
      e.count = sweep;
      e.value = move;
      e.defects = tangled;
      std::ostringstream s;
      s << "sweep " << sweep << ": max relative move " << move << ", tangled nodes " << tangled;
      e.text = s.str();
      opt_.progress(e);
    };
  }
}

// The K* smoothing of the interior nodes of the current mesh (paper Eq. 5-7),
// from r_.optimized.
void FrontOptimizer::optimize(const std::string& what) {
  begin_optimize();
  advance_optimize(sopt_.max_sweeps);
  end_optimize(what);
}

void FrontOptimizer::begin_optimize() {
  problem_ = build_smoothing_problem(r_.mesh, true);
  run_ = meshopt::SmoothingRun();
}

void FrontOptimizer::advance_optimize(int sweeps) {
  r_.smoothing = meshopt::smooth_until(r_.optimized, problem_, sopt_, sweeps, run_);
}

void FrontOptimizer::end_optimize(const std::string& what) {
  problem_ = meshopt::SmoothingProblem();
  r_.total_sweeps += r_.smoothing.sweeps;
  r_.node_visits += r_.smoothing.node_visits;
  r_.quality_optimized = mesh_quality(r_.mesh, r_.optimized);
  std::ostringstream s;
  s << "optimization (" << what << ", " << r_.mesh.num_cells() << " cells): " << r_.smoothing.sweeps << " sweeps"
    << (r_.smoothing.converged ? "" : " (not converged)") << ", " << r_.quality_optimized.inverted_cells
    << " inverted cells, min/mean quality " << r_.quality_optimized.min_mean_ratio << " / "
    << r_.quality_optimized.mean_mean_ratio;
  log("optimization", s.str());
}

// The final T-mesh's figures, and its Coons start (for the report, and the
// start if the optimization is not nested).
void FrontOptimizer::report_final_tmesh(const BoundaryRefinementReport& rep) {
  std::ostringstream s;
  s << "t-mesh: " << r_.mesh.num_cells() << " cells, " << r_.mesh.num_vertices() << " vertices ("
    << r_.mesh.num_hanging_vertices() << " hanging), max level " << r_.mesh.max_level() << ", tolerance "
    << r_.tolerance_area;
  log("tmesh", s.str());
  if (rep.edges_over_tolerance > 0)
    report_step(opt_.progress, "tmesh",
                "warning: " + std::to_string(rep.edges_over_tolerance) +
                    " boundary edges still exceed the tolerance at the maximum level " + std::to_string(opt_.max_level),
                -1, ProgressEvent::Kind::Note);
  r_.coons = coons_positions(r_.mesh, r_.boundary);
  r_.quality_coons = mesh_quality(r_.mesh, r_.coons);
  log("coons", "coons: " + std::to_string(r_.quality_coons.inverted_cells) + " inverted cells");
  clock_.stop("coons");
}

// Nested iteration: optimize on a coarse mesh, then refine, carry the
// positions over and optimize again. Gauss-Seidel sweeps remove the local
// errors quickly but the smooth, domain-wide ones slowly; on the coarse stages
// those are cheap, so the finest stage starts close to its optimum.
void FrontOptimizer::run_nested_stages() {
  const Stages st = nested_stages(opt_.initial_level, r_.tolerance_area, diag_, opt_.nested_optimization);
  // The last stage's T-mesh first (milliseconds: a test per cell), so that a
  // tolerance that needs more than max_cells fails at once (refine_to_boundary
  // throws), not after the optimization of every coarser stage.
  // Its cells also tell which stages are the last one's T-mesh already (a
  // patch of a layout often has 16 cells at every stage): those are not run,
  // the last stage gets their sweeps (they would only have optimized its own
  // mesh, from the same start, in parts).
  std::size_t last_cells = 0;
  if (st.size() > 1) {
    TMesh last(opt_.initial_level);
    refine_to_boundary(last, r_.boundary, {r_.tolerance_area, opt_.max_level, opt_.max_cells});
    refine_to_border_params(last, opt_.border_params, opt_.max_level);
    last_cells = last.num_cells();
  }
  bool ran = false;  // a stage was optimized (its mesh and positions are r_'s)
  int skipped_sweeps = 0;
  for (std::size_t k = 0; k < st.size(); ++k) {
    const bool last = k + 1 == st.size();
    // (Each stage's T-mesh depends only on its level and tolerance: from the
    // previous stage's or from the coarsest, it is the same tree.)
    TMesh coarse = ran ? r_.mesh : TMesh(st.level[0]);
    if (!ran) r_.mesh = TMesh(st.level[0]);
    refine_below(r_.mesh, st.level[k]);
    const BoundaryRefinementReport rep =
        refine_to_boundary(r_.mesh, r_.boundary, {st.tol[k], opt_.max_level, opt_.max_cells});
    refine_to_border_params(r_.mesh, opt_.border_params, opt_.max_level);
    clock_.stop("tmesh");
    if (!last && r_.mesh.num_cells() == last_cells) {
      skipped_sweeps += std::min(opt_.smoothing.max_sweeps, kIntermediateStageSweeps);
      if (ran) r_.mesh = std::move(coarse);
      continue;
    }
    if (last) {
      r_.refinement = rep;
      report_final_tmesh(rep);
    }
    // The start of this stage: the previous stage carried over, or the Coons
    // positions of this mesh, whichever has fewer inverted cells (the carried
    // ones on a tie). A coarse stage can be impossible to untangle (its
    // boundary too coarse for a thin part of the domain): Coons is then the
    // better start. But a stage that ends at its sweep cap with a few inverted
    // cells is a far better start than Coons, whose folds the finer stages
    // often cannot undo in their sweeps (hokkaido at level 7: 2,515 inverted
    // cells left at the end when every such stage restarted from Coons, none
    // with the better start).
    FrontStage stage;
    // (The Coons positions only where they are compared or taken.)
    auto coons_start = [&]() { return last ? r_.coons : coons_positions(r_.mesh, r_.boundary); };
    if (ran) {
      std::vector<Eigen::Vector2d> carried = transfer_positions(coarse, r_.optimized, r_.mesh, r_.boundary);
      stage.start_inverted = mesh_quality(r_.mesh, carried).inverted_cells;
      stage.carried = true;
      std::vector<Eigen::Vector2d> coons;
      if (r_.quality_optimized.inverted_cells > 0) {
        coons = coons_start();
        const std::size_t coons_inverted = mesh_quality(r_.mesh, coons).inverted_cells;
        stage.other_start_inverted = coons_inverted;
        if (coons_inverted < stage.start_inverted) {
          stage.other_start_inverted = stage.start_inverted;
          stage.start_inverted = coons_inverted;
          stage.carried = false;
        }
      }
      r_.optimized = stage.carried ? std::move(carried) : std::move(coons);
    } else {
      r_.optimized = coons_start();
      stage.start_inverted = mesh_quality(r_.mesh, r_.optimized).inverted_cells;
    }
    if (ran && stage.other_start_inverted)
      log("optimization", "stage " + std::to_string(k + 1) + " starts from " +
                              (stage.carried ? "the previous stage carried over (" : "Coons (") +
                              std::to_string(stage.start_inverted) + " inverted cells; " +
                              (stage.carried ? "Coons " : "carried over ") +
                              std::to_string(*stage.other_start_inverted) + ")");
    // Intermediate stages only provide a start: a bounded number of sweeps.
    sopt_.max_sweeps = last ? opt_.smoothing.max_sweeps + skipped_sweeps
                            : std::min(opt_.smoothing.max_sweeps, kIntermediateStageSweeps);
    ran = true;
    begin_optimize();
    // stop_when_tangled: the final stage pauses once it has had an
    // intermediate stage's sweeps, if its mesh is still tangled then (resume()
    // goes on as if it had not: meshopt::smooth_until).
    if (last && opt_.stop_when_tangled) {
      advance_optimize(kIntermediateStageSweeps);
      if (!run_.finished) {
        const std::size_t inverted = mesh_quality(r_.mesh, r_.optimized).inverted_cells;
        if (inverted > 0) {
          paused_ = stage;
          paused_inverted_ = inverted;
          clock_.stop("optimization");
          return;
        }
      }
    }
    advance_optimize(sopt_.max_sweeps);
    end_optimize(last ? "final mesh" : "stage " + std::to_string(k + 1) + " of " + std::to_string(st.size()));
    end_stage(stage);
  }
}

void FrontOptimizer::end_stage(FrontStage stage) {
  stage.cells = r_.mesh.num_cells();
  stage.end_inverted = r_.quality_optimized.inverted_cells;
  stage.sweeps = r_.smoothing.sweeps;
  r_.stages.push_back(stage);
  clock_.stop("optimization");
}

void FrontOptimizer::resume() {
  clock_.restart();  // (a corner trial may have waited since its stages)
  if (!paused_) return;
  advance_optimize(sopt_.max_sweeps);
  end_optimize("final mesh");
  end_stage(*paused_);
  paused_.reset();
}

// ParameterizationOptions::stop_when_tangled, before any repair round.
void FrontOptimizer::stop_if_tangled() const {
  if (!opt_.stop_when_tangled || inverted_cells() == 0) return;
  throw FrontTangled(
      "the optimized T-mesh is tangled " +
      (paused_ ? std::to_string(kIntermediateStageSweeps) + " sweeps into its final stage ("
               : std::string("after its nested stages (")) +
      std::to_string(inverted_cells()) + " inverted cells of " + std::to_string(r_.mesh.num_cells()) + ")");
}

// Repair: cells that stay inverted lack interior freedom (typically thin
// features of the domain). Refine them, place the new vertices in the current
// physical mesh, re-balance and optimize again.
void FrontOptimizer::repair() {
  sopt_.max_sweeps = opt_.smoothing.max_sweeps;
  for (int round = 0; round < opt_.max_repair_rounds && r_.quality_optimized.inverted_cells > 0; ++round)
    if (!repair_round(round)) break;
}

// One repair round; false where the repair stops (r_.repair_stop_reason says why).
bool FrontOptimizer::repair_round(int round) {
  const std::vector<CellQuality> q = cell_qualities(r_.mesh, r_.optimized);
  std::vector<int> inverted;
  for (int c = 0; c < static_cast<int>(q.size()); ++c)
    if (!q[c].valid && r_.mesh.cell_level(c) < opt_.max_level) inverted.push_back(c);
  if (inverted.empty()) {
    r_.repair_stop_reason = "the " + std::to_string(r_.quality_optimized.inverted_cells) +
                            " inverted cells are at `max_level` " + std::to_string(opt_.max_level);
    log("repair", "repair stopped: " + r_.repair_stop_reason);
    return false;
  }
  const std::size_t refined = inverted.size();
  TMesh finer = refine_cells(r_.mesh, inverted);
  if (finer.num_cells() > opt_.max_cells) {
    // The domain needs a finer mesh than allowed (typically a long thin
    // part): say so and stop rather than go on with a tangled mesh.
    std::ostringstream s;
    s << "the polygon needs more than " << opt_.max_cells << " cells (`max_cells`): after " << round
      << " repair round(s) " << r_.quality_optimized.inverted_cells << " of " << r_.mesh.num_cells()
      << " T-mesh cells are still inverted, and refining them makes " << finer.num_cells()
      << " cells; raise `max_cells`, or check the polygon for long thin parts (spikes, narrow channels)";
    throw InputError(s.str());
  }
  // The state before this round, restored if the round makes things worse.
  std::vector<Eigen::Vector2d> before = r_.optimized;
  const MeshQualityStats quality_before = r_.quality_optimized;
  const meshopt::SmoothingReport smoothing_before = r_.smoothing;
  const TMesh coarse = std::exchange(r_.mesh, std::move(finer));
  r_.optimized = transfer_positions(coarse, r_.optimized, r_.mesh, r_.boundary);
  r_.repair_refined_cells.push_back(refined);
  log("repair", "repair round " + std::to_string(round + 1) + ": refined " + std::to_string(refined) +
                    " inverted cells, now " + std::to_string(r_.mesh.num_cells()) + " cells");
  optimize("repair " + std::to_string(round + 1));
  clock_.stop("repair");
  if (r_.quality_optimized.inverted_cells <= quality_before.inverted_cells) return true;
  // Diverging (the inverted region grows with each round, as where a long
  // thin part needs far finer cells than its neighbourhood): more rounds
  // only multiply the cells. Keep the mesh before this round.
  r_.repair_stop_reason = "repair round " + std::to_string(round + 1) + " left more inverted cells (" +
                          std::to_string(r_.quality_optimized.inverted_cells) + ") than before it (" +
                          std::to_string(quality_before.inverted_cells) + "); kept the mesh before it";
  r_.mesh = coarse;
  r_.optimized = std::move(before);
  r_.quality_optimized = quality_before;
  r_.smoothing = smoothing_before;
  r_.repair_refined_cells.pop_back();
  log("repair", "repair stopped: " + r_.repair_stop_reason);
  return false;
}

FrontRun::FrontRun(BoundaryMap boundary, const ParameterizationOptions& options)
    : front_(std::make_unique<FrontOptimizer>(std::move(boundary), options)) {
  front_->run_nested_stages();
}
FrontRun::FrontRun(FrontRun&&) noexcept = default;
FrontRun& FrontRun::operator=(FrontRun&&) noexcept = default;
FrontRun::~FrontRun() = default;

std::size_t FrontRun::inverted_cells() const { return front_->inverted_cells(); }
std::size_t FrontRun::cells() const { return front_->result().mesh.num_cells(); }

FrontResult FrontRun::finish() {
  front_->resume();
  front_->repair();
  FrontResult r = front_->take_result();
  front_.reset();
  return r;
}

FrontResult optimize_front(BoundaryMap boundary, const ParameterizationOptions& options) {
  FrontOptimizer front(std::move(boundary), options);
  front.run_nested_stages();
  front.stop_if_tangled();
  front.resume();
  front.repair();
  return front.take_result();
}

}  // namespace tspline
