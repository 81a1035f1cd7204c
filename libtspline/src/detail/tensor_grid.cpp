// Sum factorization of bicubic Bernstein polynomials on a tensor grid; see tensor_grid.h.
#include "tspline/detail/tensor_grid.h"

#include <utility>

namespace tspline::detail {

void TensorGrid::set(std::vector<double> points, std::vector<double> weights) {
  point = std::move(points);
  weight = std::move(weights);
  m = static_cast<int>(point.size());
  b.assign(4 * point.size(), 0.0);
  db.assign(4 * point.size(), 0.0);
  for (std::size_t p = 0; p < point.size(); ++p) {
    const double s = point[p], r = 1.0 - s;
    b[4 * p + 0] = r * r * r;
    b[4 * p + 1] = 3.0 * s * r * r;
    b[4 * p + 2] = 3.0 * s * s * r;
    b[4 * p + 3] = s * s * s;
    db[4 * p + 0] = -3.0 * r * r;
    db[4 * p + 1] = 3.0 * r * r - 6.0 * s * r;
    db[4 * p + 2] = 6.0 * s * r - 3.0 * s * s;
    db[4 * p + 3] = 3.0 * s * s;
  }
}

void tensor_values(const TensorGrid& g, const double* c, double* f, double* fs, double* ft, double* scratch) {
  if (g.m == 5) return tensor_values_fixed<5>(g, c, f, fs, ft, scratch);  // 5 x 5 Gauss-Lobatto points, the default
  if (g.m == 4) return tensor_values_fixed<4>(g, c, f, fs, ft, scratch);
  tensor_values_fixed<0>(g, c, f, fs, ft, scratch);
}

void tensor_values_transpose(const TensorGrid& g, const double* a, const double* as, const double* at, double* c,
                             double* scratch) {
  if (g.m == 5) return tensor_values_transpose_fixed<5>(g, a, as, at, c, scratch);
  if (g.m == 4) return tensor_values_transpose_fixed<4>(g, a, as, at, c, scratch);
  tensor_values_transpose_fixed<0>(g, a, as, at, c, scratch);
}

}  // namespace tspline::detail
