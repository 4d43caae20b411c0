// The subcommands of `sdfc`: their options (filled by CLI11) and their runs.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "api/scene.h"

// Only the files that build the options include CLI11: its header alone takes
// about 8 s to compile in every file that includes it.
namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace sdfc {

inline constexpr const char* kSdfcVersion = api::kVersion;

// The exit codes (kExitOk ... kExitInterrupted) are api/scene.h's.

struct CommandLine {
  std::string command;
  std::string input;
  std::string output;
  std::vector<std::string> defines;  // -D name=value
  std::string diagnostics_format = "text";
  bool werror = false;
  std::vector<std::string> warning_options;  // -W values: no-NAME, error
  int error_limit = 20;                       // --error-limit (diag/diagnostics.h kDefaultErrorLimit)
  // compile
  std::string emit = "glsl";
  bool line_directives = false;
  int timings = 0;  // compile: repeat the compilation this many times and print stage times
  bool no_bounds = false;
  int instance_threshold = 32;  // see passes/instancing.cpp; 0 = always inline
  bool for_cpu = false;       // compile: the kernel for a CPU device (planned bounds)
  bool force_bounds = false;  // render: bounds even on a CPU device
  bool no_fuse = false;
  bool no_analytic_spheres = false;
  bool prune = false;  // --prune: the root union's prune grid (passes/prune_grid.cpp)
  std::string mesh_mode;  // --mesh-mode exact|grid (empty: the compiler chooses per mesh)
  bool optimize = false;
  bool no_cache = false;       // --no-cache: bypass the on-disk SPIR-V and pipeline caches
  bool stage_timings = false;  // render, view: --timings, every fixed stage's time
  bool paper_baseline = false;
  bool white_noise = false;
  bool count_evaluations = false;
  std::string count_event;  // --count-event kind.quantity (emit/glsl_emitter.h)
  // render
  std::string size;
  int spp = 0, bounces = -1, light_samples = -1;
  std::string denoiser;  // empty: the command's default (render nlr, view none)
  std::string denoise_aovs = "auto";  // the denoiser's features: auto | jittered | specular | centre
  std::vector<float> denoise_select;  // nlm/nlr last-pass strengths chosen per pixel; empty: off
  // Adaptive sampling at the same mean spp (runtime/adaptive.h, docs/adaptive.md).
  bool adaptive = false;
  bool layers = false;  // render --layers: one multi-channel EXR (docs/layers.md)
  std::string adaptive_estimate = "variance";  // uniform | variance | denoised
  float adaptive_share = 0.25f;                // first phase, of spp
  float adaptive_cap = 8.0f;                   // a pixel's total, x the first phase
  uint32_t adaptive_block = 8;                 // pixels per block side
  float adaptive_power = 0.5f;                 // extra samples ~ estimate^power
  std::string adaptive_budget = "samples";     // samples | time (cost-aware)
  float adaptive_cost_offset = 1.0f;           // cost = steps + this x mean steps
  std::string adaptive_cost = "iterations";    // time budget's cost: iterations | steps
  std::string view = "beauty";
  double time = 0;
  std::string frames;
  unsigned seed = 0;
  int device = -1;
  double exposure = 0;
  bool aces = false;                 // the old spelling of --tonemap aces
  std::string tonemap = "neutral";   // PNG and view: neutral | aces | linear (runtime/image_io.h)
  bool quiet = false;
  // render shards (farm/): task shard_index of a job cut into `shards` per image
  int shards = 0;
  int shard_index = -1;
  double fps = 24;
  // merge (shard files or directories) and fmt (.sdf files)
  std::vector<std::string> inputs;
  bool png = false;
  // farm submit / status
  std::string farm_command;
  std::string partition, account, time_limit, video;
  std::vector<std::string> sbatch_args;
  int retries = 1;
  int max_running = 0;
  bool dry_run = false;
  // view
  std::string script;     // scripted input (viewer/script.h)
  std::string frame_log;  // one line per presented frame
  bool no_dynamic_resolution = false;
  // eval
  std::string points;
  bool gradient = false;
  bool material = false;
  // mesh
  int resolution = 128;
  double voxel_size = 0;
  std::string box;
  // export
  std::string export_target = "html";
  int max_data_rows = 2048;  // the scene-data texture's rows (emit/glsl_es.h kEsMaxDataRows)
  // fmt
  bool check_format = false;
  bool write_in_place = false;
  bool lsp_stdio = true;  // lsp: --stdio, the only transport
};

void registerCommands(CLI::App& app, CommandLine& cl);
int runCommand(const CommandLine& cl);

int runCheck(const CommandLine& cl);
int runCompile(const CommandLine& cl);
int runRender(const CommandLine& cl);
int runEval(const CommandLine& cl);
int runMesh(const CommandLine& cl);
int runExport(const CommandLine& cl);
int runDevices(const CommandLine& cl);
int runMerge(const CommandLine& cl);
int runFarm(const CommandLine& cl);
int runFmt(const CommandLine& cl);
int runLsp(const CommandLine& cl);
int runView(const CommandLine& cl);  // cmd_view.cpp (links the viewer)

}  // namespace sdfc
