#pragma once
// The check of a map of any number of patches (`tspline check`, Python's
// Map.check): per patch the certificate of det J > 0 on every Bezier element
// (map_certification.h), the certified lower bounds of J_r and the scaled
// Jacobian with their dense sample (map_quality_bounds.h), the 9 x 9 dense and
// 4 x 4 Gauss samples (map_quality.h) and the worst corner the boundary fixes
// (corner_quality.h); over the whole map the minima of all of them, and the
// largest gap between the two images of an interface. Each patch's Bezier
// extraction is made once for all its figures; the patches are checked in
// parallel (a single patch: its elements), and the figures do not depend on
// the number of threads.
#include <optional>
#include <vector>

#include "tspline/multipatch/patch_layout.h"
#include "tspline/spline/tspline_map.h"
#include "tspline/validity/corner_quality.h"
#include "tspline/validity/map_certification.h"
#include "tspline/validity/map_quality.h"
#include "tspline/validity/map_quality_bounds.h"

namespace tspline {

struct PatchCheck {
  std::size_t cells = 0;
  MapCertification certification;
  MapQualityBounds quality;  ///< certified bounds of J_r and SJ over the patch, and their dense sample
  DenseMapQuality dense;     ///< J_r on (dense_samples + 1)^2 points per element
  MapQualityStats gauss;     ///< J_r at gauss x gauss points per cell
  std::optional<BoundaryCornerQuality> corner;  ///< the worst corner of the patch's square
};

struct MapCheckOptions {
  CertificationOptions certification;
  QualityBoundOptions quality;  ///< as the report's (io::report_quality_bound_options) unless changed
  int dense_samples = 8;        ///< (k + 1)^2 points per element of `dense`
  int gauss = 4;
};

struct MapCheck {
  std::vector<PatchCheck> patches;
  /// Over every patch (map_quality_bounds.h, several maps): element indices
  /// count through the patches in order.
  MapQualityBounds quality;
  std::size_t cells = 0, elements = 0, certified = 0, invalid = 0, undecided = 0;
  std::size_t certified_patches = 0;
  int max_depth_used = 0;
  double min_relative_det_lower_bound = 0.0;  ///< over the patches (-inf if one has mean det J <= 0)
  double min_det_lower_bound = 0.0;
  double min_dense_mean_ratio = 1.0, min_gauss_mean_ratio = 1.0;
  std::optional<BoundaryCornerQuality> corner;  ///< the worst over the patches
  std::size_t corner_patch = 0;
  double max_interface_gap = 0.0;  ///< 0 without interfaces
  bool certified_valid() const { return !patches.empty() && certified_patches == patches.size(); }
};

/// \throw InputError for options out of range.
MapCheck check_map(const std::vector<const TSplineMap*>& patches, const std::vector<Interface>& interfaces = {},
                   const MapCheckOptions& options = {});

}  // namespace tspline
