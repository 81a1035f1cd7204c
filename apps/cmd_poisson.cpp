// `tspline poisson`: solve -Laplace(u) = f, u = g on the boundary, with T-spline
// isogeometric analysis on the domain of a T-spline file of one or more
// patches, and refine adaptively or uniformly (tspline/analysis/poisson.h: one
// path for every map). Writes convergence.csv, convergence.png, report.json and
// solution.pvd + solution/step_NNN.vtu into OUTDIR. This file parses and prints.
// Under `mpirun -n P` every process runs the same loop; the interior system is
// assembled and solved by all of them (PETSc module, tspline/petsc_solver.h) when
// the iterative solver is chosen, and only rank 0 prints and writes files.
#include <unistd.h>

#include <Eigen/Core>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "exit_codes.h"
#include "expression.h"
#include "petsc_session.h"
#include "progress.h"
#include "toolkit/io/atomic_file.h"
#include "toolkit/io/vtu_writer.h"
#include "toolkit/timing.h"
#include "tspline/analysis/poisson.h"
#include "tspline/errors.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/output_files.h"
#include "tspline/io/poisson_output.h"
#include "tspline/io/tspline_file.h"
#include "tspline/petsc_solver.h"
#include "vtu_compression_option.h"

namespace tspline_app {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

using toolkit::seconds_since;

/// A number for messages (10 significant digits).
std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

/// --rtol: "auto" (nullopt) or a number > 0. \throw InputError otherwise.
std::optional<double> parse_rtol(const std::string& text) {
  if (text == "auto") return std::nullopt;
  double v = 0.0;
  std::size_t used = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw tspline::InputError("--rtol must be 'auto' or a number > 0, got '" + text + "'");
  if (!(v > 0.0) || !std::isfinite(v)) throw tspline::InputError("--rtol must be > 0, got " + fmt(v));
  return v;
}

struct PoissonArgs {
  std::string file, out_dir, f, g, exact, problem, refine = "adaptive";
  std::string solver = "auto", preconditioner = "boomeramg";
  std::string rtol = "auto";  // "auto" (tspline::petsc::automatic_rtol) or a number > 0
  int max_iterations = tspline::petsc::IterativeOptions{}.max_iterations;
  std::size_t direct_below = tspline::petsc::kAutoIterativeFrom;
  int steps = 5;
  double gamma = 0.5;
  std::size_t max_dofs = 200000;
  int samples = 2;
  toolkit::io::VtuCompression vtu_compression = toolkit::io::VtuCompression::LZ4;
  bool quiet = false;
  bool json = false;
  CLI::Option *f_opt = nullptr, *g_opt = nullptr, *exact_opt = nullptr, *problem_opt = nullptr;
};

// report.json's "options": the numerical options by their field names (the
// flags' names with '_'); from_json comes with the macro and is unused.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(PoissonArgs, refine, steps, gamma, max_dofs, samples, solver, preconditioner, rtol,
                                   max_iterations, direct_below)

// ------------------------------------------------------------------ problems

struct ProblemSetup {
  tspline::PoissonProblem problem;
  json description;
};

/// A field given on the command line, checked: a non-finite value is an input
/// error naming the option (the core checks f and g too, without the option name).
tspline::ScalarField checked_field(const std::string& option, tspline::ScalarField u) {
  return [option, u = std::move(u)](double x, double y) {
    const double v = u(x, y);
    if (!std::isfinite(v))
      throw tspline::InputError(option + " is not finite at x = " + fmt(x) + ", y = " + fmt(y) + " (value " +
                                fmt(v) + ")");
    return v;
  };
}

/// Parses the expressions or picks the built-in problem. Throws InputError.
ProblemSetup make_problem(const PoissonArgs& a, const tspline::AnalysisGeometry& geometry) {
  ProblemSetup s;
  const std::string gradient_note =
      "exact gradient by central differences, step " + fmt(tspline::kGradientStep);
  if (!a.problem.empty()) {
    const tspline::ManufacturedProblem m = tspline::manufactured_problem(a.problem, geometry);
    s.problem = m.problem;
    s.description = {{"name", m.name}, {"u", m.u}, {"f", m.f}, {"g", m.g}, {"choice", m.choice},
                     {"exact_gradient", "analytic"}};
    for (const auto& [name, value] : m.constants) s.description[name] = value;
    return s;
  }
  s.problem.f = checked_field("--f", make_field("--f", a.f));
  s.problem.g = checked_field("--g", make_field("--g", a.g));
  s.description = {{"name", "expressions"}, {"f", a.f}, {"g", a.g}};
  if (a.exact_opt->count() > 0) {
    s.problem.exact = checked_field("--exact", make_field("--exact", a.exact));
    s.description["u"] = a.exact;
    s.description["exact_gradient"] = gradient_note;
  } else {
    s.description["u"] = nullptr;
  }
  return s;
}

// ------------------------------------------------------------------ validation

void validate_options(const PoissonArgs& a) {
  const bool has_f = a.f_opt->count() > 0, has_g = a.g_opt->count() > 0, has_exact = a.exact_opt->count() > 0;
  const bool has_problem = a.problem_opt->count() > 0;
  if (has_problem && (has_f || has_g || has_exact))
    throw tspline::InputError("--problem cannot be combined with --f, --g or --exact");
  if (!has_problem) {
    if (!has_f && !has_g)
      throw tspline::InputError(
          "give --f EXPR and --g EXPR (and optionally --exact EXPR), or --problem NAME");
    if (!has_g) throw tspline::InputError("--f needs --g (the Dirichlet data)");
    if (!has_f) throw tspline::InputError("--g needs --f (the source)");
  }
  if (a.steps < 1) throw tspline::InputError("--steps must be at least 1, got " + std::to_string(a.steps));
  if (!(a.gamma >= 0.0 && a.gamma <= 1.0))
    throw tspline::InputError("--gamma must lie in [0, 1], got " + fmt(a.gamma));
  if (a.max_dofs < 1) throw tspline::InputError("--max-dofs must be at least 1");
  if (a.samples < 1 || a.samples > 64)
    throw tspline::InputError("--samples must be in [1, 64], got " + std::to_string(a.samples));
  if (a.out_dir.empty()) throw tspline::InputError("--out: empty path");
  tspline::petsc::parse_solver_choice(a.solver);
  tspline::petsc::parse_preconditioner(a.preconditioner);
  parse_rtol(a.rtol);
  if (a.max_iterations < 1)
    throw tspline::InputError("--max-iterations must be at least 1, got " + std::to_string(a.max_iterations));
}

tspline::petsc::IterativeOptions iterative_options(const PoissonArgs& a) {
  tspline::petsc::IterativeOptions o;
  o.choice = tspline::petsc::parse_solver_choice(a.solver);
  o.preconditioner = tspline::petsc::parse_preconditioner(a.preconditioner);
  o.rtol = parse_rtol(a.rtol);
  o.max_iterations = a.max_iterations;
  o.auto_threshold = a.direct_below;
  return o;
}

// ------------------------------------------------------------------ output

/// What the program prints of the steps (the files: tspline::io::PoissonOutputWriter).
void print_header() {
  std::printf("%4s %9s %9s %11s %11s %11s %8s %-12s %5s %9s %8s %8s %8s %8s\n", "step", "dofs", "cells", "eta",
              "L2", "H1", "eta/H1", "solver", "its", "residual", "assembly", "solve", "seconds", "peak_MiB");
}
void print_row(const tspline::PoissonStep& s, double peak_mib) {
  char l2[32] = "-", h1[32] = "-", ratio[32] = "-";
  if (s.has_errors) {
    std::snprintf(l2, sizeof l2, "%.4e", s.errors.l2);
    std::snprintf(h1, sizeof h1, "%.4e", s.errors.h1);
    if (s.errors.h1 > 0) std::snprintf(ratio, sizeof ratio, "%.3f", s.eta / s.errors.h1);
  }
  std::printf("%4d %9zu %9zu %11.4e %11s %11s %8s %-12s %5d %9.2e %8.3f %8.3f %8.3f %8.1f\n", s.step, s.dofs,
              s.cells, s.eta, l2, h1, ratio, tspline::io::short_solver_name(s.solver).c_str(), s.solver.iterations,
              s.solver.relative_residual, s.assembly_seconds, s.solver.seconds, s.seconds, peak_mib);
  std::fflush(stdout);
}


// ------------------------------------------------------------------ run

/// The loop on every process; rank 0 writes and prints.
int run_poisson_process(const PoissonArgs& args, const PetscSession& session,
                        std::chrono::steady_clock::time_point t_start) {
  const bool root = session.rank() == 0;
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(args.file);
  tspline::AnalysisGeometry geometry;
  geometry.interfaces = maps.interfaces;
  std::size_t cells = 0, functions = 0, hanging = 0;
  for (const tspline::io::LoadedTSpline& t : maps.patches) {
    geometry.patches.push_back(&t.map);
    cells += t.map.mesh().num_cells();
    functions += t.map.basis().size();
    hanging += t.map.mesh().num_hanging_vertices();
  }
  const ProblemSetup setup = make_problem(args, geometry);

  tspline::AdaptiveSolveOptions opt;
  opt.refine = args.refine == "uniform" ? tspline::AdaptiveSolveOptions::Refine::Uniform
                                        : tspline::AdaptiveSolveOptions::Refine::Adaptive;
  opt.steps = args.steps;
  opt.gamma = args.gamma;
  opt.max_dofs = args.max_dofs;
  tspline::petsc::PetscPoissonSolver solver(iterative_options(args));
  opt.solver = &solver;

  json report = {
      {"command", "poisson"},
      {"input", args.file},
      {"problem", setup.description},
      {"options", args},
      {"geometry",
       {{"patches", maps.patches.size()},
        {"interfaces", maps.interfaces.size()},
        {"cells", cells},
        {"functions", functions},
        {"hanging_vertices", hanging}}},
      {"analysis_space",
       "cubic hierarchical B-splines of the analysis T-mesh of every patch, glued C0 across the interfaces (one "
       "unknown per glued pair)"},
      {"dirichlet", "L2 projection of g onto the traces of the Dirichlet functions on the domain's boundary "
                    "(physical arc length)"},
      {"quadrature", {{"assembly", "4x4 Gauss"}, {"errors", "6x6 Gauss"}, {"estimator", "4x4 Gauss"}}}};
  report["options"]["processes"] = session.size();
  Progress progress(root ? output_mode(args.quiet, args.json) : OutputMode::Quiet);
  tspline::io::PoissonOutputWriter output(args.out_dir, args.samples, setup.problem, std::move(report),
                                          args.vtu_compression);
  tspline::AdaptiveSolveResult run;
  try {
    run = tspline::solve_adaptive(geometry, setup.problem, opt,
                                    [&](const tspline::PoissonStep& st, const tspline::PoissonSolution& sol,
                                        const std::vector<double>& eta) {
                                      const std::vector<double> peak = tspline::petsc::peak_memory_mib();
                                      if (!root) return;
                                      if (!output.started() && progress.human()) print_header();
                                      json event = output.add_step(st, sol, eta, peak);
                                      if (progress.human()) print_row(st, output.peak_total_mib().back());
                                      event["event"] = "step";
                                      progress.event(event);
                                    });
  } catch (const std::exception& e) {
    // Keep what was written consistent and say why the run stopped.
    if (root && output.started()) {
      output.report()["error"] = e.what();
      output.report()["seconds_total"] = seconds_since(t_start);
      try {
        output.write_tables(false);
      } catch (const std::exception&) {  // the original error is the one to report
      }
    }
    throw;
  }
  // The library's words, with the limit named as the option the user set.
  const std::string stop = run.stop == tspline::AdaptiveSolveStop::MaxDofs
                               ? "the next space would have more than --max-dofs " + std::to_string(args.max_dofs) +
                                     " DOFs"
                               : tspline::describe(run.stop, opt);
  if (!root) return 0;
  output.report()["stop_reason"] = stop;
  output.report()["seconds_total"] = seconds_since(t_start);
  output.write_tables(true);
  std::vector<std::string> files;
  std::string file_list;
  for (const std::string_view f : tspline::io::output_files::kPoisson) {
    files.emplace_back(f);
    file_list += (file_list.empty() ? "" : ", ") + files.back();
  }
  progress.event({{"event", "result"},
                  {"steps", run.steps.size()},
                  {"stop_reason", stop},
                  {"out", args.out_dir},
                  {"files", files}});
  if (progress.human())
    std::cout << run.steps.size() << " steps (" << stop << "); wrote " << file_list << " to " << args.out_dir
              << std::endl;
  return 0;
}

int run_poisson(const PoissonArgs& args) {
  const auto t_start = Clock::now();
  // Everything that can be checked is checked before OUTDIR is created.
  validate_options(args);
  toolkit::io::check_writable_directory(args.out_dir);
  const PetscSession session;
  if (session.rank() == 0) return run_poisson_process(args, session, t_start);
  // Other ranks fail alike (same input, same collective calls); only rank 0 prints the message.
  try {
    return run_poisson_process(args, session, t_start);
  } catch (...) {
    return exit_code_for(std::current_exception());  // the same code as rank 0, without its message
  }
}

}  // namespace

void add_poisson_command(CLI::App& app, CommandAction& action) {
  const Subcommand<PoissonArgs> cmd_sub = add_subcommand<PoissonArgs>(
      app, "poisson",
      "Solve -Laplace(u) = f in the domain of a T-spline file (one patch or a multi-patch map), u = g on its "
      "boundary, with isogeometric analysis (cubic hierarchical B-splines of an analysis T-mesh per patch that "
      "starts as the geometry's and is refined, glued C0 across the interfaces; the geometry map stays fixed), and "
      "refine adaptively (residual estimator eta_e^2 = int h^2 (f + Laplace u_h)^2, cells with eta_e > gamma max "
      "eta over all patches split with their neighbours, refinement carried across the interfaces) or uniformly. "
      "Dirichlet data by L2 projection on the boundary functions. Prints one table row per step and writes "
      "OUTDIR/convergence.csv, OUTDIR/convergence.png, OUTDIR/report.json and OUTDIR/solution.pvd with "
      "OUTDIR/solution/step_NNN.vtu (every patch; point data u_h, u_exact, error = u_h - u_exact; cell data eta, "
      "level, cell, patch). Built-in problems (f = -Laplace(u) analytic, g = u, exact gradient analytic), in "
      "X = (x - x_lo) / L, Y = (y - y_lo) / L with (x_lo, y_lo) the lower-left corner of the bounding box of the "
      "control points of every patch and L its longer side: sinsin u = sin(pi X) sin(pi Y); polynomial u = X^3 + "
      "X^2 Y - 2 Y^3 + X Y (in the discrete space when the map is affine); gaussian u = exp(-((x-x0)^2 + "
      "(y-y0)^2)/s^2) with (x0, y0) the centre of that box and s = 0.1 x its diagonal");
  CLI::App* const cmd = cmd_sub.cmd;
  const std::shared_ptr<PoissonArgs> a = cmd_sub.args;
  add_tspline_file_argument(*cmd, a->file, "T-spline file (tspline.json written by `tspline param`)");
  cmd->add_option("--out", a->out_dir, "Output directory (created when the first step is done)")
      ->type_name("DIR")
      ->required();
  a->f_opt =
      cmd->add_option("--f", a->f,
                      "Source f(x, y) as a muParser expression (+ - * / ^, sin cos tan exp log=ln sqrt abs "
                      "..., constants pi, _pi, _e); needs --g")
          ->type_name("EXPR");
  a->g_opt =
      cmd->add_option("--g", a->g, "Dirichlet data g(x, y) as an expression; needs --f")->type_name("EXPR");
  a->exact_opt =
      cmd->add_option("--exact", a->exact,
                      "Exact solution u(x, y) as an expression: enables the L2 and H1 errors. Its "
                      "gradient (for the H1 error) is computed by central differences with step 1e-5")
          ->type_name("EXPR");
  a->problem_opt = cmd->add_option("--problem", a->problem,
                                   "Built-in manufactured problem instead of --f/--g/--exact (see above)")
                       ->check(CLI::IsMember(tspline::manufactured_problem_names()));
  cmd->add_option("--refine", a->refine,
                  "adaptive: split the cells with eta_e > gamma max eta; uniform: split every cell")
      ->check(CLI::IsMember({"adaptive", "uniform"}))
      ->capture_default_str();
  cmd->add_option("--steps", a->steps, "Number of solves (refinements + 1)")->capture_default_str();
  cmd->add_option("--gamma", a->gamma, "Marking parameter in [0, 1] (adaptive)")->capture_default_str();
  cmd->add_option("--max-dofs", a->max_dofs, "Stop before solving on a space with more DOFs than this")
      ->capture_default_str();
  cmd->add_option("--samples", a->samples,
                  "solution/step_NNN.vtu: k x k sub-quads per analysis cell, k in [1, 64]")
      ->capture_default_str();
  add_vtu_compression_option(cmd, a->vtu_compression);
  cmd->add_option("--solver", a->solver,
                  "Linear solver of each step: direct (CHOLMOD sparse Cholesky), iterative (PETSc CG with an "
                  "algebraic multigrid preconditioner, distributed under mpirun), or auto: direct below "
                  "--direct-below interior DOFs, iterative from there")
      ->type_name("auto|direct|iterative")
      ->capture_default_str();
  cmd->add_option("--preconditioner", a->preconditioner,
                  "AMG preconditioner of the iterative solver: boomeramg (hypre) or gamg (PETSc)")
      ->type_name("boomeramg|gamg")
      ->capture_default_str();
  cmd->add_option("--rtol", a->rtol,
                  "Iterative solver: stop when ||b - K u|| <= rtol ||b|| (rtol > 0); auto: "
                  "min(1e-10, max(1e-15, 0.02 / n^2)) for n unknowns, so that the algebraic error stays below "
                  "the discretization error")
      ->type_name("auto|R")
      ->capture_default_str();
  cmd->add_option("--max-iterations", a->max_iterations,
                  "Iterative solver: CG iterations at most; not converging by then is an error (exit 3)")
      ->capture_default_str();
  cmd->add_option("--direct-below", a->direct_below,
                  "--solver auto: the direct solver below this many interior DOFs (the measured crossover)")
      ->capture_default_str();
  cmd->add_flag("--quiet,-q", a->quiet, "Print errors only");
  cmd->add_flag("--json", a->json,
                "Print one JSON object per line instead of the table: an event 'step' per solve (the record of "
                "report.json) and a final 'result'");
  cmd->callback([a, &action] { action = [a] { return run_poisson(*a); }; });
}

}  // namespace tspline_app
