// `tspline poisson`: solve -Laplace(u) = f, u = g on the boundary, with T-spline
// isogeometric analysis on the domain of a T-spline file, and refine adaptively
// or uniformly (libtspline/include/tspline/poisson.h). Writes convergence.csv, convergence.png,
// report.json and solution.pvd + solution/step_NNN.vtu into OUTDIR.
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
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "progress.h"
#include "expression.h"
#include "tspline/errors.h"
#include "tspline/io/atomic_file.h"
#include "tspline/io/convergence_plot.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/tspline_file.h"
#include "poisson_multipatch.h"
#include "tspline/io/cell_grid.h"
#include "tspline/io/vtu_writer.h"
#include "petsc_session.h"
#include "tspline/petsc_solver.h"
#include "tspline/poisson.h"

namespace tspline_app {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

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
  bool quiet = false;
  bool json = false;
  CLI::Option *f_opt = nullptr, *g_opt = nullptr, *exact_opt = nullptr, *problem_opt = nullptr;
};

// ------------------------------------------------------------------ problems

struct ProblemSetup {
  tspline::PoissonProblem problem;
  json description;
};

constexpr double kPi = std::numbers::pi;

ProblemSetup sinsin_problem() {
  ProblemSetup s;
  s.problem.exact = [](double x, double y) { return std::sin(kPi * x) * std::sin(kPi * y); };
  s.problem.exact_gradient = [](double x, double y) {
    return Eigen::Vector2d(kPi * std::cos(kPi * x) * std::sin(kPi * y),
                           kPi * std::sin(kPi * x) * std::cos(kPi * y));
  };
  s.problem.f = [](double x, double y) { return 2 * kPi * kPi * std::sin(kPi * x) * std::sin(kPi * y); };
  s.problem.g = s.problem.exact;
  s.description = {{"u", "sin(pi x) sin(pi y)"}, {"f", "2 pi^2 sin(pi x) sin(pi y)"}, {"g", "u"}};
  return s;
}

ProblemSetup polynomial_problem() {
  ProblemSetup s;
  s.problem.exact = [](double x, double y) { return x * x * x + x * x * y - 2 * y * y * y + x * y; };
  s.problem.exact_gradient = [](double x, double y) {
    return Eigen::Vector2d(3 * x * x + 2 * x * y + y, x * x - 6 * y * y + x);
  };
  s.problem.f = [](double x, double y) { return -6 * x + 10 * y; };
  s.problem.g = s.problem.exact;
  s.description = {{"u", "x^3 + x^2 y - 2 y^3 + x y"}, {"f", "-6 x + 10 y"}, {"g", "u"}};
  return s;
}

/// Gaussian peak centred on the bounding box of the control points, width 0.1 x its diagonal.
ProblemSetup gaussian_problem(const tspline::TSplineMap& map) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Eigen::Vector2d& p : map.control_points()) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double x0 = 0.5 * (lo.x() + hi.x()), y0 = 0.5 * (lo.y() + hi.y());
  const double s = 0.1 * (hi - lo).norm();
  if (!(s > 0.0) || !std::isfinite(s))
    throw tspline::InputError("--problem gaussian: the control points span no area (bounding box diagonal " +
                              fmt((hi - lo).norm()) + ")");
  const double s2 = s * s;
  ProblemSetup p;
  p.problem.exact = [=](double x, double y) {
    return std::exp(-((x - x0) * (x - x0) + (y - y0) * (y - y0)) / s2);
  };
  p.problem.exact_gradient = [=](double x, double y) {
    const double u = std::exp(-((x - x0) * (x - x0) + (y - y0) * (y - y0)) / s2);
    return Eigen::Vector2d(-2 * (x - x0) / s2 * u, -2 * (y - y0) / s2 * u);
  };
  p.problem.f = [=](double x, double y) {
    const double r2 = (x - x0) * (x - x0) + (y - y0) * (y - y0);
    return std::exp(-r2 / s2) * (4 / s2 - 4 * r2 / (s2 * s2));
  };
  p.problem.g = p.problem.exact;
  p.description = {
      {"u", "exp(-((x - x0)^2 + (y - y0)^2) / s^2)"},
      {"f", "u (4 / s^2 - 4 ((x - x0)^2 + (y - y0)^2) / s^4)"},
      {"g", "u"},
      {"x0", x0},
      {"y0", y0},
      {"s", s},
      {"choice", "(x0, y0) = centre of the bounding box of the control points, s = 0.1 x its diagonal"}};
  return p;
}

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
ProblemSetup make_problem(const PoissonArgs& a, const tspline::TSplineMap& map) {
  ProblemSetup s;
  const std::string gradient_note =
      "exact gradient by central differences, step " + fmt(tspline::kGradientStep);
  if (!a.problem.empty()) {
    if (a.problem == "sinsin")
      s = sinsin_problem();
    else if (a.problem == "polynomial")
      s = polynomial_problem();
    else
      s = gaussian_problem(map);
    s.description["name"] = a.problem;
    s.description["exact_gradient"] = "analytic";
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

/// Fails (IoError) if `dir` could not be created or written, without creating it:
/// it must be a writable directory, or its nearest existing ancestor must be one.
void check_output_directory(const std::string& dir) {
  std::error_code ec;
  const fs::path p = fs::absolute(fs::path(dir), ec);
  if (ec) throw tspline::IoError("cannot use output directory " + dir + ": " + ec.message());
  auto writable = [](const fs::path& d) { return ::access(d.c_str(), W_OK | X_OK) == 0; };
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec))
      throw tspline::IoError("output directory " + dir + " exists and is not a directory");
    if (!writable(p))
      throw tspline::IoError("output directory " + dir + " is not writable: " + std::strerror(errno));
    return;
  }
  fs::path a = p.parent_path();
  while (!a.empty() && a != a.root_path() && !fs::exists(a, ec)) a = a.parent_path();
  if (a.empty()) a = p.root_path();
  if (!fs::is_directory(a, ec))
    throw tspline::IoError("cannot create output directory " + dir + ": " + a.string() +
                           " is not a directory");
  if (!writable(a))
    throw tspline::IoError("cannot create output directory " + dir + ": " + a.string() +
                           " is not writable: " + std::strerror(errno));
}

// ------------------------------------------------------------------ output

/// The solution sampled per analysis cell with k x k sub-quads.
tspline::io::VtuMesh solution_vtu(const tspline::TSplineMap& map, const tspline::PoissonSolution& sol,
                                  const tspline::PoissonProblem& problem, const std::vector<double>& eta,
                                  int k) {
  const tspline::TMesh& mesh = sol.space->mesh();
  std::vector<double> uh, ue, err, cell_eta;
  tspline::io::VtuMesh out = tspline::io::cell_grid_vtu(mesh, k, [&](int c, const Eigen::Vector2d& uv) {
    const tspline::SolutionValue v = tspline::evaluate_solution(map, sol, c, uv, 0);
    uh.push_back(v.u);
    if (problem.exact) {
      const double u = problem.exact(v.x.x(), v.x.y());
      ue.push_back(u);
      err.push_back(v.u - u);
    }
    return v.x;
  });
  for (int c : out.cell_ints["cell"]) cell_eta.push_back(eta[c]);
  out.point_scalars["u_h"] = std::move(uh);
  if (problem.exact) {
    out.point_scalars["u_exact"] = std::move(ue);
    out.point_scalars["error"] = std::move(err);
  }
  out.cell_scalars["eta"] = std::move(cell_eta);
  return out;
}

std::string short_solver(const tspline::SolverStats& s) {
  if (s.kind == "CholmodSupernodalLLT") return "CHOLMOD";
  if (s.kind == "SimplicialLDLT") return "LDLT";
  if (s.kind == "ConjugateGradient+IncompleteCholesky") return "CG+IC";
  if (s.kind == "PETSc CG + hypre BoomerAMG") return "CG+BoomerAMG";
  if (s.kind == "PETSc CG + PETSc GAMG") return "CG+GAMG";
  return s.kind;
}

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

class PoissonOutput {
 public:
  PoissonOutput(const PoissonArgs& args, const tspline::TSplineMap& map,
                const tspline::PoissonProblem& problem, json report, Progress& progress)
      : args_(args), map_(map), problem_(problem), report_(std::move(report)), progress_(progress) {
    report_["steps"] = json::array();
  }

  /// peak_mib: peak resident memory of every process so far (MiB, by rank).
  void step(const tspline::PoissonStep& st, const tspline::PoissonSolution& sol, const std::vector<double>& eta,
            const std::vector<double>& peak_mib) {
    const auto t0 = Clock::now();
    const fs::path out(args_.out_dir);
    if (!started_) {
      // Created on the first completed step: a run failing before it leaves nothing.
      tspline::io::ensure_writable_directory(out.string());
      tspline::io::ensure_writable_directory((out / "solution").string());
      started_ = true;
      if (progress_.human()) print_header();
    }
    char name[64];
    std::snprintf(name, sizeof name, "solution/step_%03d.vtu", st.step);
    tspline::io::write_vtu((out / name).string(), solution_vtu(map_, sol, problem_, eta, args_.samples));
    pvd_.push_back({static_cast<double>(st.step), name, 0});

    json rec = {{"step", st.step},
                {"dofs", st.dofs},
                {"interior_dofs", sol.interior_dofs},
                {"cells", st.cells},
                {"max_level", sol.space->mesh().max_level()},
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
      const tspline::PoissonErrors& e = st.errors;
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
      const tspline::PoissonStep& p = steps_.back();
      rec["rates_vs_dofs"] = {
          {"eta", rate(p.eta, st.eta, p.dofs, st.dofs)},
          {"l2", st.has_errors ? rate(p.errors.l2, st.errors.l2, p.dofs, st.dofs) : json(nullptr)},
          {"h1", st.has_errors ? rate(p.errors.h1, st.errors.h1, p.dofs, st.dofs) : json(nullptr)}};
    }
    steps_.push_back(st);
    peak_total_.push_back(std::accumulate(peak_mib.begin(), peak_mib.end(), 0.0));
    rec["output_seconds"] = seconds_since(t0);
    json event = rec;
    event["event"] = "step";
    report_["steps"].push_back(std::move(rec));
    write_tables(false);
    if (progress_.human()) print_row(st, peak_total_.back());
    progress_.event(event);
  }

  bool started() const { return started_; }

  /// Rewrites convergence.csv, solution.pvd and report.json (each atomically).
  void write_tables(bool finished) {
    const fs::path out(args_.out_dir);
    report_["finished"] = finished;
    std::ostringstream csv;
    csv << "step,dofs,cells,eta,l2,h1,eta_over_h1,solver,residual,seconds,iterations,assembly_seconds,"
           "solve_seconds,peak_mib\n";
    for (std::size_t k = 0; k < steps_.size(); ++k) {
      const tspline::PoissonStep& s = steps_[k];
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
    tspline::io::write_text_atomic((out / "convergence.csv").string(), csv.str());
    tspline::io::write_convergence_plot((out / "convergence.png").string(), steps_);
    tspline::io::write_pvd((out / "solution.pvd").string(), pvd_);
    tspline::io::write_text_atomic((out / "report.json").string(), report_.dump(2) + "\n");
  }

  json& report() { return report_; }
  const std::vector<tspline::PoissonStep>& steps() const { return steps_; }

 private:
  static void print_header() {
    std::printf("%4s %9s %9s %11s %11s %11s %8s %-12s %5s %9s %8s %8s %8s %8s\n", "step", "dofs", "cells", "eta",
                "L2", "H1", "eta/H1", "solver", "its", "residual", "assembly", "solve", "seconds", "peak_MiB");
  }
  static void print_row(const tspline::PoissonStep& s, double peak_mib) {
    char l2[32] = "-", h1[32] = "-", ratio[32] = "-";
    if (s.has_errors) {
      std::snprintf(l2, sizeof l2, "%.4e", s.errors.l2);
      std::snprintf(h1, sizeof h1, "%.4e", s.errors.h1);
      if (s.errors.h1 > 0) std::snprintf(ratio, sizeof ratio, "%.3f", s.eta / s.errors.h1);
    }
    std::printf("%4d %9zu %9zu %11.4e %11s %11s %8s %-12s %5d %9.2e %8.3f %8.3f %8.3f %8.1f\n", s.step, s.dofs,
                s.cells, s.eta, l2, h1, ratio, short_solver(s.solver).c_str(), s.solver.iterations,
                s.solver.relative_residual, s.assembly_seconds, s.solver.seconds, s.seconds, peak_mib);
    std::fflush(stdout);
  }

  const PoissonArgs& args_;
  const tspline::TSplineMap& map_;
  const tspline::PoissonProblem& problem_;
  json report_;
  std::vector<tspline::PoissonStep> steps_;
  std::vector<double> peak_total_;  // per step: sum over the processes of their peak memory, MiB
  std::vector<tspline::io::PvdEntry> pvd_;
  bool started_ = false;
  Progress& progress_;
};

// ------------------------------------------------------------------ run

/// The loop on every process; rank 0 writes and prints.
int run_poisson_process(const PoissonArgs& args, const PetscSession& session,
                        std::chrono::steady_clock::time_point t_start) {
  const bool root = session.rank() == 0;
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(args.file);
  if (maps.version == 2) {  // multi-patch map: C0 coupling across the interfaces (poisson_multipatch.h)
    const ProblemSetup mp = make_problem(args, maps.patches.front().map);
    return root ? tspline_app::run_multipatch_poisson(
                      maps, {args.refine, args.steps, args.gamma, args.max_dofs, args.out_dir, args.quiet || args.json},
                      mp.problem, mp.description)
                : 0;
  }
  const tspline::io::LoadedTSpline& t = maps.patches.front();
  const ProblemSetup setup = make_problem(args, t.map);

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
      {"options",
       {{"refine", args.refine},
        {"steps", args.steps},
        {"gamma", args.gamma},
        {"max_dofs", args.max_dofs},
        {"samples", args.samples},
        {"solver", args.solver},
        {"preconditioner", args.preconditioner},
        {"rtol", args.rtol},
        {"max_iterations", args.max_iterations},
        {"direct_below", args.direct_below},
        {"processes", session.size()}}},
      {"geometry",
       {{"cells", t.map.mesh().num_cells()},
        {"functions", t.map.basis().size()},
        {"hanging_vertices", t.map.mesh().num_hanging_vertices()}}},
      {"analysis_space", "cubic hierarchical B-splines of the analysis T-mesh"},
      {"dirichlet", "L2 projection of g onto the boundary functions' traces on the parameter square's border"},
      {"quadrature", {{"assembly", "4x4 Gauss"}, {"errors", "6x6 Gauss"}, {"estimator", "4x4 Gauss"}}}};
  Progress progress(root ? output_mode(args.quiet, args.json) : OutputMode::Quiet);
  PoissonOutput output(args, t.map, setup.problem, std::move(report), progress);
  std::vector<tspline::PoissonStep> steps;
  try {
    steps = tspline::solve_adaptive(t.map, setup.problem, opt,
                                    [&](const tspline::PoissonStep& st, const tspline::PoissonSolution& sol,
                                        const std::vector<double>& eta) {
                                      const std::vector<double> peak = tspline::petsc::peak_memory_mib();
                                      if (root) output.step(st, sol, eta, peak);
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
  std::string stop;
  if (static_cast<int>(steps.size()) == args.steps)
    stop = "all " + std::to_string(args.steps) + " steps done";
  else if (!steps.empty() && steps.back().eta_at_roundoff)
    stop = "the estimator is at round-off (u_h solves the problem exactly): nothing to refine";
  else if (!steps.empty() && steps.back().marked == 0)
    stop = "no cell marked (eta = 0 everywhere)";
  else
    stop = "the next space would have more than --max-dofs " + std::to_string(args.max_dofs) + " DOFs";
  if (!root) return 0;
  output.report()["stop_reason"] = stop;
  output.report()["seconds_total"] = seconds_since(t_start);
  output.write_tables(true);
  progress.event({{"event", "result"},
                  {"steps", steps.size()},
                  {"stop_reason", stop},
                  {"out", args.out_dir},
                  {"files", {"convergence.csv", "convergence.png", "report.json", "solution.pvd", "solution/"}}});
  if (progress.human())
    std::cout << steps.size() << " steps (" << stop
              << "); wrote convergence.csv, convergence.png, report.json, solution.pvd, solution/"
              << " to " << args.out_dir << std::endl;
  return 0;
}

int run_poisson(const PoissonArgs& args) {
  const auto t_start = Clock::now();
  // Everything that can be checked is checked before OUTDIR is created.
  validate_options(args);
  check_output_directory(args.out_dir);
  const PetscSession session;
  if (session.rank() == 0) return run_poisson_process(args, session, t_start);
  // Other ranks fail alike (same input, same collective calls); only rank 0 prints the message.
  try {
    return run_poisson_process(args, session, t_start);
  } catch (const tspline::InputError&) {
    return 1;
  } catch (const tspline::IoError&) {
    return 2;
  } catch (const tspline::NumericalError&) {
    return 3;
  } catch (const std::exception&) {
    return 4;
  }
}

}  // namespace

void add_poisson_command(CLI::App& app, CommandAction& action) {
  auto a = std::make_shared<PoissonArgs>();
  CLI::App* cmd = app.add_subcommand(
      "poisson",
      "Solve -Laplace(u) = f in the domain of a T-spline file, u = g on its boundary, with isogeometric "
      "analysis (cubic hierarchical B-splines of an analysis T-mesh that starts as the geometry's and is refined; "
      "the geometry map stays fixed), and refine adaptively (residual estimator eta_e^2 = int h^2 (f + Laplace "
      "u_h)^2, cells with eta_e > gamma max eta split with their neighbours) or uniformly. Dirichlet data by L2 "
      "projection on the boundary "
      "functions. Prints one table row per step and writes OUTDIR/convergence.csv, OUTDIR/convergence.png, OUTDIR/report.json and "
      "OUTDIR/solution.pvd with OUTDIR/solution/step_NNN.vtu (point data u_h, u_exact, error = u_h - "
      "u_exact; cell "
      "data eta, level, cell). Built-in problems (f = -Laplace(u) analytic, g = u, exact gradient analytic): "
      "sinsin u = sin(pi x) sin(pi y); polynomial u = x^3 + x^2 y - 2 y^3 + x y (in the discrete space when "
      "the map is affine); gaussian u = exp(-((x-x0)^2 + (y-y0)^2)/s^2) with "
      "(x0, y0) the centre of the bounding box of the control points and s = 0.1 x its diagonal");
  cmd->add_option("TSPLINE", a->file, "T-spline file (tspline.json written by `tspline param`)")
      ->type_name("FILE")
      ->required();
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
                       ->check(CLI::IsMember({"gaussian", "sinsin", "polynomial"}));
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
