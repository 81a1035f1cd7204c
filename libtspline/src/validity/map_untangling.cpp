// Global untangling of a T-spline map; see map_untangling.h for the method.
#include "tspline/validity/map_untangling.h"

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

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

}  // namespace

MapUntanglingReport untangle_map(TSplineMap& map, const MapUntanglingOptions& opt) {
  if (opt.max_stages < 1 || opt.max_iterations_per_stage < 1 || opt.max_iterations < 1)
    throw std::invalid_argument("untangle_map: stage and iteration limits must be >= 1");
  if (!(opt.eps_floor > 0.0) || !(opt.energy_tolerance > 0.0))
    throw std::invalid_argument("untangle_map: eps_floor and energy_tolerance must be > 0");
  const auto t0 = std::chrono::steady_clock::now();
  MapEnergy energy(map, opt.energy);
  MapUntanglingReport rep;
  rep.free_points = energy.free_functions().size();
  rep.fixed_points = map.basis().size() - rep.free_points;
  rep.elements = energy.num_elements();
  Eigen::VectorXd x = energy.variables(map);
  rep.before = energy.stats(x.data());
  const std::size_t num_cells = map.mesh().num_cells();

  std::optional<Eigen::VectorXd> best;  // the last certified iterate
  MapCertification best_cert;
  auto certify = [&](const Eigen::VectorXd& v) {
    return certify_map(energy.extraction(), num_cells, energy.control_points(v.data()), opt.certification);
  };
  // A map without free points is what it is.
  if (rep.free_points == 0) {
    rep.certification = certify(x);
    rep.certified = rep.certification.certified_valid();
    rep.after = rep.before;
    rep.stop_reason = "no interior control points";
    rep.samples = energy.num_samples();
    rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return rep;
  }

  // A map valid at every sample starts at the floor (quality phase only).
  // Garanzha et al. start from eps = 1 (det J is normalized to 1 on average)
  // and their code from 0.2 |D_min|; the smaller of the two keeps a map with
  // a few shallow folds close to where it is.
  double eps = rep.before.nonpositive > 0 ? std::clamp(0.2 * std::abs(rep.before.min_det), 1e-3, 1.0) : opt.eps_floor;
  ceres::GradientProblemSolver::Options so;
  so.line_search_direction_type = ceres::LBFGS;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-14;
  so.parameter_tolerance = 1e-14;

  bool resampled = false;
  int quality_stages = 0;  // certified stages at the floor eps
  for (int stage = 0; stage < opt.max_stages; ++stage) {
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
    const double E_prev = energy.evaluate(x.data(), eps, nullptr, nullptr, power);
    so.max_num_iterations = std::min(opt.max_iterations_per_stage, opt.max_iterations - rep.iterations);
    {
      ceres::GradientProblem problem(new EnergyFunction(energy, eps, barrier, power, &rep.evaluations));
      ceres::GradientProblemSolver::Summary summary;
      Eigen::VectorXd trial = x;
      ceres::Solve(so, problem, trial.data(), &summary);
      rep.iterations += static_cast<int>(summary.iterations.size() > 0 ? summary.iterations.size() - 1 : 0);
      // Ceres returns the best point it evaluated successfully.
      if (trial.allFinite()) x = trial;
    }
    ++rep.stages;
    const double E = energy.evaluate(x.data(), eps, nullptr, nullptr, power);
    const SampleStats st = energy.stats(x.data());
    bool certified_now = false;
    if (st.nonpositive == 0) {
      MapCertification cert = certify(x);
      if (cert.certified_valid()) {
        certified_now = true;
        best = x;
        best_cert = std::move(cert);
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
          const MapUntanglingReport lr = untangle_map(local, local_repair_options(map, energy, cert, opt));
          rep.iterations += lr.iterations;
          rep.evaluations += lr.evaluations;
          if (lr.certified) {
            ++rep.local_repairs_certified;
            x = energy.variables(local);
            certified_now = true;
            best = x;
            best_cert = lr.certification;
            resampled = false;  // the finer samples of the failing elements stay; they are positive now
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
      rep.stop_reason = "reached the L-BFGS iteration limit";
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
    const double sigma = std::max(1.0 - E / E_prev, opt.min_decrease);
    const double mu = (1.0 - sigma) * regularized_det(st.min_det, eps);
    eps = st.min_det < mu ? std::max(opt.eps_floor, 2.0 * std::sqrt(mu * (mu - st.min_det))) : opt.eps_floor;
  }

  if (best) {
    x = *best;
    rep.certified = true;
    rep.certification = std::move(best_cert);
  } else {
    rep.certification = certify(x);
    rep.certified = rep.certification.certified_valid();
  }
  map.set_control_points(energy.control_points(x.data()));
  rep.after = energy.stats(x.data());
  rep.samples = energy.num_samples();
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

}  // namespace tspline
