#pragma once
// Bezier extraction export (`tspline export --bezier`): the T-spline map as
// rational Bezier elements with their extraction operators, the interchange
// form of T-spline IGA in finite element codes (Scott, Borden, Verhoosel,
// Sederberg, Hughes, IJNME 2011). Format: docs/bezier_format.md.
#include <nlohmann/json.hpp>
#include <string>

#include "tspline/spline/tspline_map.h"

namespace tspline::io {

/// The document described in docs/bezier_format.md.
nlohmann::json bezier_document(const TSplineMap& map, const std::string& source);

}  // namespace tspline::io
