// libFuzzer target: the image readers on arbitrary bytes, as each extension
// they tell apart (PNG and the rest through stb_image, Radiance .hdr, EXR
// through tinyexr): textures (check/image_file.cpp), environment maps
// (check/env_map_file.cpp) and the EXR header read (check/image_header.cpp).
// Every input must end in an image or a reason; an image must have the texels
// its size says.
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "check/env_map_file.h"
#include "check/image_file.h"
#include "check/image_header.h"
#include "fuzz/input_file.h"

namespace {

void expectConsistent(const std::shared_ptr<sdfc::ir::TextureImage>& image, const std::string& reason,
                      const char* reader, const char* extension) {
  if (!image && reason.empty()) {
    std::fprintf(stderr, "image_file_fuzz: %s refused .%s without a reason\n", reader, extension);
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* extension : {"png", "hdr", "exr"}) {
    const std::string path = sdfc::fuzz::writeInput(data, size, extension);
    const sdfc::ImageFile texture = sdfc::readImageFile(path);
    expectConsistent(texture.image, texture.reason, "the texture reader", extension);
    const sdfc::EnvMapFile map = sdfc::readEnvMapFile(path);
    expectConsistent(map.image, map.reason, "the map reader", extension);
    int width = 0, height = 0;
    (void)sdfc::exrSizeFromHeader(path, width, height);
  }
  return 0;
}
