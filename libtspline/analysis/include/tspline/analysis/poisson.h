#pragma once
// The IGA Poisson solver of tspline_analysis, all of it, for maps of 1 to n
// patches: the glued analysis space (analysis_space.h), the solver
// (poisson_solver.h), its residual estimator (poisson_estimator.h), the
// adaptive loop (poisson_adaptive.h) and the built-in manufactured problems
// (manufactured_problems.h).
#include "tspline/analysis/analysis_space.h"
#include "tspline/analysis/manufactured_problems.h"
#include "tspline/analysis/poisson_adaptive.h"
#include "tspline/analysis/poisson_estimator.h"
#include "tspline/analysis/poisson_solver.h"
