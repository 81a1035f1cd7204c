#pragma once
// The output folder of `tspline poisson` (the writer; the program prints):
//   solution/step_NNN.vtu  per step: u_h, u, u_h - u sampled per analysis cell, eta per cell
//   solution.pvd           the steps as a ParaView series
//   convergence.csv        one row per step: DOFs, eta, L2, H1, solver, times, memory
//   convergence.png        errors and eta against DOFs (convergence_plot.h)
//   report.json            the options, the problem and one record per step
// The tables are rewritten (each atomically) after every step, so that a run
// that stops with an error leaves a consistent folder of the steps done.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "toolkit/io/vtu_writer.h"
#include "tspline/analysis/poisson.h"

namespace tspline::io {

/// The solution sampled per analysis cell of every patch with k x k
/// sub-quads. Point data u_h (and u_exact, error = u_h - u_exact if the
/// problem has an exact solution); cell data eta, cell (of its patch), level,
/// patch. `eta`: per global cell (AnalysisSpace numbering).
toolkit::io::VtuMesh solution_vtu(const PoissonSolution& sol, const PoissonProblem& problem,
                                  const std::vector<double>& eta, int k);

/// A short name of the solver of a step ("CHOLMOD", "CG+BoomerAMG", ...).
std::string short_solver_name(const SolverStats& s);

class PoissonOutputWriter {
 public:
  /// `report`: the run's description (command, input, options, problem, ...);
  /// the writer adds "steps" and "finished". Nothing is written before add_step.
  PoissonOutputWriter(std::string out_dir, int samples, const PoissonProblem& problem, nlohmann::json report,
                      toolkit::io::VtuCompression compression = toolkit::io::VtuCompression::LZ4);

  /// Writes the step's .vtu (creating the folder on the first step) and
  /// rewrites the tables. peak_mib: peak resident memory of every process so
  /// far (MiB, by rank). Returns the step's record, as in report.json.
  /// \throw IoError.
  nlohmann::json add_step(const PoissonStep& st, const PoissonSolution& sol, const std::vector<double>& eta,
                          const std::vector<double>& peak_mib);

  /// Whether a step was written (the folder exists).
  bool started() const { return started_; }

  /// Rewrites convergence.csv, convergence.png, solution.pvd and report.json
  /// (each atomically); `finished`: the run ended normally. \throw IoError.
  void write_tables(bool finished);

  nlohmann::json& report() { return report_; }
  const std::vector<PoissonStep>& steps() const { return steps_; }
  /// Per step: the sum over the processes of their peak memory, MiB.
  const std::vector<double>& peak_total_mib() const { return peak_total_; }

 private:
  std::string out_dir_;
  int samples_;
  toolkit::io::VtuCompression compression_;
  const PoissonProblem& problem_;
  nlohmann::json report_;
  std::vector<PoissonStep> steps_;
  std::vector<double> peak_total_;
  std::vector<toolkit::io::PvdEntry> pvd_;
  bool started_ = false;
};

}  // namespace tspline::io
