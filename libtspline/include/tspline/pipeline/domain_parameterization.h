#pragma once
// The parameterization of any domain, with the choice of its layout:
//   single: one patch, the whole domain mapped onto the unit square
//           (run_parameterization; domains without holes only);
//   quad:   an automatic quad layout (layout/quad_layout.h), every patch a
//           map of its own, interfaces conforming (run_multipatch_parameterization);
//   cuts:   the layout given by cuts (patch_layout.h);
//   auto:   one patch where a first try (at most 3 adaptive rounds) is
//           certified and good over the whole map (scaled Jacobian >= 0.3
//           and J_r >= 0.1 over the dense sample), the quad layout otherwise;
//           for domains with holes the quad layout, unless they have at most
//           4 holes and the automatic cuts are certified and good by the same
//           measure. Where the quad layout fails (NumericalError) or its map is
//           not certified, auto keeps the single patch (run in full) or the
//           certified automatic cuts. Without a quad mesher in the
//           build, domains with holes fall back to the automatic cuts
//           (automatic_cuts.h) and domains without keep the single patch.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/layout/quad_layout.h"
#include "tspline/multipatch/multipatch_parameterization.h"
#include "tspline/pipeline/adaptive_parameterization.h"
#include "tspline/validity/corner_quality.h"

namespace tspline {

enum class LayoutMode { Auto, Single, Quad };

/// "auto", "single", "quad"; InputError naming the choices otherwise.
LayoutMode parse_layout_mode(const std::string& name);
const char* layout_mode_name(LayoutMode mode);

struct DomainParameterizationOptions {
  LayoutMode layout = LayoutMode::Auto;
  /// Given cuts (then `layout` must be Auto or Quad; the cuts are the layout).
  std::optional<std::vector<Cut>> cuts;
  QuadLayoutOptions quad;
  MultiPatchOptions multi;
  /// Auto: a single patch is kept when its whole map reaches both.
  QualityFloor good{0.3, 0.1};
  /// Auto: adaptive rounds of the single-patch first try at most.
  int first_try_rounds = 3;
  /// Auto: the single-patch try also stops once its boundary is frozen
  /// (before its untangling) where its interpolating map folds (det J <= 0)
  /// at more than this fraction of the untangling's samples: it is not a
  /// quick try, and the map it would untangle to is poor. Measured on the 13
  /// shared coastlines, the 8 polygons and 60 rotated, mirrored, rescaled and
  /// reversed copies of the coastlines: every try kept as one patch folded at
  /// 0.28 % of its samples or fewer (Trinidad 0.13 %, the gear 0.28 %); the
  /// tries folded at 1 % or more (Bali 2.1 %, Hispaniola 2.5 %, Hokkaido
  /// 4.0 %, Newfoundland 9.3 %) all untangled to maps far below the
  /// thresholds. Only a good layout is kept over a try stopped so; where the
  /// layout's map is not good the try runs again in full and the choice is the
  /// whole try's. 0: never.
  double first_try_max_folded = 0.01;
  /// Auto: the single-patch try stops in its T-mesh optimization, before any
  /// repair round, where the T-mesh of every corner trial is still tangled
  /// after its nested stages, looked at 100 sweeps into the final one
  /// (ParameterizationOptions::stop_when_tangled): it is not a quick try. A
  /// try not stopped so is the whole try, bit for bit. As for
  /// first_try_max_folded, only a good layout is kept over a try stopped so;
  /// else the try runs again in full (with its repair rounds) and the choice
  /// is the whole try's. Measured on the 13 shared coastlines, the 8 polygons
  /// and 60 rotated, mirrored, rescaled and reversed copies of the
  /// coastlines: every try kept as one patch had a trial untangled there (the
  /// C-shape has one with 18 % of its cells inverted at the end beside three
  /// untangled: a rule on any one trial would lose it), and every try stopped
  /// so gave way to a good layout, the same as before (Newfoundland, Vancouver
  /// Island, Bali, ...). Newfoundland's try stops at 1.1 s instead of 6.6 s
  /// (16.1 -> 13.3 s in all).
  bool first_try_stop_when_tangled = true;
  /// Auto: domains with at most this many holes try the automatic cuts
  /// (automatic_cuts.h: few, large patches) first and keep them where good.
  int first_try_max_holes = 4;
  /// Auto and quad: where a quad layout's certified map misses the two
  /// thresholds above, one more layout with patches this many times larger
  /// (size field factor) is made, and its map kept where certified and better
  /// (the worse of the two figures). 1 (or 0): no second layout. (On rotated,
  /// mirrored and rescaled copies of the bundled coastlines and seas, 4 maps
  /// of 62 missed the scaled Jacobian 0.3; with patches 1.2 times larger all
  /// four reached it, with 0.85 times one.) Where the first layout gave flat
  /// ring corners sheets of quads (QuadLayoutOptions::corner_sheets), the
  /// second pillows their rings instead, from the first's ring nodes (any
  /// factor other than 1 or 0).
  double retry_size_factor = 1.2;
  /// Initial T-mesh level of the patches of a quad layout (they are small and
  /// nearly square; refinement adds what they need); unset: the options' own.
  std::optional<int> patch_initial_level = 2;
};

struct DomainParameterization {
  std::string layout;  ///< "single", "quad", "cuts" or "automatic cuts"
  std::string reason;  ///< why this layout, for the report
  std::optional<ParameterizationResult> single;
  std::optional<MultiPatchResult> patches;
  std::optional<QuadLayoutStats> quad_stats;
  /// The single-patch first try of `auto` that was not kept (whole-map figures), if any.
  std::optional<DenseMapQuality> rejected_single;
  /// Where auto's single-patch first try was stopped at its frozen boundary
  /// (because its corners rule out the thresholds and the layout kept is at
  /// least as good as those corners, or because its interpolating map folds
  /// widely and the layout kept is good): the corners with the least scaled
  /// Jacobian and the least J_r, upper bounds of what the whole try would reach.
  std::optional<BoundaryCornerMinima> single_corners;
  /// Why that try was stopped (its corners, or its interpolating map's folds:
  /// DomainParameterizationOptions::first_try_max_folded), where it was; also
  /// where it was stopped before its first fit for its tangled T-mesh
  /// (first_try_stop_when_tangled; then single_corners is unset).
  std::string single_stopped;
};

/// Whether whole-map figures (dense samples) reach auto's thresholds: scaled
/// Jacobian >= good.scaled_jacobian and J_r >= good.mean_ratio.
bool reaches_good_quality(const DenseMapQuality& q, const DomainParameterizationOptions& c);

/// Auto's choice once both a certified quad layout's map (`layout`) and the
/// single patch's first try (`single`, certified or not) exist: the layout is
/// kept where it reaches the thresholds (the single patch, which was tried
/// first, did not), where one patch is not certified, or where the worse of
/// its two figures is no lower than one patch's. One patch is kept only where
/// neither is good and it is better: a layout can split a sharp tip that one
/// patch keeps whole.
bool keep_layout_over_single(const DenseMapQuality& layout, const DenseMapQuality& single, bool single_certified,
                             const DomainParameterizationOptions& c);

/// \param on_iteration for the single-patch run (as run_parameterization's).
/// \throw InputError for invalid input or options; NumericalError as the runs.
DomainParameterization parameterize_domain(const Domain& domain, const ParameterizationOptions& options,
                                           const AdaptiveOptions& adaptive,
                                           const DomainParameterizationOptions& choice = {},
                                           const IterationCallback& on_iteration = {},
                                           const PatchCallback& on_patch = {});

}  // namespace tspline
