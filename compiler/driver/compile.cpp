#include "driver/compile.h"

#include <chrono>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "check/checker.h"

#include "passes/passes.h"
#include "spirv/glsl_to_spirv.h"
#include "spirv/spirv_cache.h"
#include "syntax/parser.h"
#include "syntax/pragmas.h"

namespace sdfc {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Shape nodes that become shader code, each shared one once. Copies grouped
// into an Instances node are data; only its template is code.
size_t codeNodeCount(const ir::Scene& scene) {
  std::unordered_set<const ir::Node*> seen;
  std::vector<const ir::Node*> stack = {scene.root.get()};
  while (!stack.empty()) {
    const ir::Node* n = stack.back();
    stack.pop_back();
    if (!seen.insert(n).second) continue;
    for (const ir::NodeRef& c : n->children) stack.push_back(c.get());
  }
  return seen.size();
}

// Shader code nodes under `n` with every use of a shared node (a definition)
// counted, an instance set's templates once (its copies are data): what the
// driver inlines. Capped just past kMaxExpandedNodes (a doubling chain's
// count overflows otherwise); shared nodes are counted once each (memo).
size_t expandedCodeNodes(const ir::Node& n, std::unordered_map<const ir::Node*, size_t>& sizes) {
  if (auto it = sizes.find(&n); it != sizes.end()) return it->second;
  size_t total = 1;
  for (const ir::NodeRef& c : n.children) total = std::min(total + expandedCodeNodes(*c, sizes), kMaxExpandedNodes + 1);
  sizes[&n] = total;
  return total;
}

const ir::Node* firstInstances(const ir::Scene& scene) {
  std::unordered_set<const ir::Node*> seen;
  std::vector<const ir::Node*> stack = {scene.root.get()};
  while (!stack.empty()) {
    const ir::Node* n = stack.back();
    stack.pop_back();
    if (!n || !seen.insert(n).second) continue;
    if (n->kind == ir::NodeKind::Instances) return n;
    for (const ir::NodeRef& c : n->children) stack.push_back(c.get());
  }
  return nullptr;
}

// The same limit for check and render: the data is what the emitter builds.
bool sceneDataFits(const ir::Scene& scene, const EmitResult& emitted, size_t limit, Diagnostics& diags) {
  const size_t bytes = emitted.scene_data.size() * sizeof(float);
  if (bytes <= limit) return true;
  const ir::Node* at = firstInstances(scene);
  diags.error(at ? at->range : scene.root->range,
              "the instances' data (their records, grid and hierarchy) would take " + std::to_string(bytes) +
                  " bytes; at most " + std::to_string(limit) +
                  " (128 MiB, the storage buffer every Vulkan device offers): use fewer copies, about a "
                  "million spheres fit");
  return false;
}

CompiledScene frontEnd(const std::string& path, std::string text, const CompileOptions& options,
                       Diagnostics& diags) {
  CompiledScene out;
  out.source = std::make_unique<SourceFile>(path, std::move(text));
  auto t0 = std::chrono::steady_clock::now();
  {
    // The syntax tree ends here: nothing after the checker points into it, and
    // at 100,000 parts it holds 370 MB that the passes and the emitter would
    // otherwise add to.
    std::vector<Comment> comments;
    ast::File ast = parse(*out.source, diags, &comments);
    applyWarningPragmas(ast, *out.source, comments, diags);
    out.times.parse = secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    out.scene = check(ast, *out.source, diags, options.check);
    out.times.check = secondsSince(t0);
  }
  if (diags.hasErrors() || !out.scene.root) return out;
  t0 = std::chrono::steady_clock::now();
  if (options.fuse_transforms) fuseTransforms(out.scene);
  // Bounds first (grouping needs the templates'), then again over the new nodes.
  analyze(out.scene, diags);
  if (!diags.hasErrors()) {
    formInstances(out.scene, options.instancing);
    Diagnostics quiet;  // the second run repeats the first one's warnings
    analyze(out.scene, quiet);
    // Compile time (glslang, then the driver's pipeline) grows faster than
    // the shader: 1000 translated spheres as code take 1.3 s to SPIR-V, 4000
    // take 17 s. Refuse, with the size, instead of running for minutes.
    const size_t nodes = codeNodeCount(out.scene);
    if (nodes > static_cast<size_t>(kMaxSceneNodes))
      diags.error(out.scene.root->range,
                  "the scene has " + std::to_string(nodes) +
                      " shapes and operations as shader code (a named shape counts once; copies "
                      "of one shape with constant placements become data); at most " +
                      std::to_string(kMaxSceneNodes) +
                      ", as compile time grows faster than that; use 'instances' or 'repeat' for many "
                      "copies");
    // Written out, each use of a definition is a copy of its code (the driver
    // inlines every call): a definition that uses the previous one twice, 20
    // times over, must not check. Copies that became data count once.
    std::unordered_map<const ir::Node*, size_t> sizes;
    size_t expanded = 0;
    for (const ir::NodeRef& c : out.scene.root->children) {
      expanded += expandedCodeNodes(*c, sizes);
      if (expanded > kMaxExpandedNodes) {
        diags.error(c->range, "the scene grows to more than " + std::to_string(kMaxExpandedNodes) +
                                  " shapes and operations here, with every use of a definition written out "
                                  "(each use is evaluated at every point); use fewer nested copies, or "
                                  "'instances' or 'repeat' for many copies");
        break;
      }
    }
  }
  out.times.passes = secondsSince(t0);
  return out;
}

}  // namespace

CompiledScene checkSource(const std::string& path, std::string text, const CompileOptions& options,
                          Diagnostics& diags) {
  CompiledScene out = frontEnd(path, std::move(text), options, diags);
  out.ok = !diags.hasErrors() && out.scene.root;
  // Instances' data is built by the emitter; building it here keeps `check`
  // to the limit a render meets (an 8M-row file used to check, then fail 30 s
  // into the render).
  if (out.ok && firstInstances(out.scene)) {
    auto t0 = std::chrono::steady_clock::now();
    out.ok = sceneDataFits(out.scene, emitGlsl(out.scene, options.emit), options.max_scene_data_bytes, diags);
    out.times.emit = secondsSince(t0);
  }
  return out;
}

CompiledScene compileSource(const std::string& path, std::string text, const CompileOptions& options,
                            Diagnostics& diags) {
  CompiledScene out = frontEnd(path, std::move(text), options, diags);
  if (diags.hasErrors() || !out.scene.root) return out;
  auto t0 = std::chrono::steady_clock::now();
  // The shader works in the camera's frame when that gains precision; eval,
  // mesh and check (checkSource) stay in world coordinates.
  if (options.camera_frame) {
    Diagnostics quiet;
    rebaseToCamera(out.scene, quiet);
  }
  EmitOptions emit = options.emit;
  // A CPU device: the bounding-volume checks that pay on this scene.
  if (!emit.bounding_volumes && emit.planned_bounds && emit.with_kernel)
    out.bounds_plan = planBoundChecks(out.scene, emit.march, emit.bound_cost_threshold);
  // `--prune`: each march step evaluates only the parts near it.
  if (emit.with_kernel && emit.prune) planPruneGrid(out.scene);
  if (options.spirv_cache) emit.mesh_grid_cache_version = options.cache_version;
  out.emitted = emitGlsl(out.scene, emit);
  out.times.emit = secondsSince(t0);
  if (!sceneDataFits(out.scene, out.emitted, options.max_scene_data_bytes, diags)) return out;
  if (options.produce_spirv) {
    t0 = std::chrono::steady_clock::now();
    SpirvResult spv =
        options.spirv_cache
            ? cachedGlslToSpirv(out.emitted.glsl, ShaderStage::Fragment, path + ".glsl",
                                options.optimize_spirv, options.validate_spirv, options.cache_version)
            : glslToSpirv(out.emitted.glsl, ShaderStage::Fragment, path + ".glsl",
                          options.optimize_spirv, options.validate_spirv);
    out.times.spirv = secondsSince(t0);
    out.times.validate = spv.validate_seconds;
    out.times.spirv_cached = spv.from_cache;
    out.spirv_cache_key = spv.cache_key;
    if (!spv.ok()) {
      // A shader the compiler wrote that glslang rejects is a compiler bug;
      // say so, with glslang's words.
      diags.error({}, "internal error: the generated shader does not compile:\n" + spv.log);
      return out;
    }
    out.spirv = std::move(spv.words);
  }
  out.ok = true;
  return out;
}

CompiledScene compileFile(const std::string& path, const CompileOptions& options, Diagnostics& diags) {
  std::unique_ptr<SourceFile> file = readSourceFile(path);
  if (!file) {
    diags.error({}, "cannot read '" + path + "'");
    return {};
  }
  return compileSource(path, std::move(file->text), options, diags);
}

}  // namespace sdfc
