// sdfc_nlr_tune: nlr's relMSE and CPU time for several parameter sets on one
// rendered input, so the filter can be tuned without rendering again.
//
//   sdfc_nlr_tune SCENE.sdf --ref REF.f32 [--size WxH] [--spp N] [--seed S]
//                 [--write DIR] VARIANT...
//
// REF.f32: the converged reference, H x W x 3 little-endian float32, top row first
// (bench/castle_5s.py writes it from bench/cache's .npz). A VARIANT is
// `name:key=value,key=value...` over nlrParams(): radius, patch, k1, k2, passes,
// vr (variance box radius), ridge, ff (firefly ratio; 0 turns the clamp off),
// select (strengths joined by '/'), fw (feature weights 0/1), reg (regression 0/1).
// Renders the halves once as `sdfc render` does for nlr, then prints one JSON line
// per variant: relMSE (mean (x - ref)^2 / (ref^2 + 0.01)) and the filter's CPU ms.
// --write DIR: also DIR/raw.pfm, DIR/NAME.pfm (each variant's image), DIR/normal_depth.pfm
// and DIR/albedo.pfm (the features), for a look at where the error is.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "denoise.h"
#include "image_io.h"
#include "nlr_input.h"
#include "renderer.h"
#include "scene_render.h"

namespace {

double relMse(const sdfc::FloatImage& image, const std::vector<float>& ref) {
  double sum = 0;
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = ref[i * 3 + c], d = image.rgba[i * 4 + c] - r;
      sum += d * d / (r * r + 0.01);
    }
  return sum / (3.0 * image.pixelCount());
}

// `name:key=value,...` applied to nlrParams(); false on an unknown key.
bool parseVariant(const std::string& spec, std::string& name, sdfc::NlmParams& p) {
  p = sdfc::nlrParams();
  const size_t colon = spec.find(':');
  name = spec.substr(0, colon);
  if (colon == std::string::npos) return true;
  std::stringstream items(spec.substr(colon + 1));
  std::string item;
  while (std::getline(items, item, ',')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) return false;
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    const double v = std::atof(value.c_str());
    if (key == "radius") p.radius = int(v);
    else if (key == "patch") p.patch_radius = int(v);
    else if (key == "k1") p.k_first = float(v);
    else if (key == "k2") p.k_second = float(v);
    else if (key == "passes") p.passes = int(v);
    else if (key == "vr") p.variance_radius = int(v);
    else if (key == "ridge") p.ridge = float(v);
    else if (key == "ff") { p.clamp_fireflies = v > 0; if (v > 0) p.fireflies.ratio = float(v); }
    else if (key == "fw") p.feature_weights = v != 0;
    else if (key == "reg") p.regression = v != 0;
    else if (key == "select") {
      std::stringstream ks(value);
      std::string k;
      while (std::getline(ks, k, '/')) p.select_k.push_back(float(std::atof(k.c_str())));
    } else return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sdfc;
  std::string scene_path, ref_path, write_dir;
  std::vector<std::string> variants;
  int spp = 32, seed = 7;
  std::pair<int, int> size = {640, 360};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--size" && has_value) {
      const auto s = parseImageSize(argv[++i]);
      if (!s) return 2;
      size = *s;
    } else if (a == "--spp" && has_value) spp = std::max(2, std::atoi(argv[++i]));
    else if (a == "--seed" && has_value) seed = std::atoi(argv[++i]);
    else if (a == "--ref" && has_value) ref_path = argv[++i];
    else if (a == "--write" && has_value) write_dir = argv[++i];
    else if (a[0] != '-' && scene_path.empty()) scene_path = a;
    else if (a[0] != '-') variants.push_back(a);
    else {
      std::fprintf(stderr, "sdfc_nlr_tune: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (scene_path.empty() || ref_path.empty()) {
    std::fprintf(stderr, "usage: sdfc_nlr_tune SCENE.sdf --ref REF.f32 [--size WxH] [--spp N] [--seed S] VARIANT...\n");
    return 2;
  }
  std::vector<float> ref(size_t(size.first) * size.second * 3);
  std::ifstream ref_file(ref_path, std::ios::binary);
  if (!ref_file.read(reinterpret_cast<char*>(ref.data()), std::streamsize(ref.size() * sizeof(float)))) {
    std::fprintf(stderr, "sdfc_nlr_tune: %s is not a %dx%d float32 RGB image\n", ref_path.c_str(), size.first,
                 size.second);
    return 1;
  }

  bench::NlrInput input;
  if (!bench::renderNlrInput(scene_path, size, spp, seed, "sdfc_nlr_tune", input)) return 1;
  const RenderOutput& out = input.out;
  const SampleHalves& halves = input.halves;
  std::printf("{\"variant\": \"raw\", \"spp\": %d, \"seed\": %d, \"relmse\": %.6g, \"cpu_ms\": 0}\n", spp, seed,
              relMse(out.color, ref));
  if (!write_dir.empty()) {
    writeImage(write_dir + "/raw.pfm", out.color);
    writeImage(write_dir + "/normal_depth.pfm", out.normal_depth);
    writeImage(write_dir + "/albedo.pfm", out.albedo_steps);
  }
  for (const std::string& spec : variants) {
    std::string name;
    NlmParams params;
    if (!parseVariant(spec, name, params)) {
      std::fprintf(stderr, "sdfc_nlr_tune: bad variant %s\n", spec.c_str());
      return 2;
    }
    const double start = bench::processCpuMs();
    const FloatImage image = nlmDenoise(halves, out.normal_depth, out.albedo_steps, params);
    const double cpu = bench::processCpuMs() - start;
    if (!write_dir.empty()) writeImage(write_dir + "/" + name + ".pfm", image);
    std::printf("{\"variant\": \"%s\", \"spec\": \"%s\", \"spp\": %d, \"seed\": %d, \"relmse\": %.6g, \"cpu_ms\": %.0f}\n",
                name.c_str(), spec.c_str(), spp, seed, relMse(image, ref), cpu);
    std::fflush(stdout);
  }
  return 0;
}
