#pragma once
// Analytic parameterized surfaces for the libmeshopt surface tests: phi given as
// one generic lambda, differentiated exactly (to second order) with a small
// forward-mode jet, so every surface comes with first and second derivatives.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <utility>

#include "meshopt/surface.h"

namespace surface_test {

/// Value, gradient (g0, g1) and Hessian (h00, h01, h11) with respect to (u, v)
/// (plain doubles: the tests evaluate surfaces millions of times, also under ASan).
struct Jet {
  double v = 0.0, g0 = 0.0, g1 = 0.0, h00 = 0.0, h01 = 0.0, h11 = 0.0;
  Jet() = default;
  Jet(double value) : v(value) {}  // NOLINT: constants mix freely with jets
};
inline Jet operator+(const Jet& a, const Jet& b) {
  Jet r;
  r.v = a.v + b.v;
  r.g0 = a.g0 + b.g0;
  r.g1 = a.g1 + b.g1;
  r.h00 = a.h00 + b.h00;
  r.h01 = a.h01 + b.h01;
  r.h11 = a.h11 + b.h11;
  return r;
}
inline Jet operator-(const Jet& a) {
  Jet r;
  r.v = -a.v;
  r.g0 = -a.g0;
  r.g1 = -a.g1;
  r.h00 = -a.h00;
  r.h01 = -a.h01;
  r.h11 = -a.h11;
  return r;
}
inline Jet operator-(const Jet& a, const Jet& b) { return a + (-b); }
inline Jet operator*(const Jet& a, const Jet& b) {
  Jet r;
  r.v = a.v * b.v;
  r.g0 = a.v * b.g0 + b.v * a.g0;
  r.g1 = a.v * b.g1 + b.v * a.g1;
  r.h00 = a.v * b.h00 + b.v * a.h00 + 2.0 * a.g0 * b.g0;
  r.h01 = a.v * b.h01 + b.v * a.h01 + a.g0 * b.g1 + a.g1 * b.g0;
  r.h11 = a.v * b.h11 + b.v * a.h11 + 2.0 * a.g1 * b.g1;
  return r;
}
/// f(a) for a scalar function with f(a.v) = f0, f'(a.v) = f1, f''(a.v) = f2.
inline Jet chain(const Jet& a, double f0, double f1, double f2) {
  Jet r;
  r.v = f0;
  r.g0 = f1 * a.g0;
  r.g1 = f1 * a.g1;
  r.h00 = f1 * a.h00 + f2 * a.g0 * a.g0;
  r.h01 = f1 * a.h01 + f2 * a.g0 * a.g1;
  r.h11 = f1 * a.h11 + f2 * a.g1 * a.g1;
  return r;
}
inline Jet operator/(const Jet& a, const Jet& b) { return a * chain(b, 1.0 / b.v, -1.0 / (b.v * b.v), 2.0 / (b.v * b.v * b.v)); }
inline Jet sin(const Jet& a) { return chain(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v)); }
inline Jet cos(const Jet& a) { return chain(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v)); }
inline Jet exp(const Jet& a) {
  const double e = std::exp(a.v);
  return chain(a, e, e, e);
}

/// A surface phi(u, v) = f(u, v) (f: generic lambda returning std::array<T, 3>)
/// over the box [lo, hi].
template <class F>
class AnalyticSurface final : public meshopt::ParametricSurface {
 public:
  AnalyticSurface(F f, Eigen::Vector2d lo, Eigen::Vector2d hi) : f_(std::move(f)), lo_(lo), hi_(hi) {}
  Eigen::Vector3d value(const Eigen::Vector2d& u) const override {
    const auto r = f_(u.x(), u.y());
    return {r[0], r[1], r[2]};
  }
  meshopt::SurfacePoint evaluate(const Eigen::Vector2d& u, int /*order*/) const override {
    Jet a(u.x()), b(u.y());
    a.g0 = 1.0;
    b.g1 = 1.0;
    const auto r = f_(a, b);
    meshopt::SurfacePoint p;
    for (int k = 0; k < 3; ++k) {
      p.x[k] = r[k].v;
      p.d(k, 0) = r[k].g0;
      p.d(k, 1) = r[k].g1;
      p.duu[k] = r[k].h00;
      p.duv[k] = r[k].h01;
      p.dvv[k] = r[k].h11;
    }
    return p;
  }
  bool contains(const Eigen::Vector2d& u) const override {
    return (u.array() >= lo_.array()).all() && (u.array() <= hi_.array()).all();
  }

 private:
  F f_;
  Eigen::Vector2d lo_, hi_;
};

template <class F>
AnalyticSurface<F> make_surface(F f, Eigen::Vector2d lo, Eigen::Vector2d hi) {
  return AnalyticSurface<F>(std::move(f), lo, hi);
}

}  // namespace surface_test

#include <vector>

#include "meshopt/surface_mesh.h"

namespace surface_test {

/// Structured nx x ny grid of nodes over [lo, hi] of one face, mapped to the
/// surface; boundary nodes fixed. Triangles: each cell split along the same diagonal.
inline meshopt::SurfaceMesh grid_mesh(const meshopt::ParametricSurface& s, Eigen::Vector2d lo, Eigen::Vector2d hi,
                                      int nx, int ny, bool quads) {
  meshopt::SurfaceMesh m;
  m.faces = {&s};
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector2d u(lo.x() + (hi.x() - lo.x()) * i / (nx - 1), lo.y() + (hi.y() - lo.y()) * j / (ny - 1));
      m.u.push_back(u);
      m.x.push_back(s.value(u));
      m.free_face.push_back(i == 0 || j == 0 || i == nx - 1 || j == ny - 1 ? -1 : 0);
    }
  auto id = [nx](int i, int j) { return j * nx + i; };
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (quads) {
        m.elements.push_back({{a, b, c, d}, 4, 0});
      } else {
        m.elements.push_back({{a, b, c, 0}, 3, 0});
        m.elements.push_back({{a, c, d, 0}, 3, 0});
      }
    }
  return m;
}

}  // namespace surface_test
