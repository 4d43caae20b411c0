#include "commands.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <unistd.h>

#include "cli_support.h"
#include "eval/color_field.h"
#include "api/evaluate.h"
#include "spirv/glsl_to_spirv.h"
#include "driver_select.h"
#include "vulkan_context.h"

namespace sdfc {
void registerCommands(CLI::App& app, CommandLine& cl) {
  auto common = [&](CLI::App* sub, bool needs_input = true) {
    if (needs_input) sub->add_option("scene", cl.input, "the .sdf file")->required();
    sub->add_option("-D,--define", cl.defines, "override a `let` number: -D name=value");
    sub->add_option("--diagnostics-format", cl.diagnostics_format, "text or json")
        ->check(CLI::IsMember({"text", "json"}));
    sub->add_flag("--Werror", cl.werror, "treat warnings as errors");
    sub->add_option("-W", cl.warning_options,
                    "-Wno-NAME turns the warning NAME off (its name is shown as [-WNAME]; "
                    "docs/language.md lists them), -Werror as --Werror")
        ->allow_extra_args(false);
    sub->add_option("--error-limit", cl.error_limit,
                    "stop printing after this many errors (default 20; 0 prints every one)")
        ->check(wholeNumberIn(0, 1 << 30));
    sub->add_option("--instance-threshold", cl.instance_threshold,
                    "copies of one shape in a union from which they become data + a hierarchy "
                    "(default 32; 0 = always inline code)")
        ->check(wholeNumberIn(0, 1 << 30));
    sub->callback([&cl, sub] { cl.command = sub->get_name(); });
  };
  auto emit_flags = [&](CLI::App* sub) {
    sub->add_flag("--no-bounds", cl.no_bounds, "do not skip subtrees by their bounding volumes");
    sub->add_flag("--no-fuse", cl.no_fuse, "do not fuse transform chains");
    sub->add_flag("--no-analytic-spheres", cl.no_analytic_spheres,
                  "march top-level spheres instead of intersecting them in closed form");
    sub->add_flag("--prune", cl.prune,
                  "evaluate only the parts of the scene's union near each point, listed per cell of a grid "
                  "(docs/large_scenes.md; slower on lavapipe, for GPUs)");
    sub->add_option("--mesh-mode", cl.mesh_mode,
                    "how mesh(file: ...) is drawn: exact (its triangles) or grid (a sampled distance); "
                    "default: the compiler chooses per mesh and --emit ir says which")
        ->check(CLI::IsMember({"exact", "grid"}));
    sub->add_flag("-O,--optimize", cl.optimize, "run spirv-opt's performance passes");
    sub->add_flag("--no-cache", cl.no_cache,
                  "compile the kernel even when the SPIR-V cache ($XDG_CACHE_HOME/sdfc) holds it, "
                  "and store nothing there")
        ->envname("SDFC_NO_CACHE");
    sub->add_flag("--paper-baseline", cl.paper_baseline,
                  "march like the paper: fixed epsilon 1e-3, 256 steps, max distance 100, no scene box");
    sub->add_flag("--white-noise", cl.white_noise, "PCG hash sampler instead of Owen-scrambled Sobol");
    sub->add_flag("--count-evaluations", cl.count_evaluations,
                  "instrument: each primitive evaluation adds 1 to --view iterations");
    sub->add_option("--count-event", cl.count_event,
                    "instrument --view iterations: count one event per pixel into green, KIND.QUANTITY with KIND "
                    "all|primary|bounce|shadow|normal, QUANTITY segments|iterations|lookups|entries|visits|hits")
        ->check([](const std::string& name) {
          int kind = 0, quantity = 0;
          return countEventFromName(name, kind, quantity) ? std::string()
                                                          : "not KIND.QUANTITY (see --help): " + name;
        });
  };

  CLI::App* check = app.add_subcommand("check", "report the scene's diagnostics");
  common(check);

  CLI::App* compile = app.add_subcommand("compile", "compile to GLSL, SPIR-V or IR");
  common(compile);
  compile->add_option("-o,--output", cl.output, "output file (default: stdout for text)");
  compile->add_option("--emit", cl.emit, "glsl | spv | spvasm | ir")
      ->check(CLI::IsMember({"glsl", "spv", "spvasm", "ir"}));
  compile->add_option("--view", cl.view,
                      "the view the kernel is specialised for: beauty | normal | steps | depth | "
                      "albedo | iterations | all (every view, chosen at run time); default beauty")
      ->check(CLI::IsMember({"beauty", "normal", "steps", "depth", "albedo", "iterations", "all"}));
  compile->add_flag("--cpu", cl.for_cpu,
                    "the kernel `render` builds for a CPU device such as lavapipe: bounding-volume "
                    "checks only where the compiler's plan says they pay (--emit ir shows it)");
  compile->add_flag("--line-directives", cl.line_directives,
                    "emit #line so shader errors point at the .sdf");
  compile->add_option("--timings", cl.timings,
                      "compile N more times in this process and print the median stage times "
                      "(the first compile also pays glslang's one-time set-up)")
      ->check(wholeNumberIn(1, 1000));
  emit_flags(compile);

  CLI::App* render = app.add_subcommand("render", "path-trace the scene to an image");
  common(render);
  render->add_option("-o,--output", cl.output, "image: .png, .exr or .pfm")->required();
  render->add_option("--size", cl.size, "WxH, e.g. 640x360");
  render->add_option("--spp", cl.spp, "samples per pixel")->check(limitOf(api::Option::Spp));
  render->add_option("--bounces", cl.bounces, "maximum path length")->check(limitOf(api::Option::Bounces));
  render->add_option("--light-samples", cl.light_samples, "light samples per vertex")->check(limitOf(api::Option::LightSamples));
  render->add_option("--denoise", cl.denoiser,
                     "none | bilateral | atrous | svgf | nlm | nlr | nlr-fast (default nlr, nlr-fast for "
                     "--frames: it leaves converged pixels as they are; none for reference images)")
      ->check(CLI::IsMember({"none", "bilateral", "atrous", "svgf", "nlm", "nlr", "nlr-fast"}));
  render->add_option("--denoise-aovs", cl.denoise_aovs,
                     "features of svgf, nlm, nlr: auto (specular for nlr, else centre) | jittered "
                     "(means over the samples) | specular (jittered, through specular first hits) | "
                     "centre (one unjittered ray)")
      ->check(CLI::IsMember({"auto", "jittered", "specular", "centre"}));
  render->add_option("--denoise-select", cl.denoise_select,
                     "nlm, nlr: colour strengths of the last pass, e.g. 0.7,1.25,2.5; each pixel "
                     "takes the one of least error estimated against the other half (docs/denoise.md)")
      ->delimiter(',')
      ->check(numberIn(0, 1000, /*open_low=*/true));
  render->add_flag("--layers", cl.layers,
                   "-o x.exr: also albedo, N, Z, material, object and variance channels (docs/layers.md)");
  render->add_flag("--adaptive", cl.adaptive,
                   "adaptive sampling: --spp is the mean; a first share uniform, the rest where the "
                   "estimated error after denoising is (docs/adaptive.md)");
  render->add_option("--adaptive-estimate", cl.adaptive_estimate,
                     "what drives --adaptive: variance (of the halves' mean) | denoised (nlr's half "
                     "against the other) | display (halves clamped to [0, 1] in sRGB: what FLIP sees) | uniform")
      ->check(CLI::IsMember({"uniform", "variance", "denoised", "display"}));
  render->add_option("--adaptive-share", cl.adaptive_share, "--adaptive's uniform first phase, of --spp")
      ->check(numberIn(0.01, 1.0));
  render->add_option("--adaptive-cap", cl.adaptive_cap,
                     "--adaptive: a pixel's samples at most this many times the first phase's")
      ->check(numberIn(1.0, 1024.0));
  render->add_option("--adaptive-block", cl.adaptive_block, "--adaptive: counts per NxN block")
      ->check(wholeNumberIn(1, 256));
  render->add_option("--adaptive-power", cl.adaptive_power,
                     "--adaptive: extra samples proportional to the estimate to this power")
      ->check(numberIn(0.0, 4.0));
  render->add_option("--adaptive-budget", cl.adaptive_budget,
                     "--adaptive: samples (--spp is the mean) | time (the uniform --spp render's "
                     "predicted time, from each block's cost per sample)")
      ->check(CLI::IsMember({"samples", "time"}));
  render->add_option("--adaptive-cost-offset", cl.adaptive_cost_offset,
                     "--adaptive-budget time: cost per sample = primary steps + this x their mean")
      ->check(numberIn(0.0, 100.0));
  render->add_option("--adaptive-cost", cl.adaptive_cost,
                     "--adaptive-budget time: each pixel's cost per sample from iterations (a "
                     "half-size one-sample --view iterations pass) | steps (its primary march steps)")
      ->check(CLI::IsMember({"iterations", "steps"}));
  render->add_option("--view", cl.view, "beauty | normal | steps | depth | albedo | iterations")
      ->check(CLI::IsMember({"beauty", "normal", "steps", "depth", "albedo", "iterations"}));
  render->add_option("--time", cl.time, "scene time in seconds");
  render->add_option("--frames", cl.frames,
                     "A-B: render frames A..B at --fps (time = frame / fps); the output name gets "
                     "the frame number");
  render->add_option("--shards", cl.shards,
                     "render one shard of a job cut into this many sample ranges per image; "
                     "-o is then the shard directory (docs/farm.md)")
      ->check(wholeNumberIn(1, 1 << 20));
  render->add_option("--shard-index", cl.shard_index,
                     "which shard: 0 .. frames * shards - 1 (a Slurm array index or "
                     "JOB_COMPLETION_INDEX)")
      ->check(wholeNumberIn(0, 1 << 30));
  render->add_option("--fps", cl.fps, "frames per second of --frames (default 24)")
      ->check(numberIn(0.001, 1e6));
  render->add_option("--seed", cl.seed, "random seed")->check(limitOf(api::Option::Seed));
  render->add_option("--device", cl.device, "Vulkan device index (see `sdfc devices`)");
  render->add_option("--exposure", cl.exposure, "exposure in stops for PNG output")->check(limitOf(api::Option::Exposure));
  render->add_option("--tonemap", cl.tonemap,
                     "PNG tone curve: neutral (Khronos PBR Neutral, the default) | aces | linear "
                     "(clamp); EXR and PFM stay linear")
      ->check(CLI::IsMember({"neutral", "aces", "linear"}));
  render->add_flag("--aces", cl.aces, "the same as --tonemap aces");
  render->add_flag("-q,--quiet", cl.quiet, "no progress output");
  render->add_flag("--timings", cl.stage_timings,
                   "print every fixed stage's time: process start, device, front end, glslang, "
                   "validation, pipeline, the first draw's kernel compile, passes, readback, encoding");
  render->add_flag("--bounds", cl.force_bounds,
                   "keep every bounding-volume check on a CPU device (by default there the compiler "
                   "keeps only those it measures to pay on this scene: docs/large_scenes.md)");
  emit_flags(render);

  CLI::App* view = app.add_subcommand(
      "view", "a window that path-traces the scene progressively and reloads it on save");
  common(view);
  view->add_option("--size", cl.size, "window size WxH (default: the scene's render size)");
  view->add_option("--spp", cl.spp, "samples to accumulate while still (default: the scene's)")->check(limitOf(api::Option::Spp));
  view->add_option("--bounces", cl.bounces, "maximum path length")->check(limitOf(api::Option::Bounces));
  view->add_option("--light-samples", cl.light_samples, "light samples per vertex")->check(limitOf(api::Option::LightSamples));
  view->add_option("--view", cl.view, "first view: beauty | normal | steps | depth | albedo")
      ->check(CLI::IsMember({"beauty", "normal", "steps", "depth", "albedo"}));
  view->add_option("--denoise", cl.denoiser, "none | atrous (start with the denoiser on)")
      ->check(CLI::IsMember({"none", "atrous"}));
  view->add_option("--time", cl.time, "start time in seconds");
  view->add_option("--seed", cl.seed, "random seed")->check(limitOf(api::Option::Seed));
  view->add_option("--device", cl.device, "Vulkan device index (see `sdfc devices`)");
  view->add_option("--exposure", cl.exposure, "exposure in stops")->check(limitOf(api::Option::Exposure));
  view->add_option("--tonemap", cl.tonemap, "tone curve: neutral (default) | aces | linear (clamp)")
      ->check(CLI::IsMember({"neutral", "aces", "linear"}));
  view->add_flag("--aces", cl.aces, "the same as --tonemap aces");
  view->add_flag("--no-dynamic-resolution", cl.no_dynamic_resolution,
                 "draw every frame at full resolution, also while the camera moves");
  view->add_option("--script", cl.script, "drive the view from a file of commands (docs/view.md)");
  view->add_option("--frame-log", cl.frame_log, "write a line per presented frame (with its hash)");
  view->add_flag("--timings", cl.stage_timings,
                 "print the start-up stages and, once a second, each frame's split (pass, tone map, "
                 "copy, acquire, present, wait)");
  view->add_flag("--bounds", cl.force_bounds, "keep bounding-volume checks on a CPU device");
  emit_flags(view);

  CLI::App* eval = app.add_subcommand(
      "eval", "print float64 distances at points `x y z`, one a line (stdin or --points)");
  common(eval);
  eval->add_option("--points", cl.points, "file of points (default: stdin)");
  eval->add_option("--time", cl.time, "scene time in seconds");
  eval->add_flag("--gradient", cl.gradient, "also print the gradient");
  eval->add_flag("--material", cl.material, "also print the material name and its colour at the point");
  // Accepted so render's flags can be reused, and ignored: eval and mesh use the float64 distance.
  auto ignored_mesh_mode = [](CLI::App* sub) {
    sub->add_option_function<std::string>("--mesh-mode", [](const std::string&) {},
                                          "ignored: meshes are always their exact float64 distance here")
        ->check(CLI::IsMember({"exact", "grid"}));
  };
  ignored_mesh_mode(eval);

  CLI::App* mesh = app.add_subcommand("mesh", "export a triangle mesh (.glb, .gltf or .stl)");
  common(mesh);
  ignored_mesh_mode(mesh);
  mesh->add_option("-o,--output", cl.output, "mesh file")->required();
  mesh->add_option("--resolution", cl.resolution, "cells along the longest side")->check(limitOf(api::Option::Resolution));
  mesh->add_option("--voxel-size", cl.voxel_size, "cell size (overrides --resolution)")->check(limitOf(api::Option::VoxelSize));
  mesh->add_option("--box", cl.box, "x0,y0,z0,x1,y1,z1: region for infinite scenes");
  mesh->add_option("--time", cl.time, "scene time in seconds");
  mesh->add_flag("-q,--quiet", cl.quiet, "no progress output");

  CLI::App* web = app.add_subcommand(
      "export", "a self-contained web page that path-traces the scene in WebGL2, or Shadertoy code");
  common(web);
  web->add_option("-o,--output", cl.output, "the .html page (or .glsl with --target shadertoy)")->required();
  web->add_option("--target", cl.export_target,
                  "html (the progressive path tracer, orbit/pan/zoom, views on keys) | shadertoy "
                  "(the normal view, for an image tab)")
      ->check(CLI::IsMember({"html", "shadertoy"}));
  web->add_option("--size", cl.size, "the page's image WxH (default: the scene's render size)");
  web->add_option("--spp", cl.spp, "samples the page accumulates (default: the scene's)")->check(limitOf(api::Option::Spp));
  web->add_option("--bounces", cl.bounces, "maximum path length")->check(limitOf(api::Option::Bounces));
  web->add_option("--light-samples", cl.light_samples, "light samples per vertex")->check(limitOf(api::Option::LightSamples));
  web->add_option("--time", cl.time, "scene time in seconds");
  web->add_option("--seed", cl.seed, "random seed")->check(limitOf(api::Option::Seed));
  web->add_option("--exposure", cl.exposure, "exposure in stops")->check(limitOf(api::Option::Exposure));
  web->add_option("--tonemap", cl.tonemap, "tone curve: neutral (default) | aces | linear (clamp)")
      ->check(CLI::IsMember({"neutral", "aces", "linear"}));
  web->add_flag("--aces", cl.aces, "the same as --tonemap aces");
  web->add_option("--max-data-rows", cl.max_data_rows,
                  "rows of the 2048-wide texture the instances' data travels in (default 2048, "
                  "the size WebGL2 guarantees; more refuses fewer scenes but fails on some browsers)")
      ->check(wholeNumberIn(1, 16384));
  web->add_flag("--bounds", cl.force_bounds, "keep bounding-volume checks (for GPUs)");
  web->add_flag("-q,--quiet", cl.quiet, "no summary");
  emit_flags(web);

  CLI::App* merge = app.add_subcommand(
      "merge", "merge render shards into images, exactly (refuses shards that do not belong together)");
  merge->add_option("shards", cl.inputs, "shard directories or shard_*.exr files")->required();
  merge->add_option("-o,--output", cl.output,
                    "image: .exr, .png or .pfm (animations: a frame number is added)")->required();
  merge->add_option("--frames", cl.frames, "A-B: require these frames");
  merge->add_flag("--png", cl.png, "also write an sRGB PNG beside each image");
  merge->add_flag("-q,--quiet", cl.quiet, "no summary");
  merge->callback([&cl] { cl.command = "merge"; });

  CLI::App* farm = app.add_subcommand("farm", "render on a Slurm cluster (docs/farm.md)");
  farm->require_subcommand(1);
  CLI::App* submit = farm->add_subcommand(
      "submit", "check the scene, then submit a shard array and a dependent merge job");
  common(submit);
  submit->add_option("-o,--output", cl.output, "job directory on the shared file system")->required();
  submit->add_option("--spp", cl.spp, "samples per pixel")->check(limitOf(api::Option::Spp));
  submit->add_option("--shards", cl.shards, "shards per image (sample ranges)")->check(wholeNumberIn(1, 1 << 16));
  submit->add_option("--frames", cl.frames, "A-B: render frames A..B (time = frame / fps)");
  submit->add_option("--fps", cl.fps, "frames per second (default 24)")->check(numberIn(0.001, 1e6));
  submit->add_option("--size", cl.size, "WxH");
  submit->add_option("--bounces", cl.bounces, "maximum path length")->check(limitOf(api::Option::Bounces));
  submit->add_option("--light-samples", cl.light_samples, "light samples per vertex")->check(limitOf(api::Option::LightSamples));
  submit->add_option("--time", cl.time, "scene time of a still");
  submit->add_option("--seed", cl.seed, "random seed")->check(limitOf(api::Option::Seed));
  submit->add_option("--video", cl.video, "encode the frames with ffmpeg into this file (animations)");
  submit->add_option("--partition", cl.partition, "sbatch --partition");
  submit->add_option("--account", cl.account, "sbatch --account");
  submit->add_option("--time-limit", cl.time_limit, "sbatch --time per shard, e.g. 2:00:00");
  submit->add_option("--sbatch-arg", cl.sbatch_args, "any further sbatch option, repeatable");
  submit->add_option("--retries", cl.retries, "re-runs of a failed shard inside its job (default 1)")
      ->check(wholeNumberIn(0, 100));
  submit->add_option("--max-running", cl.max_running, "at most this many shards at once (--array %N)")
      ->check(wholeNumberIn(0, 1 << 20));
  submit->add_flag("--dry-run", cl.dry_run, "write the job scripts, print the sbatch commands, submit nothing");
  submit->add_flag("--bounds", cl.force_bounds, "as `sdfc render --bounds`");
  submit->add_flag("--layers", cl.layers, "shards of `sdfc render --layers`: the merge writes its EXR (docs/layers.md)");
  emit_flags(submit);
  submit->callback([&cl] { cl.command = "farm"; cl.farm_command = "submit"; });
  CLI::App* status = farm->add_subcommand("status", "progress of a farm job from its files and Slurm");
  status->add_option("dir", cl.output, "job directory")->required();
  status->callback([&cl] { cl.command = "farm"; cl.farm_command = "status"; });

  CLI::App* devices = app.add_subcommand("devices", "list Vulkan devices");
  devices->callback([&cl] { cl.command = "devices"; });

  CLI::App* fmt = app.add_subcommand("fmt", "rewrite .sdf files in the canonical layout");
  fmt->add_option("files", cl.inputs, "the .sdf files (none: stdin to stdout)");
  fmt->add_flag("--check", cl.check_format,
                "change nothing; list the files that are not formatted and exit 1 if any");
  fmt->add_flag("-w,--write", cl.write_in_place, "write the result back to each file");
  fmt->callback([&cl] { cl.command = "fmt"; });

  CLI::App* lsp = app.add_subcommand("lsp", "the Language Server Protocol server, over stdio");
  lsp->add_flag("--stdio", cl.lsp_stdio, "talk over stdin/stdout (the only transport; accepted for clients that pass it)");
  lsp->callback([&cl] { cl.command = "lsp"; });
}

int runCommand(const CommandLine& cl) {
  if (cl.command == "check") return runCheck(cl);
  if (cl.command == "compile") return runCompile(cl);
  if (cl.command == "render") return runRender(cl);
  if (cl.command == "eval") return runEval(cl);
  if (cl.command == "mesh") return runMesh(cl);
  if (cl.command == "export") return runExport(cl);
  if (cl.command == "devices") return runDevices(cl);
  if (cl.command == "merge") return runMerge(cl);
  if (cl.command == "farm") return runFarm(cl);
  if (cl.command == "fmt") return runFmt(cl);
  if (cl.command == "lsp") return runLsp(cl);
  return kExitUsage;
}

int runCheck(const CommandLine& cl) {
  Diagnostics diags;
  LoadedScene loaded = loadScene(cl, diags, false);
  return loaded.exit_code;
}

namespace {
// Median stage times over repeated in-process compilations: the figure a
// long-running tool (or a frame sequence) sees after glslang's first set-up.
void printTimings(const CommandLine& cl, const CompiledScene& first) {
  std::vector<StageTimes> runs;
  for (int i = 0; i < cl.timings; ++i) {
    Diagnostics diags;
    CompileOptions options = compileOptionsFrom(cl);
    runs.push_back(compileSource(cl.input, first.source->text, options, diags).times);
  }
  auto median = [&](double StageTimes::*field) {
    std::vector<double> v;
    for (const StageTimes& t : runs) v.push_back(t.*field * 1000);
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::vector<double> totals;
  for (const StageTimes& t : runs) totals.push_back(t.total() * 1000);
  std::sort(totals.begin(), totals.end());
  std::fprintf(stderr,
               "sdfc: first compile %.1f ms; median of %d more: total %.1f ms (parse %.2f, check %.2f, "
               "passes %.2f, emit %.2f, GLSL->validated SPIR-V %.1f); SPIR-V %zu bytes\n",
               first.times.total() * 1000, cl.timings, totals[totals.size() / 2],
               median(&StageTimes::parse), median(&StageTimes::check), median(&StageTimes::passes),
               median(&StageTimes::emit), median(&StageTimes::spirv), first.spirv.size() * 4);
}
}  // namespace

int runCompile(const CommandLine& cl) {
  if (!cl.output.empty()) checkWritablePath(cl.output);  // before the work, not after
  Diagnostics diags;
  const bool needs_spirv = cl.emit == "spv" || cl.emit == "spvasm";
  CompileOptions options = compileOptionsFrom(cl);
  if (cl.for_cpu) options.emit.bounding_volumes = false;
  LoadedScene loaded = loadScene(cl, diags, true, needs_spirv, options, true);
  if (loaded.exit_code != kExitOk) return loaded.exit_code;
  const CompiledScene& c = loaded.compiled;
  if (cl.timings > 0) printTimings(cl, c);
  if (cl.emit == "spv") {
    if (cl.output.empty() || (cl.output == "-" && isatty(STDOUT_FILENO))) {
      std::cerr << "sdfc: error: --emit spv needs -o (binary output; '-o -' when standard output "
                   "is not a terminal)\n";
      return kExitUsage;
    }
    std::string bytes(reinterpret_cast<const char*>(c.spirv.data()), c.spirv.size() * 4);
    writeFileAtomically(cl.output, bytes);
    return kExitOk;
  }
  std::string text = cl.emit == "glsl"    ? c.emitted.glsl
                     : cl.emit == "ir"    ? ir::dump(c.scene)
                                          : disassembleSpirv(c.spirv);
  if (cl.output.empty() || cl.output == "-") {
    std::cout << text << std::flush;
    if (!std::cout) {
      std::cerr << "sdfc: error: cannot write to standard output\n";
      return kExitIo;
    }
  } else {
    writeFileAtomically(cl.output, text);
  }
  return kExitOk;
}

int runEval(const CommandLine& cl) {
  if (!checkTimeOption(cl.time)) return kExitUsage;
  Diagnostics diags;
  LoadedScene loaded = loadScene(cl, diags, false);
  if (loaded.exit_code != kExitOk) return loaded.exit_code;
  const ir::Scene& scene = loaded.compiled.scene;
  std::ifstream file;
  if (!cl.points.empty()) {
    file.open(cl.points);
    if (!file) {
      std::cerr << "sdfc: error: cannot read '" << cl.points << "'\n";
      return kExitIo;
    }
  }
  // std::cin on its own buffer (no stdio sync; this command prints with printf
  // only), so in_avail() below says whether more input is ready.
  if (cl.points.empty()) std::ios::sync_with_stdio(false);
  std::istream& in = cl.points.empty() ? std::cin : file;
  // Points are evaluated in batches (the block evaluator, every core), a batch
  // ending where the input has nothing more ready, so a program writing one
  // point and waiting for its answer still gets it.
  constexpr size_t kBatch = 1 << 14;
  std::vector<double> points, distance, gradient;
  std::vector<int> material;
  auto flush = [&] {
    const size_t n = points.size() / 3;
    if (n == 0) return;
    distance.resize(n);
    material.resize(n);
    gradient.resize(3 * n);
    api::EvalBatch batch;
    batch.points = points.data();
    batch.count = n;
    batch.time = cl.time;
    batch.distance = distance.data();
    batch.material = material.data();
    batch.gradient = cl.gradient || cl.material ? gradient.data() : nullptr;
    api::evaluate(scene, batch);
    for (size_t i = 0; i < n; ++i) {
      std::printf("%.17g", distance[i]);
      const glm::dvec3 g(gradient[3 * i], gradient[3 * i + 1], gradient[3 * i + 2]);
      if (cl.gradient) std::printf(" %.12g %.12g %.12g", g.x, g.y, g.z);
      if (cl.material) {
        const int m = material[i];
        std::string name = "-";
        if (m >= 0) {
          name = scene.materials[m].name;
          if (name.empty()) name = "material" + std::to_string(m);
        }
        std::printf(" %s", name.c_str());
        // The colour at p (a field's value there; else the constant).
        if (m >= 0) {
          const glm::dvec3 p(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
          const glm::dvec3 nrm = glm::length(g) > 0 ? glm::normalize(g) : glm::dvec3(0, 1, 0);
          const glm::dvec3 c = materialColor(scene.materials[m], p + scene.origin, nrm, cl.time);
          std::printf(" %.12g %.12g %.12g", c.x, c.y, c.z);
        }
      }
      std::printf("\n");
    }
    std::fflush(stdout);
    points.clear();
  };
  std::string line;
  int line_number = 0;
  int bad = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") != std::string::npos && line[0] != '#') {
      std::istringstream words(line);
      glm::dvec3 p;
      std::string extra;
      if (!(words >> p.x >> p.y >> p.z) || (words >> extra)) {
        flush();  // the message after the answers to the lines before it
        std::cerr << (cl.points.empty() ? "<stdin>" : cl.points) << ":" << line_number
                  << ": error: expected three numbers 'x y z'\n";
        ++bad;
        continue;
      }
      points.insert(points.end(), {p.x, p.y, p.z});
    }
    if (points.size() / 3 >= kBatch || in.rdbuf()->in_avail() <= 0) flush();
  }
  flush();
  return bad ? kExitUsage : kExitOk;
}

int runDevices(const CommandLine&) {
  const std::vector<DeviceInfo> devices = listDevices();
  const DriverSelection& driver = selectedDriver();
  std::cout << "driver: " << driver.reason;
  if (driver.bundled) std::cout << " (" << driver.icd << ")";
  std::cout << "\n";
  if (devices.empty()) {
    std::cerr << "sdfc: error: no Vulkan device (install mesa-vulkan-drivers for lavapipe)\n";
    return kExitDevice;
  }
  for (const DeviceInfo& d : devices)
    std::cout << d.index << ": " << d.name << " (" << deviceTypeName(d.type) << ", " << d.driver
              << ")\n";
  return kExitOk;
}

}  // namespace sdfc
