// The camera inside a closed diffuse sphere (radius 5) that both emits and
// reflects: radiance is emission * sum_{k=0..B} albedo^k with B bounces.
const float kSceneMaxDist = 20.0;
const int kSceneMaxSteps = 400;  // grazing chords of a cavity converge slowly
const float kSceneHitEps = 1e-4;
const float kScenePixelCone = 0.0;
const float kSceneStepScale = 1.0;
float sdScene(vec3 p) { return 5.0 - length(p); }  // positive inside the cavity
int sdMaterialId(vec3 p) { return 0; }
vec2 sdSceneMaterial(vec3 p) { return vec2(sdScene(p), float(sdMaterialId(p))); }
Material sdMaterial(int id) { return Material(MAT_DIFFUSE, vec3(0.8), vec3(0.25), 1.0, 0.0); }
vec3 sdSky(vec3 dir) { return vec3(0.0); }
