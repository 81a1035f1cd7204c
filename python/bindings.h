#pragma once
// The pieces of the Python module `tspline` (module.cpp) and what they share:
// NumPy argument checks and conversions. Each bind_* adds one group of names.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace tspline_python {

namespace py = pybind11;
/// Arrays are read in place when float64 and C-contiguous, converted once otherwise.
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// tspline.Error and its subclasses; translates the C++ exceptions (errors.cpp).
void bind_errors(py::module_& m);
/// tspline.parameterize, tspline.param_options, tspline.load, tspline.Map (maps.cpp).
void bind_maps(py::module_& m);
/// tspline.poisson and tspline.Solution (poisson.cpp).
void bind_poisson(py::module_& m);
/// tspline.meshopt: smooth and remesh on Gmsh models where Gmsh is built (meshopt.cpp).
void bind_meshopt(py::module_& m);

/// The rows of an (n, 2) array. \throw tspline::InputError naming `what` otherwise.
std::size_t rows_of(const Array& a, const char* what);
/// Row i of an (n, 2) array as a parametric point, checked to lie in [0,1]^2.
Eigen::Vector2d checked_uv(const Array& uv, std::size_t i);
/// A JSON value as the Python object json.loads would give.
py::object to_python(const nlohmann::json& j);
/// str or os.PathLike -> the path; nullopt for anything else.
std::optional<std::string> path_of(const py::handle& obj);

}  // namespace tspline_python
