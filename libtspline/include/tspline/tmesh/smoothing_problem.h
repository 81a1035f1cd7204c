#pragma once
// The T-mesh optimization as a problem for libmeshopt (Brovka 2013 Sect. 4):
// every interior vertex of the T-mesh is a free node whose objective is the
// weighted K* distortion of its local submesh (the triangles of Sect. 4.2 with
// the weights of Eqs. 4-5, detail/tmesh_submesh.h); meshopt::smooth() then
// untangles and smooths the physical positions by Gauss-Seidel sweeps.
#include "meshopt/node_smoother.h"
#include "tspline/tmesh/tmesh.h"

namespace tspline {

/// All interior vertices (not on the boundary of [0,1]^2) as free nodes with
/// their local submeshes; boundary vertices stay fixed. `weighted` = false
/// gives the unweighted K* (all weights 1), for comparison.
meshopt::SmoothingProblem build_smoothing_problem(const TMesh& mesh, bool weighted = true);

}  // namespace tspline
