// The render defaults, decided in one place: what samples per pixel, denoiser
// and sampling a render gets from the scene's own render() and the options the
// user gave, and why. `sdfc render`, the Python package's render() and
// `sdfc view` all ask here, so they cannot drift apart (issue 48). The values
// themselves are measured in bench/results/DEFAULT_CHOICE.md.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "denoise.h"
#include "ir/scene.h"
#include "shader_interface.h"

namespace sdfc {

// What the user asked for explicitly; an unset field takes its default.
struct RenderRequest {
  std::optional<int> spp;            // --spp, spp=
  std::optional<Denoiser> denoiser;  // --denoise, denoise=
  uint32_t view = gpu::kViewBeauty;
  bool layers = false;    // --layers: the raw mean and the primary ray's layers
  bool adaptive = false;  // --adaptive
  // Frames of the render (--frames A-B); more than one: an animation, whose
  // filter runs every frame and gets nlr-fast by default.
  size_t frames = 1;
  // --denoise-select: per-pixel strengths of nlm's and nlr's last pass (nlr-fast's
  // single pass has none), so an animation asking for it keeps nlr.
  bool denoise_select = false;
};

// The settings chosen, and the one line that says why.
struct RenderChoice {
  // Samples per pixel of the beauty view (the other views take one sample);
  // 0 when neither the request nor a scene gives it (the scene is not read yet).
  uint32_t spp = 0;
  // The filter a beauty image is given to (renderImage leaves the other views,
  // and a 1-spp image under a variance-guided filter, as they are).
  Denoiser denoiser = Denoiser::Nlr;
  bool denoises = false;   // the beauty view, a filter, and enough samples for it
  bool adaptive = false;   // adaptive sampling runs (the beauty view only)
  // The kernel needs its feature outputs (normal, depth, albedo). Decided from
  // the request alone, never the scene's spp: `sdfc render` compiles the kernel
  // before the scene's settings are known.
  bool kernel_features = true;
  std::string reason;  // e.g. "16 spp + nlr denoiser: the scene's render() sets spp 16; ..."
};

// `scene`: the scene's render() settings, or null before the scene is read
// (then spp is the request's or 0, and the reason says "the scene's").
RenderChoice chooseRenderSettings(const RenderRequest& request, const ir::RenderSettings* scene);

// The samples the viewer accumulates while the camera is still: the same spp
// as a render (one for the debug views).
uint32_t viewTargetSpp(const RenderRequest& request, const ir::RenderSettings& scene);

}  // namespace sdfc
