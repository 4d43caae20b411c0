#include "render_defaults.h"

#include <algorithm>

#include "scene_render.h"

namespace sdfc {
namespace {

const char* viewName(uint32_t view) {
  switch (view) {
    case gpu::kViewBeauty: return "beauty";
    case gpu::kViewNormal: return "normal";
    case gpu::kViewSteps: return "steps";
    case gpu::kViewDepth: return "depth";
    case gpu::kViewAlbedo: return "albedo";
    case gpu::kViewIterations: return "iterations";
    default: return "debug";
  }
}

}  // namespace

RenderChoice chooseRenderSettings(const RenderRequest& request, const ir::RenderSettings* scene) {
  RenderChoice c;
  const bool beauty = request.view == gpu::kViewBeauty;
  std::string spp_why;
  if (request.spp) {
    c.spp = uint32_t(*request.spp);
    spp_why = "--spp " + std::to_string(c.spp);
  } else if (scene) {
    c.spp = uint32_t(std::max(1, scene->spp));
    spp_why = scene->spp_given ? "the scene's render() sets spp " + std::to_string(c.spp)
                               : "the default spp " + std::to_string(c.spp) + " (the scene's render() sets none)";
  } else {
    spp_why = "the scene's spp";
  }
  // Beauty renders are denoised by default: nlr's weights fade with the
  // estimated variance, so a converged pixel is left as it is (docs/denoise.md).
  // --layers: the raw mean (a compositor's denoiser wants it and the variance).
  std::string denoiser_why;
  if (request.layers) {
    c.denoiser = Denoiser::None;
    denoiser_why = "--layers writes the raw mean (docs/layers.md)";
  } else if (request.denoiser) {
    c.denoiser = *request.denoiser;
    denoiser_why = std::string("--denoise ") + denoiserName(c.denoiser);
  } else if (request.frames > 1 && !request.denoise_select) {
    // The filter runs once a frame: nlr-fast's time is a smaller share of the
    // frame's, and the samples that time buys lower the error more than nlr's
    // wider window does (bench/results/anim_denoise.md).
    c.denoiser = Denoiser::NlrFast;
    denoiser_why = "nlr-fast is an animation's default denoiser (nlr in one pass, about 40% of its time; docs/denoise.md)";
  } else {
    c.denoiser = Denoiser::Nlr;
    denoiser_why = request.frames > 1 ? "nlr is the default denoiser for --denoise-select (nlr-fast, an "
                                        "animation's, has no last pass to select in; docs/denoise.md)"
                                      : "nlr is the default denoiser (docs/denoise.md)";
  }
  c.adaptive = request.adaptive && beauty;
  // Without two halves (1 spp) a variance-guided filter leaves the image as it is.
  const auto enough_samples = [&](uint32_t spp) { return !needsVariance(c.denoiser) || spp >= 2; };
  c.denoises = beauty && c.denoiser != Denoiser::None && (c.spp == 0 || enough_samples(c.spp));
  // With the request's spp, or any number of samples when it gives none.
  ImageOptions probe;
  probe.denoiser = c.denoiser;
  probe.layers = request.layers;
  c.kernel_features = request.adaptive ||
                      imageReadsFeatures(request.view, request.spp ? uint32_t(*request.spp) : UINT32_MAX, probe);

  if (!beauty) {
    c.reason = std::string("1 sample, no denoiser: the ") + viewName(request.view) +
               " view takes one sample and is never denoised (docs/debug_views.md)";
    return c;
  }
  const std::string spp_text = c.spp ? std::to_string(c.spp) : std::string("the scene's");
  c.reason = spp_text + " spp" + (c.adaptive ? " (mean, adaptive)" : "") + " + " +
             (c.denoiser == Denoiser::None ? std::string("no denoiser")
                                           : std::string(denoiserName(c.denoiser)) + " denoiser") +
             ": " + spp_why + "; " + denoiser_why;
  if (c.denoiser != Denoiser::None && !c.denoises)
    c.reason += std::string("; ") + denoiserName(c.denoiser) + " leaves a 1-spp image as it is (no second half)";
  if (c.adaptive) c.reason += "; --adaptive spends the samples where the noise is (docs/adaptive.md)";
  return c;
}

uint32_t viewTargetSpp(const RenderRequest& request, const ir::RenderSettings& scene) {
  if (request.view != gpu::kViewBeauty) return 1;
  return chooseRenderSettings(request, &scene).spp;
}

}  // namespace sdfc
