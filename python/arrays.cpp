// What the parts of the module share: NumPy argument checks and conversions.
#include <string>

#include "bindings.h"
#include "tspline/errors.h"

namespace tspline_python {

std::size_t rows_of(const Array& a, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 2)
    throw tspline::InputError(std::string(what) + ": expected an array of shape (n, 2)");
  return static_cast<std::size_t>(a.shape(0));
}

Eigen::Vector2d checked_uv(const Array& uv, std::size_t i) {
  const double u = uv.data()[2 * i], v = uv.data()[2 * i + 1];
  if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0))
    throw tspline::InputError("uv: parametric point (" + std::to_string(u) + ", " + std::to_string(v) +
                              ") outside [0,1]^2");
  return {u, v};
}

py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

std::optional<std::string> path_of(const py::handle& obj) {
  if (!py::isinstance<py::str>(obj) && !py::hasattr(obj, "__fspath__")) return std::nullopt;
  return py::str(py::module_::import("os").attr("fspath")(obj)).cast<std::string>();
}

}  // namespace tspline_python
