// The last save's first error drawn over the viewer's image (issue 29): the
// title bar alone is invisible without a window manager. Drawn into the RGB8
// frame on the CPU after the tone map, so `save` and S still write the render.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace sdfc {
class Diagnostics;
}

namespace sdfc::view {

// The first error in source order as "file:line:col: message" (the file's
// name without its folder); "" when there is none.
std::string firstErrorText(const Diagnostics& diagnostics);

// A dark banner along the image's bottom edge with `text` in it, wrapped at
// spaces to the width (at most kOverlayMaxLines lines, the last cut with
// "..."). Returns the banner's first row (height when nothing was drawn).
constexpr int kOverlayMaxLines = 4;
uint32_t drawErrorOverlay(std::vector<uint8_t>& rgb, uint32_t width, uint32_t height, const std::string& text);

}  // namespace sdfc::view
