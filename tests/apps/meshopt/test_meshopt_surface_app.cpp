// End-to-end tests of `meshopt smooth` on a CAD model made with Gmsh's
// OpenCASCADE kernel (a fused cylinder and sphere): mesh, tangle in parametric
// space, untangle through the command; and its bad-input errors.
#include <doctest/doctest.h>
#include <gmsh.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "meshopt/gmsh/gmsh_mesh.h"
#include "meshopt/surface_smoother.h"
#include "cad_fixtures.h"
#include "meshopt_app_support.h"
#include "test_support.h"

TEST_SUITE_BEGIN("meshopt_surface_app");

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer: OpenCASCADE (libTK*, e.g. its STEP reader's static tables),
// Gmsh, GDAL/PROJ (driver registry, PROJ contexts) and Cairo/fontconfig (font
// caches) keep allocations to the end of the process; suppress leaks whose
// stack passes through those third-party libraries only (our own code stays
// checked). One definition for the whole unit_tests binary.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libTK\nleak:libgmsh\nleak:libgdal\nleak:libproj\nleak:libcairo\nleak:libfontconfig\n";
}
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif

namespace fs = std::filesystem;
using namespace meshopt;
using test_support::contains;

namespace {

using meshopt_app_test::run_meshopt;

/// Writes the fused cylinder and sphere as a BRep file and reopens it, so that
/// its surface tags are those a reader of the file sees. \pre a gmsh_io::Session is alive.
void make_model(const fs::path& brep) {
  cad_fixtures::add_cylinder_sphere();
  gmsh::write(brep.string());
  gmsh::clear();
  gmsh_io::open_model(brep.string());
}

using cad_fixtures::tangle;

std::size_t tangled_elements() {
  const gmsh_io::GmshSurfaceMesh g = gmsh_io::read_surface_mesh();
  return surface_mesh_quality(g.mesh, SurfaceMeasure::shape).tangled;
}

void write_msh(const fs::path& path, bool parametric) {
  gmsh::option::setNumber("Mesh.SaveParametric", parametric ? 1 : 0);
  gmsh::write(path.string());
}

}  // namespace

TEST_CASE("meshopt smooth: a tangled mesh of a fused cylinder and sphere (OpenCASCADE) is untangled") {
  const fs::path dir = test_support::scratch_dir("meshopt_app", "cad");
  std::size_t tangled_in = 0;
  {
    gmsh_io::Session session;
    make_model(dir / "model.brep");
    gmsh::option::setNumber("Mesh.MeshSizeMax", 0.15);
    gmsh_io::generate_surface_mesh();
    REQUIRE(tangled_elements() == 0);
    tangle(3, 0.04, 17);
    tangled_in = tangled_elements();
    write_msh(dir / "tangled.msh", true);
  }
  MESSAGE("CAD model: " << tangled_in << " tangled elements before meshopt smooth");
  REQUIRE(tangled_in >= 20);
  const auto run = run_meshopt(std::string("smooth '") + (dir / "model.brep").string() + "' --mesh '" +
                                   (dir / "tangled.msh").string() + "' --out '" + (dir / "out/smoothed.msh").string() +
                                   "' --vtu '" + (dir / "out/smoothed.vtu").string() + "' --quiet",
                               dir);
  CAPTURE(run.out);
  CAPTURE(run.err);
  REQUIRE(run.exit_code == 0);
  CHECK(contains(run.out, "tangled"));
  const nlohmann::json rep = nlohmann::json::parse(test_support::slurp(dir / "out/smoothed.json"));
  CHECK(rep["before"]["tangled"].get<std::size_t>() == tangled_in);
  CHECK(rep["after"]["tangled"].get<std::size_t>() == 0);
  CHECK(rep["after"]["min"].get<double>() > 0.3);
  CHECK(rep["surfaces"].get<int>() >= 3);
  CHECK(fs::file_size(dir / "out/smoothed.vtu") > 1000);
  MESSAGE("CAD model after: min/mean quality " << rep["after"]["min"] << "/" << rep["after"]["mean"] << ", "
                                               << rep["sweeps"] << " sweeps, " << rep["seconds"] << " s");
  // The output opens in Gmsh with the same model, with parametric coordinates, untangled.
  gmsh_io::Session session;
  gmsh_io::open_model((dir / "model.brep").string());
  gmsh_io::merge_mesh((dir / "out/smoothed.msh").string());
  CHECK(tangled_elements() == 0);
}

TEST_CASE("meshopt smooth: bad input gives one clear error and exit 1") {
  const fs::path dir = test_support::scratch_dir("meshopt_app", "bad");
  const std::string out = std::string(" --out '") + (dir / "o.msh").string() + "' --quiet";
  {
    gmsh_io::Session session;
    make_model(dir / "model.brep");
    gmsh::option::setNumber("Mesh.MeshSizeMax", 0.3);
    gmsh_io::generate_surface_mesh();
    write_msh(dir / "no_parametric.msh", false);
    // A node inside surface 1 moved out of the surface's parameter range.
    std::vector<std::size_t> tags;
    std::vector<double> xyz, uv, lo, hi;
    gmsh::model::mesh::getNodes(tags, xyz, uv, 2, 1, false, true);
    gmsh::model::getParametrizationBounds(2, 1, lo, hi);
    REQUIRE(!tags.empty());
    gmsh::model::mesh::setNode(tags[0], {xyz[0], xyz[1], xyz[2]}, {hi[0] + 1.0, uv[1]});
    write_msh(dir / "outside.msh", true);
    gmsh::model::mesh::setNode(tags[0], {xyz[0], xyz[1], xyz[2]}, {uv[0], uv[1]});
    // A node moved into a trimmed-away part of a face (inside its parameter box):
    // the sphere, cut where the cylinder enters it.
    bool trimmed = false;
    gmsh::vectorpair faces;
    gmsh::model::getEntities(faces, 2);
    for (const auto& [d, f] : faces) {
      std::vector<std::size_t> ft;
      std::vector<double> fx, fuv, flo, fhi;
      gmsh::model::mesh::getNodes(ft, fx, fuv, 2, f, false, true);
      gmsh::model::getParametrizationBounds(2, f, flo, fhi);
      for (int i = 1; i < 20 && !trimmed && !ft.empty(); ++i)
        for (int j = 1; j < 20 && !trimmed; ++j) {
          const std::vector<double> p{flo[0] + (fhi[0] - flo[0]) * i / 20.0, flo[1] + (fhi[1] - flo[1]) * j / 20.0};
          if (gmsh::model::isInside(2, f, p) != 0) continue;
          std::vector<double> x;
          gmsh::model::getValue(2, f, p, x);
          gmsh::model::mesh::setNode(ft[0], x, p);
          trimmed = true;
        }
    }
    REQUIRE(trimmed);
    write_msh(dir / "trimmed.msh", true);
  }
  {
    // A sphere with a node inside it moved onto its pole (phi_u = 0 there).
    gmsh_io::Session session;
    gmsh::model::add("sphere");
    gmsh::model::occ::addSphere(0, 0, 0, 1.0, 1);
    gmsh::model::occ::synchronize();
    gmsh::write((dir / "sphere.brep").string());
    gmsh::clear();
    gmsh_io::open_model((dir / "sphere.brep").string());
    gmsh::option::setNumber("Mesh.MeshSizeMax", 0.3);
    gmsh_io::generate_surface_mesh();
    gmsh::vectorpair faces;
    gmsh::model::getEntities(faces, 2);
    const int f = faces.at(0).second;
    std::vector<std::size_t> tags;
    std::vector<double> xyz, uv, lo, hi, pole;
    gmsh::model::mesh::getNodes(tags, xyz, uv, 2, f, false, true);
    gmsh::model::getParametrizationBounds(2, f, lo, hi);
    const std::vector<double> p{0.5 * (lo[0] + hi[0]), hi[1]};
    gmsh::model::getValue(2, f, p, pole);
    gmsh::model::mesh::setNode(tags.at(0), pole, p);
    write_msh(dir / "pole.msh", true);
  }
  std::ofstream(dir / "garbage.step") << "not a STEP file\n";
  const std::string model = std::string("'") + (dir / "model.brep").string() + "'";
  const std::vector<meshopt_app_test::BadInput> cases = {
      {std::string("smooth '") + (dir / "missing.step").string() + "'" + out, "cannot read the model"},
      {std::string("smooth '") + (dir / "garbage.step").string() + "'" + out, "cannot load the model"},
      {std::string("smooth ") + model + " --mesh '" + (dir / "no_parametric.msh").string() + "'" + out,
       "no parametric coordinates for the nodes inside surface"},
      {std::string("smooth ") + model + " --mesh '" + (dir / "outside.msh").string() + "'" + out,
       "is outside the surface's parameter range"},
      {std::string("smooth ") + model + " --mesh '" + (dir / "trimmed.msh").string() + "'" + out,
       "lies outside the trimmed face"},
      {std::string("smooth '") + (dir / "sphere.brep").string() + "' --mesh '" + (dir / "pole.msh").string() + "'" + out,
       "lies at a degenerate point of the surface"},
      {std::string("smooth ") + model + " --measure angle" + out, "--measure must be shape, size or size-shape"},
      {std::string("smooth ") + model + " --measure size --size 'x+' " + out, "--size: cannot parse"},
  };
  meshopt_app_test::check_bad_inputs(cases, dir, dir / "o.msh");
}

TEST_SUITE_END();
