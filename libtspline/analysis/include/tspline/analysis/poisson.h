#pragma once
// The IGA Poisson solver of tspline_analysis, all of it: the solver
// (poisson_solver.h), its residual estimator (poisson_estimator.h) and the
// adaptive loop (poisson_adaptive.h).
#include "tspline/analysis/poisson_adaptive.h"
#include "tspline/analysis/poisson_estimator.h"
#include "tspline/analysis/poisson_solver.h"
