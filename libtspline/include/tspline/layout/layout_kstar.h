#pragma once
// The first untangling of a quad layout's inner nodes, by libmeshopt's
// weighted K* smoothing (Brovka et al. 2014, Eqs. 3-5) with the ring nodes
// fixed. Per quad (x, n1, o, n2) around an inner node x of valence k, the
// three corner triangles that contain x, each with the ideal shape of the
// rhombus with angle 2 pi / k at x (a square where k = 4); and where a cut
// joins x to a ring node b, the two triangles (b, b+, x) and (b, x, b-), b+-
// the points of the ring at arc length +- |x - b| / 5 from b, ideal with a
// right angle at b, so that cuts leave the coast at right angles. The
// regularized objective of a tangled start can shrink quads to a point: where
// a quad has lost more than 99 % of its shortest edge, its nodes go back.
#include "meshopt/node_smoother.h"
#include "tspline/layout/layout_mesh.h"

namespace tspline {

meshopt::SmoothingReport smooth_layout_kstar(LayoutMesh& m, const LayoutRings& rings);

}  // namespace tspline
