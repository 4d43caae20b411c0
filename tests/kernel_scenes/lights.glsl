// A ground plane and a sphere (diffuse or metal by TEST_MATERIAL_B) under a black
// sky, lit by a wide sun and two sphere lights: for NEE/MIS consistency tests.
#ifndef TEST_MATERIAL_B
#define TEST_MATERIAL_B Material(MAT_METAL, vec3(0.9, 0.7, 0.5), vec3(0.0), 1.0, 0.3)
#endif
const float kSceneMaxDist = 40.0;
const int kSceneMaxSteps = 96;
const float kSceneHitEps = 2e-4;
const float kScenePixelCone = 1e-3;
const float kSceneStepScale = 0.9;
#ifdef SDFC_HAS_SUN
const vec3 kSunDir = normalize(vec3(0.3, 1.0, 0.2));
const float kSunCosAngle = 0.95;
const vec3 kSunRadiance = vec3(3.0);
#endif
#ifdef SDFC_HAS_SPHERE_LIGHTS
const int kNumSphereLights = 2;
const vec4 kSphereLights[kNumSphereLights] = vec4[](vec4(-2.0, 2.5, 1.0, 0.8), vec4(2.0, 1.5, -1.0, 0.5));
const vec3 kSphereLightRadiance[kNumSphereLights] = vec3[](vec3(4.0, 3.0, 2.0), vec3(1.0, 2.0, 6.0));
#endif
float sdScene(vec3 p) { return min(p.y + 1.0, length(p) - 1.0); }
int sdMaterialId(vec3 p) { return p.y + 1.0 < length(p) - 1.0 ? 0 : 1; }
vec2 sdSceneMaterial(vec3 p) { return vec2(sdScene(p), float(sdMaterialId(p))); }
Material sdMaterial(int id) {
  if (id == 0) return Material(MAT_DIFFUSE, vec3(0.7), vec3(0.0), 1.0, 0.0);
  return TEST_MATERIAL_B;
}
vec3 sdSky(vec3 dir) { return vec3(0.0); }
