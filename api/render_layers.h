// `sdfc render -o x.exr --layers`: the channels of one multi-channel EXR
// (docs/layers.md). The beauty and the variance come from the samples (the
// kernel compiled with EmitOptions::layers keeps their squared luminance in a);
// albedo, normal and depth from the unjittered primary ray the renderer draws
// for its AOVs (the same ray and values as --view albedo / normal / depth);
// the material and object ids from the float64 evaluator at that ray's hit.
#pragma once
#include <vector>

#include "driver/compile.h"
#include "exr_channels.h"
#include "renderer.h"

namespace sdfc {

// Channel values where the primary ray met nothing.
constexpr float kLayersMissDepth = 1e10f;  // Z, as Blender writes the sky
constexpr float kLayersMissId = -1.0f;     // material, object

// `out` from a render of `compiled` (its kernel emitted with layers) whose AOV
// ray was read (not jittered); `settings` its size and time. The channels of
// layerSampleChannels and layerRayChannels together.
std::vector<ExrChannel> renderLayers(const CompiledScene& compiled, const CameraDesc& camera,
                                     const RenderSettings& settings, const RenderOutput& out);

// R, G, B and variance.Y from the mean colour of `samples` samples per pixel (a:
// their mean squared luminance): what `sdfc merge` computes from summed shards.
std::vector<ExrChannel> layerSampleChannels(const FloatImage& color, uint64_t samples);
// albedo.*, N.*, Z, material, object: the centre ray's, the same in every pass
// (what the shard holding sample 0 stores; farm/shard_file.h).
std::vector<ExrChannel> layerRayChannels(const CompiledScene& compiled, const CameraDesc& camera,
                                         const RenderSettings& settings, const RenderOutput& out);
// Their names, as layerRayChannels returns them.
extern const char* const kLayerRayChannelNames[9];

// The top-level shape the ray (origin o, unit direction d) enters at its hit
// distance t (its index among the scene's top-level shapes) and its material:
// the nearest shape, and that shape's material, at a point just past the hit.
void layerIdsAt(const ir::Scene& scene, double time, const glm::dvec3& o, const glm::dvec3& d, double t,
                int& object, int& material);

}  // namespace sdfc
