#pragma once
// The names of the files `tspline param` and `tspline poisson` write into
// their output folder, in one place (the writers, the programs' summaries and
// `tspline render`, which reads them back, all use these).
#include <array>
#include <string_view>

namespace tspline::io::output_files {

// tspline param (single patch and multipatch)
inline constexpr std::string_view kTSpline = "tspline.json";       ///< the T-spline file (docs/tspline_format.md)
inline constexpr std::string_view kSurface = "surface.vtu";        ///< the map sampled, with J_r and det J
/// The map exactly: one rational bicubic Bezier cell per element (bezier_vtu.h)
inline constexpr std::string_view kBezierSurface = "surface_bezier.vtu";
inline constexpr std::string_view kControlNet = "control_net.vtu";
inline constexpr std::string_view kAdaptSeries = "adapt.pvd";      ///< the adaptive rounds (folder adapt/)
inline constexpr std::string_view kAdaptFolder = "adapt";
inline constexpr std::string_view kParametricTMesh = "parametric_tmesh.vtu";
inline constexpr std::string_view kPhysicalTMesh = "physical_tmesh.vtu";
inline constexpr std::string_view kBoundary = "boundary.vtu";
inline constexpr std::string_view kReport = "report.json";         ///< written last: the run's summary
/// What `tspline param` writes (single patch), in the order of its summary line.
inline constexpr std::array<std::string_view, 9> kParam = {kTSpline,       kSurface,     kBezierSurface,
                                                           kControlNet,    kAdaptSeries, kParametricTMesh,
                                                           kPhysicalTMesh, kBoundary,    kReport};
/// What `tspline param` writes for a map of several patches (no adapt.pvd).
inline constexpr std::array<std::string_view, 8> kMultipatchParam = {
    kTSpline, kSurface, kBezierSurface, kControlNet, kParametricTMesh, kPhysicalTMesh, kBoundary, kReport};

// tspline poisson
inline constexpr std::string_view kConvergenceCsv = "convergence.csv";
inline constexpr std::string_view kConvergencePlot = "convergence.png";
inline constexpr std::string_view kSolutionSeries = "solution.pvd";  ///< the steps (folder solution/)
inline constexpr std::string_view kSolutionFolder = "solution";
/// What `tspline poisson` writes, in the order of its summary line.
inline constexpr std::array<std::string_view, 5> kPoisson = {kConvergenceCsv, kConvergencePlot, kReport,
                                                             kSolutionSeries, "solution/"};

}  // namespace tspline::io::output_files
