// sdfc_denoise_speed: the denoisers' own time on one fixed input, the runtime's
// nlr against nlr as it was at ab4eac1 (legacy_nlm.cpp), in the same process.
//
//   sdfc_denoise_speed SCENE.sdf [--size WxH] [--spp N] [--seed S] [--reps N] [--out DIR] [--nlm]
//
// --nlm: nlm (NlmParams' defaults: feature weights, no fit) in place of nlr, old and new.
// Renders the scene's two halves as `sdfc render` does for nlr (jittered and
// specular features), then times, interleaved rep by rep: legacy nlr, nlr,
// svgf (JSON keys legacy, nlr, svgf: with --nlm, nlm's in the first two). Wall and process CPU milliseconds. Writes DIR/raw.pfm (the samples'
// mean), DIR/legacy.pfm, DIR/nlr.pfm, DIR/svgf.pfm and prints one JSON object
// with the timings and the largest difference between the two nlr images
// (bench/denoise_speed.py reads it and measures the images' error).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "denoise.h"
#include "image_io.h"
#include "legacy_nlm.h"
#include "nlr_input.h"
#include "renderer.h"
#include "scene_render.h"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) {
    char b[32];
    std::snprintf(b, sizeof b, "%s%.1f", i ? ", " : "", v[i]);
    s += b;
  }
  return s + "]";
}

int usage() {
  std::fprintf(stderr, "usage: sdfc_denoise_speed SCENE.sdf [--size WxH] [--spp N] [--seed S] [--reps N] [--out DIR]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sdfc;
  std::string scene_path, out_dir = ".";
  bool nlm = false;
  int reps = 5, spp = 16, seed = 7;
  std::pair<int, int> size = {640, 360};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--size" && has_value) {
      const auto s = parseImageSize(argv[++i]);
      if (!s) return usage();
      size = *s;
    } else if (a == "--spp" && has_value) spp = std::max(2, std::atoi(argv[++i]));
    else if (a == "--seed" && has_value) seed = std::atoi(argv[++i]);
    else if (a == "--reps" && has_value) reps = std::max(1, std::atoi(argv[++i]));
    else if (a == "--out" && has_value) out_dir = argv[++i];
    else if (a == "--nlm") nlm = true;
    else if (a[0] != '-' && scene_path.empty()) scene_path = a;
    else return usage();
  }
  if (scene_path.empty()) return usage();

  bench::NlrInput input;
  if (!bench::renderNlrInput(scene_path, size, spp, seed, "sdfc_denoise_speed", input)) return 1;
  const RenderOutput& out = input.out;
  const SampleHalves& halves = input.halves;

  std::vector<double> legacy_ms, nlr_ms, svgf_ms, legacy_cpu, nlr_cpu, svgf_cpu;
  FloatImage legacy_image, nlr_image, svgf_image;
  for (int r = 0; r < reps; ++r) {
    auto time = [&](auto&& run, std::vector<double>& wall, std::vector<double>& cpu, FloatImage& image) {
      const auto start = Clock::now();
      const double cpu_start = bench::processCpuMs();
      image = run();
      wall.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
      cpu.push_back(bench::processCpuMs() - cpu_start);
    };
    const NlmParams params = nlm ? NlmParams() : nlrParams();
    time([&] { return legacy::nlmDenoise(halves, out.normal_depth, out.albedo_steps, params); },
         legacy_ms, legacy_cpu, legacy_image);
    time([&] { return nlmDenoise(halves, out.normal_depth, out.albedo_steps, params); }, nlr_ms,
         nlr_cpu, nlr_image);
    time([&] { return denoise(Denoiser::Svgf, out.color, out.normal_depth, out.albedo_steps, &halves); },
         svgf_ms, svgf_cpu, svgf_image);
  }
  double max_abs = 0, max_rel = 0, sum_abs = 0;
  for (size_t i = 0; i < nlr_image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double a = legacy_image.rgba[i * 4 + c], b = nlr_image.rgba[i * 4 + c];
      const double d = std::fabs(a - b);
      max_abs = std::max(max_abs, d);
      max_rel = std::max(max_rel, d / std::max(std::fabs(a), 1e-3));
      sum_abs += d;
    }
  writeImage(out_dir + "/raw.pfm", out.color);
  writeImage(out_dir + "/legacy.pfm", legacy_image);
  writeImage(out_dir + "/nlr.pfm", nlr_image);
  writeImage(out_dir + "/svgf.pfm", svgf_image);
  std::printf("{\"filter\": \"%s\", \"scene\": \"%s\", \"size\": \"%dx%d\", \"spp\": %u, \"threads\": %u, "
              "\"legacy_ms\": %s, \"nlr_ms\": %s, \"svgf_ms\": %s, "
              "\"legacy_cpu_ms\": %s, \"nlr_cpu_ms\": %s, \"svgf_cpu_ms\": %s, "
              "\"median_legacy_ms\": %.1f, \"median_nlr_ms\": %.1f, \"median_svgf_ms\": %.1f, "
              "\"median_legacy_cpu_ms\": %.1f, \"median_nlr_cpu_ms\": %.1f, \"median_svgf_cpu_ms\": %.1f, "
              "\"max_abs_diff\": %.3g, \"max_rel_diff\": %.3g, \"mean_abs_diff\": %.3g}\n",
              nlm ? "nlm" : "nlr", scene_path.c_str(), size.first, size.second, out.samples_done,
              std::thread::hardware_concurrency(), list(legacy_ms).c_str(), list(nlr_ms).c_str(),
              list(svgf_ms).c_str(), list(legacy_cpu).c_str(), list(nlr_cpu).c_str(), list(svgf_cpu).c_str(),
              median(legacy_ms), median(nlr_ms), median(svgf_ms), median(legacy_cpu), median(nlr_cpu),
              median(svgf_cpu), max_abs, max_rel, sum_abs / (3.0 * nlr_image.pixelCount()));
  return 0;
}
