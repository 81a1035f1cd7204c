#include "tspline/io/poisson_output.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <sstream>
#include <utility>

#include "toolkit/io/atomic_file.h"
#include "tspline/io/cell_grid.h"
#include "tspline/io/convergence_plot.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/output_files.h"
#include "toolkit/timing.h"

namespace tspline::io {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

/// -2 log(e2/e1) / log(n2/n1): the rate in h for 2D (n ~ h^-2); null if undefined.
json rate(double e1, double e2, std::size_t n1, std::size_t n2) {
  if (!(e1 > 0.0) || !(e2 > 0.0) || n1 == n2) return nullptr;
  const double r = -2.0 * std::log(e2 / e1) / std::log(static_cast<double>(n2) / static_cast<double>(n1));
  return std::isfinite(r) ? json(r) : json(nullptr);
}

}  // namespace

toolkit::io::VtuMesh solution_vtu(const PoissonSolution& sol, const PoissonProblem& problem,
                                  const std::vector<double>& eta, int k) {
  std::vector<toolkit::io::VtuMesh> parts;
  for (std::size_t p = 0; p < sol.space->num_patches(); ++p) {
    std::vector<double> uh, ue, err, cell_eta;
    // Built here if this process does not hold it (a distributed run's rank 0), one patch at a time.
    const std::shared_ptr<const PatchSpace> space = sol.space->patch_space(p);
    toolkit::io::VtuMesh part = cell_grid_vtu(space->mesh(), k, [&](int c, const Eigen::Vector2d& uv) {
      const SolutionValue v = evaluate_solution(sol, p, *space, c, uv, 0);
      uh.push_back(v.u);
      if (problem.exact) {
        const double u = problem.exact(v.x.x(), v.x.y());
        ue.push_back(u);
        err.push_back(v.u - u);
      }
      return v.x;
    });
    const std::size_t offset = sol.space->cell_offset(p);
    for (int c : part.cell_ints["cell"]) cell_eta.push_back(eta[offset + static_cast<std::size_t>(c)]);
    part.point_scalars["u_h"] = std::move(uh);
    if (problem.exact) {
      part.point_scalars["u_exact"] = std::move(ue);
      part.point_scalars["error"] = std::move(err);
    }
    part.cell_scalars["eta"] = std::move(cell_eta);
    parts.push_back(std::move(part));
  }
  return merge_patches(parts);
}

std::string short_solver_name(const SolverStats& s) {
  if (s.kind == "CholmodSupernodalLLT") return "CHOLMOD";
  if (s.kind == "SimplicialLDLT") return "LDLT";
  if (s.kind == "ConjugateGradient+IncompleteCholesky") return "CG+IC";
  if (s.kind == "PETSc CG + hypre BoomerAMG") return "CG+BoomerAMG";
  if (s.kind == "PETSc CG + PETSc GAMG") return "CG+GAMG";
  return s.kind;
}

PoissonOutputWriter::PoissonOutputWriter(std::string out_dir, int samples, const PoissonProblem& problem,
                                         json report, toolkit::io::VtuCompression compression)
    : out_dir_(std::move(out_dir)),
      samples_(samples),
      compression_(compression),
      problem_(problem),
      report_(std::move(report)) {
  report_["steps"] = json::array();
}

json PoissonOutputWriter::add_step(const PoissonStep& st, const PoissonSolution& sol, const std::vector<double>& eta,
                                   const std::vector<double>& peak_mib) {
  const auto t0 = std::chrono::steady_clock::now();
  const fs::path out(out_dir_);
  if (!started_) {
    // Created on the first completed step: a run failing before it leaves nothing.
    toolkit::io::ensure_writable_directory(out.string());
    toolkit::io::ensure_writable_directory((out / output_files::kSolutionFolder).string());
    started_ = true;
  }
  char name[64];
  std::snprintf(name, sizeof name, "%s/step_%03d.vtu", std::string(output_files::kSolutionFolder).c_str(), st.step);
  toolkit::io::write_vtu((out / name).string(), solution_vtu(sol, problem_, eta, samples_), compression_);
  pvd_.push_back({static_cast<double>(st.step), name, 0});

  int max_level = 0;
  for (std::size_t p = 0; p < sol.space->num_patches(); ++p)
    max_level = std::max(max_level, sol.space->mesh(p).max_level());
  json rec = {{"step", st.step},
              {"dofs", st.dofs},
              {"interior_dofs", sol.interior_dofs},
              {"cells", st.cells},
              {"max_level", max_level},
              {"patches", sol.space->num_patches()},
              {"glued_pairs", sol.space->glued_pairs()},
              {"max_interface_jump", st.max_interface_jump},
              {"marked", st.marked},
              {"refined", st.refined},
              {"eta", st.eta},
              {"eta_at_roundoff", st.eta_at_roundoff},
              {"eta_max_cell", eta.empty() ? 0.0 : *std::max_element(eta.begin(), eta.end())},
              {"solver",
               {{"kind", st.solver.kind},
                {"seconds", st.solver.seconds},
                {"relative_residual", st.solver.relative_residual},
                {"iterations", st.solver.iterations},
                {"rtol", st.solver.tolerance},
                {"processes", st.solver.processes}}},
              {"peak_memory_mib",
               {{"per_process", peak_mib},
                {"max", *std::max_element(peak_mib.begin(), peak_mib.end())},
                {"total", std::accumulate(peak_mib.begin(), peak_mib.end(), 0.0)}}},
              {"dirichlet_seconds", sol.dirichlet_seconds},
              {"assembly_seconds", st.assembly_seconds},
              {"solve_seconds", st.solver.seconds},
              {"step_seconds", st.seconds},
              {"file", name}};
  if (st.has_errors) {
    const PoissonErrors& e = st.errors;
    rec["l2"] = e.l2;
    rec["h1"] = e.h1;
    rec["l2_relative"] = e.l2_exact > 0 ? json(e.l2 / e.l2_exact) : json(nullptr);
    rec["h1_relative"] = e.h1_exact > 0 ? json(e.h1 / e.h1_exact) : json(nullptr);
    rec["max_abs_error_at_quadrature_points"] = e.max_abs_at_qp;
    rec["eta_over_h1"] = e.h1 > 0 ? json(st.eta / e.h1) : json(nullptr);
  } else {
    rec["l2"] = rec["h1"] = rec["eta_over_h1"] = nullptr;
  }
  if (!steps_.empty()) {
    const PoissonStep& p = steps_.back();
    rec["rates_vs_dofs"] = {
        {"eta", rate(p.eta, st.eta, p.dofs, st.dofs)},
        {"l2", st.has_errors ? rate(p.errors.l2, st.errors.l2, p.dofs, st.dofs) : json(nullptr)},
        {"h1", st.has_errors ? rate(p.errors.h1, st.errors.h1, p.dofs, st.dofs) : json(nullptr)}};
  }
  steps_.push_back(st);
  peak_total_.push_back(std::accumulate(peak_mib.begin(), peak_mib.end(), 0.0));
  rec["output_seconds"] = toolkit::seconds_since(t0);
  report_["steps"].push_back(rec);
  write_tables(false);
  return rec;
}

void PoissonOutputWriter::write_tables(bool finished) {
  const fs::path out(out_dir_);
  report_["finished"] = finished;
  std::ostringstream csv;
  csv << "step,dofs,cells,eta,l2,h1,eta_over_h1,solver,residual,seconds,iterations,assembly_seconds,"
         "solve_seconds,peak_mib\n";
  for (std::size_t k = 0; k < steps_.size(); ++k) {
    const PoissonStep& s = steps_[k];
    csv << s.step << ',' << s.dofs << ',' << s.cells << ',' << num(s.eta) << ',';
    if (s.has_errors)
      csv << num(s.errors.l2) << ',' << num(s.errors.h1) << ','
          << (s.errors.h1 > 0 ? num(s.eta / s.errors.h1) : std::string());
    else
      csv << ",,";
    csv << ',' << s.solver.kind << ',' << num(s.solver.relative_residual) << ',' << num(s.seconds) << ','
        << s.solver.iterations << ',' << num(s.assembly_seconds) << ',' << num(s.solver.seconds) << ','
        << num(peak_total_[k]) << '\n';
  }
  toolkit::io::write_text_atomic((out / output_files::kConvergenceCsv).string(), csv.str());
  write_convergence_plot((out / output_files::kConvergencePlot).string(), steps_);
  toolkit::io::write_pvd((out / output_files::kSolutionSeries).string(), pvd_);
  toolkit::io::write_text_atomic((out / output_files::kReport).string(), report_.dump(2) + "\n");
}

}  // namespace tspline::io
