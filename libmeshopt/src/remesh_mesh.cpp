// The remesher's triangle mesh and its incidence (Dassi et al. 2014, Sect. 3).
#include "meshopt/remesh_mesh.h"

#include <algorithm>
#include <set>

namespace meshopt {

int RemeshMesh::add_vertex(const RemeshVertex& v) {
  vertices.push_back(v);
  incident_.emplace_back();
  return static_cast<int>(vertices.size()) - 1;
}

int RemeshMesh::add_triangle(const RemeshTriangle& t) {
  const int id = static_cast<int>(triangles.size());
  triangles.push_back(t);
  triangles.back().alive = true;
  for (int v : t.v) incident_[v].push_back(id);
  return id;
}

void RemeshMesh::kill_triangle(int t) {
  RemeshTriangle& tr = triangles[t];
  if (!tr.alive) return;
  tr.alive = false;
  for (int v : tr.v) std::erase(incident_[v], t);
}

void RemeshMesh::set_triangle(int t, const std::array<int, 3>& v) {
  for (int a : triangles[t].v) std::erase(incident_[a], t);
  triangles[t].v = v;
  for (int a : v) incident_[a].push_back(t);
}

void RemeshMesh::rebuild_incidence() {
  incident_.assign(vertices.size(), {});
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (triangles[t].alive)
      for (int v : triangles[t].v) incident_[v].push_back(static_cast<int>(t));
}

std::vector<int> RemeshMesh::edge_triangles(int a, int b) const {
  std::vector<int> out;
  for (int t : incident_[a]) {
    const auto& v = triangles[t].v;
    if (v[0] == b || v[1] == b || v[2] == b) out.push_back(t);
  }
  return out;
}

bool RemeshMesh::has_edge(int a, int b) const {
  for (int t : incident_[a]) {
    const auto& v = triangles[t].v;
    if (v[0] == b || v[1] == b || v[2] == b) return true;
  }
  return false;
}

int RemeshMesh::feature_curve(int a, int b) const {
  const auto it = feature_edges.find(key(a, b));
  return it == feature_edges.end() ? -1 : it->second;
}

std::vector<int> RemeshMesh::neighbours(int v) const {
  std::vector<int> out;
  neighbours(v, out);
  return out;
}

void RemeshMesh::neighbours(int v, std::vector<int>& out) const {
  out.clear();
  for (int t : incident_[v])
    for (int w : triangles[t].v)
      if (w != v && std::find(out.begin(), out.end(), w) == out.end()) out.push_back(w);
}

std::vector<std::array<int, 2>> RemeshMesh::edges() const {
  std::vector<std::array<int, 2>> out;
  for (std::size_t a = 0; a < vertices.size(); ++a)
    for (int b : neighbours(static_cast<int>(a)))
      if (static_cast<int>(a) < b) out.push_back({static_cast<int>(a), b});
  return out;
}

std::size_t RemeshMesh::live_triangles() const {
  return static_cast<std::size_t>(std::count_if(triangles.begin(), triangles.end(), [](const auto& t) { return t.alive; }));
}

std::size_t RemeshMesh::live_vertices() const {
  return static_cast<std::size_t>(std::count_if(incident_.begin(), incident_.end(), [](const auto& l) { return !l.empty(); }));
}

void RemeshMesh::compact() {
  std::vector<int> new_index(vertices.size(), -1);
  std::vector<RemeshVertex> kept;
  for (std::size_t v = 0; v < vertices.size(); ++v)
    if (!incident_[v].empty()) {
      new_index[v] = static_cast<int>(kept.size());
      kept.push_back(std::move(vertices[v]));
    }
  std::vector<RemeshTriangle> tris;
  for (const RemeshTriangle& t : triangles)
    if (t.alive) {
      RemeshTriangle n = t;
      for (int& v : n.v) v = new_index[v];
      tris.push_back(n);
    }
  std::unordered_map<EdgeKey, int, EdgeKeyHash> features;
  for (const auto& [k, curve] : feature_edges) {
    const int a = new_index[k.a], b = new_index[k.b];
    if (a >= 0 && b >= 0) features[key(a, b)] = curve;
  }
  vertices = std::move(kept);
  triangles = std::move(tris);
  feature_edges = std::move(features);
  rebuild_incidence();
}

std::map<int, long> RemeshMesh::euler_characteristics() const {
  std::map<int, std::set<int>> verts;
  std::map<int, std::set<EdgeKey>> edges_of;
  std::map<int, long> faces;
  for (const RemeshTriangle& t : triangles) {
    if (!t.alive) continue;
    ++faces[t.patch];
    for (int i = 0; i < 3; ++i) {
      verts[t.patch].insert(t.v[i]);
      edges_of[t.patch].insert(key(t.v[i], t.v[(i + 1) % 3]));
    }
  }
  std::map<int, long> chi;
  for (const auto& [p, f] : faces)
    chi[p] = static_cast<long>(verts[p].size()) - static_cast<long>(edges_of[p].size()) + f;
  return chi;
}

std::size_t RemeshMesh::non_manifold_edges() const {
  std::unordered_map<EdgeKey, std::array<int, 2>, EdgeKeyHash> uses;  // key -> (count, net direction)
  for (const RemeshTriangle& t : triangles) {
    if (!t.alive) continue;
    for (int i = 0; i < 3; ++i) {
      const int a = t.v[i], b = t.v[(i + 1) % 3];
      auto& u = uses[key(a, b)];
      ++u[0];
      u[1] += a < b ? 1 : -1;
    }
  }
  std::size_t bad = 0;
  for (const auto& [k, u] : uses)
    if (u[0] > 2 || (u[0] == 2 && u[1] != 0)) ++bad;
  return bad;
}

}  // namespace meshopt
