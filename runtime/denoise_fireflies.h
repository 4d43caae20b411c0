// Fireflies out of the two halves before a filter reads them (nlm, nlr).
//
// A firefly is one sample of very high value, a caustic path found by chance
// (glass over a table: issue 29). NL-means measures its colour distances in
// units of the estimated variance, and the variance box around a firefly is
// huge, so every pixel near it accepts every neighbour in its window: the
// firefly is spread into a bright square the window's width (11 px) and the
// second pass, guided by the first, keeps the square. Clamping first removes
// the cause.
//
// A pixel of half a is an outlier when its luminance is more than `ratio` times
// both the median of the two halves over the 5x5 around it (robust while up to
// half of those are fireflies, as seen through glass) and half b's own pixel;
// it is scaled (hue kept) down to the larger of the two bounds, and so is half b
// against half a. What both halves see (a one-pixel highlight, a thin bright
// line) is kept by the second bound. At convergence the halves agree, so no
// pixel exceeds it and the images are untouched; the energy a clamp takes is
// that of samples the other half did not see, which vanishes as samples grow.
#pragma once
#include "denoise_svgf.h"  // SampleHalves

namespace sdfc {

struct FireflyParams {
  float ratio = 4.0f;  // above ratio x both its neighbourhood's median and the other half's pixel
};

// Clamps both halves in place; returns the number of pixel values changed.
size_t clampFireflies(SampleHalves& halves, const FireflyParams& params = {});

}  // namespace sdfc
