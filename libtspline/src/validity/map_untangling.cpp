// Global untangling of a T-spline map; see map_untangling.h for the method.
#include "tspline/validity/map_untangling.h"

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <vector>

#include "toolkit/errors.h"
#include "toolkit/timing.h"
#include "tspline/detail/lbfgs.h"
#include "tspline/validity/eps_rule.h"
#include "tspline/validity/map_energy.h"
#include "tspline/validity/map_quality.h"

namespace tspline {

namespace {

// E_eps for Ceres. At the floor eps a point with a sample det J <= 0 is
// reported as infeasible, so that the line search backs off instead of stepping
// across the barrier between two samples' worth of fold.
class EnergyFunction final : public ceres::FirstOrderFunction {
 public:
  EnergyFunction(const MapEnergy& energy, double eps, bool barrier, double power, int* evaluations)
      : energy_(energy), eps_(eps), barrier_(barrier), power_(power), evaluations_(evaluations) {}
  bool Evaluate(const double* x, double* cost, double* gradient) const override {
    ++*evaluations_;
    std::size_t nonpositive = 0;
    *cost = energy_.evaluate(x, eps_, gradient, &nonpositive, power_);
    if (barrier_ && nonpositive > 0) return false;
    return std::isfinite(*cost);
  }
  int NumParameters() const override { return static_cast<int>(energy_.num_variables()); }

 private:
  const MapEnergy& energy_;
  double eps_;
  bool barrier_;
  double power_;
  int* evaluations_;
};

// Projected Newton on one eps stage (map_untangling.h). The Hessian's
// pattern and CHOLMOD's symbolic analysis are kept across stages (same
// MapEnergy, same T-mesh): only the numeric factorization is redone.
class NewtonStage {
 public:
  NewtonStage(const MapEnergy& energy, bool conjugate_gradient, int max_cg_iterations)
      : energy_(energy), cg_(conjugate_gradient), max_cg_(max_cg_iterations) {
    llt_.cholmod().print = 0;  // a failed (shifted) attempt is not an error
  }

  // Up to max_iter iterations at (eps, power) from x. certify(v) is asked
  // before accepting a step from a certified x (certified: in and out).
  template <class Certify>
  void run(Eigen::VectorXd& x, double eps, double power, int max_iter, double tol, bool barrier,
           bool& certified, const Certify& certify, MapUntanglingReport& rep) {
    const Eigen::Index n = x.size();
    Eigen::VectorXd g(n), d(n), xt(n);
    g_prev_ = 0.0;  // a new stage: a new energy, the forcing starts over
    for (int it = 0; it < max_iter; ++it) {
      std::size_t nonpos = 0;
      const double E0 = energy_.evaluate(x.data(), eps, g.data(), &nonpos, power);
      ++rep.evaluations;
      if (!std::isfinite(E0) || (barrier && nonpos > 0)) return;
      if (!direction(x, eps, power, g, d, rep)) return;
      double slope = g.dot(d);
      if (!(slope < 0.0)) {  // cannot happen with a positive definite system; round-off
        d = -g;
        slope = -g.squaredNorm();
      }
      if (!(slope < 0.0)) return;  // stationary
      ++rep.iterations;
      const bool keep_positive = nonpos == 0;
      double a = keep_positive ? energy_.max_positive_step(x.data(), d.data(), 1.0, 0.9) : 1.0;
      bool accepted = false;
      double Et = E0;
      for (int ls = 0; ls < 40 && a > 0.0; ++ls, a *= 0.5) {
        xt = x + a * d;
        std::size_t np = 0;
        Et = energy_.evaluate(xt.data(), eps, nullptr, &np, power);
        ++rep.evaluations;
        if (!std::isfinite(Et) || Et > E0 + 1e-4 * a * slope) continue;
        if (keep_positive && np > 0) continue;
        if (certified) {
          ++rep.line_search_certifications;
          if (np > 0 || !certify(xt)) continue;
        }
        accepted = true;
        break;
      }
      if (!accepted) return;
      x.swap(xt);
      if (rep.iterations >= max_total_) return;
      if (E0 - Et <= tol * std::abs(E0)) return;
    }
  }
  void set_max_total(int m) { max_total_ = m; }

 private:
  bool direction(const Eigen::VectorXd& x, double eps, double power, const Eigen::VectorXd& g, Eigen::VectorXd& d,
                 MapUntanglingReport& rep) {
    auto t = std::chrono::steady_clock::now();
    energy_.hessian(x.data(), eps, H_, power, true);
    ++rep.factorizations;
    auto t2 = std::chrono::steady_clock::now();
    rep.hessian_seconds += std::chrono::duration<double>(t2 - t).count();
    if (cg_) {
      // Inexact Newton: CG preconditioned by the diagonal, to the relative
      // residual eta of Eisenstat & Walker (SIAM J. Sci. Comput. 17, 1996,
      // choice 2: eta = 0.9 (|g| / |g_prev|)^2, safeguarded by 0.9 eta_prev^2
      // when that is above 0.1), in [1e-4, 0.5]. From 0, every CG iterate is a
      // descent direction of the positive semi-definite model.
      const double gn = g.norm();
      double eta = 0.5;
      if (g_prev_ > 0.0) {
        eta = 0.9 * (gn / g_prev_) * (gn / g_prev_);
        const double safeguard = 0.9 * eta_ * eta_;
        if (safeguard > 0.1) eta = std::max(eta, safeguard);
      }
      eta = std::clamp(eta, 1e-4, 0.5);
      eta_ = eta, g_prev_ = gn;
      cg_solver_.setTolerance(eta);
      cg_solver_.setMaxIterations(max_cg_);
      cg_solver_.compute(H_);
      d = cg_solver_.solve(-g);
      rep.cg_iterations += static_cast<int>(cg_solver_.iterations());
      rep.solve_seconds += toolkit::seconds_since(t2);
      return d.allFinite() && g.dot(d) < 0.0;
    }
    if (!analyzed_) {
      llt_.analyzePattern(H_);
      analyzed_ = true;
    }
    // A projected Hessian is positive semi-definite; with the boundary fixed
    // it is almost always definite. If not, shift the diagonal (Levenberg).
    double shift = 0.0;
    double mean_diag = 0.0;
    bool ok = false;
    for (int attempt = 0; attempt < 12; ++attempt) {
      if (attempt > 0) ++rep.shifted_factorizations;
      llt_.setShift(shift);
      llt_.factorize(H_);
      if (llt_.info() == Eigen::Success) {
        d = llt_.solve(-g);
        ok = d.allFinite();
        if (ok) break;
      }
      if (mean_diag == 0.0) {
        for (Eigen::Index j = 0; j < H_.outerSize(); ++j) mean_diag += H_.coeff(j, j);
        mean_diag = std::max(mean_diag / std::max<Eigen::Index>(1, H_.outerSize()), 1e-300);
      }
      shift = shift == 0.0 ? 1e-8 * mean_diag : 10.0 * shift;
    }
    rep.solve_seconds += toolkit::seconds_since(t2);
    return ok;
  }

  const MapEnergy& energy_;
  Eigen::SparseMatrix<double> H_;
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt_;
  bool analyzed_ = false;
  bool cg_ = false;  // inexact Newton with CG instead of the Cholesky factorization
  int max_cg_ = 200;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::DiagonalPreconditioner<double>> cg_solver_;
  double g_prev_ = 0.0, eta_ = 0.5;  // Eisenstat-Walker forcing
  int max_total_ = 1 << 30;
};

// The local problem for hidden folds: the functions of the failing elements
// and of the elements sharing a function with them move, nothing else.
MapUntanglingOptions local_repair_options(const TSplineMap& map, const MapEnergy& energy,
                                          const MapCertification& cert, const MapUntanglingOptions& opt) {
  const std::vector<BezierElement>& es = energy.extraction().elements();
  std::vector<char> failing_function(map.basis().size(), 0);
  for (const CertificationFailure& f : cert.failures)
    for (int a : es[f.element].functions) failing_function[a] = 1;
  MapUntanglingOptions lo = opt;
  lo.energy.movable.assign(map.basis().size(), 0);
  for (const BezierElement& e : es) {
    bool near = false;
    for (int a : e.functions) near = near || failing_function[a];
    if (near)
      for (int a : e.functions) lo.energy.movable[a] = 1;
  }
  lo.local_repair = false;
  lo.progress = nullptr;
  return lo;
}

// The first eps of a continuation from a map with folds, D_min < 0 its
// smallest normalized sample det J. Garanzha et al. start from eps = 1 (det J
// is normalized to 1 on average) and their code from 0.2 |D_min|; the smaller
// of the two keeps a map with a few shallow folds close to where it is.
double starting_eps(double min_det) { return std::clamp(0.2 * std::abs(min_det), 1e-3, 1.0); }

}  // namespace

MapUntanglingReport untangle_map(TSplineMap& map, const MapUntanglingOptions& opt,
                                 const CertificationOptions& certification,
                                 const BezierExtraction* extraction) {
  if (opt.max_stages < 1 || opt.max_iterations_per_stage < 1 || opt.max_iterations < 1)
    throw toolkit::InputError("untangle_map: stage and iteration limits must be >= 1");
  if (!(opt.eps_floor > 0.0) || !(opt.energy_tolerance > 0.0))
    throw toolkit::InputError("untangle_map: eps_floor and energy_tolerance must be > 0");
  if (opt.max_newton_iterations_per_stage < 1 || !(opt.newton_stage_tolerance >= 0.0))
    throw toolkit::InputError("untangle_map: max_newton_iterations_per_stage must be >= 1 and newton_stage_tolerance >= 0");
  for (const double s : {opt.min_decrease, opt.newton_min_decrease, opt.newton_stalled_min_decrease,
                         opt.newton_fast_folded_fraction})
    if (!(s > 0.0 && s < 1.0))
      throw toolkit::InputError(
          "untangle_map: min_decrease, newton_min_decrease, newton_stalled_min_decrease and "
          "newton_fast_folded_fraction must be in (0, 1)");
  if (opt.newton_after_stalled_stages < 0)
    throw toolkit::InputError("untangle_map: newton_after_stalled_stages must be >= 0");
  if (opt.max_cg_iterations < 1 || opt.newton_cholesky_below < 0)
    throw toolkit::InputError("untangle_map: max_cg_iterations must be >= 1 and newton_cholesky_below >= 0");
  const auto t0 = std::chrono::steady_clock::now();
  MapEnergy energy(map, opt.energy, extraction);
  MapUntanglingReport rep;
  rep.free_points = energy.free_functions().size();
  rep.fixed_points = map.basis().size() - rep.free_points;
  rep.elements = energy.num_elements();
  Eigen::VectorXd x = energy.variables(map);
  rep.before = energy.stats(x.data());
  const std::size_t num_cells = map.mesh().num_cells();

  // The last certified iterate, and the certified iterate with the highest
  // min J_r at the samples: the quality phase minimizes a sum, which can lower
  // the minimum (bali at level 8: 0.083 -> 0.068 in its last quality stage).
  // Of the two, the map keeps the one whose whole map is better (below).
  struct Certified {
    Eigen::VectorXd x;
    MapCertification cert;
    double min_mean_ratio = 0.0;  // at the samples
  };
  std::optional<Certified> last, best;
  auto keep_certified = [&](const Eigen::VectorXd& v, MapCertification&& cert, double min_mean_ratio) {
    last = Certified{v, std::move(cert), min_mean_ratio};
    if (!best || min_mean_ratio > best->min_mean_ratio) best = last;
  };
  // A local problem (movable functions) examines only its own elements: the
  // others do not move, and the caller certified them.
  std::vector<char> local_elements;
  if (!opt.energy.movable.empty())
    for (std::size_t k = 0; k < energy.num_elements(); ++k) local_elements.push_back(energy.element_active(k));
  auto certify = [&](const Eigen::VectorXd& v) {
    return certify_map(energy.extraction(), num_cells, energy.control_points(v.data()), certification,
                       local_elements.empty() ? nullptr : &local_elements);
  };
  // A map without free points is what it is.
  if (rep.free_points == 0) {
    rep.certification = certify(x);
    rep.certified = rep.certification.certified_valid();
    rep.after = rep.before;
    rep.stop_reason = "no interior control points";
    rep.samples = energy.num_samples();
    rep.seconds = toolkit::seconds_since(t0);
    return rep;
  }

  // A map valid at every sample starts at the floor (quality phase only).
  double eps = rep.before.nonpositive > 0 ? starting_eps(rep.before.min_det) : opt.eps_floor;
  ceres::GradientProblemSolver::Options so;
  so.line_search_direction_type = ceres::LBFGS;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-14;

  bool resampled = false;
  int quality_stages = 0;  // certified stages at the floor eps
  bool x_certified = false;  // x is the last certified iterate (Newton keeps it certified)
  const bool newton_cg = opt.newton_solver == NewtonSolver::ConjugateGradient ||
                         (opt.newton_solver == NewtonSolver::Auto &&
                          energy.num_variables() > static_cast<std::size_t>(opt.newton_cholesky_below));
  NewtonStage newton(energy, newton_cg, opt.max_cg_iterations);
  newton.set_max_total(opt.max_iterations);
  detail::Lbfgs lbfgs;
  double lbfgs_eps = -1.0, lbfgs_power = 0.0;  // of its last stage
  auto certified_valid = [&](const Eigen::VectorXd& v) { return certify(v).certified_valid(); };
  // The optimizer of the coming stages: L-BFGS hands over to Newton where it
  // stalls (newton_after_stalled_stages).
  MapOptimizer optimizer = opt.optimizer;
  std::vector<std::size_t> folded_after_stage;  // samples with det J <= 0 after each L-BFGS stage that left some
  for (int stage = 0; stage < opt.max_stages; ++stage) {
    const bool new_samples = resampled;
    if (resampled) {
      // Finer samples can show det J <= 0 where the coarser ones had none:
      // leave the barrier (eps above the floor) but keep the regularization
      // small, chi(D_min, eps) ~ 0.0025 |D_min|: a large eps would undo the
      // progress everywhere else (measured on Newfoundland: eps reset to
      // 2 |D_min| turned 0 folded samples into 10,000).
      const SampleStats now = energy.stats(x.data());
      if (now.nonpositive > 0) eps = std::max(eps, std::max(0.1 * std::abs(now.min_det), 1e-6));
      resampled = false;
    }
    const bool barrier = eps <= opt.eps_floor;
    // The quality phase (barrier) raises each term to quality_power.
    const double power = barrier ? opt.quality_power : 1.0;
    std::size_t folded_before = 0;  // samples with det J <= 0 at the stage's start
    const double E_prev = energy.evaluate(x.data(), eps, nullptr, &folded_before, power);
    double E_stage = std::numeric_limits<double>::quiet_NaN();  // E at the stage's end, if the minimizer knows it
    if (optimizer == MapOptimizer::Newton) {
      newton.run(x, eps, power, opt.max_newton_iterations_per_stage, opt.newton_stage_tolerance, barrier, x_certified,
                 certified_valid, rep);
    } else if (optimizer == MapOptimizer::LBFGS) {
      // The curvature pairs carry over from the last stage unless the energy
      // changed more than by a lower eps: new samples, another power, eps raised.
      if (new_samples || power != lbfgs_power || eps > lbfgs_eps) lbfgs.reset();
      lbfgs_eps = eps, lbfgs_power = power;
      const auto f = [&](const double* v, double* g) {
        std::size_t nonpositive = 0;
        const double e = energy.evaluate(v, eps, g, &nonpositive, power);
        return barrier && nonpositive > 0 ? std::numeric_limits<double>::infinity() : e;
      };
      const detail::Lbfgs::Result r =
          lbfgs.run(x, f, std::min(opt.max_iterations_per_stage, opt.max_iterations - rep.iterations));
      rep.iterations += r.iterations;
      rep.evaluations += r.evaluations;
      E_stage = r.value;
      x_certified = false;
    } else {
      so.max_num_iterations = std::min(opt.max_iterations_per_stage, opt.max_iterations - rep.iterations);
      ceres::GradientProblem problem(new EnergyFunction(energy, eps, barrier, power, &rep.evaluations));
      ceres::GradientProblemSolver::Summary summary;
      Eigen::VectorXd trial = x;
      ceres::Solve(so, problem, trial.data(), &summary);
      rep.iterations += static_cast<int>(summary.iterations.size() > 0 ? summary.iterations.size() - 1 : 0);
      // Ceres returns the best point it evaluated successfully.
      if (trial.allFinite()) x = trial;
      x_certified = false;
    }
    ++rep.stages;
    const double E = std::isfinite(E_stage) ? E_stage : energy.evaluate(x.data(), eps, nullptr, nullptr, power);
    const SampleStats st = energy.stats(x.data());
    bool certified_now = false;
    x_certified = false;
    if (st.nonpositive == 0) {
      MapCertification cert = certify(x);
      if (cert.certified_valid()) {
        certified_now = true;
        x_certified = true;
        keep_certified(x, std::move(cert), st.min_mean_ratio);
      } else {
        for (const CertificationFailure& f : cert.failures) {
          const int level = energy.sample_level(f.element);
          if (level < energy.max_sample_level()) {
            energy.set_sample_level(f.element, level + 1);
            ++rep.sample_refinements;
            resampled = true;
          }
        }
        if (opt.local_repair && opt.energy.movable.empty()) {
          ++rep.local_repairs;
          TSplineMap local = map;
          local.set_control_points(energy.control_points(x.data()));
          const MapUntanglingReport lr = untangle_map(local, local_repair_options(map, energy, cert, opt), certification);
          rep.local_repair_iterations += lr.iterations;
          rep.local_repair_seconds += lr.seconds;
          rep.iterations += lr.iterations;
          rep.evaluations += lr.evaluations;
          if (lr.certified) {
            // The local problem certified its own elements; the whole map once more.
            const Eigen::VectorXd xl = energy.variables(local);
            MapCertification whole = certify(xl);
            if (whole.certified_valid()) {
              ++rep.local_repairs_certified;
              x = xl;
              certified_now = true;
              x_certified = true;
              keep_certified(x, std::move(whole), energy.stats(x.data()).min_mean_ratio);
              resampled = false;  // the finer samples of the failing elements stay; they are positive now
            }
          }
        }
      }
    }
    if (opt.progress) opt.progress({stage, eps, E, rep.iterations, st, certified_now});
    const double rel = std::abs(E_prev - E) / std::max(std::abs(E), 1e-300);
    if (certified_now && barrier) ++quality_stages;
    if (certified_now && barrier && rel < opt.energy_tolerance) {
      rep.stop_reason = "certified, and the energy converged";
      break;
    }
    if (certified_now && quality_stages >= opt.max_quality_stages) {
      rep.stop_reason = "certified, and the quality stages done";
      break;
    }
    if (rep.iterations >= opt.max_iterations) {
      rep.stop_reason = "reached the iteration limit";
      break;
    }
    if (stage + 1 == opt.max_stages) {
      rep.stop_reason = "reached the stage limit";
      break;
    }
    if (st.nonpositive == 0 && !certified_now && !resampled && barrier) {
      // Valid at the finest samples but not certified: only a finer map can help.
      rep.stop_reason = "valid at every sample but not certified at the finest sample level";
      break;
    }
    // eps update (Garanzha et al. 2021): a fresh sample set restarts nothing,
    // the rule only looks at this stage's progress and the smallest det J.
    if (optimizer == MapOptimizer::LBFGS && opt.newton_after_stalled_stages > 0 && st.nonpositive > 0) {
      // The folded samples fell by less than a tenth over the last
      // newton_after_stalled_stages stages that ended with folds: Newton from
      // here, its continuation started over as at the start.
      folded_after_stage.push_back(st.nonpositive);
      const std::size_t k = folded_after_stage.size(), K = opt.newton_after_stalled_stages;
      if (k > K && 10 * st.nonpositive > 9 * folded_after_stage[k - 1 - K]) {
        optimizer = MapOptimizer::Newton;
        rep.newton_from_stage = stage + 1;
        eps = starting_eps(st.min_det);
        continue;
      }
    }
    eps = detail::next_eps({eps, E_prev, E, folded_before, st, optimizer}, opt);
  }

  if (last) {
    // The whole map decides between the last and the best certified iterate:
    // the higher of min J_r and min scaled Jacobian over a dense sample (the
    // samples' minimum alone picked Trinidad's map with the lower certified
    // J_r, 0.284 against 0.367).
    const Certified* keep = &*last;
    if (opt.keep_best_certified && best->min_mean_ratio > last->min_mean_ratio) {
      auto figure = [&](const Certified& c) {
        const DenseMapQuality q = dense_map_quality(energy.extraction(), energy.control_points(c.x.data()));
        return std::min(q.min_mean_ratio, q.min_scaled);
      };
      if (figure(*best) > figure(*last)) {
        keep = &*best;
        rep.kept_earlier_iterate = true;
      }
    }
    x = keep->x;
    rep.certified = true;
    rep.certification = keep->cert;
  } else {
    rep.certification = certify(x);
    rep.certified = rep.certification.certified_valid();
  }
  map.set_control_points(energy.control_points(x.data()));
  rep.after = energy.stats(x.data());
  rep.samples = energy.num_samples();
  rep.seconds = toolkit::seconds_since(t0);
  return rep;
}

}  // namespace tspline
