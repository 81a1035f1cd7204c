#pragma once
// Pictures of the toolkit's outputs without ParaView: `tspline render`.
// Reads the .vtu files that `tspline param` / `tspline poisson` wrote into a
// directory and draws one view with Cairo (canvas.h) into a PNG, SVG or PDF
// file, by the file's extension.
#include <string>

#include "toolkit/io/vtu_writer.h"

namespace tspline::io {

enum class RenderView {
  Auto,        ///< Solution if the directory holds solution/step_*.vtu, else Jacobian
  TMesh,       ///< image of the T-mesh cells under the map (curved edges), boundary polygon
  Jacobian,    ///< mean ratio Jacobian J_r on [0, 1] (viridis; J_r < 0 red), T-mesh edges
  ControlNet,  ///< control net (lines and points) over the boundary polygon
  Solution,    ///< u_h of the last (or a given) Poisson step, analysis cell edges
  Layout       ///< the patches of a multi-patch map, one colour each; interfaces, layout nodes
};

/// Parses "auto", "tmesh", "jacobian", "control-net", "solution", "layout". \throw InputError.
RenderView parse_render_view(const std::string& name);

struct RenderOptions {
  RenderView view = RenderView::Auto;
  int width = 1200;
  int height = 900;
  int step = -1;  ///< Solution: the Poisson step to draw (-1: the last)
};

struct RenderSummary {
  RenderView view = RenderView::Auto;  ///< the view drawn (Auto resolved)
  std::string source;                  ///< the main .vtu file read
  double min = 0.0, max = 0.0;         ///< range of the colour-mapped field (0, 0 if none; Layout: max = patches)
};

/// Draws `dir`'s outputs into `png_path` (written atomically), a PNG, SVG or
/// PDF file by its extension.
/// \throw IoError if a needed file is missing or unreadable (the message names
/// it and the command that writes it) or the PNG cannot be written; InputError
/// for bad options.
RenderSummary render_png(const std::string& dir, const std::string& png_path, const RenderOptions& options);

/// The meshes of a map's pictures, as `tspline param` writes them into
/// surface.vtu (surface_vtu; patches merged, multipatch_output.h),
/// boundary.vtu and control_net.vtu; those a view does not draw may be empty.
struct MapMeshes {
  toolkit::io::VtuMesh surface, boundary, control_net;
};

/// The same pictures of a map from its meshes in memory (the Python module's
/// Map.render): every view but Solution (Auto: Jacobian).
/// 	hrow InputError for the Solution view or bad options; IoError as render_png.
RenderSummary render_map(const MapMeshes& meshes, const std::string& path, const RenderOptions& options);

}  // namespace tspline::io
