// The tspline program reads GIS input through the GDAL module it loads at its
// first GIS input (apps/gis_module.cpp), and makes quad layouts with the Gmsh
// module it loads at its first layout (apps/gmsh_module.cpp): the program
// itself loads neither GDAL nor Gmsh; without a module what needs it is one
// clear error (the rest still works), and TSPLINE_GIS_MODULE and
// TSPLINE_GMSH_MODULE point to them from anywhere.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_support.h"

namespace fs = std::filesystem;
using test_support::contains;
using test_support::count_lines;
using test_support::quoted;
using test_support::run_app;
using test_support::run_program;

namespace {

const std::string kGeojson = std::string(TSPLINE_TEST_DATA_DIR) + "/gis/corsica_lonlat.geojson";

std::string param_args(const std::string& input, const fs::path& out, const std::string& layout = "single") {
  return "param " + quoted(fs::path(input)) + " -q --out " + quoted(out) + " --layout " + layout +
         " --max-adapt 0";
}

const std::string kPlate = std::string(TSPLINE_TEST_DATA_DIR) + "/holes/plate_with_hole.txt";

// The program alone, copied into dir/bin: no module next to it (nor in ../lib/tspline).
fs::path program_alone(const fs::path& dir) {
  const fs::path alone = dir / "bin" / "tspline";
  fs::create_directories(alone.parent_path());
  fs::copy_file(TSPLINE_APP_PATH, alone, fs::copy_options::overwrite_existing);
  return alone;
}

// A run that needed a missing module: one line naming the module and the
// variable, an I/O error (a file the program needs is missing), no report.
void check_missing_module(const test_support::AppRun& r, const std::string& module,
                          const std::string& variable, const fs::path& out) {
  CAPTURE(r.err);
  CHECK(r.exit_code == 2);
  CHECK(count_lines(r.err) == 1);
  CHECK(contains(r.err, module));
  CHECK(contains(r.err, variable));
  CHECK(!fs::exists(out / "report.json"));
}

// Sets an environment variable for the scope (the programs run inherit it).
struct ScopedEnv {
  ScopedEnv(const char* name, const std::string& value) : name_(name) { ::setenv(name, value.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name_); }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
};

}  // namespace

TEST_SUITE("modules_app") {
  TEST_CASE("GIS input through the module: the program does not load GDAL, reads GeoJSON with it") {
    const fs::path dir = test_support::scratch_dir("modules_app", "gis");
    // What the dynamic linker loads for the program (ldd's way): no GDAL.
    // (Set by env for the program only: the shell that runs it would list its own.)
    {
      const test_support::AppRun r =
          run_program("/usr/bin/env", "LD_TRACE_LOADED_OBJECTS=1 " + quoted(fs::path(TSPLINE_APP_PATH)), dir);
      REQUIRE(r.exit_code == 0);
      CHECK(contains(r.out, "libc.so"));  // the listing itself
      CHECK(contains(r.out, "libvtkIOXML"));
      CHECK(!contains(r.out, "libgdal"));
      CHECK(!contains(r.out, "libgmsh"));
    }
    const test_support::AppRun r = run_app(param_args(kGeojson, dir / "out"), dir);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    std::ifstream f(dir / "out" / "report.json");
    const nlohmann::json report = nlohmann::json::parse(f);
    CHECK(report["input_geometry"]["format"] == "GeoJSON");
    CHECK(report["input_geometry"]["units"] == "m");  // longitude/latitude projected by PROJ, through GDAL
    CHECK(report["input_geometry"]["projection"]["name"] == "Lambert azimuthal equal-area");
  }

  TEST_CASE(
      "without the module: one clear error for GIS input, text polygons as before; TSPLINE_GIS_MODULE") {
    const fs::path dir = test_support::scratch_dir("modules_app", "no_gis");
    const fs::path alone = program_alone(dir);
    check_missing_module(run_program(alone.string(), param_args(kGeojson, dir / "gis"), dir),
                         "libtspline_gis.so", "TSPLINE_GIS_MODULE", dir / "gis");
    const test_support::AppRun text =
        run_program(alone.string(), param_args(test_support::polygon_file("square.txt"), dir / "text"), dir);
    CAPTURE(text.err);
    CHECK(text.exit_code == 0);
    CHECK(fs::exists(dir / "text" / "report.json"));
    // The module named by TSPLINE_GIS_MODULE: read as next to the program.
    const ScopedEnv module("TSPLINE_GIS_MODULE",
                           (fs::path(TSPLINE_APP_PATH).parent_path() / "libtspline_gis.so").string());
    const test_support::AppRun found = run_program(alone.string(), param_args(kGeojson, dir / "found"), dir);
    CAPTURE(found.err);
    CHECK(found.exit_code == 0);
    CHECK(fs::exists(dir / "found" / "report.json"));
  }

  TEST_CASE("quad layouts through the Gmsh module; without it one clear error, one patch as before") {
    if (!fs::exists(fs::path(TSPLINE_APP_PATH).parent_path() / "libtspline_gmsh.so"))
      return;  // (a build without Gmsh)
    const fs::path dir = test_support::scratch_dir("modules_app", "gmsh");
    {
      const test_support::AppRun r = run_app(param_args(kPlate, dir / "quad", "quad"), dir);
      CAPTURE(r.err);
      REQUIRE(r.exit_code == 0);
      std::ifstream f(dir / "quad" / "report.json");
      const nlohmann::json report = nlohmann::json::parse(f);
      CHECK(report["layout"]["chosen"] == "quad");
      CHECK(report["patches_count"].get<int>() > 1);
    }
    const fs::path alone = program_alone(dir);
    check_missing_module(run_program(alone.string(), param_args(kPlate, dir / "no_module", "quad"), dir),
                         "libtspline_gmsh.so", "TSPLINE_GMSH_MODULE", dir / "no_module");
    const test_support::AppRun text =
        run_program(alone.string(), param_args(test_support::polygon_file("square.txt"), dir / "text"), dir);
    CAPTURE(text.err);
    CHECK(text.exit_code == 0);
    const ScopedEnv module("TSPLINE_GMSH_MODULE",
                           (fs::path(TSPLINE_APP_PATH).parent_path() / "libtspline_gmsh.so").string());
    const test_support::AppRun found =
        run_program(alone.string(), param_args(kPlate, dir / "found", "quad"), dir);
    CAPTURE(found.err);
    CHECK(found.exit_code == 0);
    CHECK(fs::exists(dir / "found" / "report.json"));
  }
}
