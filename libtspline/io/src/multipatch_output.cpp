#include "tspline/io/multipatch_output.h"

#include <array>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <initializer_list>
#include <iomanip>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "toolkit/errors.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/detail/shared_pieces.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/io/front_output.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/output_files.h"
#include "tspline/io/param_output.h"

namespace tspline::io {
namespace {

using json = nlohmann::json;

// The worst patch corner whose two sides lie on the domain's boundary (rings,
// not cuts: a corner on a cut could move with the layout).
std::optional<BoundaryCornerQuality> worst_domain_corner(const MultiPatchResult& R) {
  std::optional<BoundaryCornerQuality> worst;
  for (std::size_t p = 0; p < R.patches.size(); ++p) {
    if (!R.patches[p].map) continue;
    const std::array<int, 4>& cut = R.layout.patches[p].side_cut;
    std::array<bool, 4> on_rings{};
    for (int k = 0; k < 4; ++k) on_rings[k] = cut[(k + 3) % 4] < 0 && cut[k] < 0;
    auto c = worst_boundary_corner(*R.patches[p].map, on_rings);
    if (!c) continue;
    c->patch = p;
    if (!worst || c->scaled_jacobian < worst->scaled_jacobian) worst = c;
  }
  return worst;
}

// The patches' whole-map quality figures combined (combine_whole_map_quality_json).
json whole_map_of(const json& patch_reports) {
  std::vector<json> w;
  for (const json& p : patch_reports)  // one entry per patch (null without figures), so that indices are patches
    w.push_back(p.contains("jacobian") && p["jacobian"].contains("whole_map") ? p["jacobian"]["whole_map"] : json());
  return combine_whole_map_quality_json(w);
}

}  // namespace

toolkit::io::VtuMesh merge_patches(const std::vector<toolkit::io::VtuMesh>& parts) {
  return toolkit::io::merge_vtu(parts, "patch");
}

toolkit::io::VtuMesh merge_patches(std::vector<toolkit::io::VtuMesh>&& parts) {
  return toolkit::io::merge_vtu(std::move(parts), "patch");
}

json multipatch_report(const MultiPatchResult& R, const std::string& input_path, double seconds) {
  json rep;
  rep["input"] = input_path;
  rep["patches_count"] = R.patches.size();
  rep["cuts"] = {{"count", R.layout.cuts.size()}, {"choice", R.cuts_explanation}};
  std::size_t cells = 0, functions = 0, elements = 0, certified = 0;
  for (const auto& r : R.patches) {
    cells += r.map->mesh().num_cells();
    functions += r.map->basis().size();
    elements += r.certification.elements;
    certified += r.certification.certified;
  }
  // Each patch's report bounds its map's quality (certified_map_quality):
  // the patches on the pool's threads, handed out one at a time.
  std::vector<json> per_patch(R.patches.size());
  detail::parallel_items(R.patches.size(), detail::pool_threads(),
                         [&](std::size_t p) { per_patch[p] = param_report(R.patches[p], input_path); });
  json patches = json::array();
  for (json& p : per_patch) patches.push_back(std::move(p));
  json faces = json::array();
  for (std::size_t i = 0; i < R.interfaces.size(); ++i) {
    const Interface& f = R.layout.interfaces[i];
    faces.push_back({{"cut", f.cut},
                     {"patch_a", f.patch_a},
                     {"side_a", side_name(f.side_a)},
                     {"patch_b", f.patch_b},
                     {"side_b", side_name(f.side_b)},
                     {"max_gap", R.interfaces[i].max_gap},
                     {"knots_a", R.interfaces[i].knots_a},
                     {"knots_b", R.interfaces[i].knots_b},
                     {"same_knots", R.interfaces[i].same_knots}});
  }
  rep["totals"] = {{"cells", cells},
                   {"functions", functions},
                   {"bezier_elements", elements},
                   {"certified_elements", certified},
                   {"certified_valid", R.certified_valid()},
                   {"valid", R.valid()},
                   {"min_relative_det_lower_bound", R.min_relative_det_bound()},
                   {"min_mean_ratio_whole_map", R.min_mean_ratio_dense()},  // the adaptive loop's sample
                   {"min_scaled_jacobian_whole_map", R.min_scaled_jacobian_dense()},  // the same sample
                   {"whole_map", whole_map_of(patches)},  // certified bounds and 26 x 26 samples (param_output.h)
                   {"min_mean_ratio_gauss", R.min_mean_ratio_gauss()},
                   {"domain_area", R.domain_area},
                   {"map_area", R.map_area},
                   {"area_relative_error", std::abs(R.map_area - R.domain_area) / R.domain_area},
                   {"max_interface_gap", R.max_gap()},
                   {"max_interface_gap_relative", R.max_gap() / R.diameter},
                   {"interface_rounds", R.sync_rounds},
                   {"seconds", seconds}};
  // What a single-patch report has at its top level, over every patch, so
  // that a reader of report.json needs no case for multi-patch maps.
  if (const auto corner = worst_domain_corner(R))
    rep["totals"]["whole_map"]["boundary_corner"] = boundary_corner_json(*corner);
  rep["certified_valid"] = R.certified_valid();
  rep["valid"] = R.valid();
  rep["jacobian"]["min_mean_ratio_jacobian"] = R.min_mean_ratio_gauss();
  rep["jacobian"]["whole_map"] = rep["totals"]["whole_map"];
  rep["jacobian"]["whole_map"]["min_mean_ratio"] = R.min_mean_ratio_dense();
  rep["jacobian"]["whole_map"]["min_scaled"] = R.min_scaled_jacobian_dense();
  rep["jacobian"]["note"] = "over every patch (totals; per patch: patches[k].jacobian)";
  rep["interfaces"] = std::move(faces);
  rep["patches"] = std::move(patches);
  return rep;
}

void write_multipatch_outputs(const MultiPatchResult& R, const std::string& out_dir, const json& report,
                              int samples, toolkit::io::VtuCompression compression, std::size_t piece_cells) {
  const std::filesystem::path dir(out_dir);
  const std::size_t n = R.patches.size();
  std::vector<const TSplineMap*> maps(n);
  std::vector<TSplineFileMeta> metas(n);
  for (std::size_t p = 0; p < n; ++p) {
    const ParameterizationResult& r = R.patches[p];
    maps[p] = &*r.map;
    metas[p].source = report.value("input", "");
    metas[p].boundary = r.front.boundary.polygon();
    metas[p].corners = r.front.boundary.corners().index;
  }
  // Each VTU file written in pieces of whole patches, about piece_cells T-mesh
  // cells each (write_vtu_pieces: VTK asks for one piece after the other);
  // a piece's patches are made on the pool's threads, merged, written and
  // released before the next piece is made, so that a sea of 9,000 patches
  // never holds a whole file (it held the parts of surface.vtu and its VTK
  // grid at once: 0.7 GiB).
  using Part = std::function<toolkit::io::VtuMesh(std::size_t)>;
  // Files of one patch's own parts (the others are made from the Bezier
  // elements: SharedPieces).
  const std::vector<std::pair<std::string_view, Part>> files = {
      {output_files::kControlNet, [&](std::size_t p) { return control_net_vtu(*R.patches[p].map); }},
      {output_files::kBoundary, [&](std::size_t p) { return boundary_vtu(R.patches[p].front.boundary); }},
      {output_files::kParametricTMesh, [&](std::size_t p) {
         // The patches side by side in the parameter plane.
         const TMesh& mesh = R.patches[p].front.mesh;
         std::vector<Eigen::Vector2d> uv(mesh.num_vertices());
         for (int v = 0; v < static_cast<int>(uv.size()); ++v)
           uv[v] = mesh.vertex_param(v) + Eigen::Vector2d(1.25 * static_cast<double>(p), 0.0);
         return tmesh_vtu(mesh, uv);
       }}};
  const std::array<std::string_view, 3> shared_files = {output_files::kSurface, output_files::kBezierSurface,
                                                        output_files::kPhysicalTMesh};
  if (piece_cells < 1) throw toolkit::InputError("write_multipatch_outputs: piece_cells must be >= 1");
  std::vector<std::size_t> piece_begin = {0};  // patches [piece_begin[i], piece_begin[i + 1]) make piece i
  for (std::size_t p = 0, cells = 0; p < n; ++p) {
    cells += R.patches[p].map->mesh().num_cells();
    if (cells >= piece_cells && p + 1 < n) piece_begin.push_back(p + 1), cells = 0;
  }
  piece_begin.push_back(n);
  const int pieces = static_cast<int>(piece_begin.size() - 1);
  // The patches [first, first + parts.size()) of piece i as one mesh, patch
  // ids counted from the first patch of the layout. (Written from the parts:
  // their merged copy took 0.2 s of Newfoundland's CPU.)
  auto merged = [&](int i, std::vector<toolkit::io::VtuMesh>&& parts) {
    return toolkit::io::VtuParts{std::move(parts), "patch",
                                 static_cast<int>(piece_begin[static_cast<std::size_t>(i)])};
  };
  auto patches_of = [&](int i) {
    return piece_begin[static_cast<std::size_t>(i) + 1] - piece_begin[static_cast<std::size_t>(i)];
  };
  // Piece i of file f: the patches' parts on the pool's threads.
  auto make_piece = [&](std::size_t f, int i) {
    const std::size_t first = piece_begin[static_cast<std::size_t>(i)];
    std::vector<toolkit::io::VtuMesh> parts(patches_of(i));
    detail::parallel_items(parts.size(), detail::pool_threads(),
                           [&](std::size_t k) { parts[k] = files[f].second(first + k); });
    return merged(i, std::move(parts));
  };
  // Piece i of the three files made from the Bezier elements: one extraction
  // per patch (three before: 15 % of Newfoundland's files).
  detail::SharedPieces<toolkit::io::VtuParts> shared(pieces, shared_files.size(), 1, [&](int i) {
    const std::size_t first = piece_begin[static_cast<std::size_t>(i)];
    const std::size_t m = patches_of(i);
    std::array<std::vector<toolkit::io::VtuMesh>, 3> parts;
    for (auto& p : parts) p.resize(m);
    detail::parallel_items(m, detail::pool_threads(), [&](std::size_t k) {
      const ParameterizationResult& r = R.patches[first + k];
      const BezierExtraction extraction(r.map->basis());
      parts[0][k] = surface_vtu(*r.map, samples, &extraction);
      parts[1][k] = bezier_vtu(r, &extraction);
      parts[2][k] = physical_tmesh_vtu(r, samples, &extraction);
    });
    std::vector<toolkit::io::VtuParts> out;
    for (auto& p : parts) out.push_back(merged(i, std::move(p)));
    return out;
  });
  // Three lanes of files written at once, each on its own thread (VTK
  // compresses serially), one for each of the shared files, with the small
  // files after them: the shared pieces are made by whichever lane asks first
  // and taken by the others. In a lane, while VTK compresses a piece of a file
  // of its own parts, the next piece of it is made on another thread.
  auto write_own = [&](std::size_t f) {
    std::future<toolkit::io::VtuParts> ahead;
    int ahead_piece = -1;
    toolkit::io::write_vtu_part_pieces(
        (dir / files[f].first).string(), pieces,
        [&](int i) {
          toolkit::io::VtuParts piece;
          if (ahead.valid() && ahead_piece == i)
            piece = ahead.get();
          else
            piece = make_piece(f, i);
          if (ahead.valid()) ahead.wait();  // not the one asked for (VTK asks in order): dropped
          if (i + 1 < pieces)
            ahead_piece = i + 1, ahead = std::async(std::launch::async, make_piece, f, i + 1);
          return piece;
        },
        compression);
    if (ahead.valid()) ahead.get();  // raises its error, if any
  };
  auto write_lane = [&](std::size_t s, std::initializer_list<std::string_view> own, bool with_tspline_file) {
    try {
      if (with_tspline_file)
        write_multipatch_file((dir / output_files::kTSpline).string(), maps, metas, R.layout.interfaces,
                              R.layout.cuts, report.value("input", ""), &R.domain);
      toolkit::io::write_vtu_part_pieces((dir / shared_files[s]).string(), pieces,
                                         [&](int i) { return shared.take(s, i); }, compression);
      for (const std::string_view name : own)
        for (std::size_t f = 0; f < files.size(); ++f)
          if (files[f].first == name) write_own(f);
    } catch (...) {
      shared.fail(std::current_exception());  // (the other lanes stop waiting for this one)
      throw;
    }
  };
  // report.json appears last, after every other file, and is streamed: its
  // text whole (92 MB on Newfoundland, and the copy when the string grows) set
  // the run's peak memory, 1,060 MiB against 915 MiB while the other files
  // were written. The lane of physical_tmesh.vtu, which ends first, streams it
  // to its temporary name while the other lanes still write, and renames it
  // once they have written their files too (if one fails, it is removed).
  {
    namespace of = output_files;
    std::promise<void> surface_lane, bezier_lane;
    std::shared_future<void> surface_done = surface_lane.get_future().share();
    std::shared_future<void> bezier_done = bezier_lane.get_future().share();
    const std::string report_path = (dir / of::kReport).string();
    std::future<void> tmesh = std::async(std::launch::async, [&] {
      write_lane(2, {of::kParametricTMesh}, false);
      toolkit::io::write_atomic(report_path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << std::setw(2) << report << '\n';
        out.close();
        if (!out) throw toolkit::IoError("cannot write " + report_path);
        surface_done.get();  // (rethrows that lane's error: the temporary file goes)
        bezier_done.get();
      });
    });
    std::future<void> bezier = std::async(std::launch::async, [&] {
      try {
        write_lane(1, {}, false);
        bezier_lane.set_value();
      } catch (...) {
        bezier_lane.set_exception(std::current_exception());
        throw;
      }
    });
    std::exception_ptr error;
    try {
      write_lane(0, {of::kControlNet, of::kBoundary}, true);
      surface_lane.set_value();
    } catch (...) {
      error = std::current_exception();
      surface_lane.set_exception(error);
    }
    for (std::future<void>* lane : {&bezier, &tmesh}) {
      try {
        lane->get();  // waits for the lane in any case
      } catch (...) {
        if (!error) error = std::current_exception();
      }
    }
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace tspline::io
