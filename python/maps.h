#pragma once
// tspline.Map: the map of [0,1]^2 (one patch) or of several parameter squares
// (one per patch, C0 across their interfaces) onto a domain, from
// tspline.parameterize or tspline.load.
#include <memory>
#include <string>
#include <vector>

#include "bindings.h"
#include "param_session.h"
#include "tspline/io/multipatch_file.h"

namespace tspline_python {

struct Map {
  std::shared_ptr<const tspline_app::ParamRun> run;     ///< tspline.parameterize (else null)
  std::shared_ptr<const tspline::io::LoadedMaps> file;  ///< tspline.load (else null)
  std::vector<const tspline::TSplineMap*> maps;         ///< one per patch, owned by `run` or `file`
  std::vector<tspline::io::TSplineFileMeta> metas;      ///< per patch: source, boundary polygon, corners
  std::vector<tspline::Interface> interfaces;
  std::vector<tspline::Cut> cuts;
  int version = 1;  ///< of its T-spline file: 1 for one patch, 2 for a multi-patch layout
  std::string source;
  py::object report;  ///< report.json as a dict (parameterize), or a short description (load)
  bool certified_valid = false;

  const tspline::TSplineMap& patch(std::size_t p) const;
};

}  // namespace tspline_python
