#include "poisson_multipatch.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "tspline/errors.h"
#include "toolkit/io/atomic_file.h"
#include "tspline/analysis/multipatch_poisson.h"
#include "tspline/io/multipatch_output.h"
#include "tspline/io/poisson_output.h"

namespace tspline_app {

int run_multipatch_poisson(const tspline::io::LoadedMaps& maps, const MultiPatchPoissonArgs& args,
                           const tspline::PoissonProblem& problem, const nlohmann::json& problem_description) {
  if (!(args.gamma >= 0.0 && args.gamma <= 1.0)) throw tspline::InputError("--gamma must be in [0, 1]");
  const bool adaptive = args.refine == "adaptive";
  if (args.samples < 1 || args.samples > 64) throw tspline::InputError("--samples must be in [1, 64]");
  toolkit::io::ensure_writable_directory(args.out_dir);  // before any computation
  std::vector<const tspline::TSplineMap*> patch_maps;
  std::vector<tspline::TMesh> meshes;
  for (const auto& p : maps.patches) patch_maps.push_back(&p.map), meshes.push_back(p.map.mesh());
  nlohmann::json steps = nlohmann::json::array();
  const std::filesystem::path out(args.out_dir);
  std::vector<toolkit::io::PvdEntry> pvd;
  // The step's u_h on every patch (solution_vtu of each patch's PoissonSolution
  // view of the glued coefficients), merged with cell data `patch`.
  auto write_step = [&](int step, const tspline::MultiPatchSolution& S, const std::vector<std::vector<double>>& eta) {
    std::vector<toolkit::io::VtuMesh> parts;
    for (std::size_t p = 0; p < patch_maps.size(); ++p) {
      tspline::PoissonSolution sol;
      sol.space = S.spaces[p];
      sol.coefficients.resize(static_cast<Eigen::Index>(S.global[p].size()));
      for (std::size_t i = 0; i < S.global[p].size(); ++i)
        sol.coefficients[static_cast<Eigen::Index>(i)] = S.values[S.global[p][i]];
      parts.push_back(tspline::io::solution_vtu(*patch_maps[p], sol, problem, eta[p], args.samples));
    }
    if (step == 0) toolkit::io::ensure_writable_directory((out / "solution").string());
    char name[64];
    std::snprintf(name, sizeof name, "solution/step_%03d.vtu", step);
    toolkit::io::write_vtu((out / name).string(), tspline::io::merge_patches(parts));
    pvd.push_back({static_cast<double>(step), name, 0});
    toolkit::io::write_pvd((out / "solution.pvd").string(), pvd);
  };
  if (!args.quiet) std::printf("step  unknowns     cells         eta          L2          H1   max jump    seconds\n");
  for (int step = 0; step < args.steps; ++step) {
    const auto t0 = std::chrono::steady_clock::now();
    const tspline::MultiPatchSolution S =
        tspline::solve_multipatch_poisson(patch_maps, maps.interfaces, meshes, problem);
    if (S.unknowns > args.max_dofs) break;
    std::size_t cells = 0;
    for (const auto& m : meshes) cells += m.num_cells();
    const double jump = tspline::multipatch_interface_jump(maps.interfaces, S);
    nlohmann::json rec = {{"step", step}, {"unknowns", S.unknowns}, {"interior_unknowns", S.interior_unknowns},
                          {"cells", cells}, {"glued_pairs", S.glued_pairs}, {"max_interface_jump", jump}};
    double l2 = NAN, h1 = NAN;
    if (problem.exact) {
      const tspline::PoissonErrors e = tspline::multipatch_errors(patch_maps, S, problem);
      l2 = e.l2, h1 = e.h1;
      rec["l2_error"] = e.l2, rec["h1_error"] = e.h1;
      if (step > 0) {
        rec["l2_rate"] = std::log2(steps.back()["l2_error"].get<double>() / e.l2);
        rec["h1_rate"] = std::log2(steps.back()["h1_error"].get<double>() / e.h1);
      }
    }
    const std::vector<std::vector<double>> eta = tspline::multipatch_estimate(patch_maps, S, problem);
    double eta2 = 0.0, max_eta = 0.0;
    for (const auto& e : eta)
      for (double v : e) eta2 += v * v, max_eta = std::max(max_eta, v);
    rec["eta"] = std::sqrt(eta2);
    std::vector<std::vector<int>> marked(eta.size());
    std::size_t n_marked = 0;
    for (std::size_t p = 0; p < eta.size(); ++p)
      for (int c = 0; c < static_cast<int>(eta[p].size()); ++c)
        if (!adaptive || eta[p][c] > args.gamma * max_eta) marked[p].push_back(c), ++n_marked;
    rec["marked"] = n_marked;
    write_step(step, S, eta);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    rec["seconds"] = seconds;
    steps.push_back(rec);
    if (!args.quiet)
      std::printf("%4d %9zu %9zu %11.4e %11.4e %11.4e %10.2e %10.3f\n", step, S.unknowns, cells, std::sqrt(eta2), l2,
                  h1, jump, seconds);
    if (n_marked == 0) break;
    meshes = tspline::refine_multipatch(meshes, maps.interfaces, marked);
  }
  const nlohmann::json report = {{"command", "poisson"},
                                 {"patches", maps.patches.size()},
                                 {"interfaces", maps.interfaces.size()},
                                 {"problem", problem_description},
                                 {"refine", args.refine},
                                 {"gamma", args.gamma},
                                 {"coupling", "C0: one unknown per glued group of border functions"},
                                 {"steps", steps}};
  toolkit::io::write_text_atomic((std::filesystem::path(args.out_dir) / "report.json").string(),
                                 report.dump(2) + "\n");
  return 0;
}

}  // namespace tspline_app
