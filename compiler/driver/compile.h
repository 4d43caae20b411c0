// The whole compiler as one call: .sdf text in, checked scene, GLSL and
// validated SPIR-V out, with the time each stage took.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "check/checker.h"
#include "diag/diagnostics.h"
#include "emit/glsl_emitter.h"
#include "ir/scene.h"
#include "passes/passes.h"

namespace sdfc {

// The instances' data (records, grid, hierarchy: EmitResult::scene_data) is
// one storage buffer, and 2^27 bytes is the maxStorageBufferRange Vulkan
// guarantees on every device (lavapipe reports exactly that). `check`,
// `compile` and everything else refuse more, so a scene that checks renders
// on any device; docs/language.md gives what fits (about a million spheres).
constexpr size_t kMaxSceneDataBytes = size_t(1) << 27;

struct CompileOptions {
  CheckOptions check;
  EmitOptions emit;
  bool fuse_transforms = true;
  // compileSource moves a far scene to the camera's frame (scene.origin).
  bool camera_frame = true;
  InstancingOptions instancing;
  bool produce_spirv = true;
  bool optimize_spirv = false;
  // false: SPIR-V comes out unvalidated and the caller runs validateSpirv
  // before it reaches a driver (sdfc view, alongside pipeline creation).
  bool validate_spirv = true;
  // The on-disk SPIR-V cache (spirv/spirv_cache.h); off unless a front end asks
  // (the command line does, unless --no-cache), so a library user or a test
  // never touches a user's cache. `cache_version` (sdfc's) is part of the key.
  bool spirv_cache = false;
  std::string cache_version;
  // kMaxSceneDataBytes; lower only in tests (a small scene then meets it).
  size_t max_scene_data_bytes = kMaxSceneDataBytes;
};

struct StageTimes {
  // spirv: glslang with validation (or the cache lookup); validate: the part of
  // it the validator took.
  double parse = 0, check = 0, passes = 0, emit = 0, spirv = 0, validate = 0;
  bool spirv_cached = false;  // the SPIR-V came from the on-disk cache
  double device_emit = 0;     // `render`: emitted again for a GPU once the device was known
  double total() const { return parse + check + passes + emit + spirv; }
};

struct CompiledScene {
  std::unique_ptr<SourceFile> source;  // diagnostics point into it
  ir::Scene scene;
  EmitResult emitted;
  std::vector<std::uint32_t> spirv;
  std::string spirv_cache_key;  // with CompileOptions::spirv_cache: the entry's key
  StageTimes times;
  BoundsPlan bounds_plan;  // compileSource on a CPU device (EmitOptions::planned_bounds)
  bool ok = false;  // no errors and (if asked) SPIR-V produced
};

// `text` is the file's content; `path` names it in diagnostics.
CompiledScene compileSource(const std::string& path, std::string text, const CompileOptions& options,
                            Diagnostics& diags);
// Reads `path` first; a file that cannot be read is a diagnostic.
CompiledScene compileFile(const std::string& path, const CompileOptions& options, Diagnostics& diags);

// Parse and check only (no emission): for `sdfc check`, `eval` and `mesh`.
CompiledScene checkSource(const std::string& path, std::string text, const CompileOptions& options,
                          Diagnostics& diags);

}  // namespace sdfc
