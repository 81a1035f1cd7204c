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

/// Value, gradient and Hessian with respect to (u, v).
struct Jet {
  double v = 0.0;
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  Jet() = default;
  Jet(double value) : v(value) {}  // NOLINT: constants mix freely with jets
};
inline Jet operator+(const Jet& a, const Jet& b) {
  Jet r;
  r.v = a.v + b.v;
  r.g = a.g + b.g;
  r.H = a.H + b.H;
  return r;
}
inline Jet operator-(const Jet& a) {
  Jet r;
  r.v = -a.v;
  r.g = -a.g;
  r.H = -a.H;
  return r;
}
inline Jet operator-(const Jet& a, const Jet& b) { return a + (-b); }
inline Jet operator*(const Jet& a, const Jet& b) {
  Jet r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  r.H = a.v * b.H + b.v * a.H + a.g * b.g.transpose() + b.g * a.g.transpose();
  return r;
}
/// f(a) for a scalar function with f(a.v) = f0, f'(a.v) = f1, f''(a.v) = f2.
inline Jet chain(const Jet& a, double f0, double f1, double f2) {
  Jet r;
  r.v = f0;
  r.g = f1 * a.g;
  r.H = f1 * a.H + f2 * a.g * a.g.transpose();
  return r;
}
inline Jet operator/(const Jet& a, const Jet& b) { return a * chain(b, 1.0 / b.v, -1.0 / (b.v * b.v), 2.0 / (b.v * b.v * b.v)); }
inline Jet sin(const Jet& a) { return chain(a, std::sin(a.v), std::cos(a.v), -std::sin(a.v)); }
inline Jet cos(const Jet& a) { return chain(a, std::cos(a.v), -std::sin(a.v), -std::cos(a.v)); }
inline Jet exp(const Jet& a) { return chain(a, std::exp(a.v), std::exp(a.v), std::exp(a.v)); }

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
    a.g = Eigen::Vector2d(1, 0);
    b.g = Eigen::Vector2d(0, 1);
    const auto r = f_(a, b);
    meshopt::SurfacePoint p;
    for (int k = 0; k < 3; ++k) {
      p.x[k] = r[k].v;
      p.d(k, 0) = r[k].g[0];
      p.d(k, 1) = r[k].g[1];
      p.duu[k] = r[k].H(0, 0);
      p.duv[k] = r[k].H(0, 1);
      p.dvv[k] = r[k].H(1, 1);
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
