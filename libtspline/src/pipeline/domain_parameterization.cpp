#include "tspline/pipeline/domain_parameterization.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <functional>
#include <future>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <vector>

#include "tspline/boundary/domain.h"
#include "tspline/detail/enum_names.h"
#include "tspline/errors.h"
#include "tspline/layout/quad_mesher.h"
#include "tspline/multipatch/automatic_cuts.h"
#include "tspline/validity/corner_quality.h"
#include "tspline/validity/map_energy.h"

namespace tspline {

namespace {

constexpr std::array<detail::EnumName<LayoutMode>, 3> kLayoutModeNames{
    {{LayoutMode::Auto, "auto"}, {LayoutMode::Single, "single"}, {LayoutMode::Quad, "quad"}}};

// The domain's rings cleaned and validated with the run's boundary tolerance
// (needles narrower than its width removed, ParameterizationOptions::
// needle_width): a layout's patches are cut from these rings and not cleaned
// again. `notes`: whether its notes are reported (not where a single-patch
// try of the same ring reports its own).
Domain cleaned_domain(const Domain& input, const ParameterizationOptions& options, bool notes) {
  DomainCleaningOptions how;
  how.needle_width = run_needle_width(input.outer, options);
  std::vector<std::string> said;
  if (notes) how.notes = &said;
  Domain d = validate_domain(input, how);
  for (const std::string& note : said)
    report_step(options.progress, "cleaning", "note: " + note, -1, ProgressEvent::Kind::Note);
  return d;
}

}  // namespace

LayoutMode parse_layout_mode(const std::string& name) {
  if (const std::optional<LayoutMode> mode = detail::enum_value(kLayoutModeNames, name)) return *mode;
  throw InputError("layout '" + name + "' is not one of auto, single, quad");
}

const char* layout_mode_name(LayoutMode mode) { return detail::enum_name(kLayoutModeNames, mode, "auto"); }

namespace {

// Callbacks of a run made ahead of a decision: held, in order, until the run
// is kept (release: replayed, then passed straight on), dropped with it.
class HeldEvents {
 public:
  void pass(std::function<void()> f) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (open_) f();
    else held_.push_back(std::move(f));
  }
  void release() {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
    for (const auto& f : held_) f();
    held_.clear();
  }

 private:
  std::mutex mutex_;
  bool open_ = false;
  std::vector<std::function<void()>> held_;
};

// The figures auto decides by: the least over the adaptive loop's dense
// sample and the Gauss points (the report adds certified lower bounds).
std::string figures(const DenseMapQuality& q) {
  std::ostringstream s;
  s.precision(3);
  s << "scaled Jacobian " << q.min_scaled << ", J_r " << q.min_mean_ratio << " sampled";
  return s.str();
}

// A multi-patch map's whole-map figures (dense samples): the least over its patches.
DenseMapQuality dense_figures(const MultiPatchResult& R) {
  DenseMapQuality q;
  q.min_scaled = R.min_scaled_jacobian_dense();
  q.min_mean_ratio = R.min_mean_ratio_dense();
  return q;
}

// Why one patch with these corner figures (corner_quality.h) cannot reach
// `good`, or "" where its corners allow it. The margin: J at a corner is the
// boundary's, which the later rounds' transfers reproduce up to round-off.
std::string corners_rule_out(const BoundaryCornerMinima& m, const QualityFloor& good) {
  constexpr double margin = 1e-9;
  auto at = [](std::ostringstream& s, const BoundaryCornerQuality& q) {
    s << "its corner at (" << q.at.x() << ", " << q.at.y() << "), where the boundary curves meet at ";
    s.precision(3);
    s << q.angle_degrees << " degrees, fixes ";
  };
  std::ostringstream s;
  if (m.scaled.scaled_jacobian < good.scaled_jacobian - margin) {
    at(s, m.scaled);
    s << "the scaled Jacobian at " << m.scaled.scaled_jacobian << ", below " << good.scaled_jacobian;
  } else if (m.mean_ratio.mean_ratio < good.mean_ratio - margin) {
    at(s, m.mean_ratio);
    s << "J_r at " << m.mean_ratio.mean_ratio << ", below " << good.mean_ratio;
  }
  return s.str();
}

// Why one patch is not a quick try where its interpolating map, boundary
// frozen, folds (det J <= 0) at more than c.first_try_max_folded of the
// untangling's samples (map_energy.h), or "".
std::string folds_rule_out(const TSplineMap& map, const MapEnergyOptions& energy_options,
                           const DomainParameterizationOptions& c) {
  const MapEnergy energy(map, energy_options);
  const SampleStats s = energy.stats(energy.variables(map).data());
  if (s.points == 0) return "";
  const double folded = static_cast<double>(s.nonpositive) / static_cast<double>(s.points);
  if (!(folded > c.first_try_max_folded)) return "";
  std::ostringstream out;
  out.precision(3);
  out << "its interpolating map folds (det J <= 0) at " << 100.0 * folded << " % of the untangling's "
      << s.points << " samples, more than " << 100.0 * c.first_try_max_folded
      << " %: not a quick try (such maps untangle to poor maps)";
  return out.str();
}

// The worse of the two figures: how maps that are not both good are ranked.
double worse_figure(const DenseMapQuality& q) { return std::min(q.min_scaled, q.min_mean_ratio); }

}  // namespace

bool reaches_good_quality(const DenseMapQuality& q, const DomainParameterizationOptions& c) {
  return c.good.met_by(q);
}

bool keep_layout_over_single(const DenseMapQuality& layout, const DenseMapQuality& single, bool single_certified,
                             const DomainParameterizationOptions& c) {
  return !single_certified || reaches_good_quality(layout, c) || worse_figure(layout) >= worse_figure(single);
}

DomainParameterization parameterize_domain(const Domain& input, const ParameterizationOptions& options,
                                           const AdaptiveOptions& adaptive, const DomainParameterizationOptions& c,
                                           const IterationCallback& on_iteration, const PatchCallback& on_patch) {
  // The options before any work (a layout takes seconds before its first
  // patch would check them). The levels only as far as a patch's initial
  // level is not yet known (a quad layout's patches start at 2 unless given):
  // each run checks its own.
  {
    ParameterizationOptions check = options;
    check.initial_level = std::min(check.initial_level, std::max(1, check.max_level));
    validate_options(check);
    validate_options(adaptive);
  }
  if (c.first_try_rounds < 0) throw InputError("the first try's adaptive rounds must be >= 0");
  if (!(c.first_try_max_folded >= 0.0 && c.first_try_max_folded <= 1.0))
    throw InputError("the first try's largest folded fraction must be in [0, 1]");
  // One ring goes to run_parameterization as it is (it validates and cleans it
  // itself, with the run's tolerance, and reports the notes); rings with holes
  // are validated here.
  const bool holes = !input.holes.empty();
  const Domain domain =
      holes || c.cuts || c.layout == LayoutMode::Quad ? cleaned_domain(input, options, true) : input;
  DomainParameterization out;
  // The layouts of this domain share a memo (a second layout from the same
  // ring nodes takes the first's mesh and first optimization pass).
  QuadLayoutOptions layout_options = c.quad;
  if (!layout_options.memo) layout_options.memo = make_quad_layout_memo();
  if (c.cuts) {
    if (c.layout == LayoutMode::Single) throw InputError("cuts make a layout of several patches: not with layout single");
    out.layout = "cuts";
    out.reason = "the cuts were given";
    out.patches.emplace(run_multipatch_parameterization(domain, build_patch_layout(domain, *c.cuts), "given", options,
                                                        adaptive, c.multi, on_patch));
    return out;
  }
  if (c.layout == LayoutMode::Single && holes)
    throw InputError("a domain with holes cannot be one patch: use layout auto or quad (or give cuts)");
  if (c.layout == LayoutMode::Single) {
    out.layout = "single";
    out.reason = "layout single was asked for";
    out.single.emplace(run_parameterization(domain.outer, options, adaptive, on_iteration));
    return out;
  }
  // The layout of a domain without holes under auto, built on a thread of its
  // own while the single patch is tried (below), so that the two share the
  // cores; cancelled where one patch is kept.
  struct LayoutAhead {
    Domain valid;
    QuadLayout layout;
    std::string explanation;                 ///< the layout's, before its patches took it
    std::optional<MultiPatchResult> patches;  ///< run ahead of the decision, if the layout was first
    std::string stopped;  ///< why its patches' run was stopped (first_layout_multi), if it was
  };
  // The layout's progress and the single patch's, from two threads, one at a time.
  std::mutex progress_mutex;
  ParameterizationOptions serial = options;
  if (options.progress)
    serial.progress = [&progress_mutex, cb = options.progress](const ProgressEvent& e) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      cb(e);
    };
  auto layout_progress = [cb = serial.progress](const std::string& prefix) {
    return cb ? std::function<void(const std::string&)>(
                    [cb, prefix](const std::string& text) { report_step(cb, "layout", prefix + text); })
              : std::function<void(const std::string&)>();
  };
  // The patches' own options (run_quad's, or the run ahead's).
  ParameterizationOptions patch_options = options;
  if (c.patch_initial_level) patch_options.initial_level = *c.patch_initial_level;
  // What the patches run ahead report is held back until their run is kept
  // (declared before `ahead`: destroyed after the run ahead is waited for).
  HeldEvents held;
  std::atomic<bool> cancel{false};  // the run ahead's: set where it is not wanted
  std::future<LayoutAhead> ahead;
  auto good_patches = [&](const MultiPatchResult& R) {
    return (!adaptive.certify || R.certified_valid()) && reaches_good_quality(dense_figures(R), c);
  };
  auto patch_figures = [](const MultiPatchResult& R) { return figures(dense_figures(R)); };
  // The first layout's patches stop at the first patch that is certified but
  // below the thresholds where another layout will be tried: that layout's map
  // cannot be good (its figures are the least over its patches), and the rest
  // of its patches would only be needed if the other layout does no better
  // (then they are run after all; retry_with_another_layout).
  const bool retry_possible = c.retry_size_factor > 0.0 && c.retry_size_factor != 1.0;
  MultiPatchOptions first_layout_multi = c.multi;
  if (retry_possible)
    first_layout_multi.stop_when = [&c, &adaptive](std::size_t, const ParameterizationResult& r) {
      if ((adaptive.certify && !r.certified_valid()) || reaches_good_quality(r.dense_quality, c))
        return std::string();
      return "is certified but below the thresholds (" + figures(r.dense_quality) + ")";
    };
  // A certified map of a quad layout below the thresholds: one more layout of
  // `valid`, kept where its map is certified and the worse of its two figures
  // is higher. Where the first gave flat ring corners sheets of quads, the
  // second pillows their rings instead (the same ring nodes); else its
  // patches are c.retry_size_factor times larger (another mesh of the domain,
  // whose worst corners fall elsewhere). `stopped`: why the first layout's
  // patches were stopped (first_layout_multi), its map not made; it is made
  // in full only if the second's map is not good, to compare the two.
  auto retry_with_another_layout = [&](const Domain& valid, const QuadLayout& first_layout,
                                       const std::string& first_explanation, const std::string& stopped) {
    const bool pillow = first_layout.stats.corner_sheets > 0;
    if (!retry_possible) return;
    if (stopped.empty() &&
        (good_patches(*out.patches) || (adaptive.certify && !out.patches->certified_valid())))
      return;
    std::ostringstream second;
    if (pillow)
      second << "a second quad layout with the rings of its flat corners pillowed instead of sheets through them";
    else
      second << "a second quad layout with patches " << c.retry_size_factor << " times larger";
    report_step(
        serial.progress, "layout",
        (stopped.empty()
             ? "the layout's map is certified but below the thresholds (" + patch_figures(*out.patches) + ")"
             : "the layout's " + stopped + ", so its map cannot be good; its other patches are not run") +
            ": " + second.str());
    // The first layout's map in full, where it was stopped (to compare, or to
    // keep where the second fails).
    std::string first_note;  // where the first was stopped: what became of its other patches
    if (!stopped.empty()) first_note = " (the layout's " + stopped + ": its other patches were not run)";
    auto make_first = [&] {
      if (out.patches) return;
      first_note = " (the layout's " + stopped + ": its other patches were run only to compare)";
      report_step(serial.progress, "layout", "the first quad layout's patches in full, to compare");
      out.patches.emplace(run_multipatch_parameterization(valid, first_layout.layout, first_explanation,
                                                          patch_options, adaptive, c.multi, on_patch));
    };
    std::string outcome;
    try {
      QuadLayoutOptions q = layout_options;
      if (pillow) {
        q.corner_sheets = false;
        q.start_ring_nodes = first_layout.ring_nodes;  // its repairs done already
      } else
        q.size.factor *= c.retry_size_factor;
      q.progress = layout_progress(pillow ? "quad layout, pillowed: " : "quad layout, larger patches: ");
      QuadLayout L = build_quad_layout(valid, q);
      const std::string explanation = L.explanation();
      report_step(serial.progress, "layout", explanation);
      MultiPatchResult R = run_multipatch_parameterization(valid, std::move(L.layout), explanation, patch_options,
                                                           adaptive, c.multi, on_patch);
      // Where the first was stopped, a good second map is kept at once (the
      // first's cannot be good); else the two are compared.
      const bool second_good = good_patches(R);
      if (!(stopped.size() && second_good)) make_first();
      const bool second_certified = !adaptive.certify || R.certified_valid();
      const bool first_certified = out.patches && (!adaptive.certify || out.patches->certified_valid());
      if (second_certified && (!out.patches || !first_certified ||
                               worse_figure(dense_figures(R)) > worse_figure(dense_figures(*out.patches)))) {
        outcome = second.str() + (second_good ? " gave a good map (" : " gave a better map (") +
                  patch_figures(R) + "): kept";
        out.patches.emplace(std::move(R));
        out.quad_stats = L.stats;
      } else {
        outcome = second.str() + " gave no better certified map (" + patch_figures(R) + "): the first kept";
      }
    } catch (const NumericalError& e) {
      outcome = second.str() + " failed (" + e.what() + "): the first kept";
      make_first();
    }
    report_step(serial.progress, "layout", outcome);
    out.reason += "; below the thresholds" + first_note + ", " + outcome;
  };
  auto run_quad = [&](const std::string& reason) {
    LayoutAhead a;
    if (ahead.valid()) {
      held.release();  // the run ahead is kept: what it reported so far, then as it goes
      a = ahead.get();
    } else {
      a.valid = holes || c.layout == LayoutMode::Quad ? domain : cleaned_domain(input, options, false);
      QuadLayoutOptions q = layout_options;
      q.progress = layout_progress("quad layout: ");
      a.layout = build_quad_layout(a.valid, q);
      a.explanation = a.layout.explanation();
    }
    if (!a.patches && a.stopped.empty())
      report_step(serial.progress, "layout", a.explanation);  // (else the run ahead did)
    out.layout = "quad";
    out.reason = reason;
    out.quad_stats = a.layout.stats;
    if (a.patches) {
      out.patches.emplace(std::move(*a.patches));
    } else if (a.stopped.empty()) {
      try {
        out.patches.emplace(run_multipatch_parameterization(
            a.valid, a.layout.layout, a.explanation, patch_options, adaptive, first_layout_multi, on_patch));
      } catch (const MultiPatchStopped& e) {
        a.stopped = e.what();
      }
    }
    retry_with_another_layout(a.valid, a.layout, a.explanation, a.stopped);
  };
  if (c.layout == LayoutMode::Quad) {
    run_quad("layout quad was asked for");
    return out;
  }
  // Auto.
  if (holes) {
    // A few holes: the automatic cuts first (few, large patches), kept where good.
    std::string why = "the domain has holes";
    std::optional<MultiPatchResult> by_cuts;  // kept in case the quad layout does worse
    if (domain.holes.size() <= static_cast<std::size_t>(c.first_try_max_holes) && quad_mesher_available()) {
      bool cuts_found = false;
      try {
        AutomaticCuts a = automatic_cuts(domain);
        cuts_found = true;
        MultiPatchResult R = run_multipatch_parameterization(domain, build_patch_layout(domain, std::move(a.cuts)),
                                                             "automatic: " + a.explanation, options, adaptive,
                                                             c.multi, on_patch);
        const std::string q = patch_figures(R);
        if (good_patches(R)) {
          out.layout = "automatic cuts";
          out.reason = "the automatic cuts between the holes are certified and good over the whole map (" + q + ")";
          out.patches.emplace(std::move(R));
          return out;
        }
        why = "the automatic cuts between the holes are certified but poor, or not certified (" + q + ")";
        if (!adaptive.certify || R.certified_valid()) by_cuts.emplace(std::move(R));
      } catch (const InputError& e) {
        why = std::string(
                  cuts_found
                      ? "the domain has holes, and the automatic cuts make a patch that cannot be mapped ("
                      : "the domain has holes, and no automatic cuts were found (") +
              e.what() + ")";
      }
      report_step(serial.progress, "layout", why + ": building a quad layout");
    }
    if (quad_mesher_available()) {
      if (!by_cuts) {
        run_quad(why);
        return out;
      }
      // The certified automatic cuts stay where the quad layout fails or is not certified.
      std::string fallback;
      try {
        run_quad(why);
        if (!adaptive.certify || out.patches->certified_valid()) return out;
        fallback = "the quad layout's map is not certified on every patch";
      } catch (const NumericalError& e) {
        fallback = std::string("no quad layout (") + e.what() + ")";
      }
      report_step(serial.progress, "layout", fallback + ": keeping the automatic cuts");
      out.quad_stats.reset();
      out.layout = "automatic cuts";
      out.reason = why + "; " + fallback + ", so the certified automatic cuts are kept";
      out.patches.emplace(std::move(*by_cuts));
      return out;
    }
    AutomaticCuts a = automatic_cuts(domain);
    out.layout = "automatic cuts";
    out.reason = "the domain has holes, and this build has no quad mesher";
    out.patches.emplace(run_multipatch_parameterization(domain, build_patch_layout(domain, std::move(a.cuts)),
                                                        "automatic: " + a.explanation, options, adaptive, c.multi,
                                                        on_patch));
    return out;
  }
  // Declared after `ahead`, so destroyed before it: whatever way this function
  // leaves, the layout (and its patches) still running are told to stop before
  // they are waited for; the flag itself outlives the wait.
  struct CancelOnExit {
    std::atomic<bool>& flag;
    ~CancelOnExit() { flag = true; }
  } cancel_on_exit{cancel};
  if (quad_mesher_available()) {
    QuadLayoutOptions q = layout_options;
    q.cancel = &cancel;
    q.progress = layout_progress("quad layout (built while one patch is tried): ");
    // Once the layout is built, its patches are run at once, while the single
    // patch may still be tried: kept if one patch is not (their progress held
    // back until then), cancelled if it is. Their result does not depend on
    // when they run. (Measured: 0.5 s less on coastlines whose layout is done
    // before the single patch's try, 0.3 s more where one patch is kept and
    // its try shares the cores; neither a nice-19 run ahead, which would
    // starve on a loaded machine, nor one limited to one thread did better.)
    MultiPatchOptions ahead_multi = first_layout_multi;
    ahead_multi.cancel = &cancel;
    ParameterizationOptions ahead_options = patch_options;
    if (serial.progress)
      ahead_options.progress = [&held, cb = serial.progress](const ProgressEvent& e) {
        held.pass([cb, e] { cb(e); });
      };
    PatchCallback ahead_on_patch;
    if (on_patch)
      ahead_on_patch = [&held, on_patch](std::size_t p, int round) { held.pass([on_patch, p, round] { on_patch(p, round); }); };
    ahead = std::async(std::launch::async, [&input, q, &adaptive, ahead_multi, ahead_options, ahead_on_patch] {
      LayoutAhead a;
      a.valid = cleaned_domain(input, ahead_options, false);
      a.layout = build_quad_layout(a.valid, q);
      a.explanation = a.layout.explanation();
      report_step(ahead_options.progress, "layout", a.explanation);
      try {
        a.patches.emplace(run_multipatch_parameterization(
            a.valid, a.layout.layout, a.explanation, ahead_options, adaptive, ahead_multi, ahead_on_patch));
      } catch (const MultiPatchStopped& e) {
        a.stopped = e.what();
      }
      return a;
    });
  }
  auto drop_layout = [&] {
    if (!ahead.valid()) return;
    cancel = true;
    try {
      ahead.get();
    } catch (...) {  // cancelled, or failed: not wanted either way
    }
  };
  AdaptiveOptions first = adaptive;
  first.max_adapt = std::min(adaptive.max_adapt, c.first_try_rounds);
  // No polish where it cannot make the try good (AdaptiveOptions::polish_skip):
  // a try whose polish is skipped is poor, so no kept map lacks its polish.
  QualityFloor& skip = first.polish_skip;
  skip.scaled_jacobian = std::max(skip.scaled_jacobian, 0.5 * c.good.scaled_jacobian);
  skip.mean_ratio = std::max(skip.mean_ratio, 0.25 * c.good.mean_ratio);
  // A try whose corners already rule out the thresholds stops once its
  // boundary is frozen, before its untangling: J at the corners of the square
  // is the boundary's, and the whole-map minima cannot exceed it
  // (corner_quality.h; a corner on a nearly straight coast caps the scaled
  // Jacobian at the sine of its angle). Its figures are needed only where the
  // layout is neither good nor at least as good as those corners: the try is
  // then run again without the stop, so that every choice is the one the
  // whole try would give.
  // It also stops there where its interpolating map folds at more than
  // c.first_try_max_folded of the untangling's samples (not a quick try; such
  // maps untangled to poor maps on every coastline measured): then only a good
  // layout is kept over it, else the try runs again in full as above.
  // Before all that, a try whose T-mesh (optimized without repair rounds) is
  // still tangled stops at its front half (c.first_try_stop_when_tangled),
  // with the same consequences as a stop for folds.
  std::optional<BoundaryCornerMinima> corners;
  bool stopped_not_quick = false;  // for its folds, or its tangled T-mesh
  ParameterizationOptions try_options = serial;
  if (quad_mesher_available()) {  // (else one patch is all there is)
    first.stop_when_boundary_frozen = [&c, &corners, &adaptive, &stopped_not_quick](const TSplineMap& map) {
      corners = boundary_corner_minima(map);
      std::string why = corners_rule_out(*corners, c.good);
      if (why.empty() && c.first_try_max_folded > 0.0) {
        why = folds_rule_out(map, adaptive.untangling.energy, c);
        stopped_not_quick = !why.empty();
      }
      return why;
    };
    try_options.stop_when_tangled = c.first_try_stop_when_tangled;
  }
  std::optional<ParameterizationResult> single;
  std::string stopped;
  try {
    single.emplace(run_parameterization(domain.outer, try_options, first, on_iteration));
  } catch (const FrontTangled& e) {
    stopped = std::string(e.what()) + ": not a quick try (it would need repair rounds)";
    stopped_not_quick = true;
  } catch (const ParameterizationStopped& e) {
    stopped = e.what();
  }
  DenseMapQuality q;
  bool certified = false, cut_short = false;
  auto assess = [&] {
    q = single->dense_quality;
    certified = !adaptive.certify || single->certified_valid();
    // A first try cut short by its round limit is run again in full, so that
    // auto gives what layout single gives wherever it keeps one patch.
    cut_short =
        first.max_adapt < adaptive.max_adapt && single->stop_reason.rfind("reached `max_adapt`", 0) == 0;
  };
  auto try_in_full = [&] {
    if (single) return;
    AdaptiveOptions again = first;
    again.stop_when_boundary_frozen = nullptr;
    report_step(serial.progress, "layout", "one patch tried again to the end, to compare");
    single.emplace(run_parameterization(domain.outer, serial, again, on_iteration));
    assess();
  };
  if (single) {
    assess();
    const bool good = certified && single->map && reaches_good_quality(q, c);
    if (good) drop_layout();
    if ((good || !quad_mesher_available()) && cut_short)
      single = run_parameterization(domain.outer, options, adaptive, on_iteration);
    if (good || !quad_mesher_available()) {
      out.layout = "single";
      out.reason = good ? "one patch is certified and good over the whole map (" + figures(q) + ")"
                        : "this build has no quad mesher";
      out.single.emplace(std::move(*single));
      return out;
    }
  }
  std::string why =
      !single      ? (stopped_not_quick ? "one patch is stopped: " : "one patch cannot be good: ") + stopped
      : !certified ? std::string("one patch is not certified after ") + std::to_string(first.max_adapt) +
                         " adaptive rounds"
                   : "one patch is certified but poor over the whole map (" + figures(q) + ")";
  report_step(serial.progress, "layout", why + ": building a quad layout");
  try {
    run_quad(why);
    if (!adaptive.certify || out.patches->certified_valid()) {
      const DenseMapQuality lq = dense_figures(*out.patches);
      // The stopped try's figures are at most its corners': a layout kept over
      // those is kept over the try.
      DenseMapQuality at_corners;
      if (corners) {
        at_corners.min_scaled = corners->scaled.scaled_jacobian;
        at_corners.min_mean_ratio = corners->mean_ratio.mean_ratio;
      }
      // A try stopped for its folds or its tangled T-mesh: a good layout is kept over it.
      if (!single && (stopped_not_quick ? reaches_good_quality(lq, c)
                                        : keep_layout_over_single(lq, at_corners, true, c))) {
        out.single_corners = corners;
        out.single_stopped = stopped;
        return out;
      }
      try_in_full();
      if (keep_layout_over_single(lq, q, certified, c)) {
        out.rejected_single = q;
        return out;
      }
      why = "the quad layout's map is certified but poorer than one patch (" + figures(lq) + "); one patch instead";
    } else {
      why = "the quad layout's map is not certified on every patch; one patch instead";
    }
  } catch (const NumericalError& e) {
    why = std::string("no quad layout (") + e.what() + "); one patch instead";
  }
  // The quad layout failed or did worse: the single patch, with every adaptive
  // round it may take (what layout single gives).
  report_step(serial.progress, "layout", why);
  try_in_full();
  out.patches.reset();
  out.quad_stats.reset();
  out.layout = "single";
  out.reason = why;
  if (cut_short) single = run_parameterization(domain.outer, options, adaptive, on_iteration);
  out.single.emplace(std::move(*single));
  return out;
}

}  // namespace tspline
