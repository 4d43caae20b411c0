// Every material model, both light types, time and aperture: the widest feature
// set, for compile checks and the loop-cap test.
const float kSceneMaxDist = 50.0;
const int kSceneMaxSteps = 128;
const float kSceneHitEps = 1e-4;
const float kScenePixelCone = 5e-4;
const float kSceneStepScale = 0.8;
#ifdef SDFC_HAS_SUN
const vec3 kSunDir = normalize(vec3(-0.4, 1.0, 0.3));
const float kSunCosAngle = 0.99996;
const vec3 kSunRadiance = vec3(2000.0);
#endif
#ifdef SDFC_HAS_SPHERE_LIGHTS
const int kNumSphereLights = 1;
const vec4 kSphereLights[kNumSphereLights] = vec4[](vec4(0.0, 4.0, 0.0, 0.5));
const vec3 kSphereLightRadiance[kNumSphereLights] = vec3[](vec3(20.0));
#endif
float sdBox(vec3 p, vec3 b) {
  vec3 q = abs(p) - b;
  return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
}
float sdTorus(vec3 p, vec2 t) { return length(vec2(length(p.xz) - t.x, p.y)) - t.y; }
vec4 sceneParts(vec3 p) {
  float bob = 0.0;
#ifdef SDFC_USES_TIME
  bob = 0.2 * sin(frame.cam_forward.w);
#endif
  return vec4(p.y + 1.0, length(p - vec3(-1.5, bob, 0.0)) - 1.0,
              sdBox(p - vec3(1.5, 0.0, 0.0), vec3(0.7)), sdTorus(p - vec3(0.0, 0.0, 2.0), vec2(0.8, 0.25)));
}
float sdScene(vec3 p) {
  vec4 d = sceneParts(p);
  return min(min(d.x, d.y), min(d.z, d.w));
}
int sdMaterialId(vec3 p) {
  vec4 d = sceneParts(p);
  float m = min(min(d.x, d.y), min(d.z, d.w));
  return m == d.x ? 0 : m == d.y ? 1 : m == d.z ? 2 : 3;
}
vec2 sdSceneMaterial(vec3 p) { return vec2(sdScene(p), float(sdMaterialId(p))); }
Material sdMaterial(int id) {
  if (id == 0) return Material(MAT_DIFFUSE, vec3(0.6), vec3(0.0), 1.0, 0.0);
  if (id == 1) return Material(MAT_GLASS, vec3(0.9, 1.0, 0.9), vec3(0.0), 1.5, 0.0);
  if (id == 2) return Material(MAT_METAL, vec3(0.95, 0.64, 0.54), vec3(0.0), 1.0, 0.2);
  if (id == 3) return Material(MAT_MIRROR, vec3(0.9), vec3(0.0), 1.0, 0.0);
  return Material(MAT_EMISSIVE, vec3(0.0), vec3(5.0), 1.0, 0.0);
}
vec3 sdSky(vec3 dir) { return mix(vec3(0.8, 0.85, 0.9), vec3(0.3, 0.5, 0.9), clamp(dir.y, 0.0, 1.0)); }
