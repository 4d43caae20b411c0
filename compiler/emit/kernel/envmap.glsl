// The environment light sky(map: ...), emitted only for a scene that has one
// (docs/lighting.md). Its data are words of the scene data from float index
// kEnvTexels: one a texel, RGB with a shared exponent (rows from the top); then, from
// kEnvColumnCdf, the CDF of the sampling grid's cells in each of its rows;
// from kEnvRowCdf, the rows' CDF.
// compiler/eval/env_map.h is the CPU twin, against which the tests check it.

float sdEnvWord(int k) { return sd_data[k >> 2][k & 3]; }

// eval/shared_exponent.h: r, g, b's 9 bits and their exponent in one word.
vec3 sdEnvTexel(int x, int y) {
  uint w = floatBitsToUint(sdEnvWord(kEnvTexels + y * kEnvWidth + x));
  uvec3 q = uvec3(w & 511u, (w >> 9) & 511u, ((w >> 18) & 31u) | ((w >> 23) & 480u));
  return vec3(q) * uintBitsToFloat((((w >> 23) & 31u) + 103u) << 23);  // 2^(e - 24)
}

// rotation: the map turned about +y by kEnvRotation = (cos, sin) of its angle.
vec3 sdEnvToLocal(vec3 d) {
  return vec3(kEnvRotation.x * d.x - kEnvRotation.y * d.z, d.y, kEnvRotation.y * d.x + kEnvRotation.x * d.z);
}
vec3 sdEnvToWorld(vec3 l) {
  return vec3(kEnvRotation.x * l.x + kEnvRotation.y * l.z, l.y, kEnvRotation.x * l.z - kEnvRotation.y * l.x);
}

// Equirectangular, y up, as Mitsuba 3: u = atan2(x, -z) / 2 pi, v = acos(y) / pi.
vec2 sdEnvUv(vec3 d) {
  float u = atan(d.x, -d.z) * (1.0 / 6.28318530717959);
  return vec2(u - floor(u), acos(clamp(d.y, -1.0, 1.0)) * (1.0 / 3.14159265358979));
}

// Radiance at map coordinates uv: bilinear, texel (i, j) at u = i / (W - 1),
// v = j / (H - 1) (the first and last columns on the seam, as Mitsuba 3).
vec3 sdEnvRadianceUv(vec2 uv) {
  float s = uv.x * float(kEnvCellsX), t = uv.y * float(kEnvCellsY);
  int x0 = min(int(s), kEnvCellsX - 1), y0 = min(int(t), kEnvCellsY - 1);
  float a = s - float(x0);
  vec3 top = mix(sdEnvTexel(x0, y0), sdEnvTexel(x0 + 1, y0), a);
  vec3 bottom = mix(sdEnvTexel(x0, y0 + 1), sdEnvTexel(x0 + 1, y0 + 1), a);
  return mix(top, bottom, t - float(y0)) * kEnvScale;
}

// Radiance toward dir.
vec3 sdSky(vec3 dir) { return sdEnvRadianceUv(sdEnvUv(sdEnvToLocal(dir))); }

#ifdef SDFC_TRACE
// The first index of cdf[base, base + n) above u (the last is 1 > u). A
// constant count of halvings: the compiler unrolls it (no run-time loop to
// count against lavapipe's cap; runtime/loop_budget.h).
int sdEnvFind(int base, int n, int steps, float u) {
  int lo = 0, hi = n - 1;
  for (int i = 0; i < steps; i++) {
    if (lo < hi) {
      int mid = (lo + hi) >> 1;
      if (sdEnvWord(base + mid) > u) hi = mid;
      else lo = mid + 1;
    }
  }
  return lo;
}

// The solid-angle pdf of sampling a direction at uv, sin_theta its distance
// from the y axis: its grid cell's probability, uniform over the cell.
float sdEnvPdfUv(vec2 uv, float sin_theta) {
  int x = min(int(uv.x * float(kEnvGridX)), kEnvGridX - 1);
  int y = min(int(uv.y * float(kEnvGridY)), kEnvGridY - 1);
  float p_row = sdEnvWord(kEnvRowCdf + y) - (y > 0 ? sdEnvWord(kEnvRowCdf + y - 1) : 0.0);
  int row = kEnvColumnCdf + y * kEnvGridX;
  float p_col = sdEnvWord(row + x) - (x > 0 ? sdEnvWord(row + x - 1) : 0.0);
  return sin_theta > 0.0 ? p_row * p_col * kEnvPdfScale / sin_theta : 0.0;
}

// A direction drawn in proportion to the grid's weights (mean luminance x
// sin(theta)) by u in [0, 1)^2, uniformly in its cell, with its map
// coordinates: the caller reads the radiance there only for a shadow ray
// that may carry it (sdEnvRadianceUv).
bool sampleEnvLight(vec2 u, out vec3 wi, out float pdf, out vec2 uv) {
  wi = vec3(0.0, 1.0, 0.0);
  pdf = 0.0;
  uv = vec2(0.0);
  int y = sdEnvFind(kEnvRowCdf, kEnvGridY, kEnvRowSteps, u.y);
  float r0 = y > 0 ? sdEnvWord(kEnvRowCdf + y - 1) : 0.0;
  float p_row = sdEnvWord(kEnvRowCdf + y) - r0;
  int row = kEnvColumnCdf + y * kEnvGridX;
  int x = sdEnvFind(row, kEnvGridX, kEnvColumnSteps, u.x);
  float c0 = x > 0 ? sdEnvWord(row + x - 1) : 0.0;
  float p_col = sdEnvWord(row + x) - c0;
  if (p_row <= 0.0 || p_col <= 0.0) return false;
  uv = vec2((float(x) + (u.x - c0) / p_col) / float(kEnvGridX), (float(y) + (u.y - r0) / p_row) / float(kEnvGridY));
  float theta = 3.14159265358979 * uv.y, phi = 6.28318530717959 * uv.x;
  float sin_theta = sin(theta);
  if (sin_theta <= 0.0) return false;
  pdf = p_row * p_col * kEnvPdfScale / sin_theta;
  wi = sdEnvToWorld(vec3(sin_theta * sin(phi), cos(theta), -sin_theta * cos(phi)));
  return true;
}

// Radiance toward a ray's direction that escaped, and (with_pdf) the solid-
// angle pdf of sampleEnvLight drawing it, from one (u, v).
vec3 sdEnvMiss(vec3 dir, bool with_pdf, out float pdf) {
  vec3 d = sdEnvToLocal(dir);
  vec2 uv = sdEnvUv(d);
  pdf = with_pdf ? sdEnvPdfUv(uv, sqrt(d.x * d.x + d.z * d.z)) : 0.0;
  return sdEnvRadianceUv(uv);
}

#endif
