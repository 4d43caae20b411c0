// A unit sphere at the origin in a uniform white sky of radiance 1 (white furnace).
// TEST_MATERIAL selects the sphere's material; the default is diffuse albedo 0.8.
#ifndef TEST_MATERIAL
#define TEST_MATERIAL Material(MAT_DIFFUSE, vec3(0.8), vec3(0.0), 1.5, 0.0)
#endif
const float kSceneMaxDist = 20.0;
const int kSceneMaxSteps = 128;
const float kSceneHitEps = 1e-4;
const float kScenePixelCone = 0.0;
const float kSceneStepScale = 1.0;
float sdScene(vec3 p) { return length(p) - 1.0; }
int sdMaterialId(vec3 p) { return 0; }
vec2 sdSceneMaterial(vec3 p) { return vec2(sdScene(p), float(sdMaterialId(p))); }
Material sdMaterial(int id) { return TEST_MATERIAL; }
vec3 sdSky(vec3 dir) { return vec3(1.0); }
