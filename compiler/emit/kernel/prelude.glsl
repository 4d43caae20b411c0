// ---- kernel prelude: interface, materials, random numbers, sampling ----
// See docs/kernel_contract.md. Follows runtime/shader_interface.h.

layout(push_constant) uniform Push { FrameParams frame; };
// Whether the driver ends loops early (VulkanContext::loop_cap): the renderer
// specialises it, so an uncapped driver's compile drops the code only a capped
// one can reach (a blend grid's hierarchy fallback: 1 s of LLVM, issue 46).
layout(constant_id = 0) const bool kDriverCapsLoops = true;
layout(location = 0) out vec4 out_color;
layout(location = 1) out vec4 out_normal_depth;
layout(location = 2) out vec4 out_albedo_steps;

struct Material { int model; vec3 albedo; vec3 emission; float ior; float roughness; };
const int MAT_DIFFUSE = 0;
const int MAT_MIRROR = 1;
const int MAT_GLASS = 2;
const int MAT_EMISSIVE = 3;
const int MAT_METAL = 4;

const float kPi = 3.14159265358979;
const float kTwoPi = 6.28318530717959;

// Every loop iteration of this invocation adds one (the kViewIterations view),
// so tests can prove lavapipe's 65,535-iteration cap is never reached.
uint g_loop_iterations = 0u;
#ifdef SDFC_HAS_BOUND_ONLY
// The last scene evaluation may be a lower bound, not the distance (an
// instance traversal out of visits where the driver caps loops): march()
// steps on it but never stops on it (docs/design/large_scenes.md).
bool g_bound_only = false;
#endif

// A zero the compiler cannot see through (push constant), so loops starting at it
// are kept as loops instead of being unrolled with sdScene copied into each copy.
int loopZero() { return int(min(frame.seed, 0u)); }

#ifdef SDFC_TRACE
// ---- random numbers (path tracing only: the debug views trace one fixed ray) ----
// A sample's numbers depend only on (pixel, sample index, dimension, frame.seed),
// never on the pass split, so accumulating passes is exact.
uvec2 g_rng_pixel;
uint g_rng_sample;
uint g_rng_dim;  // next 2D dimension pair of the current sample

void beginSample(uvec2 pixel, uint sample_index) {
  g_rng_pixel = pixel;
  g_rng_sample = sample_index;
  g_rng_dim = 0u;
}

// pcg4d and the single-word PCG hash: Jarzynski & Olano 2020, "Hash Functions
// for GPU Rendering" (JCGT 9(3)).
uvec4 pcg4d(uvec4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
  return v;
}

uint pcgHash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// 24 high bits -> [0, 1): exactly representable, never rounds up to 1.
float unitFloat(uint x) { return float(x >> 8u) * (1.0 / 16777216.0); }

vec2 hashRand2(uint pair) {
  uvec4 h = pcg4d(uvec4(g_rng_pixel, g_rng_sample, frame.seed ^ (pair * 0x9E3779B9u)));
  return vec2(unitFloat(h.x), unitFloat(h.y));
}

#ifdef SDFC_SAMPLER_SOBOL
// Owen-scrambled Sobol (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4)).
// Each of the first kSobolPairs 2D pairs is a shuffled and scrambled copy of the
// 2D Sobol (0,2)-sequence with its own seed ("padding", Burley sec. 5); later
// dimensions use the hash. Both Sobol dimensions are loop-free bit operations.
const uint kSobolPairs = 4u;

// Nested uniform (Owen) scramble: a hash where each bit depends only on less
// significant ones (Laine-Karras style, Burley's constants), applied to the
// bit-reversed value so each bit depends only on the more significant ones.
uint owenScramble(uint x, uint seed) {
  x = bitfieldReverse(x);
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return bitfieldReverse(x);
}

// Sobol dimension 1: its generator matrix is Pascal's triangle mod 2, i.e.
// (Lucas) output bit j (from the top) is the XOR of index bits k whose bit set
// contains j's: a superset transform over the 5-bit positions, in 5 masked steps.
uint sobolDim1(uint index) {
  uint r = index;
  r ^= (r >> 1u) & 0x55555555u;
  r ^= (r >> 2u) & 0x33333333u;
  r ^= (r >> 4u) & 0x0F0F0F0Fu;
  r ^= (r >> 8u) & 0x00FF00FFu;
  r ^= (r >> 16u) & 0x0000FFFFu;
  return bitfieldReverse(r);
}

vec2 sobolRand2(uint pair) {
  uint seed = pcgHash(g_rng_pixel.x ^ pcgHash(g_rng_pixel.y ^ pcgHash(frame.seed ^ pcgHash(pair))));
  uint index = owenScramble(g_rng_sample, seed);  // shuffle: a random nested permutation
  uint x = owenScramble(bitfieldReverse(index), pcgHash(seed ^ 0x5bd1e995u));
  uint y = owenScramble(sobolDim1(index), pcgHash(seed ^ 0x27d4eb2fu));
  return vec2(unitFloat(x), unitFloat(y));
}
#endif

// The next 2D sample of the current path.
vec2 rand2() {
  uint pair = g_rng_dim++;
#ifdef SDFC_SAMPLER_SOBOL
  if (pair < kSobolPairs) return sobolRand2(pair);
#endif
  return hashRand2(pair);
}

// ---- sampling helpers (local frames have z along the normal) ----

// Orthonormal basis from a unit normal without branches on a threshold:
// Duff et al. 2017, "Building an Orthonormal Basis, Revisited" (JCGT 6(1)).
void orthonormalBasis(vec3 n, out vec3 b1, out vec3 b2) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float b = n.x * n.y * a;
  b1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  b2 = vec3(b, s + n.y * n.y * a, -n.y);
}

vec3 toWorld(vec3 v, vec3 n) {
  vec3 b1, b2;
  orthonormalBasis(n, b1, b2);
  return v.x * b1 + v.y * b2 + v.z * n;
}

#ifdef SDFC_HAS_DIFFUSE
// Cosine-weighted hemisphere (Malley's method): pdf = z / pi.
vec3 sampleCosineHemisphere(vec2 u) {
  float r = sqrt(u.x);
  float phi = kTwoPi * u.y;
  return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}
#endif

#if defined(SDFC_HAS_SUN) || defined(SDFC_HAS_SPHERE_LIGHTS)
// Uniform direction in the cone cos(theta) >= 1 - one_minus_cos_max around z:
// pdf = 1 / (2 pi one_minus_cos_max). Takes 1 - cos directly so tiny cones (the
// sun) keep their precision; sin is formed from 1 - cos for the same reason.
vec3 sampleUniformCone(vec2 u, float one_minus_cos_max) {
  float one_minus_cos = u.x * one_minus_cos_max;
  float cos_theta = 1.0 - one_minus_cos;
  float sin_theta = sqrt(max(0.0, one_minus_cos * (2.0 - one_minus_cos)));
  float phi = kTwoPi * u.y;
  return vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}
#endif

#ifdef SDFC_HAS_METAL
// GGX / Trowbridge-Reitz with the Smith masking function (Walter et al. 2007).
float ggxD(float cos_h, float alpha) {
  float a2 = alpha * alpha;
  float d = cos_h * cos_h * (a2 - 1.0) + 1.0;
  return a2 / (kPi * d * d);
}

// Smith Lambda for GGX: (sqrt(1 + alpha^2 tan^2) - 1) / 2, written with cos only.
float ggxLambda(float cos_theta, float alpha) {
  float c2 = max(cos_theta * cos_theta, 1e-8);
  return 0.5 * (sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2) - 1.0);
}

// Visible-normal sampling: Heitz 2018, "Sampling the GGX Distribution of Visible
// Normals" (JCGT 7(4)). Stretch the view so the distribution is a hemisphere,
// sample the projected disc (warped toward the visible half), unstretch.
// Returns the microfacet normal; pdf(h) = G1(wo) max(0, wo.h) D(h) / wo.z.
vec3 sampleGgxVndf(vec3 wo, float alpha, vec2 u) {
  vec3 v = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
  float len2 = v.x * v.x + v.y * v.y;
  vec3 t1 = len2 > 0.0 ? vec3(-v.y, v.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(v, t1);
  float r = sqrt(u.x);
  float phi = kTwoPi * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5 * (1.0 + v.z);
  p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-6, nh.z)));
}
#endif

#ifdef SDFC_HAS_APERTURE
// Concentric square-to-disc map (Shirley & Chiu 1997): keeps strata compact.
vec2 concentricDisk(vec2 u) {
  vec2 o = 2.0 * u - 1.0;
  if (o.x == 0.0 && o.y == 0.0) return vec2(0.0);
  float r, phi;
  if (abs(o.x) > abs(o.y)) {
    r = o.x;
    phi = 0.25 * kPi * (o.y / o.x);
  } else {
    r = o.y;
    phi = 0.5 * kPi - 0.25 * kPi * (o.x / o.y);
  }
  return r * vec2(cos(phi), sin(phi));
}
#endif
#endif
