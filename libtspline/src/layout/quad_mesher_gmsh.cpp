// The quad mesher's Gmsh part (tspline/detail/quad_mesher_backend.h): linked
// into libtspline, and built alone as the module libtspline_gmsh.so that the
// tspline program loads at its first quad layout (apps/gmsh_module.cpp).
#include <cmath>
#include <string>
#include <unordered_map>

#include "tspline/detail/quad_mesher_backend.h"
#include "tspline/errors.h"

#ifdef TSPLINE_HAVE_GMSH
#include <gmsh.h>

namespace tspline::detail {

namespace {

struct GmshSession {
  GmshSession() {
    gmsh::initialize();
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
    // One thread: Gmsh reports errors by throwing, which cannot leave its OpenMP regions.
    gmsh::option::setNumber("General.NumThreads", 1);
    gmsh::option::setNumber("Mesh.MaxNumThreads2D", 1);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

std::string gmsh_last_error() {
  std::string e;
  try {
    gmsh::logger::getLastError(e);
  } catch (...) {
  }
  return e.empty() ? "no message" : e;
}

// The mesh by Gmsh in this process (quad_mesh runs it in a child process).
PlanarQuadMesh quad_mesh_here(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                              const std::function<double(const Eigen::Vector2d&)>& size) {
  GmshSession session;
  PlanarQuadMesh out;
  try {
    gmsh::model::add("layout");
    std::vector<int> loops;
    // Point tag -> (ring, segment start); line tag -> (ring, segment).
    std::unordered_map<int, std::pair<int, int>> point_of, line_of;
    int next_point = 1, next_line = 1;
    for (std::size_t r = 0; r < rings.size(); ++r) {
      const auto& ring = rings[r];
      const int first = next_point;
      for (std::size_t k = 0; k < ring.size(); ++k) {
        gmsh::model::geo::addPoint(ring[k].x(), ring[k].y(), 0.0, 0.0, next_point);
        point_of[next_point++] = {static_cast<int>(r), static_cast<int>(k)};
      }
      std::vector<int> lines;
      for (std::size_t k = 0; k < ring.size(); ++k) {
        const int a = first + static_cast<int>(k), b = first + static_cast<int>((k + 1) % ring.size());
        gmsh::model::geo::addLine(a, b, next_line);
        line_of[next_line] = {static_cast<int>(r), static_cast<int>(k)};
        lines.push_back(next_line++);
      }
      loops.push_back(gmsh::model::geo::addCurveLoop(lines));
    }
    gmsh::model::geo::addPlaneSurface(loops, 1);
    for (const auto& [line, where] : line_of) gmsh::model::geo::mesh::setTransfiniteCurve(line, 2);
    gmsh::model::geo::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
    gmsh::option::setNumber("Mesh.Algorithm", 6);  // Frontal-Delaunay
    gmsh::option::setNumber("Mesh.RecombineAll", 1);
    gmsh::option::setNumber("Mesh.RecombinationAlgorithm", 1);  // Blossom
    gmsh::option::setNumber("Mesh.SubdivisionAlgorithm", 1);    // all quadrilaterals
    gmsh::option::setNumber("Mesh.Smoothing", 10);
    // The mesh is split once at the end: mesh at twice the final size.
    gmsh::model::mesh::setSizeCallback(
        [&size](int, int, double x, double y, double) { return 2.0 * size(Eigen::Vector2d(x, y)); });
    gmsh::model::mesh::generate(2);

    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
    gmsh::model::mesh::getNodes(tags, coord, param, -1, -1, false, false);
    std::unordered_map<std::size_t, int> index;
    for (std::size_t i = 0; i < tags.size(); ++i) {
      index[tags[i]] = static_cast<int>(out.nodes.size());
      out.nodes.push_back({coord[3 * i], coord[3 * i + 1]});
    }
    out.ring.assign(out.nodes.size(), -1);
    out.segment.assign(out.nodes.size(), -1);
    out.t.assign(out.nodes.size(), 0.0);
    // Nodes on the ring segments (with their end points), t by projection on the segment.
    for (const auto& [line, where] : line_of) {
      const auto [r, k] = where;
      const auto& ring = rings[r];
      const Eigen::Vector2d a = ring[k], b = ring[(k + 1) % ring.size()];
      gmsh::model::mesh::getNodes(tags, coord, param, 1, line, true, false);
      for (std::size_t i = 0; i < tags.size(); ++i) {
        const int n = index.at(tags[i]);
        const Eigen::Vector2d p = out.nodes[n];
        double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        int seg = k;
        if ((p - a).norm() <= 1e-12 * (b - a).norm()) t = 0.0;
        if ((p - b).norm() <= 1e-12 * (b - a).norm()) t = 0.0, seg = static_cast<int>((k + 1) % ring.size());
        out.ring[n] = r;
        out.segment[n] = seg;
        out.t[n] = t;
      }
    }
    std::vector<std::size_t> element_tags, element_nodes;
    gmsh::model::mesh::getElementsByType(2, element_tags, element_nodes);
    if (!element_tags.empty())
      throw NumericalError("the quad mesher left " + std::to_string(element_tags.size()) + " triangles");
    gmsh::model::mesh::getElementsByType(3, element_tags, element_nodes);
    for (std::size_t e = 0; e < element_tags.size(); ++e) {
      std::array<int, 4> q;
      for (int j = 0; j < 4; ++j) q[j] = index.at(element_nodes[4 * e + j]);
      double area2 = 0.0;
      for (int j = 0; j < 4; ++j) {
        const Eigen::Vector2d &p = out.nodes[q[j]], &s = out.nodes[q[(j + 1) % 4]];
        area2 += p.x() * s.y() - p.y() * s.x();
      }
      if (area2 < 0.0) std::reverse(q.begin() + 1, q.end());
      out.quads.push_back(q);
    }
  } catch (const NumericalError&) {
    throw;
  } catch (const std::exception& e) {
    throw NumericalError(std::string("the quad mesher (Gmsh) failed: ") + e.what() + " (" +
                         gmsh_last_error() + ")");
  } catch (...) {
    throw NumericalError("the quad mesher (Gmsh) failed: " + gmsh_last_error());
  }
  if (out.quads.empty()) throw NumericalError("the quad mesher (Gmsh) made no quadrilaterals");
  return out;
}

constexpr QuadMesherBackend kGmshBackend{&quad_mesh_here};

}  // namespace

const QuadMesherBackend& quad_mesher_backend() { return kGmshBackend; }

}  // namespace tspline::detail

extern "C" const tspline::detail::QuadMesherBackend* tspline_quad_mesher_backend() {
  return &tspline::detail::quad_mesher_backend();
}

#endif
