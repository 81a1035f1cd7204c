// `tspline eval` and `tspline info`: read a T-spline file (docs/tspline_format.md)
// and evaluate the map S at given parametric points, or describe the file.
#include <Eigen/Dense>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.h"
#include "tspline/errors.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/tspline_file.h"

namespace tspline_app {

namespace {

struct EvalArgs {
  std::string file;
  std::optional<std::size_t> patch;
  std::vector<std::pair<std::string, std::string>> at;
  bool derivatives = false;
};

double parse_coordinate(const std::string& text, const char* name) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
    throw tspline::InputError(std::string("--at: ") + name + " = '" + text + "' is not a finite number");
  if (v < 0.0 || v > 1.0)
    throw tspline::InputError(std::string("--at: ") + name + " = " + text +
                              " is outside the parametric domain [0, 1]");
  return v;
}

int run_eval(const EvalArgs& args) {
  // Validate the points before reading a possibly large file.
  std::vector<Eigen::Vector2d> points;
  for (const auto& [u, v] : args.at) points.emplace_back(parse_coordinate(u, "U"), parse_coordinate(v, "V"));
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(args.file);
  const std::size_t n = maps.patches.size();
  if (!args.patch && n > 1)
    throw tspline::InputError(args.file + " is a multi-patch map (" + std::to_string(n) +
                              " patches): give --patch P, P in [0, " + std::to_string(n - 1) + "]");
  if (args.patch && *args.patch >= n)
    throw tspline::InputError("--patch " + std::to_string(*args.patch) + " is out of range: " + args.file + " has " +
                              std::to_string(n) + " patch(es)");
  const tspline::io::LoadedTSpline& t = maps.patches[args.patch.value_or(0)];
  for (const Eigen::Vector2d& uv : points) {
    if (args.derivatives) {
      const tspline::MapDerivatives d = t.map.derivatives(uv, 1);
      std::printf("%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", uv.x(), uv.y(), d.x.x(), d.x.y(),
                  d.J(0, 0), d.J(1, 0), d.J(0, 1), d.J(1, 1), d.J.determinant());
    } else {
      const Eigen::Vector2d x = t.map.point(uv);
      std::printf("%.17g %.17g %.17g %.17g\n", uv.x(), uv.y(), x.x(), x.y());
    }
  }
  std::fflush(stdout);
  if (std::ferror(stdout)) throw tspline::IoError("cannot write to standard output");
  return 0;
}

struct Box {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  void add(const Eigen::Vector2d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  bool empty() const { return !(lo.x() <= hi.x()); }
};

void print_box(const char* label, const Box& b) {
  std::printf("%s: [%.17g, %.17g] x [%.17g, %.17g]\n", label, b.lo.x(), b.hi.x(), b.lo.y(), b.hi.y());
}

int print_patch_info(const tspline::io::LoadedTSpline& t) {
  const tspline::TMesh& mesh = t.map.mesh();
  const tspline::TSplineBasis& basis = t.map.basis();
  std::size_t by_kind[3] = {0, 0, 0};
  for (const tspline::BlendingFunction& f : basis.functions()) ++by_kind[static_cast<int>(f.kind)];
  std::printf("cells: %zu\n", mesh.num_cells());
  std::printf("vertices: %zu\n", mesh.num_vertices());
  std::printf("hanging vertices: %zu\n", mesh.num_hanging_vertices());
  std::printf("functions: %zu (anchor %zu, edge %zu, corner %zu)\n", basis.size(), by_kind[0], by_kind[1],
              by_kind[2]);
  std::printf("max level: %d\n", mesh.max_level());
  Box cp;
  for (const Eigen::Vector2d& p : t.map.control_points()) cp.add(p);
  print_box("control points bounding box", cp);
  const tspline::Polygon& poly = t.meta.boundary;
  if (poly.vertices.empty()) {
    std::printf("boundary: none recorded\n");
    return 0;
  }
  Box bb;
  for (const Eigen::Vector2d& p : poly.vertices) bb.add(p);
  std::printf("boundary polygon: %zu vertices\n", poly.vertices.size());
  print_box("boundary bounding box", bb);
  static const char* kCorner[4] = {"(0,0)", "(1,0)", "(1,1)", "(0,1)"};
  for (int k = 0; k < 4; ++k) {
    const std::size_t c = t.meta.corners[k];
    std::printf("corner %s: polygon vertex %zu (file index %zu) at %.17g %.17g\n", kCorner[k], c, poly.file_index[c],
                poly.vertices[c].x(), poly.vertices[c].y());
  }
  return 0;
}

struct InfoArgs {
  std::string file;
  bool per_patch = false;
};

// A map of several patches: the totals over every patch first; with
// --per-patch the interfaces and every patch's own description.
void print_totals(const tspline::io::LoadedMaps& maps) {
  std::size_t cells = 0, vertices = 0, hanging = 0, functions = 0, by_kind[3] = {0, 0, 0};
  std::size_t fewest = static_cast<std::size_t>(-1), most = 0;
  int level = 0;
  Box cp, bb;
  for (const tspline::io::LoadedTSpline& t : maps.patches) {
    const tspline::TMesh& mesh = t.map.mesh();
    cells += mesh.num_cells();
    fewest = std::min(fewest, mesh.num_cells());
    most = std::max(most, mesh.num_cells());
    vertices += mesh.num_vertices();
    hanging += mesh.num_hanging_vertices();
    functions += t.map.basis().size();
    for (const tspline::BlendingFunction& f : t.map.basis().functions()) ++by_kind[static_cast<int>(f.kind)];
    level = std::max(level, mesh.max_level());
    for (const Eigen::Vector2d& p : t.map.control_points()) cp.add(p);
    for (const Eigen::Vector2d& p : t.meta.boundary.vertices) bb.add(p);
  }
  std::printf("cells: %zu (per patch %zu to %zu)\n", cells, fewest, most);
  std::printf("vertices: %zu (the patches' own: a vertex on a cut counts in both patches)\n", vertices);
  std::printf("hanging vertices: %zu\n", hanging);
  std::printf("functions: %zu (anchor %zu, edge %zu, corner %zu)\n", functions, by_kind[0], by_kind[1], by_kind[2]);
  std::printf("max level: %d\n", level);
  print_box("control points bounding box", cp);
  if (!bb.empty()) print_box("boundary bounding box", bb);
}

int run_info(const InfoArgs& args) {
  const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(args.file);
  std::printf("format: tspline version %d (degree 3)\n", maps.version);
  std::printf("source: %s\n", maps.source.c_str());
  if (maps.version == 1) return print_patch_info(maps.patches.front());
  std::printf("patches: %zu\n", maps.patches.size());
  std::printf("interfaces: %zu (cuts %zu)\n", maps.interfaces.size(), maps.cuts.size());
  print_totals(maps);
  if (!args.per_patch) return 0;
  for (const tspline::Interface& f : maps.interfaces)
    std::printf("interface along cut %zu: patch %zu side %s = patch %zu side %s, reversed\n", f.cut, f.patch_a,
                tspline::io::side_name(f.side_a), f.patch_b, tspline::io::side_name(f.side_b));
  for (std::size_t p = 0; p < maps.patches.size(); ++p) {
    std::printf("patch %zu:\n", p);
    print_patch_info(maps.patches[p]);
  }
  return 0;
}

}  // namespace

void add_tspline_file_commands(CLI::App& app, CommandAction& action) {
  const Subcommand<EvalArgs> eval_sub = add_subcommand<EvalArgs>(
      app, "eval",
      "Evaluate the T-spline map S(u, v) of a T-spline file at parametric points. Prints one line per point: "
      "'u v x y' (with --derivatives also 'dx/du dy/du dx/dv dy/dv det_J'), numbers with 17 significant digits");
  CLI::App* const eval = eval_sub.cmd;
  const std::shared_ptr<EvalArgs> eval_args = eval_sub.args;
  add_tspline_file_argument(*eval, eval_args->file);
  eval->add_option("--at", eval_args->at,
                   "Parametric point U V, both in [0, 1] (u along xi, v along eta); repeat for several points, "
                   "printed in the given order")
      ->type_name("U V")
      ->required();
  eval->add_option("--patch", eval_args->patch,
                   "Multi-patch file (format version 2): the patch to evaluate (0-based); required there")
      ->type_name("P");
  eval->add_flag("--derivatives,-d", eval_args->derivatives,
                 "Also print the Jacobian columns dS/du = (dx/du, dy/du), dS/dv = (dx/dv, dy/dv) and det J");
  run_when_parsed(eval, eval_args, action, run_eval);

  const Subcommand<InfoArgs> info_sub = add_subcommand<InfoArgs>(
      app, "info",
      "Describe a T-spline file: format version, source, T-mesh counts (cells, vertices, hanging vertices, max "
      "level), blending functions by kind, bounding boxes of the control points and the boundary polygon, corners "
      "(a multi-patch file: the totals over every patch; --per-patch: also the interfaces and each patch)");
  CLI::App* const info = info_sub.cmd;
  const std::shared_ptr<InfoArgs> info_args = info_sub.args;
  add_tspline_file_argument(*info, info_args->file);
  info->add_flag("--per-patch", info_args->per_patch,
                 "A multi-patch file: also every interface and every patch's own description");
  run_when_parsed(info, info_args, action, run_info);
}

}  // namespace tspline_app
