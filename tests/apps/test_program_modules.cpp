// The tspline program's modules (apps/program_module.h): it reads GIS input
// through the GDAL module it loads at its first GIS input (apps/gis_module.cpp)
// and makes quad layouts through the Gmsh module (apps/gmsh_module.cpp): the
// program itself loads neither GDAL nor Gmsh; without a module what needs it is
// one clear error (the rest still works), and TSPLINE_GIS_MODULE and
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

// What the dynamic linker loads for the program (ldd's way; set by env for
// the program only: the shell that runs it would list its own).
std::string loaded_libraries(const fs::path& dir) {
  const test_support::AppRun r =
      run_program("/usr/bin/env", "LD_TRACE_LOADED_OBJECTS=1 " + quoted(fs::path(TSPLINE_APP_PATH)), dir);
  REQUIRE(r.exit_code == 0);
  CHECK(contains(r.out, "libc.so"));  // the listing itself
  CHECK(contains(r.out, "libvtkIOXML"));
  return r.out;
}

// The program alone, in a folder without its modules (nor ../lib/tspline).
fs::path program_alone(const fs::path& dir) {
  const fs::path alone = dir / "bin" / "tspline";
  fs::create_directories(alone.parent_path());
  fs::copy_file(TSPLINE_APP_PATH, alone, fs::copy_options::overwrite_existing);
  return alone;
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

TEST_SUITE("program_modules") {
  TEST_CASE("GIS input through the module: the program does not load GDAL, reads GeoJSON with it") {
    const fs::path dir = test_support::scratch_dir("program_modules", "gis");
    CHECK(!contains(loaded_libraries(dir), "libgdal"));
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
    const fs::path dir = test_support::scratch_dir("program_modules", "no_gis");
    const fs::path alone = program_alone(dir);
    const test_support::AppRun gis = run_program(alone.string(), param_args(kGeojson, dir / "gis"), dir);
    CAPTURE(gis.err);
    CHECK(gis.exit_code == 2);  // an I/O error: a file the program needs is missing
    CHECK(count_lines(gis.err) == 1);
    CHECK(contains(gis.err, "libtspline_gis.so"));
    CHECK(contains(gis.err, "TSPLINE_GIS_MODULE"));
    CHECK(!fs::exists(dir / "gis" / "report.json"));
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

  TEST_CASE(
      "quad layouts through the Gmsh module: the program does not load Gmsh, makes the layout with it") {
    const fs::path dir = test_support::scratch_dir("program_modules", "gmsh");
    const std::string libraries = loaded_libraries(dir);
    CHECK(!contains(libraries, "libgmsh"));
    CHECK(!contains(libraries, "libTKernel"));  // OpenCASCADE, which Gmsh brings
    const test_support::AppRun r =
        run_app(param_args(test_support::polygon_file("square.txt"), dir / "out", "quad"), dir);
    CAPTURE(r.err);
    REQUIRE(r.exit_code == 0);
    std::ifstream f(dir / "out" / "report.json");
    const nlohmann::json report = nlohmann::json::parse(f);
    CHECK(report["layout"]["chosen"] == "quad");
    CHECK(report["patches_count"].get<int>() >= 4);  // Gmsh's quads, split in four each
  }

  TEST_CASE(
      "without the Gmsh module: one clear error where a layout is made, one patch as before; "
      "TSPLINE_GMSH_MODULE") {
    const fs::path dir = test_support::scratch_dir("program_modules", "no_gmsh");
    const fs::path alone = program_alone(dir);
    const std::string square = test_support::polygon_file("square.txt");
    const test_support::AppRun quad =
        run_program(alone.string(), param_args(square, dir / "quad", "quad"), dir);
    CAPTURE(quad.err);
    CHECK(quad.exit_code == 2);  // an I/O error: a file the program needs is missing
    CHECK(count_lines(quad.err) == 1);
    CHECK(contains(quad.err, "an automatic quad layout needs the Gmsh module libtspline_gmsh.so"));
    CHECK(contains(quad.err, "TSPLINE_GMSH_MODULE"));
    CHECK(!fs::exists(dir / "quad" / "report.json"));
    const test_support::AppRun single = run_program(alone.string(), param_args(square, dir / "single"), dir);
    CAPTURE(single.err);
    CHECK(single.exit_code == 0);
    CHECK(fs::exists(dir / "single" / "report.json"));
    const ScopedEnv module("TSPLINE_GMSH_MODULE",
                           (fs::path(TSPLINE_APP_PATH).parent_path() / "libtspline_gmsh.so").string());
    const test_support::AppRun found =
        run_program(alone.string(), param_args(square, dir / "found", "quad"), dir);
    CAPTURE(found.err);
    CHECK(found.exit_code == 0);
    CHECK(fs::exists(dir / "found" / "report.json"));
  }
}
