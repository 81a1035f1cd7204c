#include "arguments.h"

#include <pybind11/stl.h>

#include <cstdio>

#include "tspline/errors.h"

namespace tspline_python {
namespace {

using namespace pybind11::literals;
using tspline_app::OptionKind;
using tspline_app::ParamOption;

std::string type_name_of(const py::handle& v) {
  return py::str(py::type::of(v).attr("__name__")).cast<std::string>();
}

[[noreturn]] void wrong_type(const ParamOption& o, const char* expected, const py::handle& v) {
  throw py::type_error(o.python_name() + ": expected " + expected + ", got " + type_name_of(v));
}

/// True and False, and NumPy's bool_.
bool is_bool(const py::handle& v) { return py::isinstance<py::bool_>(v) || type_name_of(v) == "bool_"; }

/// An integer (Python int, NumPy integer; not bool) as text.
std::string integer_text(const ParamOption& o, const py::handle& v) {
  if (is_bool(v) || !PyIndex_Check(v.ptr())) wrong_type(o, "an int", v);
  return py::str(py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()))).cast<std::string>();
}

/// A real number as text that reads back to the same double.
std::string real_text(const ParamOption& o, const py::handle& v) {
  if (is_bool(v) || !(PyFloat_Check(v.ptr()) || PyIndex_Check(v.ptr()) || py::hasattr(v, "__float__")))
    wrong_type(o, "a number", v);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", py::cast<double>(v));
  return buf;
}

/// The option's value as the command line writes it; nullopt: nothing to set
/// (a flag given False).
std::optional<std::string> option_text(const ParamOption& o, const py::handle& v) {
  switch (o.kind) {
    case OptionKind::Flag:
      if (!is_bool(v)) wrong_type(o, "True or False", v);
      if (!py::cast<bool>(v)) return std::nullopt;
      return std::string("true");
    case OptionKind::Integer:
    case OptionKind::Count:
      return integer_text(o, v);
    case OptionKind::Real:
      return real_text(o, v);
    case OptionKind::Text:
      break;
  }
  if (const auto p = path_of(v)) return *p;
  if (o.name == "layer" && PyIndex_Check(v.ptr()) && !is_bool(v)) return integer_text(o, v);
  if (o.name == "corners" && py::isinstance<py::sequence>(v)) {
    std::string text;
    for (const py::handle& item : v) text += (text.empty() ? "" : ",") + integer_text(o, item);
    return text;
  }
  wrong_type(o, o.name == "corners" ? "a sequence of 4 ints" : "a str", v);
}

/// cuts= as polylines: a sequence of (k, 2) arrays.
std::vector<tspline::Cut> cuts_from_python(const py::handle& v) {
  std::vector<tspline::Cut> cuts;
  for (const py::handle& item : v) {
    const Array a = py::cast<Array>(item);
    const std::size_t n = rows_of(a, "cuts");
    tspline::Cut c;
    for (std::size_t i = 0; i < n; ++i) c.emplace_back(a.at(i, 0), a.at(i, 1));
    cuts.push_back(std::move(c));
  }
  return cuts;
}

/// A CRS given in Python: a str, or an object with to_wkt() / to_string() (pyproj.CRS).
std::string crs_text(const py::handle& v) {
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::hasattr(v, "to_wkt")) return v.attr("to_wkt")().cast<std::string>();
  if (py::hasattr(v, "to_string")) return v.attr("to_string")().cast<std::string>();
  throw py::type_error("crs: expected a str (e.g. 'EPSG:4326') or a pyproj.CRS, got " + type_name_of(v));
}

tspline::Polygon polygon_of(const Array& ring, const char* what) {
  const std::size_t n = rows_of(ring, what);
  tspline::Polygon p;
  for (std::size_t i = 0; i < n; ++i) p.vertices.emplace_back(ring.at(i, 0), ring.at(i, 1));
  if (p.vertices.size() >= 2 && p.vertices.front() == p.vertices.back()) p.vertices.pop_back();
  for (std::size_t i = 0; i < p.vertices.size(); ++i) p.file_index.push_back(i);
  return p;
}

/// The rings of an (n, 2) array (one ring) or of a sequence of them (the
/// first the outer ring, the others holes).
std::vector<Array> rings_of(const py::object& domain) {
  py::module_ np = py::module_::import("numpy");
  py::object a;
  try {
    a = np.attr("asarray")(domain, "dtype"_a = "float64");
  } catch (const py::error_already_set&) {  // ragged: a list of rings of different lengths
  }
  std::vector<Array> rings;
  if (a && a.attr("ndim").cast<int>() == 2) {
    rings.push_back(a.cast<Array>());
  } else if (a && a.attr("ndim").cast<int>() == 3) {
    for (const py::handle& r : a) rings.push_back(py::cast<Array>(r));
  } else {
    if (!py::isinstance<py::sequence>(domain) || py::isinstance<py::str>(domain))
      throw py::type_error(
          "domain: expected a path, an (n, 2) array, a list of rings, a GeoJSON dict or an object "
          "with __geo_interface__, got " +
          type_name_of(domain));
    for (const py::handle& r : domain) rings.push_back(py::cast<Array>(r));
  }
  if (rings.empty()) throw tspline::InputError("domain: no rings");
  return rings;
}

/// GeoJSON coordinates of a ring (closed, as RFC 7946 requires).
py::list geojson_ring(const Array& ring) {
  py::list coords;
  for (std::size_t i = 0; i < rows_of(ring, "ring"); ++i)
    coords.append(py::make_tuple(ring.at(i, 0), ring.at(i, 1)));
  if (py::len(coords) > 0) coords.append(coords[0]);
  return coords;
}

DomainArgument from_geojson(const py::object& geojson, tspline::io::DomainReadOptions options,
                            const std::string& name) {
  const std::string text = py::module_::import("json").attr("dumps")(geojson).cast<std::string>();
  return {tspline::io::read_geojson_domain(text, options, name), name};
}

}  // namespace

tspline_app::ParamSettings settings_from_keywords(const py::dict& keywords, std::optional<std::string>* crs) {
  tspline_app::ParamSettings s;
  for (const auto& [key, value] : keywords) {
    const std::string name = py::str(key).cast<std::string>();
    if (name == "crs" && crs) {
      if (!value.is_none()) *crs = crs_text(value);
      continue;
    }
    const ParamOption* o = tspline_app::find_param_option(name);
    if (!o || o->python_name() != name)
      throw py::type_error("parameterize: unknown keyword argument '" + name + "'");
    if (value.is_none()) continue;  // the default
    if (name == "cuts" && !path_of(value) && !py::isinstance<py::str>(value)) {
      s.choice.cuts = cuts_from_python(value);
      continue;
    }
    if (const auto text = option_text(*o, value)) o->apply(s, *text, name);
  }
  return s;
}

DomainArgument domain_from_python(const py::object& domain, const tspline::io::DomainReadOptions& options) {
  if (const auto path = path_of(domain)) return {tspline::io::read_domain(*path, options), *path};
  // GeoJSON: longitude/latitude by definition (RFC 7946), as a .geojson file.
  if (py::isinstance<py::dict>(domain)) return from_geojson(domain, options, "GeoJSON dict");
  // Shapely, GeoPandas, ...: the object's CRS if it has one (GeoPandas), else
  // planar coordinates unless crs= names theirs.
  if (py::hasattr(domain, "__geo_interface__")) {
    tspline::io::DomainReadOptions o = options;
    if (!o.crs && py::hasattr(domain, "crs") && !domain.attr("crs").is_none())
      o.crs = crs_text(domain.attr("crs"));
    const bool without_crs = !o.crs && !o.planar;
    if (without_crs) o.planar = true;
    DomainArgument d =
        from_geojson(domain.attr("__geo_interface__"), o, type_name_of(domain) + " (__geo_interface__)");
    if (without_crs) {  // not GeoJSON's WGS 84: the object has none
      d.domain.description["crs"] = nullptr;
      d.domain.description["units"] = "no CRS: planar, as given (crs= names one)";
    }
    return d;
  }
  if (options.layer || options.feature || options.polygon_index)
    throw tspline::InputError(
        "layer, feature and polygon apply to a file or GeoJSON, not to an array of vertices");
  const std::vector<Array> rings = rings_of(domain);
  if (options.crs && !options.planar) {  // in a CRS: projected as GIS data are
    py::list coordinates;
    for (const Array& r : rings) coordinates.append(geojson_ring(r));
    py::dict polygon("type"_a = "Polygon", "coordinates"_a = coordinates);
    DomainArgument d = from_geojson(polygon, options, rings.size() > 1 ? "rings" : "array");
    d.domain.description["format"] = d.source;
    return d;
  }
  DomainArgument d;
  d.source = rings.size() > 1 ? "rings" : "array";
  d.domain.outer = polygon_of(rings.front(), "domain");
  for (std::size_t h = 1; h < rings.size(); ++h) d.domain.holes.push_back(polygon_of(rings[h], "hole"));
  d.domain.description = {{"format", d.source},
                          {"crs", nullptr},
                          {"projection", nullptr},
                          {"units", "as given"},
                          {"holes", d.domain.holes.size()}};
  return d;
}

}  // namespace tspline_python
