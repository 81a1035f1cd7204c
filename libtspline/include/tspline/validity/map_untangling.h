#pragma once
// Global untangling and smoothing of a T-spline map: all interior control
// points at once, until det J > 0 is certified on every Bezier element.
//
// Interpolating an untangled T-mesh says nothing about the interpolant between
// its vertices; on real coastlines the cubic map folds there. This step moves
// the map's own degrees of freedom, with the boundary curve fixed:
//
//  1. Minimize the regularized energy E_eps of map_energy.h for a fixed eps
//     (L-BFGS by default, or projected Newton: MapOptimizer), then lower eps by the
//     rule of Garanzha et al. 2021 (Sect. 4 there): with sigma = max(1 -
//     E/E_prev, 1/10) the relative progress of the stage and D_min the smallest
//     sampled det J, mu = (1 - sigma) chi(D_min, eps), and eps = 2 sqrt(mu (mu -
//     D_min)) if D_min < mu, else eps = eps_floor. Large eps makes the energy
//     smooth and defined on folded maps; small eps turns it into a barrier on
//     det J = 0, so the stages end as a quality optimization of a valid map.
//  2. Samples are only samples: once every sample has det J > 0 the map is
//     certified (map_certification.h) and the elements that are not certified
//     get a finer sample level (map_energy.h), so that the next stages see the
//     fold between the old samples.
//  3. A certified map is kept: later stages (the quality phase) cannot
//     turn a certified map into an uncertified result. At the floor eps the
//     energy refuses any step that makes a sample's det J <= 0.
//
// The map returned is certified if an iterate was: the last certified one, or
// the certified one with the highest min J_r at the samples where its whole
// map is better (MapUntanglingOptions::keep_best_certified); else the last
// iterate (then report.certified is false).
//
// Projected Newton (Teran et al. 2005, Smith et al. 2019): each
// iteration assembles the energy's Hessian over the free control points with
// every sample's 4 x 4 Hessian in J projected to positive semi-definite
// (MapEnergy::hessian), factors it by CHOLMOD's supernodal Cholesky (the
// symbolic analysis done once per T-mesh and reused; a diagonal shift only if
// the factorization fails), and searches along the Newton direction by
// backtracking (Armijo) from the largest step that keeps every positive
// sample's det J positive (MapEnergy::max_positive_step: det J is quadratic
// along the line). Once every sample is positive no step makes one
// non-positive, and once the map is certified no step is accepted that the
// certificate does not prove valid: a certified map stays certified.
#include <cstddef>
#include <functional>
#include <string>

#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_energy_options.h"
#include "tspline/spline/tspline_map.h"

namespace tspline {

/// The minimizer of each eps stage.
enum class MapOptimizer {
  Newton,  ///< projected Newton, CHOLMOD: fewer iterations, but each costs a sparse Cholesky
  LBFGS,   ///< L-BFGS, curvature pairs kept across the stages (detail/lbfgs.h)
  CeresLBFGS  ///< Ceres' L-BFGS, restarted every stage (the method before projected Newton)
};

/// The linear solve of each Newton step.
enum class NewtonSolver {
  Auto,              ///< Cholesky below newton_cholesky_below unknowns, conjugate gradients above
  Cholesky,          ///< CHOLMOD supernodal, the symbolic analysis reused
  ConjugateGradient  ///< inexact Newton: diagonally preconditioned CG, Eisenstat-Walker forcing
};

struct UntanglingProgress {
  int stage = 0;
  double eps = 0.0;
  double energy = 0.0;
  int iterations = 0;  ///< optimizer (Newton or L-BFGS) iterations so far (all stages)
  SampleStats samples;
  bool certified = false;  ///< certified at the end of this stage
};

struct MapUntanglingOptions {
  MapEnergyOptions energy;
  /// eps continuation stages at most: a map that is still not certified then
  /// needs more freedom (the adaptive loop refines where it fails) rather than
  /// more stages (measured on Newfoundland: 80 stages of 20 iterations and two
  /// sample refinements without a certificate on 3,247 cells).
  int max_stages = 60;
  /// L-BFGS by default: on this project's 2-core machine (ATLAS BLAS) the
  /// Cholesky of the bicubic 2-component Hessian costs 60 ms at 2.7e3 and
  /// 1.6 s at 3.3e4 unknowns, more than the L-BFGS iterations it saves
  /// (bench/README.md, "Projected Newton vs L-BFGS for the untangling of the map").
  MapOptimizer optimizer = MapOptimizer::LBFGS;
  int max_iterations_per_stage = 20;  ///< L-BFGS iterations per stage
  /// Newton iterations per stage at most; a stage also ends when an
  /// iteration lowers the energy by less than newton_stage_tolerance (relative).
  int max_newton_iterations_per_stage = 8;
  double newton_stage_tolerance = 1e-4;
  NewtonSolver newton_solver = NewtonSolver::Auto;
  /// Auto: the Cholesky factorization below this many unknowns (measured on the
  /// 8.5e3 unknowns of Bali at level 6: a factorization 220 ms, CG to 1e-2 17 ms).
  int newton_cholesky_below = 4000;
  int max_cg_iterations = 200;  ///< per Newton step
  /// Newton's sigma floor in the eps rule (min_decrease below is L-BFGS'):
  /// each Newton stage ends near the stage's minimizer, so eps may fall
  /// faster (measured on Newfoundland: 8 stages and 118 Newton iterations
  /// instead of 33 and 279 with 0.25, the same certified quality).
  double newton_min_decrease = 0.9;
  /// Newton's sigma floor after a stage that did not halve the folded samples
  /// (det J <= 0): eps then falls by sqrt(1 - 0.3) = 16 % instead of by
  /// sqrt(10). Once eps is far below the folds' |det J| the folded terms
  /// grow as 1 / eps^2 and Newton no longer unfolds them: hokkaido at level 8
  /// stalled at 140,000 folded samples with the floor 0.9 alone and is
  /// certified with this one (bench/README.md, "hokkaido at level 8").
  double newton_stalled_min_decrease = 0.3;
  /// ... and also while more than this fraction of the samples is folded.
  double newton_fast_folded_fraction = 0.01;
  /// L-BFGS hands over to Newton (for the remaining stages, eps started over)
  /// when the folded samples fell by less than a tenth over this many stages;
  /// 0: never. On hokkaido at level 8 L-BFGS unfolded 5 % of 317,000 folded
  /// samples in 60 stages, Newton all of them in 11.
  int newton_after_stalled_stages = 10;
  int max_iterations = 20000;         ///< optimizer iterations in total
  /// Stop once certified and a stage at the floor eps lowered the energy by
  /// less than this fraction.
  double energy_tolerance = 1e-3;
  /// Exponent of each sample's term in the quality phase (at the floor eps):
  /// 1 favours the mean of 1/J_r, larger values the minimum J_r.
  double quality_power = 4.0;
  /// Stages at the floor eps (the quality phase) once certified, at most.
  int max_quality_stages = 3;
  double eps_floor = 1e-9;  ///< smallest eps (normalized det J units)
  /// Smallest relative decrease sigma of chi at the worst sample per stage
  /// (Garanzha et al. use 1/10; 1/4 needed 33 instead of 54 stages on Bali,
  /// 20 L-BFGS iterations per stage, and reached the same certified map).
  double min_decrease = 0.25;
  /// When every sample is positive but some elements are not certified (folds
  /// hidden between their samples): first untangle the control points of
  /// those elements and of one ring of elements around them alone, with the
  /// rest of the map fixed and finer samples there (a small problem), instead
  /// of continuing on the whole map from a raised eps.
  bool local_repair = true;
  /// Of the last certified iterate and the certified iterate with the highest
  /// min J_r at the samples, keep the one whose whole map (a dense sample) has
  /// the higher min(J_r, scaled Jacobian); false: always the last.
  bool keep_best_certified = true;
  std::function<void(const UntanglingProgress&)> progress;
};

struct MapUntanglingReport {
  std::size_t free_points = 0;
  std::size_t fixed_points = 0;
  std::size_t elements = 0;
  std::size_t samples = 0;  ///< at the end (after sample refinement)
  int stages = 0;
  int iterations = 0;   ///< optimizer (Newton or L-BFGS) iterations
  int evaluations = 0;  ///< energy (+ gradient) evaluations
  int factorizations = 0;  ///< Newton: Hessian assemblies and Cholesky factorizations
  int shifted_factorizations = 0;  ///< Newton: repeated with a diagonal shift (the first attempt failed)
  int line_search_certifications = 0;  ///< Newton: trial steps checked by the certificate
  double hessian_seconds = 0.0;  ///< Newton: assembly of the Hessians
  double solve_seconds = 0.0;    ///< Newton: CHOLMOD analysis, factorizations and solves, or CG
  int cg_iterations = 0;         ///< Newton with conjugate gradients: CG iterations in all
  int newton_from_stage = -1;    ///< the stage from which Newton took over from a stalled L-BFGS (-1: it did not)
  int sample_refinements = 0;  ///< elements whose sample level was raised
  int local_repairs = 0;        ///< local problems solved for hidden folds (see local_repair)
  int local_repairs_certified = 0;  ///< of which certified the map
  int local_repair_iterations = 0;  ///< optimizer iterations inside the local repairs (also in iterations)
  double local_repair_seconds = 0.0;  ///< time in the local repairs (also in seconds)
  SampleStats before, after;   ///< at the initial samples / at the final samples, of the returned map
  bool certified = false;
  /// The map returned is an earlier certified iterate than the last, whose
  /// whole map was better (MapUntanglingOptions::keep_best_certified).
  bool kept_earlier_iterate = false;
  MapCertification certification;  ///< of the returned map
  std::string stop_reason;
  double seconds = 0.0;
};

/// Moves the interior control points of `map` in place; `certification` says
/// how det J > 0 is certified on the elements (the stopping test).
/// `extraction`: the Bezier extraction of the map's basis, if the caller has
/// it (nullptr: made here); the basis does not change.
/// \throw InputError for options out of range.
MapUntanglingReport untangle_map(TSplineMap& map, const MapUntanglingOptions& options = {},
                                 const CertificationOptions& certification = {},
                                 const BezierExtraction* extraction = nullptr);

}  // namespace tspline
