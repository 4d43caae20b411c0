// The GLSL writer: checked, analysed scene in, one fragment shader out
// (docs/kernel_contract.md describes how the parts fit). It emits only what
// the scene uses: the primitives, operators, material models and light types
// that occur, named functions for definitions, and bounding-volume checks that
// skip costly subtrees while the point is far from them.
#pragma once
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "ir/scene.h"
#include "passes/passes.h"

namespace sdfc {

// Which view the kernel is specialised for (docs/kernel_contract.md, "Kernel
// variants"). All: one kernel for every view, chosen at run time by
// frame.view (the library default, for tests that draw several views from one
// pipeline). Beauty and Iterations hold the path tracer; the debug views
// (Normal, Steps, Depth, Albedo) trace only the primary ray: no sampling, no
// shading, no bounces. The numbering follows shader_interface.h's kView*.
enum class KernelView { Beauty = 0, Normal, Steps, Depth, Albedo, Iterations, All };

// "beauty", ..., "iterations", "all" -> the view; nullopt for anything else.
std::optional<KernelView> kernelViewFromName(const std::string& name);
const char* kernelViewName(KernelView view);

struct EmitOptions {
  KernelView view = KernelView::All;
  bool bounding_volumes = true;   // skip subtrees by their bounds
  // Without bounding_volumes (a CPU device): plan which checks pay and emit
  // those (Node::box_check, passes/bounds_plan.cpp); false: none. The front
  // ends turn it on where they adapt to a CPU device.
  bool planned_bounds = false;
  // The root union's parts pruned per cell (passes/prune_grid.cpp, planned by
  // compileSource; the emitter uses the root's grid). Off by default: on
  // lavapipe it costs more than it saves (bench/results/prune_grid.md).
  bool prune = false;
  bool line_directives = false;   // #line so glslang errors point at the .sdf
  bool sobol = true;              // low-discrepancy sampler (else PCG hash)
  bool with_kernel = true;        // false: scene code only (for tests and tools)
  // `render --layers` (docs/layers.md): the beauty kernel's a is the mean of the
  // samples' squared luminance (SDFC_LAYERS), the variance layer's moment.
  bool layers = false;
  MarchPolicy march;
  // Subtrees at least this costly (in primitive evaluations) get a bound check.
  double bound_cost_threshold = 3;
  // Instrumentation: every primitive evaluation a lane really performs adds
  // one to the kernel's loop counter, so `--view iterations` shows the
  // logical work (lavapipe masks skipped code rather than jumping over it).
  bool count_evaluations = false;
  // Instrumentation (`--count-event`, docs/design/large_scenes.md): "kind.quantity"
  // names one per-pixel event count the iterations view writes to green.
  std::string count_event;
  // Planes directly in the scene are intersected analytically by the kernel
  // (kernel emission only: sdScene then leaves them out).
  bool analytic_planes = true;
  // So are spheres there (bare or under a translate/rotate/uniform scale) of a
  // non-emissive material in a scene without glass: a ray marching inside glass
  // does not see analytic surfaces, and a light needs its own surface for
  // shadow rays.
  bool analytic_spheres = true;
  // false: a beauty kernel that records no features (SDFC_NO_AOVS): no normal,
  // depth or albedo, no jittered sums; attachment 2's w still holds the AOV
  // ray's march steps. For a render nothing reads the features of (no
  // denoiser); a denoiser fed by it would see zeros. Other views ignore it.
  bool aovs = true;
  // A finite marched part gets a bounding box: march() only steps where the
  // ray is inside it, so rays that miss or leave the scene stop at once
  // (kernel emission only).
  bool scene_box = true;
  // Non-empty (sdfc's version): meshes' grids go through the on-disk cache
  // (meshin/mesh_grid_cache.h), as the SPIR-V does when CompileOptions asks.
  std::string mesh_grid_cache_version;
};

struct EmitStats {
  int bounded_subtrees = 0;       // bound checks emitted
  int functions = 0;              // named functions emitted
  int instance_sets = 0;          // Instances nodes emitted as data
  int traversals_per_evaluation = 0;  // hierarchy loops one scene evaluation may run
  std::set<std::string> features; // SDFC_* macros the scene turned on
};

struct EmitResult {
  std::string glsl;
  MarchLimits limits;
  EmitStats stats;
  // The storage buffer at set 0, binding 0 (vec4s): instance hierarchies and
  // records; empty when the scene has no Instances node (then no binding).
  std::vector<float> scene_data;
};

EmitResult emitGlsl(const ir::Scene& scene, const EmitOptions& options);

// A GLSL float literal that round-trips a float32 (9 significant digits).
std::string glslFloat(double v);

// --count-event names: "kind.quantity" with kind one of kCountEventKinds (all =
// every kind; the normal's lookups are its own kind) and quantity one of
// kCountEventQuantities: march segments (or shading events for `normal`), loop
// iterations, grid cell lookups, list entries tested, hierarchy visits, hits
// (a shadow ray's hit: blocked). The kernel counts paths' rays, not the AOV ray.
inline constexpr const char* kCountEventKinds[] = {"all", "primary", "bounce", "shadow", "normal"};
inline constexpr const char* kCountEventQuantities[] = {"segments", "iterations", "lookups",
                                                        "entries",  "visits",     "hits"};
// kind: -1 (all) or 0..3; false if the name is not one of the above.
bool countEventFromName(const std::string& name, int& kind, int& quantity);

}  // namespace sdfc
