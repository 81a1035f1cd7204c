#pragma once
// The front half of the pipeline after the corners are chosen: the T-mesh
// adapted to the boundary, the Coons start, the nested K* optimization of the
// interior nodes and the repair of cells that stay inverted (paper section 3;
// parameterization.h runs it once per corner trial).
#include <cstddef>
#include <memory>

#include "tspline/boundary/boundary_map.h"
#include "tspline/pipeline/parameterization.h"

namespace tspline {

/// Sweeps of an intermediate nested stage at most (they only provide a start);
/// also where a final stage is looked at under stop_when_tangled.
inline constexpr int kIntermediateStageSweeps = 100;

/// The T-mesh, Coons start and optimized nodes for `boundary`; the stage
/// times go to the result's `times`, progress to `options.progress`.
/// \throw InputError if the domain needs more than `options.max_cells` cells.
/// \throw FrontTangled where options.stop_when_tangled is set and the T-mesh
/// is still tangled after its nested stages (before any repair round).
FrontResult optimize_front(BoundaryMap boundary, const ParameterizationOptions& options);

class FrontOptimizer;

/// optimize_front in two steps, for a caller that decides between them (the
/// corner trials of parameterization.cpp under stop_when_tangled): the
/// constructor builds the T-mesh and runs the nested stages; finish() runs
/// the repair rounds and gives the result, once. FrontRun(b, o).finish() is
/// optimize_front(b, o), bit for bit, without its stop_when_tangled check.
class FrontRun {
 public:
  FrontRun(BoundaryMap boundary, const ParameterizationOptions& options);
  FrontRun(FrontRun&&) noexcept;
  FrontRun& operator=(FrontRun&&) noexcept;
  ~FrontRun();
  /// Inverted cells of the optimized T-mesh, and its cells (before finish()).
  std::size_t inverted_cells() const;
  std::size_t cells() const;
  /// \throw InputError where a repair round would need more than max_cells cells.
  FrontResult finish();

 private:
  std::unique_ptr<FrontOptimizer> front_;
};

}  // namespace tspline
