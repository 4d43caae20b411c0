// A linear EXR of any number of named float channels ("R", "albedo.R", "Z", ...):
// the multi-channel file `sdfc render --layers` writes (docs/layers.md).
// Channels are stored sorted by name, as OpenEXR's own writer does, so every
// reader (Nuke, Blender, OpenImageIO) finds the layers under their prefixes.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc {

struct ExrChannel {
  std::string name;
  std::vector<float> values;  // width x height, row-major, top row first
};

// The file's bytes (ZIP compression; none under 16x16, as writeImage). Throws
// ImageIoError (image_io.h) when a channel has the wrong size or encoding fails.
std::string encodeExrChannels(uint32_t width, uint32_t height, std::vector<ExrChannel> channels);
// Through writeFileAtomically: a failed write leaves no half-written file.
void writeExrChannels(const std::string& path, uint32_t width, uint32_t height,
                      std::vector<ExrChannel> channels);

// Every channel of an EXR file by name, as floats (tests and tools).
std::vector<ExrChannel> readExrChannels(const std::string& path, uint32_t& width, uint32_t& height);

}  // namespace sdfc
