#pragma once
// OpenCASCADE models built with Gmsh and a parametric tangle of their meshes,
// shared by the meshopt tests and the CAD benchmarks (bench/ includes it).
// \pre for all: a meshopt::gmsh_io::Session is alive.
#include <gmsh.h>

#include <cstddef>
#include <random>
#include <vector>

namespace cad_fixtures {

/// Fuses the two volumes of tags 1 and 2 of the current OCC model and synchronizes.
inline void fuse_volumes_1_2() {
  gmsh::vectorpair out;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::fuse({{3, 1}}, {{3, 2}}, out, map);
  gmsh::model::occ::synchronize();
}

/// A cylinder (r 0.5, height 2) fused with a sphere (r 0.8) centred on its top.
inline void add_cylinder_sphere() {
  gmsh::model::add("cylinder_sphere");
  gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, 2, 0.5, 1);
  gmsh::model::occ::addSphere(0, 0, 2, 0.8, 2);
  fuse_volumes_1_2();
}

/// A torus (R 2, r 0.6) fused with a pipe (a cylinder of radius 0.3 through its
/// tube): curved faces, trimmed faces, sharp intersection curves.
inline void add_torus_pipe() {
  gmsh::model::add("torus_pipe");
  gmsh::model::occ::addTorus(0, 0, 0, 2.0, 0.6, 1);
  gmsh::model::occ::addCylinder(2.0, 0, -1.5, 0, 0, 3.0, 0.3, 2);
  fuse_volumes_1_2();
}

/// Moves every `stride`-th node inside each surface by a random parametric
/// offset of up to `amount` times the face's parametric extent, keeping it inside
/// the (trimmed) face and the node's position on the surface.
inline void tangle(int stride, double amount, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  gmsh::vectorpair faces;
  gmsh::model::getEntities(faces, 2);
  for (const auto& [dim, tag] : faces) {
    std::vector<double> lo, hi;
    gmsh::model::getParametrizationBounds(2, tag, lo, hi);
    std::vector<std::size_t> tags;
    std::vector<double> xyz, uv;
    gmsh::model::mesh::getNodes(tags, xyz, uv, 2, tag, false, true);
    for (std::size_t i = 0; i < tags.size(); i += stride)
      for (int attempt = 0; attempt < 20; ++attempt) {
        const std::vector<double> p{uv[2 * i] + amount * (hi[0] - lo[0]) * U(rng),
                                    uv[2 * i + 1] + amount * (hi[1] - lo[1]) * U(rng)};
        if (p[0] <= lo[0] || p[0] >= hi[0] || p[1] <= lo[1] || p[1] >= hi[1]) continue;
        if (gmsh::model::isInside(2, tag, p) == 0) continue;
        std::vector<double> x;
        gmsh::model::getValue(2, tag, p, x);
        gmsh::model::mesh::setNode(tags[i], x, p);
        break;
      }
  }
}

}  // namespace cad_fixtures
