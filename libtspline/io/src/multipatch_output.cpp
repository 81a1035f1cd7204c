#include "tspline/io/multipatch_output.h"

#include <filesystem>
#include <deque>
#include <functional>
#include <future>
#include <type_traits>
#include <utility>

#include "toolkit/io/atomic_file.h"
#include "tspline/detail/thread_pool.h"
#include "tspline/io/front_output.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/param_output.h"
#include "tspline/io/output_files.h"

namespace tspline::io {
namespace {

using json = nlohmann::json;

template <class Map>
void keep_common(Map& into, const Map& part) {
  for (auto it = into.begin(); it != into.end();) it = part.count(it->first) ? std::next(it) : into.erase(it);
}

template <class Map>
void append(Map& into, const Map& part) {
  for (auto& [name, values] : into) {
    const auto& more = part.at(name);
    values.insert(values.end(), more.begin(), more.end());
  }
}

// The patches' whole-map quality figures combined (combine_whole_map_quality_json).
json whole_map_of(const json& patch_reports) {
  std::vector<json> w;
  for (const json& p : patch_reports)  // one entry per patch (null without figures), so that indices are patches
    w.push_back(p.contains("jacobian") && p["jacobian"].contains("whole_map") ? p["jacobian"]["whole_map"] : json());
  return combine_whole_map_quality_json(w);
}

// merge_patches; with non-const parts each part is released once appended, so
// that the parts and the merged mesh are never whole at once.
template <class Parts>
toolkit::io::VtuMesh merge(Parts& parts) {
  toolkit::io::VtuMesh out;
  if (parts.empty()) return out;
  out.quads_as_polygons = parts.front().quads_as_polygons;
  out.point_scalars = parts.front().point_scalars, out.cell_scalars = parts.front().cell_scalars;
  out.cell_ints = parts.front().cell_ints, out.point_ints = parts.front().point_ints;
  out.point_vectors = parts.front().point_vectors, out.cell_vectors = parts.front().cell_vectors;
  out.rational_weights = parts.front().rational_weights;
  for (auto& [k, v] : out.point_scalars) v.clear();
  for (auto& [k, v] : out.cell_scalars) v.clear();
  for (auto& [k, v] : out.cell_ints) v.clear();
  for (auto& [k, v] : out.point_ints) v.clear();
  for (auto& [k, v] : out.point_vectors) v.clear();
  for (auto& [k, v] : out.cell_vectors) v.clear();
  bool typed = true, degrees = true;
  for (const toolkit::io::VtuMesh& p : parts) {
    keep_common(out.point_scalars, p.point_scalars), keep_common(out.cell_scalars, p.cell_scalars);
    keep_common(out.cell_ints, p.cell_ints), keep_common(out.point_ints, p.point_ints);
    keep_common(out.point_vectors, p.point_vectors), keep_common(out.cell_vectors, p.cell_vectors);
    typed = typed && p.cell_types.size() == p.cells.size();
    degrees = degrees && p.higher_order_degrees.size() == p.cells.size();
    if (p.rational_weights != out.rational_weights) out.rational_weights.clear();
  }
  // Every array at its final size at once (growing by doubling held up to
  // twice the memory).
  std::size_t np = 0, nc = 0;
  for (const toolkit::io::VtuMesh& p : parts) np += p.points.size(), nc += p.cells.size();
  out.points.reserve(np), out.cells.reserve(nc);
  for (auto& [k, v] : out.point_scalars) v.reserve(np);
  for (auto& [k, v] : out.point_ints) v.reserve(np);
  for (auto& [k, v] : out.point_vectors) v.reserve(np);
  for (auto& [k, v] : out.cell_scalars) v.reserve(nc);
  for (auto& [k, v] : out.cell_ints) v.reserve(nc);
  for (auto& [k, v] : out.cell_vectors) v.reserve(nc);
  std::vector<int> patch;
  patch.reserve(nc);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const toolkit::io::VtuMesh& p = parts[k];
    const int offset = static_cast<int>(out.points.size());
    out.points.insert(out.points.end(), p.points.begin(), p.points.end());
    for (std::size_t c = 0; c < p.cells.size(); ++c) {
      // Released parts give their cells away (no second allocation per cell).
      std::vector<int> cell;
      if constexpr (std::is_const_v<Parts>) cell = p.cells[c];
      else cell = std::move(parts[k].cells[c]);
      for (int& i : cell) i += offset;
      out.cells.push_back(std::move(cell));
      patch.push_back(static_cast<int>(k));
    }
    append(out.point_scalars, p.point_scalars), append(out.cell_scalars, p.cell_scalars);
    append(out.cell_ints, p.cell_ints), append(out.point_ints, p.point_ints);
    append(out.point_vectors, p.point_vectors), append(out.cell_vectors, p.cell_vectors);
    if (typed) out.cell_types.insert(out.cell_types.end(), p.cell_types.begin(), p.cell_types.end());
    if (degrees)
      out.higher_order_degrees.insert(out.higher_order_degrees.end(), p.higher_order_degrees.begin(),
                                      p.higher_order_degrees.end());
    if constexpr (!std::is_const_v<Parts>) parts[k] = toolkit::io::VtuMesh();
  }
  if (!out.point_scalars.count(out.rational_weights)) out.rational_weights.clear();
  out.cell_ints["patch"] = std::move(patch);
  return out;
}

// The bytes of a mesh's arrays, roughly (the vectors' contents).
std::size_t approximate_bytes(const toolkit::io::VtuMesh& m) {
  std::size_t bytes = m.points.size() * sizeof(Eigen::Vector2d) + m.points3d.size() * sizeof(Eigen::Vector3d);
  for (const std::vector<int>& c : m.cells) bytes += sizeof(c) + c.size() * sizeof(int);
  for (const auto& [k, v] : m.point_scalars) bytes += v.size() * sizeof(double);
  for (const auto& [k, v] : m.cell_scalars) bytes += v.size() * sizeof(double);
  for (const auto& [k, v] : m.point_ints) bytes += v.size() * sizeof(int);
  for (const auto& [k, v] : m.cell_ints) bytes += v.size() * sizeof(int);
  for (const auto& [k, v] : m.point_vectors) bytes += v.size() * sizeof(Eigen::Vector2d);
  for (const auto& [k, v] : m.cell_vectors) bytes += v.size() * sizeof(Eigen::Vector2d);
  return bytes + m.cell_types.size() * sizeof(int) + m.higher_order_degrees.size() * sizeof(std::array<int, 3>);
}

}  // namespace

toolkit::io::VtuMesh merge_patches(const std::vector<toolkit::io::VtuMesh>& parts) { return merge(parts); }

toolkit::io::VtuMesh merge_patches(std::vector<toolkit::io::VtuMesh>&& parts) {
  toolkit::io::VtuMesh out = merge(parts);
  parts.clear();
  return out;
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
  // the patches on the pool's threads.
  std::vector<json> per_patch(R.patches.size());
  detail::parallel_ranges(R.patches.size(), detail::pool_threads(), [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t p = begin; p < end; ++p) per_patch[p] = param_report(R.patches[p], input_path);
  }, 2);
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
                              int samples) {
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
  write_multipatch_file((dir / output_files::kTSpline).string(), maps, metas, R.layout.interfaces, R.layout.cuts,
                        report.value("input", ""));
  // One VTU file at a time: its patches' parts built on the pool's threads
  // and merged. The writing (VTK's zlib compression is serial) runs on threads
  // of its own, one file after the other, while the next files' parts are
  // built, as long as the merged files waiting to be written fit in
  // kWritingBytes; a larger file is written before the next is built (a sea of
  // 9,000 patches: writing all six at once took 0.9 GiB more).
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
  constexpr std::size_t kWritingBytes = std::size_t{256} << 20;
  struct Writing {
    std::shared_future<void> done;
    std::size_t bytes = 0;
  };
  std::deque<Writing> writing;  // in the order of the files; each waits for the one before
  std::size_t writing_bytes = 0;
  auto wait_oldest = [&] {
    writing.front().done.get();  // raises the write's error, if any
    writing_bytes -= writing.front().bytes;
    writing.pop_front();
  };
  for (const auto& [name, part] : files) {
    toolkit::io::VtuMesh merged;
    {
      std::vector<toolkit::io::VtuMesh> parts(n);
      detail::parallel_ranges(n, detail::pool_threads(), [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t p = begin; p < end; ++p) parts[p] = part(p);
      }, 2);
      merged = merge_patches(std::move(parts));
    }
    const std::size_t bytes = approximate_bytes(merged);
    while (!writing.empty() && writing_bytes + bytes > kWritingBytes) wait_oldest();
    const std::string path = (dir / name).string();
    if (bytes > kWritingBytes) {
      toolkit::io::write_vtu(path, std::move(merged));
      continue;
    }
    std::shared_future<void> before = writing.empty() ? std::shared_future<void>() : writing.back().done;
    writing.push_back({std::async(std::launch::async,
                                  [path, before, mesh = std::move(merged)]() mutable {
                                    if (before.valid()) before.get();  // a failed write stops the later ones
                                    toolkit::io::write_vtu(path, std::move(mesh));
                                  })
                           .share(),
                       bytes});
    writing_bytes += bytes;
  }
  while (!writing.empty()) wait_oldest();
  toolkit::io::write_text_atomic((dir / output_files::kReport).string(), report.dump(2) + "\n");
}

}  // namespace tspline::io
