#include "exr_channels.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <tinyexr.h>

#include "atomic_file.h"
#include "image_io.h"

namespace sdfc {

std::string encodeExrChannels(uint32_t width, uint32_t height, std::vector<ExrChannel> channels) {
  std::sort(channels.begin(), channels.end(),
            [](const ExrChannel& a, const ExrChannel& b) { return a.name < b.name; });
  const size_t pixels = size_t(width) * height;
  std::vector<float*> planes;
  std::vector<EXRChannelInfo> infos(channels.size());
  std::vector<int> types(channels.size(), TINYEXR_PIXELTYPE_FLOAT);
  for (size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].values.size() != pixels || channels[c].name.empty() || channels[c].name.size() > 255)
      throw ImageIoError("EXR channel '" + channels[c].name + "' has the wrong size or name");
    planes.push_back(channels[c].values.data());
    std::memset(&infos[c], 0, sizeof(EXRChannelInfo));
    std::strncpy(infos[c].name, channels[c].name.c_str(), 255);
  }
  EXRImage exr;
  InitEXRImage(&exr);
  exr.num_channels = int(channels.size());
  exr.images = reinterpret_cast<unsigned char**>(planes.data());
  exr.width = int(width);
  exr.height = int(height);
  EXRHeader header;
  InitEXRHeader(&header);
  header.num_channels = int(channels.size());
  header.channels = infos.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type =
      width < 16 && height < 16 ? TINYEXR_COMPRESSIONTYPE_NONE : TINYEXR_COMPRESSIONTYPE_ZIP;
  unsigned char* memory = nullptr;
  const char* err = nullptr;
  const size_t size = SaveEXRImageToMemory(&exr, &header, &memory, &err);
  if (size == 0 || !memory) {
    const std::string message = err ? err : "unknown error";
    if (err) FreeEXRErrorMessage(err);
    throw ImageIoError("cannot encode EXR: " + message);
  }
  std::string out(reinterpret_cast<const char*>(memory), size);
  std::free(memory);
  return out;
}

void writeExrChannels(const std::string& path, uint32_t width, uint32_t height,
                      std::vector<ExrChannel> channels) {
  writeFileAtomically(path, encodeExrChannels(width, height, std::move(channels)));
}

std::vector<ExrChannel> readExrChannels(const std::string& path, uint32_t& width, uint32_t& height) {
  EXRVersion version;
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS)
    throw ImageIoError("cannot read EXR " + path + ": not an EXR file");
  EXRHeader header;
  InitEXRHeader(&header);
  const char* err = nullptr;
  if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) {
    const std::string message = err ? err : "bad header";
    if (err) FreeEXRErrorMessage(err);
    throw ImageIoError("cannot read EXR " + path + ": " + message);
  }
  for (int c = 0; c < header.num_channels; ++c) header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
  EXRImage image;
  InitEXRImage(&image);
  if (LoadEXRImageFromFile(&image, &header, path.c_str(), &err) != TINYEXR_SUCCESS) {
    const std::string message = err ? err : "bad image";
    if (err) FreeEXRErrorMessage(err);
    FreeEXRHeader(&header);
    throw ImageIoError("cannot read EXR " + path + ": " + message);
  }
  width = uint32_t(image.width);
  height = uint32_t(image.height);
  std::vector<ExrChannel> channels(header.num_channels);
  for (int c = 0; c < header.num_channels; ++c) {
    channels[c].name = header.channels[c].name;
    const float* plane = reinterpret_cast<const float*>(image.images[c]);
    channels[c].values.assign(plane, plane + size_t(width) * height);
  }
  FreeEXRImage(&image);
  FreeEXRHeader(&header);
  return channels;
}

}  // namespace sdfc
