// What `sdfc render --shards`, `sdfc merge` and `sdfc farm` share: the job's
// plan and the header fields that identify its shards, computed the same way on
// the submitting machine and on every node.
#pragma once
#include <string>

#include "cli_support.h"
#include "renderer.h"
#include "scene_render.h"
#include "shard_file.h"
#include "vulkan_context.h"

namespace sdfc {

struct ShardJob {
  farm::ShardPlan plan;
  farm::ShardHeader common;  // everything but the per-shard fields
  RenderSettings settings;   // of the whole image (spp = plan.spp)
};

// The plan of `cl` (--shards, --frames A-B, --fps) for a compiled scene. Throws
// farm::FarmError (more shards than passes, bad frame range).
ShardJob shardJobFor(const CommandLine& cl, const RenderOverrides& o, const CompiledScene& compiled);

// The header task `index` writes (device and driver from `context` when given).
farm::ShardHeader expectedHeader(const ShardJob& job, uint32_t index);

// Device and driver as recorded in shards.
std::string deviceText(const VulkanContext& context);
std::string driverText(const VulkanContext& context);

// True when `path` holds a shard equal to `expected` in everything a merge checks
// (device and driver only when `with_device`): a finished task that resuming skips.
bool shardComplete(const std::string& path, const farm::ShardHeader& expected, bool with_device);

// Renders the shard `shard.header` describes (its frame's time, its sample range,
// the whole image's pass split) and leaves its exact sums in `shard.sums` (r, g,
// b; with layers also the squared luminance) and, with layers in the shard
// holding sample 0, the centre ray's layers in `shard.features`.
RenderOutput renderShard(Renderer& renderer, const CompiledScene& compiled, const ShardJob& job,
                         farm::ShardImage& shard, const ProgressCallback& progress = {},
                         const std::atomic<bool>* interrupt = nullptr);

// `sdfc render --shards K --shard-index I -o DIR`.
int runRenderShard(const CommandLine& cl, const RenderOverrides& o);
LoadedScene compileForDevice(const CommandLine& cl, const VulkanContext& context, const RenderOverrides& o);
// The same before the device is known: compiled for a CPU device (lavapipe);
// adaptToDevice emits it again, with bounding volumes, when the device is a GPU.
// `features` false: the kernel without AOV features (EmitOptions::aovs).
LoadedScene compileForCpuDevice(const CommandLine& cl, const RenderOverrides& o, bool features = true);
void adaptToDevice(LoadedScene& loaded, const CommandLine& cl, const VulkanContext& context,
                   const RenderOverrides& o, bool features = true);

}  // namespace sdfc
