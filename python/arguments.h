#pragma once
// The arguments of tspline.parameterize: the domain (a path, an (n, 2) array,
// a list of rings, a GeoJSON dict or an object with __geo_interface__) and the
// keyword options of the table shared with `tspline param` (param_options.h).
#include <optional>
#include <string>

#include "bindings.h"
#include "param_options.h"
#include "tspline/io/gis_reader.h"

namespace tspline_python {

/// The keywords as settings, each through its table entry (the value written
/// as on the command line: ints and floats exactly, flags True/False, corners a
/// sequence of 4 ints or "i,j,k,l", cuts a path or a sequence of (k, 2)
/// polylines). `crs`, if given, is taken out into *crs (str, or an object with
/// to_wkt() or to_string(), e.g. a pyproj.CRS).
/// \throw py::type_error for an unknown keyword or a value of the wrong type;
/// tspline::InputError (named "init_level: ...") for a bad value.
tspline_app::ParamSettings settings_from_keywords(const py::dict& keywords, std::optional<std::string>* crs);

/// The domain as `tspline param` would read it, and what report.json calls it.
struct DomainArgument {
  tspline::io::DomainInput domain;
  std::string source;
};

/// \throw py::type_error for an object that is no domain; tspline::InputError /
/// IoError as the readers.
DomainArgument domain_from_python(const py::object& domain, const tspline::io::DomainReadOptions& options);

}  // namespace tspline_python
