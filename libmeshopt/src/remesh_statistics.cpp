// Statistics of remeshed surfaces (Dassi et al. 2014, Sect. 5).
#include "meshopt/remesh_statistics.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "meshopt/remesh.h"

namespace meshopt {

void Histogram::add(double value) {
  const double k = std::floor((value - lo) / width);
  const auto n = static_cast<long>(counts.size());
  ++counts[static_cast<std::size_t>(std::clamp(static_cast<long>(std::isfinite(k) ? k : n - 1), 0L, n - 1))];
}

double aspect_ratio(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  const double a = (x1 - x2).norm(), b = (x2 - x0).norm(), c = (x0 - x1).norm();
  const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
  if (!(area > 0.0)) return 0.0;
  // r = area / semiperimeter, R = abc / (4 area): q = 2r/R = 16 area^2 / (abc (a+b+c)).
  return 16.0 * area * area / (a * b * c * (a + b + c));
}

Eigen::Vector3d long_axis(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2) {
  const Eigen::Vector3d c = (x0 + x1 + x2) / 3.0;
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& x : {x0, x1, x2}) m += (x - c) * (x - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m);
  return es.eigenvectors().col(2);  // eigenvalues ascending
}

std::vector<double> triangle_aspect_ratios(const RemeshMesh& m) {
  std::vector<double> q;
  for (const RemeshTriangle& t : m.triangles)
    if (t.alive) q.push_back(aspect_ratio(m.vertices[t.v[0]].x, m.vertices[t.v[1]].x, m.vertices[t.v[2]].x));
  return q;
}

std::vector<double> triangle_length_ratios(const RemeshMesh& m, double length, double s) {
  std::vector<double> r;
  for (const RemeshTriangle& t : m.triangles) {
    if (!t.alive) continue;
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += edge_length6d(m, t.v[i], t.v[(i + 1) % 3], s);
    r.push_back(sum / (3.0 * length));
  }
  return r;
}

RemeshStatistics remesh_statistics(const RemeshMesh& m, double length, double s) {
  RemeshStatistics st;
  st.vertices = m.live_vertices();
  const auto edges = m.edges();
  st.edges = edges.size();
  double sum = 0.0;
  st.length_ratio_min = std::numeric_limits<double>::infinity();
  for (const auto& [a, b] : edges) {
    const double r = edge_length6d(m, a, b, s) / length;
    st.length_ratio.add(r);
    sum += r;
    st.length_ratio_min = std::min(st.length_ratio_min, r);
    st.length_ratio_max = std::max(st.length_ratio_max, r);
  }
  if (!edges.empty()) st.length_ratio_mean = sum / static_cast<double>(edges.size());
  double angle_sum = 0.0, q_sum = 0.0;
  st.min_angle_min = st.quality_min = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    const RemeshTriangle& tr = m.triangles[t];
    if (!tr.alive) continue;
    ++st.triangles;
    const double deg = triangle_min_angle6d(m, static_cast<int>(t), s) * 180.0 / std::numbers::pi;
    st.min_angle_degrees.add(deg);
    angle_sum += deg;
    st.min_angle_min = std::min(st.min_angle_min, deg);
    const double q = aspect_ratio(m.vertices[tr.v[0]].x, m.vertices[tr.v[1]].x, m.vertices[tr.v[2]].x);
    q_sum += q;
    st.quality_min = std::min(st.quality_min, q);
  }
  if (st.triangles > 0) {
    st.min_angle_mean = angle_sum / static_cast<double>(st.triangles);
    st.quality_mean = q_sum / static_cast<double>(st.triangles);
  }
  return st;
}

}  // namespace meshopt
