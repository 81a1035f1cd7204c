// `tspline render DIR --png FILE`: a picture of what `param` or `poisson` wrote
// into DIR, drawn without a display (tspline/io/render.h).
#include <iostream>
#include <memory>

#include "commands.h"
#include "tspline/errors.h"
#include "tspline/io/render.h"

namespace tspline_app {

namespace {

struct RenderArgs {
  std::string dir, png, view = "auto", size = "1200x900";
  int step = -1;
  bool quiet = false;
};

void parse_size(const std::string& text, int& w, int& h) {
  const auto x = text.find('x');
  std::size_t used_w = 0, used_h = 0;
  if (x != std::string::npos) try {
      w = std::stoi(text.substr(0, x), &used_w);
      h = std::stoi(text.substr(x + 1), &used_h);
    } catch (const std::exception&) {  // not a number, or out of int's range
      used_w = 0;
    }
  if (used_w == 0 || used_w != x || used_h != text.size() - x - 1 || w < 16 || h < 16 || w > 16384 || h > 16384)
    throw tspline::InputError("--size: '" + text + "' is not WIDTHxHEIGHT with 16..16384 pixels per side");
}

const char* view_name(tspline::io::RenderView v) {
  switch (v) {
    case tspline::io::RenderView::TMesh: return "tmesh";
    case tspline::io::RenderView::Jacobian: return "jacobian";
    case tspline::io::RenderView::ControlNet: return "control-net";
    case tspline::io::RenderView::Solution: return "solution";
    case tspline::io::RenderView::Layout: return "layout";
    case tspline::io::RenderView::Auto: break;
  }
  return "auto";
}

}  // namespace

void add_render_command(CLI::App& app, CommandAction& action) {
  const Subcommand<RenderArgs> cmd_sub = add_subcommand<RenderArgs>(
      app, "render",
      "Draw a picture (PNG, SVG or PDF) of the outputs in DIR without ParaView or a display: the map's mean ratio Jacobian J_r "
      "(jacobian), the curved T-mesh (tmesh), the control net (control-net) of `tspline param`, or u_h of "
      "`tspline poisson` (solution)");
  CLI::App* const cmd = cmd_sub.cmd;
  const std::shared_ptr<RenderArgs> a = cmd_sub.args;
  cmd->add_option("DIR", a->dir, "Output directory of `tspline param` or `tspline poisson`")->required();
  cmd->add_option("--png,--image", a->png, "Picture to write: PNG, SVG or PDF by the extension")->required();
  cmd->add_option("--view", a->view,
                  "auto (solution if DIR has solution/, else jacobian), tmesh, jacobian, control-net, solution, "
                  "layout (the patches of a multi-patch map, one colour each)")
      ->capture_default_str();
  cmd->add_option("--size", a->size, "Image size WIDTHxHEIGHT in pixels")->capture_default_str();
  cmd->add_option("--step", a->step, "solution: the Poisson step to draw (default: the last)");
  cmd->add_flag("--quiet,-q", a->quiet, "Print errors only");
  cmd->callback([a, &action] {
    action = [a] {
      tspline::io::RenderOptions o;
      o.view = tspline::io::parse_render_view(a->view);
      parse_size(a->size, o.width, o.height);
      o.step = a->step;
      const tspline::io::RenderSummary s = tspline::io::render_png(a->dir, a->png, o);
      if (!a->quiet) {
        std::cout << "wrote " << a->png << " (" << o.width << "x" << o.height << ", " << view_name(s.view)
                  << " from " << s.source;
        if (s.view == tspline::io::RenderView::Layout) std::cout << ", " << s.max << (s.max == 1 ? " patch" : " patches");
        else if (s.max > s.min) std::cout << ", range " << s.min << " .. " << s.max;
        std::cout << ")" << std::endl;
      }
      return 0;
    };
  });
}

}  // namespace tspline_app
