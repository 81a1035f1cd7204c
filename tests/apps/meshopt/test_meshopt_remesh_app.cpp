// End-to-end tests of `meshopt remesh` on an OpenCASCADE model (a cylinder
// fused with a sphere: several faces, sharp and boundary curves): outputs,
// JSON report, the .msh read back by Gmsh and by `meshopt smooth`; bad input.
#include <doctest/doctest.h>
#include <gmsh.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "meshopt/gmsh/gmsh_mesh.h"
#include "cad_fixtures.h"
#include "meshopt_app_support.h"
#include "test_support.h"

TEST_SUITE_BEGIN("meshopt_remesh_app");

namespace fs = std::filesystem;
using test_support::contains;

namespace {

using meshopt_app_test::run_meshopt;

/// The fused cylinder and sphere of cad_fixtures, as BRep.
void write_model(const fs::path& brep) {
  meshopt::gmsh_io::Session session;
  cad_fixtures::add_cylinder_sphere();
  gmsh::write(brep.string());
}

}  // namespace

TEST_CASE("meshopt remesh: a fused cylinder and sphere, outputs readable by Gmsh and meshopt smooth") {
  const fs::path dir = test_support::scratch_dir("meshopt_remesh_app", "cad");
  write_model(dir / "model.brep");
  const std::string model = std::string("'") + (dir / "model.brep").string() + "'";
  const auto run = test_support::require_success(
      run_meshopt("remesh " + model + " --out '" + (dir / "out/r.msh").string() + "' --vtu '" +
                      (dir / "out/r.vtu").string() + "' --length 0.15 --anisotropy 0.5",
                  dir));
  CHECK(contains(run.out, "meshopt remesh:"));
  CHECK(contains(run.out, "chordal deviation"));
  const nlohmann::json rep = nlohmann::json::parse(test_support::slurp(dir / "out/r.json"));
  MESSAGE("fused model: " << rep["before"]["triangles"] << " -> " << rep["after"]["triangles"] << " triangles, "
                          << rep["patches"] << " patches, " << rep["feature_curves"] << " feature curves, "
                          << "chordal deviation max " << rep["chordal_deviation"]["max_relative"]
                          << " of the diagonal, " << rep["seconds"]);
  CHECK(rep["patches"].get<int>() >= 3);
  CHECK(rep["feature_curves"].get<int>() >= 2);
  CHECK(rep["topology"]["kept"].get<bool>());
  CHECK(rep["topology"]["non_manifold_edges"].get<int>() == 0);
  CHECK(rep["after"]["min_angle6d_degrees"]["min"].get<double>() > 10.0);
  const double mean_ratio = rep["after"]["length6d_over_L"]["mean"].get<double>();
  CHECK(mean_ratio > 0.75);
  CHECK(mean_ratio < 1.25);
  CHECK(rep["chordal_deviation"]["max_relative"].get<double>() < 0.01);
  std::size_t hist = 0;
  for (const auto& c : rep["after"]["min_angle6d_degrees"]["histogram"]["counts"]) hist += c.get<std::size_t>();
  CHECK(hist == rep["after"]["triangles"].get<std::size_t>());
  CHECK(fs::file_size(dir / "out/r.vtu") > 1000);
  {
    // Gmsh opens it with the model: as many triangles as reported, nodes classified with parameters.
    meshopt::gmsh_io::Session session;
    meshopt::gmsh_io::open_model((dir / "model.brep").string());
    meshopt::gmsh_io::merge_mesh((dir / "out/r.msh").string());
    std::vector<std::size_t> tags, nodes;
    gmsh::model::mesh::getElementsByType(2, tags, nodes);
    CHECK(tags.size() == rep["after"]["triangles"].get<std::size_t>());
    std::vector<std::size_t> ntags;
    std::vector<double> xyz, uv;
    gmsh::model::mesh::getNodes(ntags, xyz, uv, 2, -1, false, true);
    CHECK(!ntags.empty());
  }
  // meshopt smooth reads it (nodes across smooth junctions stay fixed) and keeps it valid.
  const auto smooth = run_meshopt("smooth " + model + " --mesh '" + (dir / "out/r.msh").string() + "' --out '" +
                                      (dir / "out/s.msh").string() + "' --quiet --max-sweeps 3",
                                  dir);
  CAPTURE(smooth.err);
  CHECK(smooth.exit_code == 0);
  // --json: NDJSON on stdout ending with the result. --max-deviation D alone
  // derives L = 160 D and s = 5 L.
  const auto js = run_meshopt("remesh " + model + " --out '" + (dir / "out/j.msh").string() +
                                  "' --max-deviation 0.002 --rounds 1 --json",
                              dir);
  REQUIRE(js.exit_code == 0);
  const std::string last = js.out.substr(js.out.rfind('\n', js.out.size() - 2) + 1);
  const nlohmann::json result = nlohmann::json::parse(last);
  CHECK(result["event"] == "result");
  CHECK(result["report"]["length"].get<double>() == doctest::Approx(0.32));
  CHECK(result["report"]["anisotropy"].get<double>() == doctest::Approx(1.6));
  CHECK(result["report"]["max_deviation"].get<double>() == doctest::Approx(0.002));
}

TEST_CASE("meshopt remesh: bad input gives one clear error and exit 1, unwritable output exit 2") {
  const fs::path dir = test_support::scratch_dir("meshopt_remesh_app", "bad");
  write_model(dir / "model.brep");
  std::ofstream(dir / "garbage.step") << "not a STEP file\n";
  const std::string model = std::string("'") + (dir / "model.brep").string() + "'";
  const std::string out = " --out '" + (dir / "o.msh").string() + "' --quiet";
  const std::vector<meshopt_app_test::BadInput> cases = {
      {"remesh '" + (dir / "missing.step").string() + "' --length 0.1" + out, "cannot read the model"},
      {"remesh '" + (dir / "garbage.step").string() + "' --length 0.1" + out, "cannot load the model"},
      {"remesh " + model + " --length -1" + out, "--length must be positive"},
      {"remesh " + model + out, "give --length or --max-deviation"},
      {"remesh " + model + " --max-deviation -0.1" + out, "--max-deviation must be positive"},
      {"remesh " + model + " --length 0.1 --anisotropy -2" + out, "--anisotropy must be >= 0"},
      {"remesh " + model + " --length 0.1 --feature-angle 200" + out, "--feature-angle must be in [0, 180]"},
      {"remesh " + model + " --length 0.1 --out '" + (dir / "o.txt").string() + "'", "--out must end in .msh"},
      {"remesh " + model + " --length 0.1 --mesh '" + (dir / "missing.msh").string() + "'" + out,
       "cannot read the mesh"},
  };
  meshopt_app_test::check_bad_inputs(cases, dir, dir / "o.msh");
  std::ofstream(dir / "file") << "x";
  const auto r = run_meshopt("remesh " + model + " --length 0.3 --out '" + (dir / "file/o.msh").string() + "' --quiet", dir);
  CAPTURE(r.err);
  CHECK(r.exit_code == 2);
  CHECK(test_support::count_lines(r.err) == 1);
}

TEST_SUITE_END();
