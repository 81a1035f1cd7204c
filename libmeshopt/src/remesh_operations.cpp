// Local mesh operations of Dassi et al. 2014, Sect. 3.1: edge split, collapse and
// flip, and vertex smoothing, measured in R^6 and kept on the CAD model.
#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "meshopt/chordal_estimate.h"
#include "meshopt/flip_energy.h"
#include "remesher.h"

namespace meshopt {

double edge_length6d(const RemeshMesh& m, int a, int b, double s) {
  const RemeshVertex& va = m.vertices[a];
  const RemeshVertex& vb = m.vertices[b];
  double len = -1.0;
  if (va.normals.size() == 1 && vb.normals.size() == 1 && va.normals[0].first == vb.normals[0].first)
    return length6d(va.x, va.normals[0].second, vb.x, vb.normals[0].second, s);  // one patch: the usual case
  m.for_each_edge_triangle(a, b, [&](int t) {
    const int p = m.triangles[t].patch;
    len = std::max(len, length6d(va.x, va.normal(p), vb.x, vb.normal(p), s));
  });
  return len >= 0.0 ? len : (va.x - vb.x).norm();
}

double triangle_min_angle6d(const RemeshMesh& m, int t, double s) {
  const RemeshTriangle& tr = m.triangles[t];
  const RemeshVertex& v0 = m.vertices[tr.v[0]];
  const RemeshVertex& v1 = m.vertices[tr.v[1]];
  const RemeshVertex& v2 = m.vertices[tr.v[2]];
  return min_angle6d(embed6d(v0.x, v0.normal(tr.patch), s), embed6d(v1.x, v1.normal(tr.patch), s),
                     embed6d(v2.x, v2.normal(tr.patch), s));
}

double triangle_deviation(const RemeshMesh& m, int t) {
  const RemeshTriangle& tr = m.triangles[t];
  const auto& v = m.vertices;
  return triangle_deviation_estimate({v[tr.v[0]].x, v[tr.v[1]].x, v[tr.v[2]].x},
                                     {v[tr.v[0]].normal(tr.patch), v[tr.v[1]].normal(tr.patch), v[tr.v[2]].normal(tr.patch)});
}

namespace detail {
namespace {

/// The corners of t rotated so that `first` comes first (t must contain it).
std::array<int, 3> rotated(std::array<int, 3> t, int first) {
  while (t[0] != first) std::rotate(t.begin(), t.begin() + 1, t.end());
  return t;
}

bool contains(const std::array<int, 3>& t, int v) { return t[0] == v || t[1] == v || t[2] == v; }

int rank(VertexKind k) { return k == VertexKind::surface ? 0 : k == VertexKind::curve ? 1 : 2; }

}  // namespace

std::array<Eigen::Vector3d, 3> Remesher::positions(const std::array<int, 3>& t) const {
  return {m_.vertices[t[0]].x, m_.vertices[t[1]].x, m_.vertices[t[2]].x};
}

std::array<Eigen::Vector3d, 3> Remesher::normals(const std::array<int, 3>& t, int patch) const {
  return {m_.vertices[t[0]].normal(patch), m_.vertices[t[1]].normal(patch), m_.vertices[t[2]].normal(patch)};
}

bool Remesher::inverted(const std::array<int, 3>& t, int patch) const {
  return is_inverted(positions(t), normals(t, patch), o_.inversion_angle);
}

double Remesher::min_angle(const std::array<int, 3>& t, int patch) const {
  const double s = o_.anisotropy;
  const auto n = normals(t, patch);
  return min_angle6d(embed6d(m_.vertices[t[0]].x, n[0], s), embed6d(m_.vertices[t[1]].x, n[1], s),
                     embed6d(m_.vertices[t[2]].x, n[2], s));
}

double Remesher::deviation(const std::array<int, 3>& t, int patch) const {
  return triangle_deviation_estimate(positions(t), normals(t, patch));
}

bool Remesher::breaks_cap(const std::array<int, 3>& t, int patch, double before) const {
  if (!(o_.max_deviation > 0.0)) return false;
  const double d = deviation(t, patch);
  return d > o_.max_deviation && d > before;
}

Edge Remesher::most_curved_edge(int t) const {
  const RemeshTriangle& tr = m_.triangles[t];
  const auto x = positions(tr.v);
  const auto n = normals(tr.v, tr.patch);
  Edge best{tr.v[0], tr.v[1]};
  double best_term = -1.0;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double term = std::abs(chord_curvature_term(x[i], n[i], x[j], n[j]));
    if (term > best_term) {
      best_term = term;
      best = {tr.v[i], tr.v[j]};
    }
  }
  return best;
}

double Remesher::pair_energy(const std::array<int, 3>& t1, const std::array<int, 3>& t2, int patch) const {
  // Eq. 5: E_T1 + E_T2 + sum of E_e over the edges of both triangles. Of each E_e
  // (Eq. 4) only the terms of T1 and T2 change with a flip: the term of a
  // triangle outside the pair is the same before and after, and is left out.
  double e = 0.0;
  for (const auto& t : {t1, t2}) {
    const auto x = positions(t);
    const auto n = normals(t, patch);
    e += triangle_energy(x, n);
    const Eigen::Vector3d nt = triangle_normal(x[0], x[1], x[2]);
    for (int i = 0; i < 3; ++i) e += edge_energy(n[i], n[(i + 1) % 3], nt);
  }
  return e;
}

ProjectionHint Remesher::hint(const std::vector<int>& tris, std::initializer_list<int> first) const {
  ProjectionHint h;
  auto add_face = [&](int v) {
    const RemeshVertex& vv = m_.vertices[v];
    if (vv.kind == VertexKind::surface && std::find(h.faces.begin(), h.faces.end(), vv.on.entity) == h.faces.end())
      h.faces.push_back(vv.on.entity);
  };
  for (int v : first) add_face(v);
  for (int t : tris) {
    std::array<GeometryPoint, 3> corners;
    for (int k = 0; k < 3; ++k) {
      const int v = m_.triangles[t].v[k];
      add_face(v);
      const RemeshVertex& vv = m_.vertices[v];
      corners[k] = {vv.x, vv.kind == VertexKind::surface ? vv.on.entity : -1, vv.on.param};
    }
    h.triangles.push_back(corners);
  }
  return h;
}

Edge Remesher::extreme_edge(int t, bool longest) const {
  const auto& v = m_.triangles[t].v;
  Edge best{v[0], v[1]};
  double best_len = length(v[0], v[1]);
  for (int i = 1; i < 3; ++i) {
    const double l = length(v[i], v[(i + 1) % 3]);
    if (longest ? l > best_len : l < best_len) {
      best_len = l;
      best = {v[i], v[(i + 1) % 3]};
    }
  }
  return best;
}

int Remesher::split(int a, int b) {
  const std::vector<int> ts = m_.edge_triangles(a, b);
  if (ts.empty() || ts.size() > 2) return -1;
  const Eigen::Vector3d mid = 0.5 * (m_.vertices[a].x + m_.vertices[b].x);
  RemeshVertex nv;
  const int curve = m_.feature_curve(a, b);
  if (curve >= 0) {
    nv.kind = VertexKind::curve;
    nv.on = g_.curve_midpoint(curve, m_.vertices[a].kind, m_.vertices[a].on, m_.vertices[b].kind, m_.vertices[b].on);
  } else {
    nv.kind = VertexKind::surface;
    nv.on = g_.project_to_patch(m_.triangles[ts[0]].patch, mid, hint(ts, {a, b}));
  }
  nv.x = nv.on.x;
  // A projection far from the edge means the model is not where the mesh is.
  if (!nv.x.allFinite() || (nv.x - mid).norm() > (m_.vertices[a].x - m_.vertices[b].x).norm()) return -1;
  for (int t : ts) {
    const int p = m_.triangles[t].patch;
    if (nv.normal(p).isZero()) nv.normals.emplace_back(p, g_.patch_normal(p, nv.kind, nv.on));
    if (!nv.normals.back().second.allFinite() || nv.normals.back().second.isZero()) return -1;
  }
  const int c = m_.add_vertex(nv);
  // The two halves of each triangle; refused if one is inverted and the triangle was not.
  std::vector<std::array<std::array<int, 3>, 2>> halves;
  for (int t : ts) {
    std::array<int, 3> v = rotated(m_.triangles[t].v, a);
    if (v[1] != b) v = rotated(v, b);  // now v = (e0, e1, opposite) with {e0, e1} = {a, b}
    const std::array<int, 3> h1{v[0], c, v[2]}, h2{c, v[1], v[2]};
    const int p = m_.triangles[t].patch;
    if (!inverted(v, p) && (inverted(h1, p) || inverted(h2, p))) return -1;  // c stays unreferenced
    halves.push_back({h1, h2});
  }
  for (std::size_t k = 0; k < ts.size(); ++k) {
    const int p = m_.triangles[ts[k]].patch;
    m_.set_triangle(ts[k], halves[k][0]);
    m_.add_triangle({halves[k][1], p, true});
  }
  touch(a);
  touch(b);
  touch(c);
  for (const auto& h : halves) touch(h[0][2]);
  if (curve >= 0) {
    m_.feature_edges.erase(RemeshMesh::key(a, b));
    m_.feature_edges[RemeshMesh::key(a, c)] = curve;
    m_.feature_edges[RemeshMesh::key(c, b)] = curve;
  }
  ++r_.splits;
  return c;
}

bool Remesher::can_remove(int a, int b) const {
  const RemeshVertex& va = m_.vertices[a];
  if (va.kind == VertexKind::corner) return false;
  // A vertex on a feature curve slides only along it: onto a neighbour on the curve.
  if (va.kind == VertexKind::curve && m_.feature_curve(a, b) != va.on.entity) return false;
  // Link condition: the common neighbours of a and b are the opposite vertices
  // of the edge's triangles (otherwise the collapse changes the topology).
  std::vector<int> opposite;
  for (int t : m_.edge_triangles(a, b))
    for (int w : m_.triangles[t].v)
      if (w != a && w != b) opposite.push_back(w);
  const std::vector<int> nb = m_.neighbours(b);
  std::size_t common = 0;
  for (int w : m_.neighbours(a)) {
    if (std::find(nb.begin(), nb.end(), w) == nb.end()) continue;
    if (std::find(opposite.begin(), opposite.end(), w) == opposite.end()) return false;
    ++common;
  }
  // A closed patch as small as a tetrahedron would degenerate.
  return common == opposite.size() && m_.neighbours(a).size() > 3;
}

bool Remesher::collapse_onto(int a, int b, double max_length) {
  const RemeshVertex& vb = m_.vertices[b];
  std::vector<int> moved, removed;
  for (int t : m_.triangles_of(a)) (contains(m_.triangles[t].v, b) ? removed : moved).push_back(t);
  for (int t : moved) {
    const RemeshTriangle& tr = m_.triangles[t];
    std::array<int, 3> nv = tr.v;
    for (int& v : nv)
      if (v == a) v = b;
    if (!inverted(tr.v, tr.patch) && inverted(nv, tr.patch)) return false;
    // No fold: the triangle keeps its side.
    const auto xo = positions(tr.v), xn = positions(nv);
    if (triangle_normal(xo[0], xo[1], xo[2]).dot(triangle_normal(xn[0], xn[1], xn[2])) <= 0.0) return false;
    if (breaks_cap(nv, tr.patch, deviation(tr.v, tr.patch))) return false;
    for (int w : nv)
      if (w != b && length6d(vb.x, vb.normal(tr.patch), m_.vertices[w].x, m_.vertices[w].normal(tr.patch),
                             o_.anisotropy) > max_length)
        return false;
  }
  for (int t : removed) m_.kill_triangle(t);
  for (int t : moved) {
    std::array<int, 3> nv = m_.triangles[t].v;
    for (int& v : nv) {
      if (v == a) v = b;
      touch(v);
    }
    m_.set_triangle(t, nv);
  }
  for (int w : m_.neighbours(b)) {
    const auto it = m_.feature_edges.find(RemeshMesh::key(a, w));
    if (it == m_.feature_edges.end()) continue;
    const int curve = it->second;
    m_.feature_edges.erase(it);
    m_.feature_edges[RemeshMesh::key(b, w)] = curve;
  }
  m_.feature_edges.erase(RemeshMesh::key(a, b));
  ++r_.collapses;
  return true;
}

int Remesher::collapse(int a, int b, double max_length) {
  if (rank(m_.vertices[a].kind) > rank(m_.vertices[b].kind)) std::swap(a, b);  // remove the freer vertex
  if (can_remove(a, b) && collapse_onto(a, b, max_length)) return b;
  if (can_remove(b, a) && collapse_onto(b, a, max_length)) return a;
  ++r_.rejected_collapses;
  return -1;
}

bool Remesher::flip(int a, int b) {
  if (m_.is_feature(a, b)) return false;
  std::vector<int> ts = m_.edge_triangles(a, b);
  if (ts.size() != 2 || m_.triangles[ts[0]].patch != m_.triangles[ts[1]].patch) return false;
  const int p = m_.triangles[ts[0]].patch;
  std::array<int, 3> t1 = rotated(m_.triangles[ts[0]].v, a);
  if (t1[1] != b) {
    std::swap(ts[0], ts[1]);
    t1 = rotated(m_.triangles[ts[0]].v, a);
  }
  const std::array<int, 3> t2 = rotated(m_.triangles[ts[1]].v, b);
  if (t1[1] != b || t2[1] != a) return false;  // inconsistent orientation: leave it
  const int c = t1[2], d = t2[2];
  // Flippable: (i) the new edge is not in the mesh, (ii) not on a feature (above).
  if (c == d || m_.has_edge(c, d)) return false;
  const std::array<int, 3> n1{a, d, c}, n2{d, b, c};
  const auto x1 = positions(n1), x2 = positions(n2);
  if (triangle_normal(x1[0], x1[1], x1[2]).isZero() || triangle_normal(x2[0], x2[1], x2[2]).isZero()) return false;
  bool better;
  if (inverted(t1, p) || inverted(t2, p)) {
    better = pair_energy(n1, n2, p) < pair_energy(t1, t2, p) - 1e-14;  // criterion (a)
  } else {
    better = !inverted(n1, p) && !inverted(n2, p) &&  // criterion (b)
             std::min(min_angle(n1, p), min_angle(n2, p)) > std::min(min_angle(t1, p), min_angle(t2, p)) + 1e-12;
    if (better && o_.max_deviation > 0.0) {
      const double before = std::max(deviation(t1, p), deviation(t2, p));
      better = !breaks_cap(n1, p, before) && !breaks_cap(n2, p, before);
    }
  }
  if (!better) return false;
  m_.set_triangle(ts[0], n1);
  m_.set_triangle(ts[1], n2);
  for (int v : {a, b, c, d}) touch(v);
  ++r_.flips;
  return true;
}

void Remesher::touch(int v) {
  if (all_touched_) return;
  if (is_touched_.size() < m_.vertices.size()) is_touched_.resize(m_.vertices.size(), 0);
  if (!is_touched_[v]) {
    is_touched_[v] = 1;
    touched_.push_back(v);
  }
}

void Remesher::improve_all_by_flips() {
  std::vector<Edge> stack;
  if (all_touched_) {
    stack = m_.edges();
  } else {
    std::vector<EdgeKey> keys;
    for (int v : touched_)
      for (int t : m_.triangles_of(v)) {
        const auto& c = m_.triangles[t].v;
        for (int i = 0; i < 3; ++i) keys.push_back(RemeshMesh::key(c[i], c[(i + 1) % 3]));
      }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    // In increasing order of (a, b), as m_.edges() lists them: the stack pops the last.
    for (const EdgeKey& k : keys) stack.push_back({k.a, k.b});
  }
  for (int v : touched_) is_touched_[v] = 0;
  touched_.clear();
  all_touched_ = false;
  improve_by_flips(std::move(stack));
}

void Remesher::improve_by_flips(std::vector<Edge> stack) {
  std::vector<Edge> retry;  // the paper's S1
  std::unordered_set<EdgeKey, EdgeKeyHash> in_retry;
  for (int pass = 0; pass < o_.max_flip_passes && !stack.empty(); ++pass) {
    bool flipped = false;
    while (!stack.empty()) {
      const auto [a, b] = stack.back();
      stack.pop_back();
      const std::vector<int> ts = m_.edge_triangles(a, b);
      if (ts.empty()) continue;  // gone
      std::array<int, 2> opp{-1, -1};
      for (std::size_t k = 0; k < ts.size() && k < 2; ++k)
        for (int w : m_.triangles[ts[k]].v)
          if (w != a && w != b) opp[k] = w;
      if (flip(a, b)) {
        flipped = true;
        // The link edges of the new triangles may now flip too. (The paper retries
        // every unflipped edge; an edge whose two triangles did not change decides
        // the same way again, so only these need another look.)
        for (const Edge& e : {Edge{a, opp[0]}, Edge{a, opp[1]}, Edge{b, opp[0]}, Edge{b, opp[1]}})
          if (in_retry.insert(RemeshMesh::key(e[0], e[1])).second) retry.push_back(e);
      }
    }
    if (!flipped) break;
    stack.swap(retry);
    retry.clear();
    in_retry.clear();
  }
}

Eigen::Vector3d Remesher::smoothing_step(int v, double* mean_length) const {
  const RemeshVertex& vv = m_.vertices[v];
  if (vv.kind == VertexKind::corner || m_.triangles_of(v).empty()) return Eigen::Vector3d::Zero();
  std::vector<int>& nb = neighbour_scratch_;
  m_.neighbours(v, nb);
  if (mean_length) {
    double mean = 0.0;
    for (int w : nb) mean += (m_.vertices[w].x - vv.x).norm();
    *mean_length = nb.empty() ? 0.0 : mean / static_cast<double>(nb.size());
  }
  // Omega: all neighbours of a surface vertex; the two along the curve of a curve vertex.
  if (vv.kind == VertexKind::curve)
    std::erase_if(nb, [&](int w) { return m_.feature_curve(v, w) != vv.on.entity; });
  if (vv.kind == VertexKind::curve && nb.size() != 2) return Eigen::Vector3d::Zero();
  if (nb.empty()) return Eigen::Vector3d::Zero();
  // Eq. 6: p' = p + alpha sum f(d(p, p_i)) u_i with u_i = (p - p_i)/|p - p_i|,
  // f(d) = -d and alpha = 1/#omega (Laplacian smoothing), d measured in R^6.
  Eigen::Vector3d step = Eigen::Vector3d::Zero();
  for (int w : nb) {
    const Eigen::Vector3d e = vv.x - m_.vertices[w].x;
    const double len = e.norm();
    if (len > 0.0) step -= length(v, w) * e / len;
  }
  step /= static_cast<double>(nb.size());
  if (vv.kind == VertexKind::surface) {
    const Eigen::Vector3d n = vv.normals.front().second;
    step -= step.dot(n) * n;  // tangential; the projection puts it back on the surface
  }
  return step;
}

bool Remesher::move_vertex(int v, const Eigen::Vector3d& target) {
  RemeshVertex& vv = m_.vertices[v];
  const RemeshVertex old = vv;
  const std::vector<int> star = m_.triangles_of(v);
  double old_min = 10.0;
  std::vector<char> was_inverted;
  std::vector<double> old_deviation;
  for (int t : star) {
    was_inverted.push_back(inverted(m_.triangles[t].v, m_.triangles[t].patch));
    old_min = std::min(old_min, min_angle(t));
    if (o_.max_deviation > 0.0) old_deviation.push_back(deviation(t));
  }
  const std::vector<int> around = m_.neighbours(v);
  std::vector<double> old_length;
  for (int w : around) old_length.push_back(length(v, w));
  RemeshVertex nv = old;
  if (old.kind == VertexKind::curve) {
    nv.on = g_.project_to_curve(old.on.entity, target);
  } else {
    nv.on = g_.project_to_patch(old.normals.front().first, target, hint(star, {v}));
  }
  nv.x = nv.on.x;
  if (!nv.x.allFinite()) return false;
  for (auto& [p, n] : nv.normals) {
    n = g_.patch_normal(p, nv.kind, nv.on);
    if (!n.allFinite() || n.isZero()) return false;  // the model could not be evaluated there
  }
  vv = nv;
  // Accepted if no triangle of the star becomes inverted, its smallest 6D angle
  // stays above min(before, theta_min) and no edge grows beyond 1.5 L (which
  // only the next sampling would split again).
  double new_min = 10.0;
  bool ok = true;
  for (std::size_t k = 0; k < around.size() && ok; ++k)
    ok = length(v, around[k]) <= std::max(1.5 * o_.length, old_length[k]);
  for (std::size_t k = 0; k < star.size() && ok; ++k) {
    const RemeshTriangle& tr = m_.triangles[star[k]];
    if (!was_inverted[k] && inverted(tr.v, tr.patch)) ok = false;
    if (o_.max_deviation > 0.0 && breaks_cap(tr.v, tr.patch, old_deviation[k])) ok = false;
    new_min = std::min(new_min, min_angle(star[k]));
  }
  if (ok && new_min >= std::min(old_min, o_.min_angle)) {
    touch(v);
    return true;
  }
  vv = old;
  return false;
}

void Remesher::smooth(double fraction) {
  // Rank the movable vertices by how far Eq. 6 would move them, relative to
  // their mean 3D edge length; smooth the `fraction` that would move most.
  std::vector<std::pair<double, int>> score;
  for (std::size_t v = 0; v < m_.vertices.size(); ++v) {
    double mean = 0.0;
    const Eigen::Vector3d step = smoothing_step(static_cast<int>(v), &mean);
    if (step.isZero()) continue;
    if (mean > 0.0) score.emplace_back(step.norm() / mean, static_cast<int>(v));
  }
  const std::size_t count = std::min(score.size(), static_cast<std::size_t>(std::ceil(fraction * score.size())));
  std::partial_sort(score.begin(), score.begin() + static_cast<long>(count), score.end(),
                    [](const auto& x, const auto& y) { return x.first > y.first; });
  for (std::size_t k = 0; k < count; ++k) {
    const int v = score[k].second;
    const Eigen::Vector3d step = smoothing_step(v);
    if (step.isZero()) continue;
    const Eigen::Vector3d x = m_.vertices[v].x;
    if (move_vertex(v, x + step) || move_vertex(v, x + 0.5 * step)) ++r_.smoothing_moves;
  }
}

}  // namespace detail
}  // namespace meshopt
