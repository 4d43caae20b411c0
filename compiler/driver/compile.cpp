#include "driver/compile.h"

#include <chrono>
#include <unordered_set>
#include <vector>

#include "check/checker.h"

#include "passes/passes.h"
#include "spirv/glsl_to_spirv.h"
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

CompiledScene frontEnd(const std::string& path, std::string text, const CompileOptions& options,
                       Diagnostics& diags) {
  CompiledScene out;
  out.source = std::make_unique<SourceFile>(path, std::move(text));
  auto t0 = std::chrono::steady_clock::now();
  std::vector<Comment> comments;
  ast::File ast = parse(*out.source, diags, &comments);
  applyWarningPragmas(ast, *out.source, comments, diags);
  out.times.parse = secondsSince(t0);
  t0 = std::chrono::steady_clock::now();
  out.scene = check(ast, *out.source, diags, options.check);
  out.times.check = secondsSince(t0);
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
  }
  out.times.passes = secondsSince(t0);
  return out;
}

}  // namespace

CompiledScene checkSource(const std::string& path, std::string text, const CompileOptions& options,
                          Diagnostics& diags) {
  CompiledScene out = frontEnd(path, std::move(text), options, diags);
  out.ok = !diags.hasErrors() && out.scene.root;
  return out;
}

CompiledScene compileSource(const std::string& path, std::string text, const CompileOptions& options,
                            Diagnostics& diags) {
  CompiledScene out = frontEnd(path, std::move(text), options, diags);
  if (diags.hasErrors() || !out.scene.root) return out;
  auto t0 = std::chrono::steady_clock::now();
  out.emitted = emitGlsl(out.scene, options.emit);
  out.times.emit = secondsSince(t0);
  if (options.produce_spirv) {
    t0 = std::chrono::steady_clock::now();
    SpirvResult spv = glslToSpirv(out.emitted.glsl, ShaderStage::Fragment, path + ".glsl",
                                  options.optimize_spirv, options.validate_spirv);
    out.times.spirv = secondsSince(t0);
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
