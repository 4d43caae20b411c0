// The render defaults (api/render_defaults.h): one decision for `sdfc render`,
// the Python package and the viewer. tests/render_defaults_test.py checks that
// the command line and Python print and use the same; this pins the rules.
#include <gtest/gtest.h>

#include "render_defaults.h"
#include "scene_render.h"

namespace sdfc {
namespace {

ir::RenderSettings sceneWith(std::optional<int> spp) {
  ir::RenderSettings r;
  if (spp) {
    r.spp = *spp;
    r.spp_given = true;
  }
  return r;
}

TEST(RenderDefaults, SppFromTheRequestThenTheSceneThenTheDefault) {
  RenderRequest request;
  const ir::RenderSettings unset = sceneWith(std::nullopt), set = sceneWith(64);
  EXPECT_EQ(chooseRenderSettings(request, &unset).spp, 16u);
  EXPECT_EQ(chooseRenderSettings(request, &set).spp, 64u);
  EXPECT_EQ(chooseRenderSettings(request, nullptr).spp, 0u);  // not read yet
  request.spp = 4;
  EXPECT_EQ(chooseRenderSettings(request, &set).spp, 4u);
  EXPECT_EQ(chooseRenderSettings(request, nullptr).spp, 4u);
}

TEST(RenderDefaults, ReasonSaysWhoDecided) {
  RenderRequest request;
  const ir::RenderSettings unset = sceneWith(std::nullopt), set = sceneWith(16);
  EXPECT_EQ(chooseRenderSettings(request, &set).reason,
            "16 spp + nlr denoiser: the scene's render() sets spp 16; nlr is the default denoiser "
            "(docs/denoise.md)");
  EXPECT_EQ(chooseRenderSettings(request, &unset).reason,
            "16 spp + nlr denoiser: the default spp 16 (the scene's render() sets none); nlr is the "
            "default denoiser (docs/denoise.md)");
  request.spp = 8;
  request.denoiser = Denoiser::Svgf;
  EXPECT_EQ(chooseRenderSettings(request, &set).reason, "8 spp + svgf denoiser: --spp 8; --denoise svgf");
  request.spp = 1;
  EXPECT_EQ(chooseRenderSettings(request, &set).reason,
            "1 spp + svgf denoiser: --spp 1; --denoise svgf; svgf leaves a 1-spp image as it is (no second half)");
  request.view = gpu::kViewNormal;
  EXPECT_EQ(chooseRenderSettings(request, &set).reason,
            "1 sample, no denoiser: the normal view takes one sample and is never denoised (docs/debug_views.md)");
}

// An animation's frames each pay for the filter: nlr-fast unless asked otherwise;
// a still keeps nlr, and --denoise and --layers still decide.
TEST(RenderDefaults, AnimationGetsTheFastFilter) {
  RenderRequest request;
  const ir::RenderSettings set = sceneWith(16);
  request.frames = 24;
  RenderChoice c = chooseRenderSettings(request, &set);
  EXPECT_EQ(c.denoiser, Denoiser::NlrFast);
  EXPECT_TRUE(c.denoises);
  EXPECT_EQ(c.reason,
            "16 spp + nlr-fast denoiser: the scene's render() sets spp 16; nlr-fast is an animation's "
            "default denoiser (nlr in one pass, about 40% of its time; docs/denoise.md)");
  request.frames = 1;
  EXPECT_EQ(chooseRenderSettings(request, &set).denoiser, Denoiser::Nlr);
  request.frames = 24;
  request.denoiser = Denoiser::Nlr;
  EXPECT_EQ(chooseRenderSettings(request, &set).denoiser, Denoiser::Nlr);
  request.denoiser.reset();
  request.denoise_select = true;  // strengths of a last pass nlr-fast does not have
  EXPECT_EQ(chooseRenderSettings(request, &set).denoiser, Denoiser::Nlr);
  EXPECT_EQ(chooseRenderSettings(request, &set).reason,
            "16 spp + nlr denoiser: the scene's render() sets spp 16; nlr is the default denoiser for "
            "--denoise-select (nlr-fast, an animation's, has no last pass to select in; docs/denoise.md)");
  request.denoise_select = false;
  request.layers = true;
  EXPECT_EQ(chooseRenderSettings(request, &set).denoiser, Denoiser::None);
}

// Every combination: the denoiser, adaptive sampling and the kernel's features
// as `sdfc render` decided them before api/render_defaults.h (cli/cmd_render.cpp).
TEST(RenderDefaults, MatchesTheCommandLinesRules) {
  const std::optional<int> spps[] = {std::nullopt, 1, 2, 16};
  const std::optional<Denoiser> denoisers[] = {std::nullopt, Denoiser::None, Denoiser::Nlr, Denoiser::Svgf,
                                               Denoiser::ATrous, Denoiser::Bilateral};
  const uint32_t views[] = {gpu::kViewBeauty, gpu::kViewNormal, gpu::kViewDepth, gpu::kViewIterations};
  const std::optional<int> scene_spps[] = {std::nullopt, 1, 64};
  for (const auto& spp : spps)
    for (const auto& denoiser : denoisers)
      for (uint32_t view : views)
        for (bool layers : {false, true})
          for (bool adaptive : {false, true})
            for (const auto& scene_spp : scene_spps) {
              if (layers && denoiser && *denoiser != Denoiser::None) continue;  // a usage error
              RenderRequest request;
              request.spp = spp;
              request.denoiser = denoiser;
              request.view = view;
              request.layers = layers;
              request.adaptive = adaptive;
              const ir::RenderSettings scene = sceneWith(scene_spp);
              const RenderChoice c = chooseRenderSettings(request, &scene);
              const RenderChoice before = chooseRenderSettings(request, nullptr);
              SCOPED_TRACE(c.reason);
              // The old rules, written out.
              const Denoiser old_denoiser = layers ? Denoiser::None : denoiser.value_or(Denoiser::Nlr);
              ImageOptions probe;
              probe.denoiser = old_denoiser;
              probe.layers = layers;
              const bool old_features = adaptive || imageReadsFeatures(view, spp ? uint32_t(*spp) : UINT32_MAX, probe);
              const uint32_t old_spp = uint32_t(spp.value_or(scene.spp));
              EXPECT_EQ(c.denoiser, old_denoiser);
              EXPECT_EQ(c.adaptive, adaptive && view == gpu::kViewBeauty);
              EXPECT_EQ(c.kernel_features, old_features);
              EXPECT_EQ(before.kernel_features, old_features);  // the scene never changes the kernel
              EXPECT_EQ(c.spp, old_spp);
              EXPECT_EQ(c.denoises, view == gpu::kViewBeauty && old_denoiser != Denoiser::None &&
                                        (!needsVariance(old_denoiser) || old_spp >= 2));
              ImageOptions image;
              image.denoiser = c.denoiser;
              image.layers = layers;
              if (!adaptive) {
                EXPECT_EQ(imageReadsFeatures(view, c.spp, image), c.denoises || (layers && view == gpu::kViewBeauty));
              }
              // The viewer's target: the same spp, one for the debug views.
              EXPECT_EQ(viewTargetSpp(request, scene), view == gpu::kViewBeauty ? old_spp : 1u);
            }
}

}  // namespace
}  // namespace sdfc
