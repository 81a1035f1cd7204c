#pragma once
// The convergence plot of `tspline poisson` (convergence.png): the L2 and H1
// errors and the estimator eta against the number of DOFs on log-log axes,
// with the reference slopes of cubic elements in 2D (L2 ~ N^-2, H1 and
// eta ~ N^-3/2), drawn with Cairo (canvas.h); PNG, SVG or PDF by extension.
#include <string>
#include <vector>

#include "tspline/analysis/poisson.h"

namespace tspline::io {

/// Writes the plot of `steps` atomically (errors only where the steps have
/// them; steps with a non-positive value are left out of that curve).
/// \throw IoError if it cannot be written; InputError for a bad extension or size.
void write_convergence_plot(const std::string& path, const std::vector<PoissonStep>& steps, int width = 800,
                            int height = 600);

}  // namespace tspline::io
