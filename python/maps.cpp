// tspline.parameterize, tspline.param_options, tspline.load and tspline.Map:
// the same calls as `tspline param`, `tspline eval`, `check`, `export
// --vtk-bezier` and `render` (param_session.h and the library's writers).
#include "maps.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "arguments.h"
#include "param_options.h"
#include "param_options_cli.h"
#include "toolkit/io/vtu_writer.h"
#include "tspline/errors.h"
#include "tspline/io/bezier_vtu.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/param_output.h"
#include "tspline/io/render.h"
#include "tspline/io/tspline_file.h"
#include "tspline/multipatch/map_check.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality_bounds.h"

namespace tspline_python {

const tspline::TSplineMap& Map::patch(std::size_t p) const {
  if (p >= maps.size())
    throw tspline::InputError("patch " + std::to_string(p) + " out of range (the map has " +
                              std::to_string(maps.size()) + (maps.size() == 1 ? " patch)" : " patches)"));
  return *maps[p];
}

namespace {

using namespace pybind11::literals;
using nlohmann::json;

/// A progress callback that lets Ctrl-C stop a run (KeyboardInterrupt).
tspline::ProgressCallback interruptible() {
  return [](const tspline::ProgressEvent&) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      PyErr_Clear();
      throw tspline::Interrupted("the run was stopped (KeyboardInterrupt)");
    }
  };
}

Map map_of_run(std::shared_ptr<const tspline_app::ParamRun> run) {
  Map m;
  m.maps = run->maps();
  if (m.maps.empty()) throw tspline::NumericalError("the parameterization produced no map");
  auto meta_of = [&](const tspline::ParameterizationResult& r) {
    tspline::io::TSplineFileMeta meta;
    meta.source = run->source;
    meta.boundary = r.front.boundary.polygon();
    meta.corners = r.front.boundary.corners().index;
    return meta;
  };
  if (run->result.patches) {
    const tspline::MultiPatchResult& R = *run->result.patches;
    for (const tspline::ParameterizationResult& r : R.patches) m.metas.push_back(meta_of(r));
    m.interfaces = R.layout.interfaces;
    m.cuts = R.layout.cuts;
    m.version = 2;
  } else {
    m.metas.push_back(meta_of(*run->result.single));
  }
  m.source = run->source;
  m.report = to_python(run->report);
  m.certified_valid = run->certified_valid();
  m.run = std::move(run);
  return m;
}

namespace {

// One run of `tspline param` from Python: the keywords read through the
// option table, the domain converted, the run without the GIL (other Python
// threads go on; Ctrl-C still stops it), from `previous` if given.
Map run_from_python(const py::object& domain, const py::kwargs& kwargs,
                    std::optional<tspline_app::PreviousMap> previous) {
  std::optional<std::string> crs;
  tspline_app::ParamSettings settings = settings_from_keywords(kwargs, &crs);
  if (previous && !settings.from_file.empty()) throw tspline::InputError("deform: 'from' is this map");
  settings.domain.crs = crs;
  const auto started = std::chrono::steady_clock::now();
  DomainArgument in = domain_from_python(domain, settings.domain);
  tspline_app::ParamHooks hooks;
  hooks.progress = interruptible();
  std::shared_ptr<tspline_app::ParamRun> run;
  {
    py::gil_scoped_release release;
    run = std::make_shared<tspline_app::ParamRun>(
        tspline_app::run_param(std::move(in.domain), in.source, settings, hooks, started, std::move(previous)));
  }
  return map_of_run(std::move(run));
}

// The map as the previous map of a warm start.
tspline_app::PreviousMap previous_of(const Map& m) {
  tspline_app::PreviousMap prev;
  prev.maps = m.maps;
  prev.metas = m.metas;
  prev.layout = m.version != 1;
  prev.interfaces = m.interfaces;
  prev.cuts = m.cuts;
  if (m.run && m.run->result.patches) prev.domain = m.run->result.patches->domain;
  else if (m.file && m.file->domain) prev.domain = *m.file->domain;
  prev.name = "the previous map";
  return prev;
}

}  // namespace

Map parameterize(const py::object& domain, const py::kwargs& kwargs) {
  return run_from_python(domain, kwargs, std::nullopt);
}

Map deform(const Map& m, const py::object& domain, const py::kwargs& kwargs) {
  return run_from_python(domain, kwargs, previous_of(m));
}

Map load(const py::object& path_obj) {
  const auto path = path_of(path_obj);
  if (!path) throw py::type_error("load: expected a path (str or os.PathLike)");
  auto file = std::make_shared<tspline::io::LoadedMaps>(tspline::io::read_maps_file(*path));
  Map m;
  m.certified_valid = true;
  {
    py::gil_scoped_release release;
    for (const tspline::io::LoadedTSpline& t : file->patches) {
      m.maps.push_back(&t.map);
      m.metas.push_back(t.meta);
      m.certified_valid = tspline::certify_map(t.map).certified_valid() && m.certified_valid;
    }
  }
  m.interfaces = file->interfaces;
  m.cuts = file->cuts;
  m.version = file->version;
  m.source = file->source;  // the input the file records, so that save_tspline writes the file again
  m.report =
      to_python(json{{"input", *path}, {"version", file->version}, {"patches_count", file->patches.size()}});
  m.file = std::move(file);
  return m;
}

py::array_t<double> evaluate(const Map& m, const Array& uv, std::size_t patch) {
  const tspline::TSplineMap& map = m.patch(patch);
  const std::size_t n = rows_of(uv, "uv");
  py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{2}});
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d x = map.point(checked_uv(uv, i));
    o[2 * i] = x.x(), o[2 * i + 1] = x.y();
  }
  return out;
}

py::array_t<double> jacobian(const Map& m, const Array& uv, std::size_t patch) {
  const tspline::TSplineMap& map = m.patch(patch);
  const std::size_t n = rows_of(uv, "uv");
  py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{2}, py::ssize_t{2}});
  double* o = out.mutable_data();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix2d J = map.jacobian(checked_uv(uv, i));  // J(r, c) = d x_r / d xi_c
    o[4 * i] = J(0, 0), o[4 * i + 1] = J(0, 1), o[4 * i + 2] = J(1, 0), o[4 * i + 3] = J(1, 1);
  }
  return out;
}

/// The sum of count(patch map) over the patches.
template <class Count>
std::size_t sum_over_patches(const Map& m, Count count) {
  std::size_t n = 0;
  for (const tspline::TSplineMap* p : m.maps) n += count(*p);
  return n;
}

py::list interfaces_of(const Map& m) {
  py::list out;
  for (const tspline::Interface& f : m.interfaces)
    out.append(py::dict("patch_a"_a = f.patch_a, "side_a"_a = tspline::io::side_name(f.side_a),
                        "patch_b"_a = f.patch_b, "side_b"_a = tspline::io::side_name(f.side_b),
                        "cut"_a = f.cut));
  return out;
}

/// `tspline check` as a dict: per patch the certificate of det J > 0 and the
/// whole-map quality bounds; the largest gap between the two images of a cut.
py::dict check(const Map& m, int depth, std::size_t max_listed) {
  if (depth < 0 || depth > 20)
    throw tspline::InputError("depth: " + std::to_string(depth) + " is not in [0, 20]");
  json patches = json::array();
  tspline::MapCheckOptions o;
  o.certification.max_depth = depth;
  o.quality = tspline::io::report_quality_bound_options();
  std::optional<tspline::MapCheck> checked;
  {
    py::gil_scoped_release release;
    checked.emplace(tspline::check_map(m.maps, m.interfaces, o));
  }
  const tspline::MapCheck& mc = *checked;
  auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(); };
  for (const tspline::PatchCheck& p : mc.patches) {
    const tspline::MapCertification& c = p.certification;
    json failures = json::array();
    for (std::size_t k = 0; k < c.failures.size() && k < max_listed; ++k) {
      const tspline::CertificationFailure& f = c.failures[k];
      const bool invalid = f.certificate.status == tspline::ElementStatus::Invalid;
      failures.push_back({{"cell", f.cell},
                          {"element", f.element},
                          {"lo", {f.lo.x(), f.lo.y()}},
                          {"hi", {f.hi.x(), f.hi.y()}},
                          {"status", invalid ? "invalid" : "undecided"},
                          {"negative_at", invalid ? json{f.certificate.negative_at.x(), f.certificate.negative_at.y()}
                                                  : json()},
                          {"negative_det", invalid ? json(f.certificate.negative_det) : json()}});
    }
    patches.push_back({{"cells", p.cells},
                       {"elements", c.elements},
                       {"certified", c.certified},
                       {"invalid", c.invalid},
                       {"undecided", c.undecided},
                       {"certified_valid", c.certified_valid()},
                       {"min_relative_det_lower_bound", finite(c.min_relative_lower_bound)},
                       {"min_det_lower_bound", finite(c.min_det_lower_bound)},
                       {"max_depth_used", c.max_depth_used},
                       {"whole_map", tspline::io::whole_map_quality_json(p.quality, o.quality)},
                       {"failures", std::move(failures)},
                       {"seconds", c.seconds}});
  }
  return to_python(json{{"certified_valid", mc.certified_valid()},
                        {"patches", std::move(patches)},
                        {"elements", mc.elements},
                        {"certified", mc.certified},
                        {"min_relative_det_lower_bound", finite(mc.min_relative_det_lower_bound)},
                        {"whole_map", tspline::io::whole_map_quality_json(mc.quality, o.quality)},
                        {"max_interface_gap", mc.max_interface_gap}});
}

/// The T-spline file alone: version 1 for a single-patch map, 2 for a layout.
void save_tspline(const Map& m, const std::filesystem::path& file) {
  const std::string path = file.string();
  if (m.version == 1) return tspline::io::write_tspline_file(path, *m.maps.front(), m.metas.front());
  const tspline::Domain* domain = m.run && m.run->result.patches ? &m.run->result.patches->domain
                                  : m.file && m.file->domain    ? &*m.file->domain
                                                                : nullptr;
  tspline::io::write_multipatch_file(path, m.maps, m.metas, m.interfaces, m.cuts, m.source, domain);
}

void save(const Map& m, const std::filesystem::path& dir) {
  if (!m.run)
    throw tspline::InputError(
        "save: a map read by tspline.load has no parameterization to write (report, T-mesh "
        "files); save_tspline(path) writes its T-spline file, save_vtk_bezier(path) its cells");
  py::gil_scoped_release release;
  tspline_app::write_param_run(*m.run, dir.string());
}

/// `tspline export --vtk-bezier`: every patch's Bezier cells in one file.
void save_vtk_bezier(const Map& m, const std::filesystem::path& path) {
  py::gil_scoped_release release;
  std::vector<toolkit::io::VtuMesh> parts;
  for (const tspline::TSplineMap* map : m.maps) parts.push_back(tspline::io::bezier_vtu(*map));
  toolkit::io::write_vtu(path.string(), tspline::io::merge_patches(parts));
}

/// The domain polygon as closed line cells (boundary.vtu's lines).
toolkit::io::VtuMesh polygon_lines(const tspline::Polygon& p) {
  toolkit::io::VtuMesh out;
  out.points = p.vertices;
  const int n = static_cast<int>(p.vertices.size());
  for (int i = 0; i < n; ++i) out.cells.push_back({i, (i + 1) % n});
  return out;
}

py::dict render(const Map& m, const std::filesystem::path& path, const std::string& view,
                std::pair<int, int> size, int samples) {
  tspline::io::RenderOptions o;
  o.view = tspline::io::parse_render_view(view);
  o.width = size.first, o.height = size.second;
  if (samples < 1 || samples > 64)
    throw tspline::InputError("samples: " + std::to_string(samples) + " is not in [1, 64]");
  tspline::io::RenderSummary s;
  {
    py::gil_scoped_release release;
    std::vector<toolkit::io::VtuMesh> surface, boundary, net;
    for (std::size_t p = 0; p < m.maps.size(); ++p) {
      surface.push_back(tspline::io::surface_vtu(*m.maps[p], samples));
      boundary.push_back(polygon_lines(m.metas[p].boundary));
      net.push_back(tspline::io::control_net_vtu(*m.maps[p]));
    }
    s = tspline::io::render_map({tspline::io::merge_patches(surface), tspline::io::merge_patches(boundary),
                                 tspline::io::merge_patches(net)},
                                path.string(), o);
  }
  return py::dict("min"_a = s.min, "max"_a = s.max);
}

py::list param_options_list() {
  py::list out;
  for (const tspline_app::ParamOption& o : tspline_app::param_options()) {
    const char* kind = "str";
    switch (o.kind) {
      case tspline_app::OptionKind::Flag:
        kind = "bool";
        break;
      case tspline_app::OptionKind::Integer:
      case tspline_app::OptionKind::Count:
        kind = "int";
        break;
      case tspline_app::OptionKind::Real:
        kind = "float";
        break;
      case tspline_app::OptionKind::Text:
        break;
    }
    py::object range = o.range ? py::object(py::make_tuple(o.range->first, o.range->second)) : py::none();
    out.append(py::dict("name"_a = o.python_name(), "cli"_a = "--" + o.name, "type"_a = kind,
                        "help"_a = o.help, "default"_a = to_python(o.get(tspline_app::ParamSettings{})),
                        "choices"_a = o.choices, "range"_a = range));
  }
  return out;
}

/// The settings that these keywords give (the fields of every table entry),
/// and those that `tspline param` gives for these arguments: for the test that
/// the two front ends read options alike.
py::object settings_of_keywords(const py::kwargs& kwargs) {
  return to_python(tspline_app::settings_json(settings_from_keywords(kwargs, nullptr)));
}
py::object settings_of_arguments(const std::vector<std::string>& args) {
  return to_python(tspline_app::settings_json(tspline_app::parse_param_arguments(args)));
}

}  // namespace

void bind_maps(py::module_& m) {
  py::class_<Map, std::shared_ptr<Map>>(
      m, "Map",
      "A T-spline map onto a domain: of the unit square (one patch), or of one unit square per patch of a "
      "quad "
      "layout, continuous across the interfaces. From tspline.parameterize or tspline.load.")
      .def_readonly("certified_valid", &Map::certified_valid,
                    "bool: det J > 0 certified on every Bezier element of every patch")
      .def_readonly(
          "report", &Map::report,
          "dict: report.json of the parameterization (as `tspline param` writes it); for a loaded map "
          "{'input', 'version', 'patches_count'}")
      .def_readonly("source", &Map::source, "str: the input (path, 'array', 'rings', 'GeoJSON dict', ...)")
      .def_readonly("version", &Map::version,
                    "int: the T-spline file format version (1: one patch, 2: a layout)")
      .def_property_readonly(
          "patches", [](const Map& x) { return x.maps.size(); }, "int: number of patches")
      .def_property_readonly(
          "interfaces", &interfaces_of,
          "list of dicts {patch_a, side_a, patch_b, side_b, cut}: the cuts between patches; side "
          "t of patch_a meets side 1 - t of patch_b ('bottom', 'right', 'top', 'left')")
      .def_property_readonly(
          "layout", [](const Map& x) { return x.run ? x.run->result.layout : std::string("file"); },
          "str: 'single', 'quad', 'cuts' or 'automatic cuts' (how the layout was chosen: "
          "report['layout']); 'file' for a loaded map")
      .def_property_readonly(
          "cells",
          [](const Map& x) {
            return sum_over_patches(x, [](const auto& p) { return p.mesh().num_cells(); });
          },
          "int: T-mesh cells over all patches")
      .def_property_readonly(
          "functions",
          [](const Map& x) { return sum_over_patches(x, [](const auto& p) { return p.basis().size(); }); },
          "int: blending functions over all patches")
      .def("evaluate", &evaluate, py::arg("uv"), py::arg("patch") = 0,
           "evaluate(uv, patch=0) -> xy. uv: #uv by 2 float64 array of parameters in [0,1]^2 of patch "
           "`patch`; xy: #uv by 2 float64 array, S(uv) (as `tspline eval --patch`).")
      .def("jacobian", &jacobian, py::arg("uv"), py::arg("patch") = 0,
           "jacobian(uv, patch=0) -> J. uv: #uv by 2 float64 array; J: #uv by 2 by 2 float64 array, "
           "J[k, r, c] = d x_r / d xi_c at uv[k] (columns dS/dxi, dS/deta).")
      .def(
          "check", &check, py::arg("depth") = 8, py::arg("max_listed") = 20,
          "check(depth=8, max_listed=20) -> dict. `tspline check`: det J > 0 certified on every Bezier "
          "element "
          "(de Casteljau subdivision, at most `depth` levels), per patch ('patches': elements, certified, "
          "invalid, undecided, bounds of det J, 'whole_map' certified bounds of J_r and the scaled Jacobian, "
          "'failures' (at most max_listed)); over the whole map: 'certified_valid', 'elements', 'certified', "
          "'min_relative_det_lower_bound', 'whole_map' (the certified bounds over every patch) and "
          "'max_interface_gap'.")
      .def("save", &save, py::arg("dir"),
           "save(dir): writes the files of `tspline param` into the folder dir (created if missing): "
           "tspline.json, surface.vtu, surface_bezier.vtu, control_net.vtu, parametric_tmesh.vtu, "
           "physical_tmesh.vtu, boundary.vtu, report.json (and adapt.pvd for one patch).")
      .def("save_tspline", &save_tspline, py::arg("path"),
           "save_tspline(path): the T-spline file alone (docs/tspline_format.md; version 1 for one patch, 2 "
           "for a "
           "layout); tspline.load reads it back bit for bit.")
      .def("save_vtk_bezier", &save_vtk_bezier, py::arg("path"),
           "save_vtk_bezier(path): the map exactly as rational bicubic Bezier cells for ParaView (a .vtu "
           "file, "
           "as `tspline export --vtk-bezier`; docs/paraview.md).")
      .def("render", &render, py::arg("path"), py::arg("view") = "jacobian",
           py::arg("size") = std::pair<int, int>{1200, 900}, py::arg("samples") = 4,
           "render(path, view='jacobian', size=(1200, 900), samples=4) -> dict {min, max}: a picture (PNG, "
           "SVG or "
           "PDF by the extension) as `tspline render`: view 'jacobian' (J_r), 'tmesh', 'control-net' or "
           "'layout'; "
           "samples: k x k sub-quads per cell.")
      .def("deform", &deform, py::arg("domain"),
           "deform(domain, **options) -> Map: the map of the moved boundary `domain` (the same ring, vertex i "
           "moved to vertex i; any input tspline.parameterize takes) from this map, as `tspline param DOMAIN "
           "--from`: the same layout, T-meshes, knots and corners, the interior started from this map moved with "
           "the boundary, untangled, improved and refined only where it needs it.")
      .def(
          "poisson",
          [](const py::object& self, py::kwargs kwargs) {
            return py::module_::import("tspline").attr("poisson")(self, **kwargs);
          },
          "poisson(**options) -> Solution: tspline.poisson(self, **options).");

  m.def(
      "parameterize", &parameterize, py::arg("domain"),
      "parameterize(domain, *, crs=None, **options) -> Map, as `tspline param`.\n\n"
      "domain: a path (text polygon with optional holes, or any GIS polygon layer); an #V by 2 float array "
      "of "
      "polygon vertices; a list of rings (#V_k by 2 arrays: the outer ring, then the holes); a GeoJSON dict "
      "(geometry, Feature or FeatureCollection; longitude/latitude, projected to metres, as a .geojson "
      "file); "
      "or an object with __geo_interface__ (shapely Polygon / MultiPolygon with interiors, GeoPandas "
      "GeoSeries / GeoDataFrame: their own .crs if they have one, else planar).\n"
      "crs: the coordinates' CRS (e.g. 'EPSG:4326', a pyproj.CRS): geographic ones are projected to metres "
      "(Lambert azimuthal equal-area at the centroid), as GIS files are. planar=True keeps coordinates as "
      "given.\n"
      "options: those of `tspline param`, '-' written '_' (tspline.param_options() lists them with their "
      "defaults and help): layout, cuts (a path or a list of #P by 2 polylines), corners, tol, tol_rel, "
      "init_level, max_adapt, ... Raises tspline.InputError for invalid domains or option values, "
      "tspline.IoError for unreadable files, TypeError for unknown keywords.");
  m.def("param_options", &param_options_list,
        "param_options() -> list of dicts {name, cli, type, help, default, choices, range}: the options of "
        "tspline.parameterize, one table with `tspline param`.");
  m.def("load", &load, py::arg("path"),
        "load(path) -> Map: a T-spline file of version 1 (one patch) or 2 (a layout); certified_valid is "
        "recomputed.");
  m.def("_settings_of_keywords", &settings_of_keywords);
  m.def("_settings_of_arguments", &settings_of_arguments, py::arg("args"));
}

}  // namespace tspline_python
