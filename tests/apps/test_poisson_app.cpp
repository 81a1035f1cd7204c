// End-to-end runs of `tspline poisson`: built-in problems, expressions, output
// files, and every bad-input case (clear error, non-zero exit, nothing written).
#include <doctest/doctest.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkErrorCode.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "poisson_app_support.h"

namespace fs = std::filesystem;

namespace {

using test_support::count_lines;
using test_support::run_app;
using test_support::slurp;

fs::path scratch(const std::string& name) { return test_support::scratch_dir("poisson_app", name); }

/// The path in single quotes for the shell.
std::string q(const fs::path& p) { return test_support::quoted(p); }

/// tspline.json of a bundled polygon, made once per process by `tspline param`.
fs::path geometry(const std::string& polygon) {
  const fs::path file = test_support::single_patch_map("poisson_app", polygon);
  REQUIRE(fs::exists(file));
  return file;
}

using test_support::read_csv;
double num(const std::map<std::string, std::string>& row, const std::string& col) {
  return test_support::csv_number(row, col);
}

/// Lines of stdout that are table rows (start with a step number).
std::size_t table_rows(const std::string& out) {
  std::stringstream ss(out);
  std::string line;
  std::size_t n = 0;
  while (std::getline(ss, line)) {
    const auto p = line.find_first_not_of(' ');
    if (p != std::string::npos && std::isdigit(static_cast<unsigned char>(line[p])) &&
        line.find("steps (") == std::string::npos)
      ++n;
  }
  return n;
}

constexpr const char* kSinSin = "sin(pi*x)*sin(pi*y)";

}  // namespace

TEST_SUITE("poisson_app") {
  TEST_CASE("polynomial problem on the square is reproduced to round-off") {
    // `param` maps the square onto itself with a uniform T-mesh, so u is in the
    // discrete space; uniform refinement keeps the mesh free of T-junctions.
    const fs::path d = scratch("polynomial");
    const auto r = run_app(
        "poisson " + q(geometry("square.txt")) +
            " --problem polynomial --refine uniform --steps 2 --vtu-compression zlib --out " + q(d / "out"),
        d);
    CAPTURE(r.err);
    CAPTURE(r.out);
    REQUIRE(r.exit_code == 0);
    CHECK(r.err.empty());
    CHECK(table_rows(r.out) == 2);
    const auto rows = read_csv(d / "out" / "convergence.csv");
    REQUIRE(rows.size() == 2);
    for (const auto& row : rows) {
      CHECK(num(row, "l2") <= 1e-10);
      CHECK(num(row, "h1") <= 1e-8);
      CHECK(num(row, "eta") <= 1e-8);
      CHECK(num(row, "residual") <= 1e-10);
    }
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["problem"]["name"] == "polynomial");
    CHECK(rep["problem"]["exact_gradient"] == "analytic");
    CHECK(rep["options"]["refine"] == "uniform");
    CHECK(rep["finished"] == true);
    int solution_files = 0;  // each step's, zlib-compressed as asked (LZ4 by default)
    for (const auto& e : fs::directory_iterator(d / "out" / "solution")) {
      const std::string text = slurp(e.path());
      CHECK(text.substr(0, text.find("<AppendedData")).find("compressor=\"vtkZLibDataCompressor\"") !=
            std::string::npos);
      ++solution_files;
    }
    CHECK(solution_files == 2);
    REQUIRE(rep["steps"].size() == 2);
    for (const auto& s : rep["steps"]) {
      for (const char* k : {"assembly_seconds", "solve_seconds", "dirichlet_seconds", "step_seconds", "l2",
                            "h1", "eta", "dofs", "cells", "interior_dofs"})
        CHECK(s.contains(k));
      CHECK(s["solver"]["relative_residual"].get<double>() <= 1e-10);
    }
  }

  TEST_CASE("sinsin, uniform, 3 steps: errors decrease, every file is written") {
    const fs::path d = scratch("sinsin");
    const fs::path out = d / "out";
    const auto r = run_app("poisson " + q(geometry("square.txt")) +
                               " --problem sinsin --refine uniform --steps 3 --out " + q(out),
                           d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(table_rows(r.out) == 3);
    for (const char* h :
         {"step", "dofs", "cells", "eta", "L2", "H1", "eta/H1", "solver", "residual", "seconds"})
      CHECK(r.out.find(h) != std::string::npos);
    const auto rows = read_csv(out / "convergence.csv");
    REQUIRE(rows.size() == 3);
    CHECK(slurp(out / "convergence.csv")
              .rfind("step,dofs,cells,eta,l2,h1,eta_over_h1,solver,residual,seconds,iterations,assembly_seconds,"
                     "solve_seconds,peak_mib\n",
                     0) == 0);
    for (std::size_t k = 1; k < rows.size(); ++k) {
      CHECK(num(rows[k], "dofs") > num(rows[k - 1], "dofs"));
      CHECK(num(rows[k], "cells") == 4 * num(rows[k - 1], "cells"));
      CHECK(num(rows[k], "l2") < num(rows[k - 1], "l2") / 8);  // rate ~4 in h
      CHECK(num(rows[k], "h1") < num(rows[k - 1], "h1") / 4);  // rate ~3
      CHECK(num(rows[k], "eta") < num(rows[k - 1], "eta"));
    }
    for (const auto& row : rows) {
      CHECK(num(row, "eta_over_h1") == doctest::Approx(num(row, "eta") / num(row, "h1")).epsilon(1e-12));
      CHECK(row.at("solver") == "CholmodSupernodalLLT");
    }
    // ParaView collection: one dataset per step, each file present with its arrays.
    const std::string pvd = slurp(out / "solution.pvd");
    for (int k = 0; k < 3; ++k) {
      const std::string f = "solution/step_00" + std::to_string(k) + ".vtu";
      CHECK(pvd.find("file=\"" + f + "\"") != std::string::npos);
      CHECK(pvd.find("timestep=\"" + std::to_string(k) + "\"") != std::string::npos);
      REQUIRE(fs::exists(out / f));
      const std::string vtu = slurp(out / f);
      for (const char* a : {"\"u_h\"", "\"u_exact\"", "\"error\"", "\"eta\"", "\"level\""})
        CHECK(vtu.find(a) != std::string::npos);
    }
    CHECK(!fs::exists(out / "solution" / "step_003.vtu"));
    {
      // Read back with VTK: 64 analysis cells x 2 x 2 sub-quads (default --samples 2)
      // on the cells' shared grid points, (8 x 2 + 1)^2; u_h - u_exact = error,
      // small at the coarsest step; eta per cell.
      vtkNew<vtkXMLUnstructuredGridReader> reader;
      reader->SetFileName((out / "solution" / "step_000.vtu").c_str());
      reader->Update();
      REQUIRE(reader->GetErrorCode() == vtkErrorCode::NoError);
      vtkUnstructuredGrid* g = reader->GetOutput();
      REQUIRE(g != nullptr);
      CHECK(g->GetNumberOfCells() == 64 * 4);
      CHECK(g->GetNumberOfPoints() == 17 * 17);
      vtkDataArray* uh = g->GetPointData()->GetArray("u_h");
      vtkDataArray* ue = g->GetPointData()->GetArray("u_exact");
      vtkDataArray* er = g->GetPointData()->GetArray("error");
      vtkDataArray* eta = g->GetCellData()->GetArray("eta");
      vtkDataArray* level = g->GetCellData()->GetArray("level");
      REQUIRE(uh != nullptr);
      REQUIRE(ue != nullptr);
      REQUIRE(er != nullptr);
      REQUIRE(eta != nullptr);
      REQUIRE(level != nullptr);
      double max_err = 0;
      for (vtkIdType i = 0; i < g->GetNumberOfPoints(); ++i) {
        CHECK(er->GetTuple1(i) == doctest::Approx(uh->GetTuple1(i) - ue->GetTuple1(i)).epsilon(1e-12));
        max_err = std::max(max_err, std::abs(er->GetTuple1(i)));
        double p[3];
        g->GetPoint(i, p);
        CHECK(ue->GetTuple1(i) ==
              doctest::Approx(std::sin(std::numbers::pi * p[0]) * std::sin(std::numbers::pi * p[1]))
                  .epsilon(1e-9));
      }
      CHECK(max_err < 1e-4);
      CHECK(max_err > 0);
      for (vtkIdType c = 0; c < g->GetNumberOfCells(); ++c) {
        CHECK(eta->GetTuple1(c) >= 0);
        CHECK(level->GetTuple1(c) == 3);
      }
    }
    const auto rep = nlohmann::json::parse(slurp(out / "report.json"));
    CHECK(rep["finished"] == true);
    CHECK(rep["stop_reason"].get<std::string>().find("all 3 steps") != std::string::npos);
    REQUIRE(rep["steps"].size() == 3);
    const double l2_rate = rep["steps"][2]["rates_vs_dofs"]["l2"].get<double>();
    MESSAGE("L2 rate vs DOFs, last pair: " << l2_rate);
    CHECK(l2_rate > 3.5);
    // No temporary files left behind.
    for (const auto& e : fs::recursive_directory_iterator(out)) CHECK(e.path().filename().string()[0] != '.');
  }

  TEST_CASE("--f, --g, --exact as expressions reproduce the built-in sinsin") {
    const fs::path d = scratch("expressions");
    const std::string base = "poisson " + q(geometry("square.txt")) + " --refine uniform --steps 2 -q";
    const auto a = run_app(base + " --problem sinsin --out " + q(d / "builtin"), d);
    REQUIRE(a.exit_code == 0);
    CHECK(a.out.empty());  // --quiet
    const auto b = run_app(base + " --f '2*pi^2*" + kSinSin + "' --g '" + kSinSin + "' --exact '" + kSinSin +
                               "' --out " + q(d / "expr"),
                           d);
    CAPTURE(b.err);
    REQUIRE(b.exit_code == 0);
    const auto ra = read_csv(d / "builtin" / "convergence.csv"),
               rb = read_csv(d / "expr" / "convergence.csv");
    REQUIRE(ra.size() == 2);
    REQUIRE(rb.size() == 2);
    for (std::size_t k = 0; k < ra.size(); ++k) {
      CHECK(ra[k].at("dofs") == rb[k].at("dofs"));
      CHECK(num(rb[k], "l2") == doctest::Approx(num(ra[k], "l2")).epsilon(1e-9));
      CHECK(num(rb[k], "eta") == doctest::Approx(num(ra[k], "eta")).epsilon(1e-9));
      // The expression's gradient comes from central differences (step 1e-5).
      CHECK(num(rb[k], "h1") == doctest::Approx(num(ra[k], "h1")).epsilon(1e-6));
    }
    const auto rep = nlohmann::json::parse(slurp(d / "expr" / "report.json"));
    CHECK(rep["problem"]["name"] == "expressions");
    CHECK(rep["problem"]["u"] == kSinSin);
    CHECK(rep["problem"]["exact_gradient"].get<std::string>().find("central differences") !=
          std::string::npos);
  }

  TEST_CASE("without an exact solution: estimator only; --max-dofs stops the loop") {
    const fs::path d = scratch("no_exact");
    const auto r = run_app(
        "poisson " + q(geometry("disk.txt")) + " --f 1 --g 0 --steps 4 --max-dofs 1 -q --out " + q(d / "out"),
        d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    const auto rows = read_csv(d / "out" / "convergence.csv");
    REQUIRE(rows.size() == 1);  // the first step always runs
    CHECK(rows[0].at("l2").empty());
    CHECK(rows[0].at("h1").empty());
    CHECK(num(rows[0], "eta") > 0);
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["steps"][0]["l2"].is_null());
    CHECK(rep["stop_reason"].get<std::string>().find("--max-dofs") != std::string::npos);
    const std::string vtu = slurp(d / "out" / "solution" / "step_000.vtu");
    CHECK(vtu.find("\"u_h\"") != std::string::npos);
    CHECK(vtu.find("\"u_exact\"") == std::string::npos);
  }

  TEST_CASE("adaptive Gaussian peak on the disk: the estimator tracks the H1 error") {
    const fs::path d = scratch("gaussian");
    const auto r = run_app(
        "poisson " + q(geometry("disk.txt")) + " --problem gaussian --steps 4 -q --out " + q(d / "out"), d);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    const auto rep = nlohmann::json::parse(slurp(d / "out" / "report.json"));
    CHECK(rep["problem"]["s"].get<double>() > 0);
    REQUIRE(rep["steps"].size() == 4);
    for (const auto& s : rep["steps"]) {
      MESSAGE("dofs " << s["dofs"] << " H1 " << s["h1"] << " eta/H1 " << s["eta_over_h1"] << " marked "
                      << s["marked"]);
      CHECK(s["eta_over_h1"].get<double>() >= 3.0);
      CHECK(s["eta_over_h1"].get<double>() <= 15.0);
    }
    CHECK(rep["steps"][3]["dofs"].get<int>() > rep["steps"][0]["dofs"].get<int>());
    CHECK(rep["steps"][3]["h1"].get<double>() < rep["steps"][0]["h1"].get<double>());
  }

  TEST_CASE("bad input: one error line, exit 1 or 2, no output directory") {
    const fs::path d = scratch("bad");
    const fs::path out = d / "out";
    const std::string sq = q(geometry("square.txt"));
    std::ofstream(d / "invalid.json") << "{\"format\": \"tspline\", \"version\": 1}";
    std::ofstream(d / "plain_file") << "x";
    struct Case {
      std::string args;
      int code;
      std::string needle;
    };
    const std::vector<Case> cases = {
        {q(d / "invalid.json") + " --problem sinsin", 1, "invalid.json"},
        {sq + " --f 'x^2 +' --g 0", 1, "--f: cannot parse 'x^2 +'"},
        {sq + " --f 1 --g 'sin(x'", 1, "--g: cannot parse"},
        {sq + " --f 1 --g 0 --exact 'x + z'", 1, "--exact: cannot parse"},
        {sq + " --f 'sqrt(-1)' --g 0", 1, "--f is not finite"},
        {sq + " --f 1 --g 'sqrt(x - 0.5)'", 1, "--g is not finite"},  // NaN on part of the border
        {sq + " --problem sinsin --gamma 1.5", 1, "--gamma must lie in [0, 1]"},
        {sq + " --problem sinsin --gamma -0.1", 1, "--gamma must lie in [0, 1]"},
        {sq + " --f 1", 1, "--f needs --g"},
        {sq + "", 1, "--problem"},
        {sq + " --problem sinsin --f 1", 1, "cannot be combined"},
        {sq + " --problem nonesuch", 1, "nonesuch"},
        {sq + " --problem sinsin --steps 0", 1, "--steps"},
        {sq + " --problem sinsin --samples 0", 1, "--samples"},
        {q(d / "no_such_file.json") + " --problem sinsin", 2, "no_such_file.json"},
    };
    for (const Case& c : cases) {
      const std::string args = "poisson " + c.args + " --out " + q(out);
      CAPTURE(args);
      const auto r = run_app(args, d);
      CAPTURE(r.err);
      CHECK(r.exit_code == c.code);
      CHECK(count_lines(r.err) == 1);
      CHECK(r.err.rfind("tspline: error: ", 0) == 0);
      CHECK(r.err.find(c.needle) != std::string::npos);
      CHECK(!fs::exists(out));
    }
    // An output directory that cannot be created: exit 2 before any work.
    const auto r = run_app("poisson " + sq + " --problem sinsin --out " + q(d / "plain_file" / "sub"), d);
    CAPTURE(r.err);
    CHECK(r.exit_code == 2);
    CHECK(count_lines(r.err) == 1);
    CHECK(r.err.find("not a directory") != std::string::npos);
  }

  TEST_CASE("--help documents every option and the built-in problems") {
    const fs::path d = scratch("help");
    const auto r = run_app("poisson --help", d);
    CHECK(r.exit_code == 0);
    for (const char* s : {"--out", "--f", "--g", "--exact", "--problem", "--refine", "--steps", "--gamma",
                          "--max-dofs", "--samples", "--quiet", "central differences", "sinsin", "polynomial",
                          "gaussian", "bounding box of the control points", "0.1 x its diagonal"})
      CHECK(r.out.find(s) != std::string::npos);
  }
}
