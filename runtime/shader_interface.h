// The one place where the C++ runtime and the generated GLSL agree on layout.
// The compiler pastes this file verbatim into every emitted shader; the runtime
// includes it as C++. Keep it valid in both languages.
#ifndef SDFC_SHADER_INTERFACE_H
#define SDFC_SHADER_INTERFACE_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace sdfc::gpu {
using vec4 = glm::vec4;
using uint = std::uint32_t;
#define SDFC_CONST constexpr
#else
#define SDFC_CONST const
#endif

// Views selected by FrameParams.view. Beauty is the path-traced radiance; the
// others are the paper's debug figures (normals, march steps, depth, albedo)
// and a loop-iteration counter used to prove lavapipe's loop cap is never hit.
SDFC_CONST uint kViewBeauty = 0u;
SDFC_CONST uint kViewNormal = 1u;
SDFC_CONST uint kViewSteps = 2u;
SDFC_CONST uint kViewDepth = 3u;
SDFC_CONST uint kViewAlbedo = 4u;
SDFC_CONST uint kViewIterations = 5u;

// Lavapipe silently ends a shader invocation's loops after this many
// iterations in total (Mesa's LP_MAX_TGSI_LOOP_ITERATIONS).
SDFC_CONST uint kLavapipeLoopCap = 65535u;

// Push constants: 116 bytes, under the 128 every Vulkan device guarantees.
struct FrameParams {
  vec4 cam_origin;   // xyz: eye; w: tan(vertical fov / 2)
  vec4 cam_right;    // xyz: unit right; w: aperture radius (0 = pinhole)
  vec4 cam_up;       // xyz: unit up; w: focus distance
  vec4 cam_forward;  // xyz: unit forward; w: time in seconds
  uint width;
  uint height;
  uint sample_base;  // index of the first sample this pass takes
  uint sample_count; // samples per pixel this pass takes
  uint seed;
  uint view;         // one of kView*
  uint max_bounces;
  uint light_samples;
  // Framebuffer origin within the image: the renderer draws the image in row
  // bands with a band-sized target (memory), and gl_FragCoord is band-relative.
  // Pixel = gl_FragCoord + (tile_x, tile_y), so random numbers stay per image pixel.
  uint tile_x;
  uint tile_y;
  // Instance-hierarchy visits allowed per scene evaluation this pass (the
  // renderer derives it from the loop cap; see runtime/loop_budget.h).
  uint traversal_visits;
  // Non-zero: the path tracer skips its unjittered AOV ray (attachments 1 and 2
  // are then zero). The renderer sets it on beauty passes whose AOVs it does
  // not read: they are the same every pass, and the ray costs a primary march.
  // kAovJittered: no AOV ray; the AOVs are the means of the pass's jittered
  // samples' first hits instead (see below).
  uint skip_aov_ray;
  // Non-zero: the camera's origin is inside a solid (pinhole cameras; decided
  // per frame and time on the CPU by runtime/camera_inside.h with the kernel's
  // float threshold). Thin-lens kernels test each ray's origin instead.
  uint camera_inside;
};

// Fragment outputs (all RGBA32F attachments, one pixel per invocation):
//  location 0: beauty -> mean radiance of this pass's samples (rgb), a = 1;
//              debug views -> the view's value in rgb.
//  location 1: primary hit: world normal (xyz), hit distance (w; -1 if missed).
//  location 2: primary hit: albedo (rgb), march steps of the primary ray (w).
// With skip_aov_ray == kAovJittered (beauty): locations 1 and 2 hold the means
// over the pass's samples of normal, hit distance, albedo (0 where a sample
// missed) and march steps, and location 0's a the fraction of samples that hit.
SDFC_CONST uint kAovJittered = 2u;

#ifdef __cplusplus
static_assert(sizeof(FrameParams) == 116, "push constant layout");
}  // namespace sdfc::gpu
#endif
#endif
