// Gradient noise: the definition is in compiler/eval/noise.h (its float64
// twin, which the tests compare against). Emitted only for scenes that use it.

uint sdNoiseMix(uint h) {
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  h *= 0x846ca68bu;
  h ^= h >> 16;
  return h;
}

// dot(G[k], d) for the 12 cube-edge gradients G[k] of eval/noise.h, k = h mod 12
// (G[0..3] = (+-1, +-1, 0), G[4..7] = (+-1, 0, +-1), G[8..11] = (0, +-1, +-1);
// bit 0 of k negates the first nonzero component, bit 1 the second): the same
// sums as the table's dot, without a per-lane load from a constant array.
float sdNoiseGradientDot(uint k, vec3 d) {
  float a = k < 8u ? d.x : d.y;
  float b = k < 4u ? d.y : d.z;
  return ((k & 1u) != 0u ? -a : a) + ((k & 2u) != 0u ? -b : b);
}

float sdNoiseCorner(ivec3 i, vec3 f, ivec3 o) {
  ivec3 c = i + o;
  uint h = sdNoiseMix(uint(c.x) ^ sdNoiseMix(uint(c.y) ^ sdNoiseMix(uint(c.z))));
  return sdNoiseGradientDot(h % 12u, f - vec3(o));
}

float sdGradientNoise(vec3 p) {
  vec3 c = floor(p);
  vec3 f = p - c;
  ivec3 i = ivec3(c);
  vec3 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
  float x00 = mix(sdNoiseCorner(i, f, ivec3(0, 0, 0)), sdNoiseCorner(i, f, ivec3(1, 0, 0)), u.x);
  float x10 = mix(sdNoiseCorner(i, f, ivec3(0, 1, 0)), sdNoiseCorner(i, f, ivec3(1, 1, 0)), u.x);
  float x01 = mix(sdNoiseCorner(i, f, ivec3(0, 0, 1)), sdNoiseCorner(i, f, ivec3(1, 0, 1)), u.x);
  float x11 = mix(sdNoiseCorner(i, f, ivec3(0, 1, 1)), sdNoiseCorner(i, f, ivec3(1, 1, 1)), u.x);
  return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

float sdFractalNoise(vec3 p, int octaves) {
  float sum = 0.0, weight = 0.0, amplitude = 1.0;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * sdGradientNoise(p);
    weight += amplitude;
    amplitude *= 0.5;
    p *= 2.0;
  }
  return sum / weight;
}
