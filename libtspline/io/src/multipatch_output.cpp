#include "tspline/io/multipatch_output.h"

#include <array>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <future>
#include <optional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "toolkit/io/atomic_file.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/io/front_output.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/param_output.h"
#include "tspline/io/output_files.h"
#include "toolkit/errors.h"

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
                              int samples, std::size_t piece_cells) {
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
  const std::vector<std::pair<std::string_view, Part>> files = {
      {output_files::kSurface, [&](std::size_t p) { return surface_vtu(*R.patches[p].map, samples); }},
      {output_files::kControlNet, [&](std::size_t p) { return control_net_vtu(*R.patches[p].map); }},
      {output_files::kBezierSurface, [&](std::size_t p) { return bezier_vtu(R.patches[p]); }},
      {output_files::kBoundary, [&](std::size_t p) { return boundary_vtu(R.patches[p].front.boundary); }},
      {output_files::kPhysicalTMesh, [&](std::size_t p) { return physical_tmesh_vtu(R.patches[p], samples); }},
      {output_files::kParametricTMesh, [&](std::size_t p) {
         // The patches side by side in the parameter plane.
         const TMesh& mesh = R.patches[p].front.mesh;
         std::vector<Eigen::Vector2d> uv(mesh.num_vertices());
         for (int v = 0; v < static_cast<int>(uv.size()); ++v)
           uv[v] = mesh.vertex_param(v) + Eigen::Vector2d(1.25 * static_cast<double>(p), 0.0);
         return tmesh_vtu(mesh, uv);
       }}};
  if (piece_cells < 1) throw toolkit::InputError("write_multipatch_outputs: piece_cells must be >= 1");
  std::vector<std::size_t> piece_begin = {0};  // patches [piece_begin[i], piece_begin[i + 1]) make piece i
  for (std::size_t p = 0, cells = 0; p < n; ++p) {
    cells += R.patches[p].map->mesh().num_cells();
    if (cells >= piece_cells && p + 1 < n) piece_begin.push_back(p + 1), cells = 0;
  }
  piece_begin.push_back(n);
  const int pieces = static_cast<int>(piece_begin.size() - 1);
  // Piece i of file f: the patches' parts on the pool's threads, merged.
  auto make_piece = [&](std::size_t f, int i) {
    const std::size_t first = piece_begin[static_cast<std::size_t>(i)];
    std::vector<toolkit::io::VtuMesh> parts(piece_begin[static_cast<std::size_t>(i) + 1] - first);
    detail::parallel_items(parts.size(), detail::pool_threads(),
                           [&](std::size_t k) { parts[k] = files[f].second(first + k); });
    toolkit::io::VtuMesh piece = merge_patches(std::move(parts));
    for (int& patch : piece.cell_ints.at("patch")) patch += static_cast<int>(first);
    return piece;
  };
  // Two lanes of files written at once, each on its own thread (VTK
  // compresses serially: one lane held a core idle while it compressed the
  // large surface files; new_caledonia's outputs took 3.5 s so), of about equal
  // weight: tspline.json and surface.vtu with the small files, and
  // surface_bezier.vtu with the T-mesh files. In a lane, while VTK compresses
  // a piece, the next piece (of this file or the lane's next one) is made on
  // another thread: one piece ahead at most.
  auto write_lane = [&](const std::vector<std::size_t>& lane, bool with_tspline_file) {
    if (with_tspline_file)
      write_multipatch_file((dir / output_files::kTSpline).string(), maps, metas, R.layout.interfaces, R.layout.cuts,
                            report.value("input", ""), &R.domain);
    struct Ahead {
      std::size_t file = 0;
      int piece = -1;
      std::future<toolkit::io::VtuMesh> mesh;
    } ahead;
    for (std::size_t k = 0; k < lane.size(); ++k) {
      const std::size_t f = lane[k];
      toolkit::io::write_vtu_pieces((dir / files[f].first).string(), pieces, [&](int i) {
        toolkit::io::VtuMesh piece;
        if (ahead.mesh.valid() && ahead.file == f && ahead.piece == i) piece = ahead.mesh.get();
        else piece = make_piece(f, i);
        if (ahead.mesh.valid()) ahead.mesh.wait();  // not the one asked for (VTK asks in order): dropped
        const bool last = i + 1 == pieces;
        if (!(last && k + 1 == lane.size())) {
          ahead.file = last ? lane[k + 1] : f;
          ahead.piece = last ? 0 : i + 1;
          ahead.mesh = std::async(std::launch::async, make_piece, ahead.file, ahead.piece);
        }
        return piece;
      });
    }
    if (ahead.mesh.valid()) ahead.mesh.get();  // raises its error, if any (none is left unused)
  };
  auto lane_of = [&](std::initializer_list<std::string_view> names) {
    std::vector<std::size_t> lane;
    for (const std::string_view name : names)
      for (std::size_t f = 0; f < files.size(); ++f)
        if (files[f].first == name) lane.push_back(f);
    return lane;
  };
  // report.json appears last, after every other file, and is streamed: its
  // text whole (92 MB on Newfoundland, and the copy when the string grows) set
  // the run's peak memory, 1,060 MiB against 915 MiB while the other files
  // were written. The lane of the T-mesh files, which ends first, streams it
  // to its temporary name while the other lane still writes, and renames it
  // once that lane has written its files too (if that lane fails, it is
  // removed): on Newfoundland it took 0.7 s after both lanes.
  {
    namespace of = output_files;
    std::promise<void> surface_lane;
    std::shared_future<void> surface_lane_done = surface_lane.get_future().share();
    const std::string report_path = (dir / of::kReport).string();
    std::future<void> other = std::async(std::launch::async, [&] {
      write_lane(lane_of({of::kBezierSurface, of::kPhysicalTMesh, of::kParametricTMesh}), false);
      toolkit::io::write_atomic(report_path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << std::setw(2) << report << '\n';
        out.close();
        if (!out) throw toolkit::IoError("cannot write " + report_path);
        surface_lane_done.get();  // (rethrows that lane's error: the temporary file goes)
      });
    });
    std::exception_ptr error;
    try {
      write_lane(lane_of({of::kSurface, of::kControlNet, of::kBoundary}), true);
      surface_lane.set_value();
    } catch (...) {
      error = std::current_exception();
      surface_lane.set_exception(error);
    }
    try {
      other.get();  // waits for the other lane in any case
    } catch (...) {
      if (!error) error = std::current_exception();
    }
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace tspline::io
