// `tspline export TSPLINE.json [--bezier OUT.json] [--msh OUT.msh]
// [--vtk-bezier OUT.vtu]`: Bezier extraction export (docs/bezier_format.md),
// curved Lagrange elements for Gmsh (msh_export.h) and rational Bezier cells
// for ParaView (bezier_vtu.h).
#include <iostream>
#include <memory>
#include <vector>

#include "commands.h"
#include "toolkit/io/atomic_file.h"
#include "toolkit/io/vtu_writer.h"
#include "tspline/errors.h"
#include "tspline/io/bezier_export.h"
#include "tspline/io/bezier_vtu.h"
#include "tspline/io/msh_export.h"
#include "tspline/io/multipatch_file.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/tspline_file.h"
#include "vtu_compression_option.h"

namespace tspline_app {

namespace {

struct ExportArgs {
  std::string file, bezier, msh, vtk_bezier;
  toolkit::io::VtuCompression vtu_compression = toolkit::io::VtuCompression::LZ4;
  bool quiet = false;
};

// Version 2: one Bezier document per patch (docs/bezier_format.md, "Multi-patch maps").
void export_multipatch_bezier(const tspline::io::LoadedMaps& maps, const ExportArgs& a);

// --vtk-bezier: every patch's Bezier cells in one file (cell data `patch`).
void export_vtk_bezier(const tspline::io::LoadedMaps& maps, const ExportArgs& a) {
  std::vector<toolkit::io::VtuMesh> parts;
  for (const tspline::io::LoadedTSpline& t : maps.patches) parts.push_back(tspline::io::bezier_vtu(t.map));
  const toolkit::io::VtuMesh cells = tspline::io::merge_patches(parts);
  toolkit::io::write_vtu(a.vtk_bezier, cells, a.vtu_compression);
  if (!a.quiet)
    std::cout << "wrote " << a.vtk_bezier << ": " << cells.cells.size()
              << " rational bicubic Bezier cells (VTK_BEZIER_QUADRILATERAL) on " << maps.patches.size()
              << (maps.patches.size() == 1 ? " patch" : " patches") << std::endl;
}

// --msh: one surface entity per patch, nodes shared along the interfaces (msh_export.h).
int export_multipatch(const tspline::io::LoadedMaps& maps, const ExportArgs& a) {
  if (!a.bezier.empty()) export_multipatch_bezier(maps, a);
  if (!a.msh.empty()) {
    std::vector<const tspline::TSplineMap*> ptrs;
    for (const tspline::io::LoadedTSpline& t : maps.patches) ptrs.push_back(&t.map);
    const tspline::io::MshExportStats s = tspline::io::write_msh_file(a.msh, ptrs, maps.interfaces);
    if (!a.quiet)
      std::cout << "wrote " << a.msh << ": " << s.elements << " bicubic quadrilaterals (Gmsh type 36) on "
                << maps.patches.size() << " patches, " << s.nodes << " nodes (shared along the "
                << maps.interfaces.size() << " interfaces)" << std::endl;
  }
  return 0;
}

void export_multipatch_bezier(const tspline::io::LoadedMaps& maps, const ExportArgs& a) {
  nlohmann::json doc = {{"format", "tspline-bezier-multipatch"}, {"version", 1}, {"source", a.file}};
  std::size_t elements = 0;
  for (std::size_t p = 0; p < maps.patches.size(); ++p) {
    doc["patches"].push_back(tspline::io::bezier_document(maps.patches[p].map, a.file + " patch " + std::to_string(p)));
    elements += doc["patches"].back()["elements"].size();
  }
  doc["interfaces"] = nlohmann::json::array();
  for (const tspline::Interface& f : maps.interfaces)
    doc["interfaces"].push_back({{"patch_a", f.patch_a},
                                 {"side_a", tspline::io::side_name(f.side_a)},
                                 {"patch_b", f.patch_b},
                                 {"side_b", tspline::io::side_name(f.side_b)},
                                 {"orientation", "reversed"}});
  toolkit::io::write_text_atomic(a.bezier, doc.dump() + "\n");
  if (!a.quiet)
    std::cout << "wrote " << a.bezier << ": " << elements << " Bezier elements on " << maps.patches.size()
              << " patches" << std::endl;
}

}  // namespace

void add_export_command(CLI::App& app, CommandAction& action) {
  const Subcommand<ExportArgs> cmd_sub = add_subcommand<ExportArgs>(
      app, "export",
      "Write the T-spline as rational Bezier elements with their extraction operators (Scott et al. 2011), "
      "the interchange form for T-spline IGA in finite element codes (docs/bezier_format.md)");
  CLI::App* const cmd = cmd_sub.cmd;
  const std::shared_ptr<ExportArgs> a = cmd_sub.args;
  cmd->add_option("TSPLINE", a->file, "T-spline file written by `tspline param`")->required();
  cmd->add_option("--bezier", a->bezier, "Output JSON file of Bezier elements");
  cmd->add_option("--msh", a->msh,
                  "Output Gmsh MSH 4.1 file: the Bezier elements as bicubic 16-node Lagrange quadrilaterals "
                  "(type 36) with their nodes on the map");
  cmd->add_option("--vtk-bezier", a->vtk_bezier,
                  "Output VTK file (.vtu) for ParaView: the map exactly, one rational bicubic Bezier cell "
                  "(VTK_BEZIER_QUADRILATERAL) per Bezier element, with J_r, det J and the certificate");
  add_vtu_compression_option(cmd, a->vtu_compression);
  cmd->add_flag("--quiet,-q", a->quiet, "Print errors only");
  cmd->callback([a, &action] {
    if (a->bezier.empty() && a->msh.empty() && a->vtk_bezier.empty())
      throw CLI::ValidationError("export", "give --bezier, --msh and/or --vtk-bezier");
    action = [a] {
      const tspline::io::LoadedMaps maps = tspline::io::read_maps_file(a->file);
      if (!a->vtk_bezier.empty()) export_vtk_bezier(maps, *a);
      if (maps.version == 2) return export_multipatch(maps, *a);
      const tspline::io::LoadedTSpline& t = maps.patches.front();
      if (!a->bezier.empty()) {
        const nlohmann::json doc = tspline::io::bezier_document(t.map, a->file);
        toolkit::io::write_text_atomic(a->bezier, doc.dump() + "\n");
        if (!a->quiet)
          std::cout << "wrote " << a->bezier << ": " << doc["elements"].size() << " Bezier elements on "
                    << t.map.mesh().num_cells() << " cells, " << t.map.basis().size() << " functions" << std::endl;
      }
      if (!a->msh.empty()) {
        const tspline::io::MshExportStats s = tspline::io::write_msh_file(a->msh, t.map);
        if (!a->quiet)
          std::cout << "wrote " << a->msh << ": " << s.elements << " bicubic quadrilaterals (Gmsh type 36), "
                    << s.nodes << " nodes" << std::endl;
      }
      return 0;
    };
  });
}

}  // namespace tspline_app
