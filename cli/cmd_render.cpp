// `crowdrecon render`: pictures (and a video) of a run's frames with the
// contact force network of the paper's Figure 6 (viz/render_run.hpp).
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "crowdrecon/common/error.hpp"
#include "crowdrecon/common/output_path.hpp"
#include "crowdrecon/viz/render_run.hpp"

namespace crowdrecon::cli {

namespace {

struct RenderArgs {
  std::string run_file;
  std::string output_dir;
  std::string frames = "all";
  std::string video;
  double fps = 0.0;
  int width_px = 1280;
  double force_n_per_px = 0.0;
  std::string window;
  bool svg = false;
  bool force = false;
};

void RunRender(const RenderArgs& args) {
  const std::filesystem::path video = args.video;
  const bool mp4 = video.extension() == ".mp4";  // may fall back to .avi (viz/render_run.hpp)
  CheckOutputs({{"-o", args.output_dir, viz::FramesFolderOutput()},
                {"--video", video, VideoOutputKind()},
                {"--video (its AVI fallback)", mp4 ? std::filesystem::path(video).replace_extension(".avi") : "",
                 VideoOutputKind()}},
               {{"the run file", args.run_file}}, args.force);
  viz::RenderOptions options;
  options.output_dir = args.output_dir;
  options.frames = viz::ParseFrameSelection(args.frames);
  options.video = args.video;
  options.video_fps = args.fps;
  options.width_px = args.width_px;
  options.force_n_per_px = args.force_n_per_px;
  options.svg = args.svg;
  if (!args.window.empty()) viz::ParseRenderWindow(args.window, &options);
  // A progress line only for a person watching: logs and pipes stay clean.
  const bool terminal = isatty(fileno(stderr)) != 0;
  if (terminal)
    options.progress = [](const viz::RenderProgress& p) {
      std::fprintf(stderr, "\rrender: frame %lld (t = %.2f s), %zu of %zu", static_cast<long long>(p.frame),
                   p.time_s, p.done, p.total);
      if (p.done == p.total) std::fprintf(stderr, "\n");
      std::fflush(stderr);
    };
  const viz::RenderSummary summary = viz::RenderRun(args.run_file, options);
  std::printf("%s", summary.BriefReport().c_str());
  std::printf("pictures: %s (frame_%06lld.png ...)\n", args.output_dir.c_str(),
              static_cast<long long>(summary.first_frame));
  SayIfUnfinished(args.run_file);
}

}  // namespace

void RegisterRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* render = app.add_subcommand(
      "render", "Draw a run's frames: bodies, walls and the contact force network (paper, Figure 6)");
  render->add_option("RUN", args->run_file, "run file (.sqlite) written by `crowdrecon simulate`")->required();
  render->add_option("-o,--output", args->output_dir, "folder for frame_NNNNNN.png (created if missing; an existing one must be empty or hold only frames and videos)")
      ->required();
  render->add_option("--frames", args->frames,
                     "which frames: all (default), a list such as first,last or 0,50,last, every:N, or a time "
                     "range T1:T2 in seconds");
  render->add_option("--video", args->video,
                     "also write a video: .mp4 (MPEG-4; falls back to .avi if unsupported) or .avi (Motion-JPEG)");
  render->add_option("--fps", args->fps, "frames per second of the video (default: real time)")
      ->check(NumberIn(0.01, 1000.0, "frames/s"));
  render->add_option("--width", args->width_px, "picture width in pixels (default 1280)")
      ->check(IntegerIn(320, 8000));
  render->add_option("--force-scale", args->force_n_per_px,
                     "newtons per pixel of force-line width (default: the largest force ~0.12 m wide)")
      ->check(NumberIn(1e-6, 1e9, "N/px"));
  render->add_option("--window", args->window,
                     "draw only the world window x0,y0,x1,y1 (m, lower-left and upper-right corners), at --width: "
                     "a part of a large venue at a readable scale (default: the venue and everyone in it)");
  render->add_flag("--svg", args->svg, "also write frame_NNNNNN.svg");
  AddForceFlag(render, &args->force);
  render->callback([args] { RunRender(*args); });
}

}  // namespace crowdrecon::cli
