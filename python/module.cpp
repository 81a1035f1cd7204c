// Python module `tspline` (pybind11): a thin binding of the toolkit's C++
// calls, with the command line's options (one table, param_options.h), files
// and messages. Arrays are NumPy float64 (read in place when C-contiguous,
// converted once otherwise); results are written straight into new arrays.
#include "bindings.h"

PYBIND11_MODULE(tspline, m) {
  m.doc() =
      "T-spline parameterization of 2D domains (one patch or a quad layout of many), isogeometric Poisson "
      "solver "
      "and mesh optimization: a thin binding of libtspline, with the options, files and messages of the "
      "tspline "
      "program. Errors: tspline.Error and its subclasses InputError (a ValueError), IoError (an OSError), "
      "NumericalError (an ArithmeticError).";
  tspline_python::bind_errors(m);
  tspline_python::bind_maps(m);
  tspline_python::bind_poisson(m);
  tspline_python::bind_meshopt(m);
}
