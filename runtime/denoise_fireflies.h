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
// the brightest of the other 17 values around it (half b's 3x3 and half a's 3x3
// without the pixel itself); it is scaled (hue kept) down to that bound, and so
// is half b against half a. What both halves see (a one-pixel highlight, an
// edge) is kept: half b's own pixel is in the bound. At convergence the halves
// agree, so a pixel never exceeds its bound and the images are untouched; the
// energy a clamp takes is that of samples the other half's neighbourhood did
// not see, which vanishes as the samples grow.
#pragma once
#include "denoise_svgf.h"  // SampleHalves

namespace sdfc {

struct FireflyParams {
  float ratio = 2.0f;  // a pixel above ratio x its neighbourhood's brightest is an outlier
};

// Clamps both halves in place; returns the number of pixel values changed.
size_t clampFireflies(SampleHalves& halves, const FireflyParams& params = {});

}  // namespace sdfc
