// Gauss-Legendre on [0,1]; see tspline/detail/quadrature.h.
#include "tspline/detail/quadrature.h"

#include <stdexcept>
#include <utility>
#include "toolkit/errors.h"

namespace tspline::detail {

void gauss_points_01(int n, std::vector<double>& p, std::vector<double>& w) {
  // Nodes and weights of Gauss-Legendre on [-1,1], mapped to [0,1].
  static const std::vector<std::vector<std::pair<double, double>>> table = {
      {{0.0, 2.0}},
      {{-0.5773502691896257, 1.0}, {0.5773502691896257, 1.0}},
      {{-0.7745966692414834, 5.0 / 9}, {0.0, 8.0 / 9}, {0.7745966692414834, 5.0 / 9}},
      {{-0.8611363115940526, 0.3478548451374538},
       {-0.3399810435848563, 0.6521451548625461},
       {0.3399810435848563, 0.6521451548625461},
       {0.8611363115940526, 0.3478548451374538}},
      {{-0.9061798459386640, 0.2369268850561891},
       {-0.5384693101056831, 0.4786286704993665},
       {0.0, 0.5688888888888889},
       {0.5384693101056831, 0.4786286704993665},
       {0.9061798459386640, 0.2369268850561891}},
      {{-0.9324695142031521, 0.1713244923791704},
       {-0.6612093864662645, 0.3607615730481386},
       {-0.2386191860831969, 0.4679139345726910},
       {0.2386191860831969, 0.4679139345726910},
       {0.6612093864662645, 0.3607615730481386},
       {0.9324695142031521, 0.1713244923791704}}};
  if (n < 1 || n > 6) throw toolkit::InputError("gauss_points_01: n must be in [1, 6]");
  p.clear(), w.clear();
  for (const auto& [x, wt] : table[n - 1]) p.push_back(0.5 * (x + 1.0)), w.push_back(0.5 * wt);
}

}  // namespace tspline::detail
