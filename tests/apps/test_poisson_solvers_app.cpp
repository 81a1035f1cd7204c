// `tspline poisson --solver direct|iterative|auto`, serial and under `mpirun -n 2`:
// the PETSc CG + AMG solve (tspline/petsc_solver.h) must give the same
// discretization errors as the direct CHOLMOD solve, to 1e-6 relative, on the
// square and on a curved domain (the disk), with uniform and adaptive
// refinement; bad solver options and a solve that does not converge are errors.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "poisson_app_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using test_support::count_lines;
std::string q(const fs::path& p) { return test_support::quoted(p); }
using test_support::run_app;
using test_support::run_program;
using test_support::slurp;

fs::path scratch(const std::string& name) { return test_support::scratch_dir("poisson_solvers_app", name); }

/// tspline.json of a bundled polygon, made once per process by `tspline param`.
fs::path geometry(const std::string& polygon) {
  return test_support::single_patch_map("poisson_solvers_app", polygon);
}

json report(const fs::path& out) { return test_support::poisson_report(out); }
using test_support::check_same_errors;
using test_support::run_mpi;

}  // namespace

TEST_SUITE("poisson_solvers_app") {
  TEST_CASE("direct and iterative give the same errors: square and disk, uniform and adaptive") {
    struct Case {
      const char* polygon;
      const char* args;
    };
    for (const Case& c : {Case{"square.txt", "--problem sinsin --refine uniform --steps 3"},
                          Case{"square.txt", "--problem gaussian --steps 3"},
                          Case{"disk.txt", "--problem sinsin --refine uniform --steps 2"},
                          Case{"disk.txt", "--problem gaussian --steps 3"}}) {
      CAPTURE(c.polygon);
      CAPTURE(c.args);
      const fs::path d = scratch("agree");
      const std::string base = "poisson " + q(geometry(c.polygon)) + " " + c.args + " -q --out ";
      const auto a = run_app(base + q(d / "direct") + " --solver direct", d);
      CAPTURE(a.err);
      REQUIRE(a.exit_code == 0);
      const auto b = run_app(base + q(d / "iterative") + " --solver iterative", d);
      CAPTURE(b.err);
      REQUIRE(b.exit_code == 0);
      const json ra = report(d / "direct"), rb = report(d / "iterative");
      check_same_errors(ra, rb);
      for (const json& s : ra["steps"]) CHECK(s["solver"]["kind"] == "CholmodSupernodalLLT");
      for (const json& s : rb["steps"]) {
        CHECK(s["solver"]["kind"] == "PETSc CG + hypre BoomerAMG");
        CHECK(s["solver"]["iterations"].get<int>() >= 1);
        // AMG: 12-17 iterations on the square; on the disk, whose map is singular at the
        // four points that the square's corners go to, 24-73, leveling off near 50 under refinement.
        CHECK(s["solver"]["iterations"].get<int>() <= 100);
        // The default --rtol auto: min(1e-10, max(1e-15, 0.02 / n^2)) for n interior DOFs.
        const double n = s["interior_dofs"].get<double>();
        const double rtol = std::min(1e-10, std::max(1e-15, 0.02 / (n * n)));
        CHECK(s["solver"]["rtol"].get<double>() == doctest::Approx(rtol).epsilon(1e-12));
        CHECK(s["solver"]["relative_residual"].get<double>() <= 2 * rtol);
        CHECK(s["solver"]["processes"] == 1);
        CHECK(s["peak_memory_mib"]["per_process"].size() == 1);
        CHECK(s["peak_memory_mib"]["total"].get<double>() > 1.0);
      }
    }
  }

  TEST_CASE("GAMG agrees too; auto picks direct below --direct-below and iterative from it") {
    const fs::path d = scratch("gamg_auto");
    const std::string base =
        "poisson " + q(geometry("disk.txt")) + " --problem sinsin --refine uniform --steps 2 -q --out ";
    const auto a = run_app(base + q(d / "direct") + " --solver direct", d);
    REQUIRE(a.exit_code == 0);
    const auto b = run_app(base + q(d / "gamg") + " --solver iterative --preconditioner gamg", d);
    CAPTURE(b.err);
    REQUIRE(b.exit_code == 0);
    check_same_errors(report(d / "direct"), report(d / "gamg"));
    CHECK(report(d / "gamg")["steps"][0]["solver"]["kind"] == "PETSc CG + PETSc GAMG");
    // Threshold between the interior DOFs of the two steps.
    const json ra = report(d / "direct");
    const int n0 = ra["steps"][0]["interior_dofs"].get<int>(), n1 = ra["steps"][1]["interior_dofs"].get<int>();
    REQUIRE(n0 < n1);
    const auto c = run_app(base + q(d / "auto") + " --direct-below " + std::to_string(n1), d);
    CAPTURE(c.err);
    REQUIRE(c.exit_code == 0);
    const json rc = report(d / "auto");
    CHECK(rc["steps"][0]["solver"]["kind"] == "CholmodSupernodalLLT");
    CHECK(rc["steps"][1]["solver"]["kind"] == "PETSc CG + hypre BoomerAMG");
    check_same_errors(ra, rc);
  }

  TEST_CASE("mpirun -n 2: same errors as the serial direct solve, files written once") {
    const fs::path d = scratch("mpi");
    const std::string base = "poisson " + q(geometry("disk.txt")) + " --problem gaussian --steps 3 --out ";
    const auto a = run_app(base + q(d / "direct") + " -q --solver direct", d);
    REQUIRE(a.exit_code == 0);
    const auto b = run_mpi(2, base + q(d / "mpi") + " --solver iterative", d);
    CAPTURE(b.out);
    CAPTURE(b.err);
    REQUIRE(b.exit_code == 0);
    const json rb = report(d / "mpi");
    const json ra = report(d / "direct");
    check_same_errors(ra, rb);
    // The estimator, split over the two processes and summed, marks the same
    // cells (same DOFs, checked above) and has the same value.
    for (std::size_t k = 0; k < ra["steps"].size(); ++k) {
      const double ea = ra["steps"][k]["eta"].get<double>(), eb = rb["steps"][k]["eta"].get<double>();
      CHECK(std::abs(ea - eb) <= 1e-6 * ea);
    }
    CHECK(rb["options"]["processes"] == 2);
    for (const json& s : rb["steps"]) {
      CHECK(s["solver"]["processes"] == 2);
      CHECK(s["peak_memory_mib"]["per_process"].size() == 2);
      CHECK(s["solver"]["relative_residual"].get<double>() <= 1e-10);
    }
    // One process prints: the closing line once, one table row per step.
    std::size_t closing = 0;
    for (std::size_t p = b.out.find("steps (all 3 steps done)"); p != std::string::npos;
         p = b.out.find("steps (all 3 steps done)", p + 1))
      ++closing;
    CHECK(closing == 1);
    CHECK(fs::exists(d / "mpi" / "solution" / "step_002.vtu"));
  }

  TEST_CASE("bad solver options: one error line, exit 1, nothing written") {
    const fs::path d = scratch("bad");
    const std::string sq = q(geometry("square.txt"));
    struct Case {
      std::string args, needle;
    };
    for (const Case& c : {Case{"--solver cholesky", "unknown solver 'cholesky' (expected auto, direct or iterative)"},
                          Case{"--preconditioner ilu", "unknown preconditioner 'ilu'"},
                          Case{"--rtol 0", "--rtol must be > 0, got 0"},
                          Case{"--rtol -1e-8", "--rtol must be > 0"},
                          Case{"--rtol tight", "--rtol must be 'auto' or a number > 0, got 'tight'"},
                          Case{"--max-iterations 0", "--max-iterations must be at least 1"}}) {
      const std::string args = "poisson " + sq + " --problem sinsin " + c.args + " --out " + q(d / "out");
      CAPTURE(args);
      const auto r = run_app(args, d);
      CAPTURE(r.err);
      CHECK(r.exit_code == 1);
      CHECK(count_lines(r.err) == 1);
      CHECK(r.err.find(c.needle) != std::string::npos);
      CHECK(!fs::exists(d / "out"));
    }
  }

  TEST_CASE("a solve that does not converge: one error line, exit 3, the steps before it stay written") {
    const fs::path d = scratch("no_convergence");
    const fs::path out = d / "out";
    // Steps 0 and 1 (81 and 289 interior DOFs) direct, step 2 (1089) iterative with 2 iterations at most.
    const auto r = run_app("poisson " + q(geometry("square.txt")) +
                               " --problem sinsin --refine uniform --steps 4 -q --direct-below 1000 "
                               "--max-iterations 2 --out " + q(out),
                           d);
    CAPTURE(r.err);
    CHECK(r.exit_code == 3);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.rfind("tspline: error: iterative solve (PETSc CG + hypre BoomerAMG) did not converge", 0) == 0);
    CHECK(r.err.find("after 2 iterations (limit 2)") != std::string::npos);
    const json rep = report(out);
    CHECK(rep["finished"] == false);
    REQUIRE(rep["steps"].size() == 2);
    CHECK(rep["error"].get<std::string>().find("did not converge") != std::string::npos);
    CHECK(fs::exists(out / "solution" / "step_001.vtu"));
    CHECK(!fs::exists(out / "solution" / "step_002.vtu"));
  }
}
