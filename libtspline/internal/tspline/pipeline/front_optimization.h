#pragma once
// The front half of the pipeline after the corners are chosen: the T-mesh
// adapted to the boundary, the Coons start, the nested K* optimization of the
// interior nodes and the repair of cells that stay inverted (paper section 3;
// parameterization.h runs it once per corner trial).
#include "tspline/boundary/boundary_map.h"
#include "tspline/pipeline/parameterization.h"

namespace tspline {

/// The T-mesh, Coons start and optimized nodes for `boundary`; the stage
/// times go to the result's `times`, progress to `options.progress`.
/// \throw InputError if the domain needs more than `options.max_cells` cells.
FrontResult optimize_front(BoundaryMap boundary, const ParameterizationOptions& options);

}  // namespace tspline
