#include "farm_support.h"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "render_layers.h"
#include "spirv/glsl_to_spirv.h"

namespace sdfc {

namespace {
// Source, -D values and every flag that changes the emitted shader.
std::string sceneHash(const CommandLine& cl, const CompiledScene& compiled) {
  std::string key = compiled.source ? compiled.source->text : std::string();
  key += '\0';
  for (const std::string& d : cl.defines) key += d + '\0';
  key += std::to_string(cl.no_bounds) + std::to_string(cl.force_bounds) + std::to_string(cl.no_fuse) +
         std::to_string(cl.optimize) + std::to_string(cl.paper_baseline) + std::to_string(cl.white_noise) +
         std::to_string(cl.count_evaluations) + std::to_string(cl.no_analytic_spheres) + cl.count_event;
  return farm::fingerprint(key.data(), key.size());
}
}  // namespace

ShardJob shardJobFor(const CommandLine& cl, const RenderOverrides& o, const CompiledScene& compiled) {
  ShardJob job;
  job.settings = renderSettingsFor(compiled, o);
  if (job.settings.view != gpu::kViewBeauty) throw farm::FarmError("shards render the beauty view only");
  job.plan.spp = job.settings.spp;
  job.plan.samples_per_pass = chooseSamplesPerPass(job.settings);
  job.plan.slices = uint32_t(std::max(cl.shards, 1));
  job.plan.fps = cl.fps;
  if (!cl.frames.empty()) std::tie(job.plan.first_frame, job.plan.last_frame) = farm::parseFrameRange(cl.frames);
  farm::splitSamples(job.plan.spp, job.plan.samples_per_pass, job.plan.slices);  // throws when too many

  farm::ShardHeader& h = job.common;
  h.scene_hash = sceneHash(cl, compiled);
  h.kernel_hash = compiled.spirv.empty() ? "" : farm::fingerprint(compiled.spirv.data(), compiled.spirv.size() * 4);
  h.version = kSdfcVersion;
  const RenderSettings& s = job.settings;
  h.settings = std::to_string(s.width) + "x" + std::to_string(s.height) + " spp=" + std::to_string(s.spp) +
               " bounces=" + std::to_string(s.max_bounces) + " light_samples=" + std::to_string(s.light_samples);
  h.width = s.width;
  h.height = s.height;
  h.seed = s.seed;
  h.spp = s.spp;
  h.samples_per_pass = job.plan.samples_per_pass;
  h.slices = job.plan.slices;
  h.layers = cl.layers;
  return job;
}

farm::ShardHeader expectedHeader(const ShardJob& job, uint32_t index) {
  const farm::ShardTask task = job.plan.task(index);
  farm::ShardHeader h = job.common;
  h.slice = task.slice;
  h.frame = task.frame;
  h.samples = task.samples;
  h.time = task.frame == farm::kNoFrame ? double(job.settings.time) : job.plan.frameTime(task.frame);
  return h;
}

std::string deviceText(const VulkanContext& context) { return context.deviceName(); }

std::string driverText(const VulkanContext& context) {
  const uint32_t v = context.properties.driverVersion, api = context.properties.apiVersion;
  char text[96];
  std::snprintf(text, sizeof text, "vendor %04x driver %u.%u.%u api %u.%u.%u", context.properties.vendorID,
                v >> 22, (v >> 12) & 0x3ff, v & 0xfff, VK_API_VERSION_MAJOR(api), VK_API_VERSION_MINOR(api),
                VK_API_VERSION_PATCH(api));
  return text;
}

bool shardComplete(const std::string& path, const farm::ShardHeader& expected, bool with_device) {
  if (!std::filesystem::exists(path)) return false;
  try {
    farm::ShardHeader found = farm::readShardHeader(path);
    if (!with_device) {
      found.device = expected.device;
      found.driver = expected.driver;
    }
    if (expected.kernel_hash.empty()) found.kernel_hash = "";
    return farm::headerMismatch(found, expected).empty() && found.slices == expected.slices &&
           found.slice == expected.slice && found.frame == expected.frame &&
           found.samples.begin == expected.samples.begin && found.samples.end == expected.samples.end &&
           found.time == expected.time;
  } catch (const farm::FarmError&) {
    return false;  // unreadable or foreign: render it again
  }
}

RenderOutput renderShard(Renderer& renderer, const CompiledScene& compiled, const ShardJob& job,
                         farm::ShardImage& shard, const ProgressCallback& progress,
                         const std::atomic<bool>* interrupt) {
  const farm::ShardHeader& header = shard.header;
  RenderSettings settings = job.settings;
  settings.time = static_cast<float>(header.time);
  settings.first_sample = header.samples.begin;
  settings.spp = header.samples.count();
  settings.max_samples_per_pass = job.plan.samples_per_pass;
  settings.keep_sums = true;
  // The centre ray's layers are read once, by the shard that holds sample 0.
  const bool ray_layers = header.layers && header.samples.begin == 0;
  RenderOutput out = renderer.render(cameraFor(compiled.scene), settings, progress, interrupt);
  const size_t pixels = out.color_sums.size() / 4;
  // r, g, b; alpha is 1 without layers, the squared luminance with them.
  const uint32_t stride = header.sumsPerPixel();
  shard.sums.resize(pixels * stride);
  for (size_t p = 0; p < pixels; ++p)
    for (uint32_t c = 0; c < stride; ++c) shard.sums[p * stride + c] = out.color_sums[p * 4 + c];
  std::vector<SampleSum>().swap(out.color_sums);
  shard.features.clear();
  if (ray_layers && !out.interrupted)
    shard.features = layerRayChannels(compiled, cameraFor(compiled.scene), settings, out);
  return out;
}

}  // namespace sdfc
