// Surface mesh checks, corner normals, element qualities (Gargallo-Peiro
// Sects. 3.2, 3.5).
#include "meshopt/surface_mesh.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "meshopt/triangle_measure.h"
#include "toolkit/errors.h"

namespace meshopt {
namespace {

[[noreturn]] void fail(const std::string& what) { throw toolkit::InputError("meshopt surface mesh: " + what); }

std::string uv_string(const Eigen::Vector2d& u) {
  std::ostringstream s;
  s << '(' << u.x() << ", " << u.y() << ')';
  return s.str();
}

const Eigen::Vector2d& corner_uv_of(const SurfaceMesh& m, std::size_t e, int i) {
  return m.corner_uv.empty() ? m.u[m.elements[e].v[i]] : m.corner_uv[4 * e + i];
}

}  // namespace

std::vector<CornerTriangle> corner_triangles(int nv, double h) {
  if (nv == 3) {
    const Eigen::Vector2d v1(h, 0.0), v2(0.5 * h, 0.5 * std::sqrt(3.0) * h);
    return {CornerTriangle{{0, 1, 2}, {Eigen::Vector2d::Zero(), v1, v2}, 1.0}};
  }
  // Quad: the corner triangle at vertex k is (k, k+1, k-1), ideal = corner of a square (Fig. 3).
  std::vector<CornerTriangle> out;
  for (int k = 0; k < 4; ++k)
    out.push_back(CornerTriangle{{k, (k + 1) % 4, (k + 3) % 4},
                                 {Eigen::Vector2d::Zero(), Eigen::Vector2d(h, 0.0), Eigen::Vector2d(0.0, h)},
                                 0.25});
  return out;
}

void validate_surface_mesh(const SurfaceMesh& m, bool exact_domain) {
  const std::size_t n = m.x.size();
  if (m.u.size() != n || m.free_face.size() != n) fail("x, u and free_face must have one entry per node");
  if (!m.corner_uv.empty() && m.corner_uv.size() != 4 * m.elements.size())
    fail("corner_uv must be empty or have 4 entries per element");
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    if (!m.faces[f]) fail("face " + std::to_string(f) + " is null");
  for (std::size_t i = 0; i < n; ++i) {
    if (!m.x[i].allFinite()) fail("node " + std::to_string(i) + " has a non-finite position");
    const int f = m.free_face[i];
    if (f < -1 || f >= static_cast<int>(m.faces.size()))
      fail("node " + std::to_string(i) + " refers to face " + std::to_string(f) + " which does not exist");
    if (f < 0) continue;
    const ParametricSurface& s = *m.faces[f];
    if (!m.u[i].allFinite())
      fail("node " + std::to_string(i) + " has non-finite parametric coordinates");
    const SurfacePoint p = s.evaluate(m.u[i], 1);
    if (unit_normal(p).isZero())
      fail("node " + std::to_string(i) + " lies at a degenerate point of face " + std::to_string(f) + " (u = " +
           uv_string(m.u[i]) + ", phi_u x phi_v = 0)");
    if (!s.contains(m.u[i]))
      fail("node " + std::to_string(i) + " at u = " + uv_string(m.u[i]) + " is outside the parameter range of face " +
           std::to_string(f));
    if (exact_domain && !s.contains_exactly(m.u[i]))
      fail("node " + std::to_string(i) + " at u = " + uv_string(m.u[i]) + " lies outside the trimmed face " +
           std::to_string(f));
    const double scale = std::max({1.0, p.x.norm(), m.x[i].norm()});
    if (!((p.x - m.x[i]).norm() <= 1e-6 * scale))
      fail("node " + std::to_string(i) + ": phi(u) of face " + std::to_string(f) + " is not the node's position");
  }
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const SurfaceElement& el = m.elements[e];
    if (el.nv != 3 && el.nv != 4) fail("element " + std::to_string(e) + " has " + std::to_string(el.nv) + " nodes");
    if (el.face < 0 || el.face >= static_cast<int>(m.faces.size()))
      fail("element " + std::to_string(e) + " refers to a face that does not exist");
    for (int i = 0; i < el.nv; ++i) {
      const int v = el.v[i];
      if (v < 0 || static_cast<std::size_t>(v) >= n) fail("element " + std::to_string(e) + ": node index out of range");
      for (int j = 0; j < i; ++j)
        if (el.v[j] == v) fail("element " + std::to_string(e) + " repeats node " + std::to_string(v));
      if (m.free_face[v] >= 0 && m.free_face[v] != el.face)
        fail("free node " + std::to_string(v) + " belongs to face " + std::to_string(m.free_face[v]) +
             " but element " + std::to_string(e) + " lies on face " + std::to_string(el.face));
    }
  }
}

std::vector<Eigen::Vector3d> corner_normals(const SurfaceMesh& m) {
  std::vector<Eigen::Vector3d> out(4 * m.elements.size(), Eigen::Vector3d::Zero());
  for (std::size_t e = 0; e < m.elements.size(); ++e) {
    const SurfaceElement& el = m.elements[e];
    for (int i = 0; i < el.nv; ++i) {
      const Eigen::Vector2d& uv = corner_uv_of(m, e, i);
      const Eigen::Vector3d n = unit_normal(m.faces[el.face]->evaluate(uv, 1));
      // A fixed node may sit at a degenerate point (a sphere's pole is a CAD
      // vertex): its corner then does not take part in orienting the element.
      if (n.isZero() && m.free_face[el.v[i]] >= 0)
        fail("element " + std::to_string(e) + ", node " + std::to_string(el.v[i]) +
             ": degenerate surface point (phi_u x phi_v = 0) at u = " + uv_string(uv) + " on face " +
             std::to_string(el.face));
      out[4 * e + i] = n;
    }
  }
  return out;
}

std::vector<double> node_sizes(const SurfaceMesh& m, const SizeField& size) {
  std::vector<double> h(m.x.size(), 1.0);
  if (size) {
    for (std::size_t i = 0; i < m.x.size(); ++i) {
      h[i] = size(m.x[i]);
      if (!(h[i] > 0.0) || !std::isfinite(h[i]))
        fail("the size field is not positive and finite at node " + std::to_string(i));
    }
    return h;
  }
  double sum = 0.0;
  std::size_t cnt = 0;
  for (const SurfaceElement& el : m.elements)
    for (int i = 0; i < el.nv; ++i, ++cnt) sum += (m.x[el.v[(i + 1) % el.nv]] - m.x[el.v[i]]).norm();
  const double mean = cnt > 0 && sum > 0.0 ? sum / static_cast<double>(cnt) : 1.0;
  h.assign(m.x.size(), mean);
  return h;
}

ElementQualities element_qualities(const SurfaceMesh& m, std::span<const Eigen::Vector3d> normals,
                                   SurfaceMeasure measure, std::span<const double> node_size) {
  ElementQualities q;
  const std::size_t ne = m.elements.size();
  q.quality.assign(ne, 0.0);
  q.valid.assign(ne, 1);
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t e = 0; e < ne; ++e) {
    const SurfaceElement& el = m.elements[e];
    double h = 0.0;
    for (int i = 0; i < el.nv; ++i) h += node_size.empty() ? 1.0 : node_size[el.v[i]];
    h /= el.nv;
    double eta = 0.0;
    for (const CornerTriangle& ct : corner_triangles(el.nv, h)) {
      const auto [i0, i1, i2] = ct.local;
      const Eigen::Vector3d n = normals[4 * e + i0] + normals[4 * e + i1] + normals[4 * e + i2];
      const TriangleInvariants t =
          triangle_invariants(m.x[el.v[i0]], m.x[el.v[i1]], m.x[el.v[i2]],
                              ideal_inverse(ct.ideal[0], ct.ideal[1], ct.ideal[2]), n);
      if (!(t.sigma > 0.0)) q.valid[e] = 0;
      eta += ct.weight * distortion(measure, t.f, t.sigma, 0.0).value;
    }
    q.quality[e] = q.valid[e] && std::isfinite(eta) && eta > 0.0 ? 1.0 / eta : 0.0;
    if (!q.valid[e]) ++q.tangled;
    sum += q.quality[e];
    sum2 += q.quality[e] * q.quality[e];
    q.min = e == 0 ? q.quality[e] : std::min(q.min, q.quality[e]);
    q.max = e == 0 ? q.quality[e] : std::max(q.max, q.quality[e]);
  }
  if (ne > 0) {
    q.mean = sum / static_cast<double>(ne);
    q.stddev = std::sqrt(std::max(0.0, sum2 / static_cast<double>(ne) - q.mean * q.mean));
  }
  return q;
}

}  // namespace meshopt
