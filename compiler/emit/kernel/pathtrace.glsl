// ---- kernel: sphere tracing, normals, BSDFs, lights, main() ----
// Loop structure is mirrored by runtime/loop_budget.h: change both together.

float maxComponent(vec3 v) { return max(v.x, max(v.y, v.z)); }

// What float32 resolves of a point t along a ray from a point whose largest
// coordinate is ro_mag: 8 units in the last place of |ro| + t (>= |p|), above a
// tiny scene floor kSceneHitEps. Local: a far or huge object elsewhere in the
// scene does not coarsen a small one near the camera (issue 17).
const float kFpUlps = 8.0 * 1.1920929e-7;
float fpEps(float ro_mag, float t) { return kSceneHitEps + kFpUlps * (ro_mag + t); }
// The stopping band: float resolution, or a quarter pixel at t, whichever is wider.
// A stop is confirmed as a hit only by a sign change, or by |d| within 2^-24 of
// |ro| + t, about one ulp of p (the rounding of p alone moves d that much): at a
// silhouette the ray runs along the surface and d is resolved far better than
// fpEps (a unit sphere 1e6 away, where fpEps is 0.95 but d is good to 1e-3).
float dErr(float ro_mag, float t) { return kSceneHitEps + (kFpUlps / 16.0) * (ro_mag + t); }
float hitEps(float ro_mag, float t) { return max(fpEps(ro_mag, t), t * kScenePixelCone); }

// Iterations a hit may add to refine its distance (runtime/loop_budget.h).
const int kRefineSteps = 2;
// Iterations a stop inside, bracketed by the sample before it, may refine
// (regula falsi); taken from the march's own budget, not added to it.
const int kBracketSteps = 8;
// The largest over-relaxation of a march step (march(), docs/large_scenes.md).
const float kRelaxMax = 1.6;

#ifdef SDFC_HAS_GLASS
// -1 while the ray that hit was marched inside a solid (march() sets it).
// Such a ray whose point ahead lies inside another solid met a face the two
// share (a glass resting on a table): that face is the glass's, glass to a
// thin air gap (docs/design/glass_contact.md), so the normal is the one left
// (the other solid's outward normal, negated) and the material the glass's.
float g_hit_side = 1.0;
#endif
// The surface a marched ray hit at p = ro + t rd (not an analytic plane): its
// outward normal, and its material id (kernels that shade: the path tracer
// and the albedo view; the other views read no material).
// The surface is that of the solid the ray enters, or of the one it leaves
// when it enters none: the normal is the field's gradient just past p along
// the ray (inside the solid entered, outside the one left), and the
// material is read there or just before p. Taps centred on p mix both
// faces at an edge (a dark line along a mirror's rim) and both solids
// where two touch (a glass box on the ground: a zero gradient).
// h: 16x float resolution at p, or 1/400 of a pixel at t if wider (the
// width of the strip along an edge whose normal mixes the two faces);
// the point ahead lies past p's offset from the surface.
// The gradient comes from 4 taps on a tetrahedron's vertices (cheaper than the
// paper's 6 central differences, sec. 2.4) and the material from a 5th
// evaluation. march() runs them in its own loop after the hit, through its one
// scene call: each call site of a scene function is a whole inlined copy, and
// lavapipe's compile of it at the first draw is most of a reload's latency
// (two instance groups: bench/results/instance_groups.md).
#if defined(SDFC_TRACE) || defined(SDFC_VIEW_ALBEDO)
const int kNormalEvaluations = 5;
#else
#ifdef SDFC_VIEW_NORMAL
const int kNormalEvaluations = 4;
#else
const int kNormalEvaluations = 0;  // this kernel's view reads no normal
#endif
#endif
struct SurfaceTaps {
  vec3 p, rd, centre;
  float h, ahead;
  vec3 n;
  float field;  // the taps' mean: the field at centre to O(h^2)
};
SurfaceTaps surfaceTapsBegin(vec3 p, vec3 rd, float t, float offness) {
  SurfaceTaps s;
  s.p = p;
  s.rd = rd;
  s.h = max(16.0 * fpEps(maxComponent(abs(p)), 0.0), 0.01 * t * kScenePixelCone);
  s.ahead = 2.0 * s.h + 2.0 * offness;
  s.centre = p + rd * s.ahead;
  s.n = vec3(0.0);
  s.field = 0.0;
  return s;
}
// (+,-,-), (-,-,+), (-,+,-), (+,+,+): the even-parity cube corners
vec3 surfaceTapCorner(int i) { return vec3(i == 0 || i == 3, i >= 2, i == 1 || i == 3) * 2.0 - 1.0; }
// Where evaluation i reads the field: a tap, or the 5th, where the material
// is read, ahead when that is inside a solid.
vec3 surfaceTapPoint(SurfaceTaps s, int i) {
#ifdef SDFC_HAS_GLASS
  // A contact (g_hit_side < 0, field < 0) reads the solid the ray leaves.
  return i < 4 ? s.centre + surfaceTapCorner(i) * s.h : (s.field < 0.0 && g_hit_side > 0.0 ? s.centre : s.p - s.rd * s.ahead);
#else
  return i < 4 ? s.centre + surfaceTapCorner(i) * s.h : (s.field < 0.0 ? s.centre : s.p - s.rd * s.ahead);
#endif
}
void surfaceTapAdd(inout SurfaceTaps s, int i, vec2 dm, inout int material) {
  if (i < 4) {
    s.n += surfaceTapCorner(i) * dm.x;
    s.field += 0.25 * dm.x;
  } else {
    material = int(dm.y);
  }
}
vec3 surfaceTapsNormal(SurfaceTaps s) {
  // A degenerate field (coplanar CSG faces make a zero-width sheet whose
  // taps cancel) has no gradient: a NaN here would poison the denoisers.
  float len = length(s.n);
#ifdef SDFC_HAS_GLASS
  if (g_hit_side < 0.0 && s.field < 0.0) s.n = -s.n;
#endif
  return len > 0.0 ? s.n / len : vec3(0.0, 1.0, 0.0);
}

// Sphere tracing (Hart 1996; paper sec. 2.3): step by the distance bound scaled
// by 1 / Lipschitz. side = -1 marches inside solids (glass exit points) on the
// negated distance. Returns the hit distance, or -1 past t_max.
//
// A march stops in the hit band d < hitEps(t), a quarter pixel wide, which keeps
// rays that graze a surface from crawling along it. Then kRefineSteps secant steps
// on the distance along the ray (exact for a plane, quadratic near any smooth
// surface), each kept only if it lands nearer the surface: the band alone leaves
// an error of up to eps / cos(angle). The stop is a hit only if the refinement
// confirms it (dErr). Otherwise the ray passes the surface within the band (a
// near miss; accepting it would grow every silhouette and shadow) and resumes
// sphere tracing from the stop with the band narrowed to dErr, stepping at
// least the wide band while d is below it (so that it cannot spend its budget
// skimming the surface; docs/accuracy.md); a second unconfirmed stop there is
// passed, stepping on from its nearest sample. Out of the wide band the band
// is wide again. A stop inside after a sample outside is refined within that
// bracket (regula falsi) until float error, from the march's own budget.
//
// A ray that starts on a surface (|d| in the band at t = 0) probes one step
// ahead: moving away it is not a hit (a camera on a face looking away), moving
// in it hits at t = 0.
//
// Out of steps is not a miss when the ray is still closing in (a grazing ray
// crawling along a face): it hits at its secant root, or at its first stop. Its
// steps reach kSceneMaxSteps, which sdfc counts on the AOV ray and warns about.
//
// shade: on a marched hit (not an analytic one), the surface's normal and
// material too (SurfaceTaps), in the same loop; else normal is 0.
#ifdef SDFC_HAS_PLANES
// The analytic surface (a plane or sphere, sdPlanesHit) the last march() stopped on, or -1.
int g_plane_hit = -1;
#endif
// |distance| at the point the last march() returned: how far it may lie off the surface.
float g_hit_offness = 0.0;
#ifdef SDFC_HAS_RAY_SKIP
// The listed hits that end a march at t (docs/large_scenes.md), short of
// t_max: the skip onto a met sphere, which is the first hit (exact to float
// rounding; a shadow ray is blocked), and, for a shadow ray, which needs any
// hit, a listed sphere met however far past the cell it lies. Sets the hit.
bool listedHitEnds(float t, float t_max, inout float t_hit, inout float d_hit) {
  if (g_ray_met && t + g_ray_skip <= t_max) {
    t_hit = t + g_ray_skip;
    d_hit = 0.0;
#ifdef SDFC_HAS_SPHERE_HIT
    g_hit_sphere = g_ray_met_slot;  // its slot: the normal needs no lookup
#endif
    return true;
  }
#ifdef SDFC_HAS_SPHERE_HIT
  if (g_ray_any_hit && t + g_ray_any <= t_max) {
    t_hit = t + g_ray_any;
    d_hit = 0.0;
    return true;
  }
#endif
  return false;
}
#endif
float march(vec3 ro, vec3 rd, float t_max, float side, bool shade, out int steps, out vec3 normal,
            out int material) {
#ifdef SDFC_HAS_SPHERE_HIT
  g_hit_sphere = -1;
#endif
#ifdef SDFC_HAS_PLANES
  // Analytic planes and spheres are not in sdScene: intersect them here and
  // march no farther.
  g_plane_hit = -1;
  // An analytic hit counts at any distance short of the ray's end; only the
  // marched part is limited to the scene's reach (kSceneMaxDist).
  int plane = -1;
  float t_plane = side > 0.0 ? sdPlanesHit(ro, rd, plane) : 3.0e38;
  if (t_plane < t_max) t_max = t_plane;
  else plane = -1;
#endif
  t_max = min(t_max, kSceneMaxDist);
  float ro_mag = maxComponent(abs(ro));
  float t = 0.0;
#ifdef SDFC_HAS_SCENE_BOX
  // March only inside the box around the marched part (slab test): a ray that
  // misses it, or the part of one beyond it, takes no steps.
  {
    vec3 inv = 1.0 / (rd + vec3(equal(rd, vec3(0.0))) * 1e-30);
    vec3 ta = (kSceneBoxLo - ro) * inv, tb = (kSceneBoxHi - ro) * inv;
    vec3 near = min(ta, tb), far = max(ta, tb);
    t = max(max(max(near.x, near.y), near.z), 0.0);
    t_max = min(t_max, min(min(far.x, far.y), far.z));
  }
#endif
  float t_prev = t, d_prev = 0.0;
  float t_stop = -1.0, d_stop = 0.0;  // where the march entered the hit band
  float t_hit = -1.0, d_hit = 0.0;    // the sample nearest the surface since then
  bool crossed = false;               // a sample since the stop lies inside
  // A stop inside after a sample outside brackets the surface: [t_out, t_in],
  // narrowed by regula falsi (Illinois: `kept` is the end kept last time).
  float t_out = -1.0, d_out = 0.0, t_in = 0.0, d_in = 0.0;
  float kept = 0.0;
  bool narrow = false;                // band narrowed to float error after a near miss
  float slope = -1.0;                 // dd/dt through the last two samples
  bool leaving = false;               // moving off the surface the ray started on
  float t_first = -1.0, d_first = 0.0; // the first, unconfirmed stop
  bool exhausted = false;             // out of steps, still closing in
  bool probe = false;                 // started on a surface: the next sample decides
  float d_peak = 0.0;                 // largest d since leaving the start surface
  bool relaxed = false;               // the last step was over-relaxed
#ifdef SDFC_HAS_RAY_SKIP
  g_ray_dir = rd;
#endif
  int refined = 0;
  steps = 0;
  // The march's samples, then (shade, on a marched hit) its surface's normal
  // evaluations, in one loop around one scene call: every call site of the
  // scene is a whole inlined copy, which lavapipe compiles at the first draw.
  // A sample that ends the march sets `ended` and continues; the next
  // iteration closes the march and begins the taps (runtime/loop_budget.h:
  // at most the march's steps and the normal's evaluations, as two loops).
  bool ended = false;
  float t_end = -1.0;
  int tap = -1;  // the normal's evaluation this iteration; -1 while marching
  SurfaceTaps taps;
#ifdef SDFC_HAS_SPHERE_NORMALS
  bool exact = false;
  vec3 radial = vec3(0.0);
#endif
#ifdef SDFC_COUNT_EVENTS
  int event_kind = g_event_kind;
#endif
  normal = vec3(0.0);
  material = 0;
  for (int i = loopZero(); i < kSceneMaxSteps + kRefineSteps + max(kNormalEvaluations, 1); i++) {
    // The march is over: what followed its loop, then the taps if it hit.
    if (tap < 0 && (ended || i >= kSceneMaxSteps + kRefineSteps || !(t <= t_max))) {  // (a NaN t ends it too)
      // Out of steps and still closing in: a ray grazing a face converges too slowly
      // to reach it in budget (steps shrink by the sine of the angle). It is no sky:
      // it hits at the root of the secant through its last two samples (exact on a
      // flat face) when that lies within reach, else at its first stop if it had one.
      // Near a face, d's float noise can outweigh its fall over one short step,
      // so the last two samples need not show the ray closing in: a ray out of
      // steps whose d has fallen since its first, unconfirmed stop takes the
      // secant from that stop instead.
      bool descended = t_first >= 0.0 && t_prev > t_first && d_prev < d_first;
      if (t_hit < 0.0 && (exhausted || (descended && i >= kSceneMaxSteps))) {
        float fall = exhausted ? slope : (d_prev - d_first) / (t_prev - t_first);
        float t_root = t_prev - d_prev / min(fall, -1e-30);
        if (t_root <= t_max) {
          t_hit = t_root;
          d_hit = 0.0;
        } else if (t_first >= 0.0 && exhausted) {
          t_hit = t_first;
          d_hit = d_first;
        }
      }
#ifdef SDFC_HAS_PLANES
      if (t_hit < 0.0 && plane >= 0) {
        g_plane_hit = plane;
        g_hit_offness = 0.0;
        t_end = t_plane;
        break;
      }
#endif
      g_hit_offness = abs(d_hit);
      t_end = t_hit >= 0.0 ? max(t_hit, 0.0) : -1.0;
      if (!shade || kNormalEvaluations == 0 || t_end < 0.0) break;
#ifdef SDFC_HAS_GLASS
      g_hit_side = side;
#endif
#ifdef SDFC_COUNT_EVENTS
      // The taps count as the normal's (kind 3); the ray's kind is back after them.
      event_kind = g_event_kind;
      g_event_kind = g_event_kind < 0 ? -1 : 3;
      countEvent(0);
#endif
      taps = surfaceTapsBegin(ro + rd * t_end, rd, t_end, g_hit_offness);
      tap = 0;
    }
    g_loop_iterations++;
#ifdef SDFC_COUNT_EVENTS
    countEvent(1);
#endif
    vec3 q = ro + rd * t;
    if (tap >= 0) {
#ifdef SDFC_HAS_SPHERE_NORMALS
      // The root grid's spheres: the nearest one's radial direction, exact (one
      // lookup in this iteration instead of 4 taps; docs/large_scenes.md); the
      // material is read by the 5th evaluation unless the scene has only one.
      if (tap == 0 && sdRootSphereNormal(taps.centre, radial, taps.field)) {
        exact = true;
#ifdef SDFC_HAS_SPHERE_MATERIAL
        // A scene of one material: nothing for the 5th evaluation to read.
        material = kRootSphereMaterial;
        break;
#else
        tap = 4;
        continue;
#endif
      }
#endif
      q = surfaceTapPoint(taps, tap);
    } else {
#ifdef SDFC_HAS_RAY_SKIP
      g_ray_skip = 0.0;
      g_ray_met = false;
#endif
#ifdef SDFC_HAS_SPHERE_HIT
      g_ray_any = 1e30;
#endif
#ifdef SDFC_HAS_BOUND_ONLY
      g_bound_only = false;
#endif
    }
    // The one scene call (sdSceneMaterial is sdScene and a constant when the
    // scene has one material).
#ifdef SDFC_ONE_MATERIAL
    vec2 dm = vec2(sdScene(q), float(kSceneMaterial));
#else
#if defined(SDFC_TRACE) || defined(SDFC_VIEW_ALBEDO)
    vec2 dm = tap >= 0 ? sdSceneMaterial(q) : vec2(sdScene(q), 0.0);
#else
    vec2 dm = vec2(sdScene(q), 0.0);
#endif
#endif
    if (tap >= 0) {
      surfaceTapAdd(taps, tap, dm, material);
      if (++tap == kNormalEvaluations) break;
      continue;
    }
    float d = side * dm.x;
#ifdef SDFC_HAS_BOUND_ONLY
    // A lower bound (out of visits, on a driver that caps loops) is a step, never
    // a stop: at least a pixel's width (4 bands), so rays rationed to a few
    // visits still cross the set in budget; a part thinner than that may be
    // passed there (docs/large_scenes.md), never hit where it is not.
    if (g_bound_only) d = max(d, 4.0 * hitEps(ro_mag, t));
#endif
#ifdef SDFC_HAS_RAY_SKIP
    // A skip shorter than float resolves at t would not move the ray: at the
    // exit face of a cell whose reach is tiny (its 9th sphere just outside),
    // rays of a million-sphere cloud stood there until out of steps. The
    // floor can pass only what lies within that rounding beyond the reach.
    if (g_ray_skip > 0.0) g_ray_skip = max(g_ray_skip, dErr(ro_mag, t));
#endif
    if (i > 0) slope = (d - d_prev) / max(t - t_prev, 1e-30);
#ifdef SDFC_HAS_SPHERE_HIT
    // A point cloud's cell step (docs/large_scenes.md): where the lookup came
    // from a grid cell (g_ray_skip > 0: outside every listed sphere) and no
    // stop, probe or check is pending, the skip decides alone: a met sphere
    // is the hit, a shadow ray ends on any listed hit, else the march steps
    // by the skip or d, unrelaxed, with no hit band. The body below does the
    // same for such a lane; only when every active lane takes a cell step
    // (lanes run in lockstep) is the rest of it skipped.
    bool cell_step = side > 0.0 && g_ray_skip > 0.0 && t_stop < 0.0 && !probe && !leaving && !relaxed;
    if (subgroupAll(cell_step)) {
      steps = i + 1;
      if (i + 1 >= kSceneMaxSteps) {  // out of steps, as below
        exhausted = slope < 0.0;
        t_prev = t;
        d_prev = d;
        ended = true;
        continue;
      }
      if (listedHitEnds(t, t_max, t_hit, d_hit)) {
        ended = true;
        continue;
      }
      t_prev = t;
      d_prev = d;
      t += max(g_ray_skip, d * kSceneStepScale);
      if (t > t_max) {
        ended = true;
        continue;
      }
      continue;
    }
#endif
    if (probe) {
      probe = false;
      if (d <= d_prev) {  // moving in (or along): a hit where it started
        t_hit = 0.0;
        d_hit = d_prev;
        ended = true;
        continue;
      }
      leaving = true;
    }
    // Leaving the start surface ends out of its band, or when d falls to half
    // its peak (another surface is near). The relaxed step before may have
    // passed a surface if the two samples' spheres do not overlap: step back.
    if (leaving && (d >= hitEps(ro_mag, t) || d < 0.5 * d_peak)) {
      leaving = false;
      if (relaxed && (d + d_prev) * kSceneStepScale < t - t_prev) {
        relaxed = false;
        t = t_prev + d_prev * kSceneStepScale;
        continue;
      }
    }
    if (leaving) {
      // Still in the start surface's band: no stop. Over-relaxed steps
      // (Keinert et al. 2014): 1.9 d is safe while d grows.
      steps = i + 1;
      d_peak = max(d_peak, d);
      if (i + 1 >= kSceneMaxSteps) {
        // Out of steps, moving off the surface it started on: a miss. (This
        // branch went on into the refinement's iterations: steps reported one
        // or two over the budget, issue 49.)
        ended = true;
        continue;
      }
    } else if (t_stop >= 0.0) {
      crossed = crossed || d <= 0.0;
      if (abs(d) < abs(d_hit)) {
        t_hit = t;
        d_hit = d;
      }
      if (t_out >= 0.0) {
        // The sample replaces the bracket's end of its sign; an end kept twice
        // has its d halved (Illinois), so the bracket closes from both sides.
        if (d <= 0.0) {
          if (kept < 0.0) d_out *= 0.5;
          t_in = t;
          d_in = d;
          kept = -1.0;
        } else {
          if (kept > 0.0) d_in *= 0.5;
          t_out = t;
          d_out = d;
          kept = 1.0;
        }
      }
      // A bracketed stop refines on, within the loop's budget, until a sample
      // lies within float error (a grazing step may land a quarter pixel
      // along the ray past the surface, where two secant steps fell short).
      ++refined;
      bool bracketing = t_out >= 0.0 && refined < kBracketSteps && abs(d_hit) > dErr(ro_mag, t_hit);
      if (!bracketing && refined >= kRefineSteps) {
        if (crossed || abs(d_hit) <= dErr(ro_mag, t_hit)) {
          ended = true;
          continue;
        }
        refined = 0;
        if (!narrow) {
          // Unconfirmed: march on from the stop, which is safe (d_stop > 0).
          narrow = true;
          t_first = t_stop;
          d_first = d_stop;
          t_prev = t_stop;
          d_prev = d_stop;
          t = t_stop + d_stop * kSceneStepScale;
        } else {
          // A second near miss: pass it from its nearest sample (d_hit > 0).
          t_prev = t_hit;
          d_prev = d_hit;
          t = t_hit + max(d_hit * kSceneStepScale, fpEps(ro_mag, t_hit));
        }
        t_stop = -1.0;
        t_hit = -1.0;
        if (t > t_max) {
          ended = true;
          continue;
        }
        continue;
      }
    } else {
      steps = i + 1;
      // An over-relaxed step is safe only if the two samples' unbounding
      // spheres overlap (Keinert et al. 2014); else back to a plain step.
      if (relaxed && (d + d_prev) * kSceneStepScale < t - t_prev) {
        relaxed = false;
        t = t_prev + d_prev * kSceneStepScale;
        continue;
      }
      // Out of the wide band the near miss is behind: the next surface gets
      // the wide band and its refinement again, as on a fresh ray.
      if (narrow && d >= hitEps(ro_mag, t)) narrow = false;
      float band = narrow ? dErr(ro_mag, t) : hitEps(ro_mag, t);
#ifdef SDFC_HAS_SPHERE_HIT
      if (cell_step) band = -1.0;  // no band: d > 0 and the skip is exact
#endif
      if (i == 0 && t == 0.0 && abs(d) < band) {
        // On a surface at the ray's origin: step off it and look, far enough
        // that d moves by many roundings of the scene's unit-sized terms.
        probe = true;
        t_prev = t;
        d_prev = d;
        t = max(4.0 * band, 64.0 * kFpUlps * max(ro_mag, 1.0));
        continue;
      }
      if (d < band) {
        t_stop = t;
        d_stop = d;
        t_hit = t;
        d_hit = d;
        crossed = d <= 0.0;
        t_out = crossed && i > 0 && d_prev > 0.0 ? t_prev : -1.0;
        d_out = d_prev;
        t_in = t;
        d_in = d;
        kept = 0.0;
#ifdef SDFC_HAS_RAY_SKIP
        // A ray skip lands on an analytic hit: within float error of the
        // surface there is nothing for the secant steps to refine.
        if (abs(d) <= dErr(ro_mag, t)) {
          ended = true;
          continue;
        }
#endif
      } else if (i + 1 >= kSceneMaxSteps) {
        // Out of steps: a miss, unless still closing in.
        exhausted = slope < 0.0;
        t_prev = t;
        d_prev = d;
        ended = true;
        continue;
      }
    }
    // Over-relaxation by the slope m of d along the ray (scaled, m >= -1): if
    // d stays linear, a step of w d lands where d' = d + m w d, and the two
    // spheres overlap (d + d' >= w d) while w <= 2 / (1 - m); kRelaxMax / (1 - m)
    // keeps a margin. Head-on (m = -1) the step is plain; grazing a cloud's
    // spheres (m near 0) it is kRelaxMax d. Never past t_max, where the march
    // ends unchecked.
    float omega = 1.0;
    if (leaving) {
      omega = 1.9;
    } else if (t_stop < 0.0 && i > 0) {
      omega = clamp(kRelaxMax / (1.0 - min(slope * kSceneStepScale, 0.0)), 1.0, kRelaxMax);
      if (t + d * kSceneStepScale * omega > t_max) omega = 1.0;
    }
#ifdef SDFC_HAS_SPHERE_HIT
    if (cell_step) omega = 1.0;
#endif
    relaxed = omega > 1.0;
    float t_next = t + d * kSceneStepScale * omega;
    // Past a near miss the band is float error, and a ray that skims the
    // surface it passed crawled along it by steps of its tiny d until out of
    // steps, then drawn as sky though a surface lay behind (issue 49). It
    // steps at least the wide band (a quarter pixel) while d is below it, but
    // no farther than where d, falling at its slope, would reach 0 (a corner
    // it clips lies there): the ray enters a surface (d < 0: a stop, refined)
    // or passes it; only a sliver thinner than the band may be passed.
    if (narrow && t_stop < 0.0) {
      float floor_step = hitEps(ro_mag, t);
      if (slope < 0.0) floor_step = min(floor_step, d / -slope);
      if (t_next < t + floor_step) {
        t_next = t + floor_step;
        relaxed = false;
      }
    }
#ifdef SDFC_HAS_RAY_SKIP
    if (t_stop < 0.0 && side > 0.0 && listedHitEnds(t, t_max, t_hit, d_hit)) {
      ended = true;
      continue;
    }
    // The root grid's ray skip (docs/large_scenes.md), where longer, is safe
    // by itself: no overlap check after it, and it may pass t_max. Inside
    // solids (side < 0) it does not apply.
    if (t_stop < 0.0 && side > 0.0 && g_ray_skip > d * kSceneStepScale * omega) {
      t_next = t + g_ray_skip;
      relaxed = false;
    }
#endif
    if (t_stop >= 0.0) {
      // Secant on d(t) through the last two samples; a plain step if they
      // do not bracket a descent, and never farther than 8 |d| from the hit:
      // longer jumps tunnelled through the rims of a level-5 Menger sponge's
      // holes (0.17% of primary rays at 64 |d|).
      if (i > 0 && slope < 0.0) t_next = t - d / slope;
      // ... nor past t_max (an analytic plane may lie just beyond the hit).
      t_next = clamp(t_next, t_hit - 8.0 * abs(d_hit), min(t_hit + 8.0 * abs(d_hit), t_max));
      // A bracketed stop: regula falsi, within the bracket (a grazing step
      // into a face may land far past the root along the ray).
      if (t_out >= 0.0) t_next = clamp(t_out + (t_in - t_out) * d_out / max(d_out - d_in, 1e-30), t_out, t_in);
    }
    t_prev = t;
    d_prev = d;
    t = t_next;
    if (t_stop < 0.0 && t > t_max) {
      ended = true;
      continue;
    }
  }
#ifdef SDFC_COUNT_EVENTS
  g_event_kind = event_kind;
#endif
  if (tap >= 0) {
#ifdef SDFC_HAS_SPHERE_NORMALS
    normal = exact ? radial : surfaceTapsNormal(taps);
#else
    normal = surfaceTapsNormal(taps);
#endif
  }
  return t_end;
}

// ---- lights ----
#ifdef SDFC_HAS_SPHERE_LIGHTS
// Nearest t > 0 where the ray meets sphere s (xyz centre, w radius), or -1.
float raySphere(vec3 ro, vec3 rd, vec4 s) {
  vec3 oc = ro - s.xyz;
  float b = dot(oc, rd);
  float h = b * b - (dot(oc, oc) - s.w * s.w);
  if (h < 0.0) return -1.0;
  h = sqrt(h);
  float t = -b - h;
  if (t <= 0.0) t = -b + h;
  return t > 0.0 ? t : -1.0;
}

// Sphere lights are not in sdScene: the nearest one the ray meets before
// t_near (-1 if none), which then becomes its distance.
int nearestSphereLight(vec3 ro, vec3 rd, inout float t_near) {
  int hit = -1;
  for (int j = loopZero(); j < kNumSphereLights; j++) {
    g_loop_iterations++;
    float tj = raySphere(ro, rd, kSphereLights[j]);
    if (tj > 0.0 && tj < t_near) {
      t_near = tj;
      hit = j;
    }
  }
  return hit;
}
#endif

// Light sampling, BSDFs and the path tracer: the beauty (and iterations) kernel only.
#ifdef SDFC_TRACE
#ifdef SDFC_HAS_SUN
const int kSunLights = 1;
#else
const int kSunLights = 0;
#endif
#ifdef SDFC_HAS_SPHERE_LIGHTS
const int kSphereLightCount = kNumSphereLights;
// runtime/loop_budget.h bounds the per-ray light loop by kMaxSphereLights = 16;
// more lights must fail to compile rather than silently break that bound.
float g_sphere_light_limit[kNumSphereLights <= 16 ? 1 : -1];

// 1 - cos of the half-angle of the cone sphere s subtends from p (0 if p is inside).
float sphereConeOneMinusCos(vec3 p, vec4 s) {
  float d2 = dot(s.xyz - p, s.xyz - p);
  float sin2 = s.w * s.w / d2;
  if (sin2 >= 1.0) return 0.0;
  return sin2 / (1.0 + sqrt(1.0 - sin2));
}
#else
const int kSphereLightCount = 0;
#endif
#ifdef SDFC_HAS_ENVMAP
// The environment map is the last light (kernel/envmap.glsl).
const int kLightCount = kSunLights + kSphereLightCount + 1;
#else
const int kLightCount = kSunLights + kSphereLightCount;
#endif

#if defined(SDFC_HAS_SUN) || defined(SDFC_HAS_SPHERE_LIGHTS) || defined(SDFC_HAS_ENVMAP)
// Solid-angle pdf of next-event estimation choosing light `index` (uniform choice)
// and then direction dir from p (both lights are sampled uniformly in their cone).
float lightPdf(int index, vec3 p) {
  float one_minus_cos = 0.0;
#ifdef SDFC_HAS_SUN
  if (index == 0) one_minus_cos = 1.0 - kSunCosAngle;
#endif
#ifdef SDFC_HAS_SPHERE_LIGHTS
  if (index >= kSunLights) one_minus_cos = sphereConeOneMinusCos(p, kSphereLights[index - kSunLights]);
#endif
  if (one_minus_cos <= 0.0) return 0.0;
  return 1.0 / (float(kLightCount) * kTwoPi * one_minus_cos);
}

// Power heuristic with beta = 2 (Veach 1997, sec. 9.2), sample counts included:
// the weight of strategy a against b, given n * pdf of each.
float powerHeuristic(float a, float b) {
  return a * a / max(a * a + b * b, 1e-30);
}

// Weight of a BSDF-sampled ray that reached a light: 1 after delta scattering or
// from the camera (bsdf_pdf = 0), else MIS against frame.light_samples NEE samples.
float misBsdfWeight(float bsdf_pdf, float light_pdf) {
  if (bsdf_pdf <= 0.0) return 1.0;
  return powerHeuristic(bsdf_pdf, float(frame.light_samples) * light_pdf);
}

#ifdef SDFC_HAS_ENVMAP
// The pdf of next-event estimation choosing light `index` and direction wi
// from p: lightPdf, or the environment map's, which varies with wi.
// The map's pdf of the direction sampleLight drew last (not recomputed from wi).
float g_env_sample_pdf = 0.0;
vec2 g_env_sample_uv = vec2(0.0);  // and its map coordinates
float neeLightPdf(int index, vec3 p, vec3 wi) {
  if (index == kLightCount - 1) return g_env_sample_pdf / float(kLightCount);
  return lightPdf(index, p);
}

#endif
// Direction toward light `index` from p, its distance and radiance; pdf via lightPdf.
bool sampleLight(int index, vec3 p, vec2 u, out vec3 wi, out float dist, out vec3 radiance) {
#ifdef SDFC_HAS_ENVMAP
  if (index == kLightCount - 1) {
    dist = 3.0e38;  // to infinity, as the sun
    radiance = vec3(0.0);  // read by the caller at g_env_sample_uv if the ray may carry it
    return sampleEnvLight(u, wi, g_env_sample_pdf, g_env_sample_uv);
  }
#endif
#ifdef SDFC_HAS_SUN
  if (index == 0) {
    wi = toWorld(sampleUniformCone(u, 1.0 - kSunCosAngle), kSunDir);
    dist = 3.0e38;  // to infinity: march() limits the marched part to kSceneMaxDist
    radiance = kSunRadiance;
    return true;
  }
#endif
#ifdef SDFC_HAS_SPHERE_LIGHTS
  vec4 s = kSphereLights[index - kSunLights];
  float one_minus_cos = sphereConeOneMinusCos(p, s);
  if (one_minus_cos <= 0.0) return false;
  wi = toWorld(sampleUniformCone(u, one_minus_cos), normalize(s.xyz - p));
  float t = raySphere(p, wi, s);
  if (t <= 0.0) return false;
  dist = t * (1.0 - 1e-4);
  radiance = kSphereLightRadiance[index - kSunLights];
  return true;
#else
  return false;
#endif
}
#endif

// ---- BSDFs with a smooth lobe (next-event estimation applies) ----
#ifdef SDFC_HAS_METAL
vec3 fresnelSchlick(vec3 f0, float cos_theta) {
  float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
  float m2 = m * m;
  return f0 + (1.0 - f0) * (m2 * m2 * m);
}
#endif

// f * cos(theta_i) for wo -> wi at a surface facing n, and the pdf of sampling wi
// by the BSDF. Diffuse: Lambert. Metal: GGX microfacet with height-correlated Smith
// G2 (Heitz 2014, "Understanding the Masking-Shadowing Function") and Schlick F.
vec3 evalBsdf(Material m, vec3 n, vec3 wo, vec3 wi, out float pdf) {
  pdf = 0.0;
  float cos_i = dot(n, wi);
  if (cos_i <= 0.0) return vec3(0.0);
#ifdef SDFC_HAS_DIFFUSE
  if (m.model == MAT_DIFFUSE) {
    pdf = cos_i / kPi;
    return m.albedo * (cos_i / kPi);
  }
#endif
#ifdef SDFC_HAS_METAL
  if (m.model == MAT_METAL) {
    float cos_o = max(dot(n, wo), 1e-6);
    vec3 h = normalize(wo + wi);
    float alpha = max(m.roughness, 1e-3);
    float d = ggxD(dot(n, h), alpha);
    float lambda_o = ggxLambda(cos_o, alpha);
    float g2 = 1.0 / (1.0 + lambda_o + ggxLambda(cos_i, alpha));
    pdf = d / ((1.0 + lambda_o) * 4.0 * cos_o);  // VNDF pdf of h, times dh/dwi
    return fresnelSchlick(m.albedo, dot(wo, h)) * (d * g2 / (4.0 * cos_o));
  }
#endif
  return vec3(0.0);
}

#ifdef SDFC_HAS_GLASS
// Unpolarised Fresnel reflectance of a dielectric interface, eta = n_i / n_t.
float fresnelDielectric(float cos_i, float cos_t, float eta) {
  float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}
#endif

#endif

// ---- camera ----
// Pinhole through film position `film` (pixels, top-left origin); with
// SDFC_HAS_APERTURE and `lens` set, a thin lens focused at frame.cam_up.w.
void cameraRay(vec2 film, bool lens, out vec3 ro, out vec3 rd) {
  float tan_half = frame.cam_origin.w;
  float aspect = float(frame.width) / float(frame.height);
  vec2 ndc = vec2(2.0 * film.x / float(frame.width) - 1.0, 1.0 - 2.0 * film.y / float(frame.height));
  rd = normalize(frame.cam_forward.xyz + (ndc.x * aspect * tan_half) * frame.cam_right.xyz +
                 (ndc.y * tan_half) * frame.cam_up.xyz);
  ro = frame.cam_origin.xyz;
#ifdef SDFC_HAS_APERTURE
#ifdef SDFC_TRACE
  if (lens) {
    vec3 focus = ro + rd * (frame.cam_up.w / dot(rd, frame.cam_forward.xyz));
    vec2 d = frame.cam_right.w * concentricDisk(rand2());
    ro += d.x * frame.cam_right.xyz + d.y * frame.cam_up.xyz;
    rd = normalize(focus - ro);
  }
#endif
#endif
}

// -1 when the camera ray's origin ro is inside a solid (deeper than float
// error), else 1. A pinhole camera's rays all start at frame.cam_origin, so the
// renderer decides it once per frame on the CPU with the same float threshold
// (frame.camera_inside; runtime/camera_inside.h): no inlined copy of the scene
// here. A thin lens moves ro per sample and keeps the per-ray test.
float cameraSide(vec3 ro) {
#ifdef SDFC_HAS_APERTURE
  return sdScene(ro) < -fpEps(maxComponent(abs(ro)), 0.0) ? -1.0 : 1.0;
#else
  return frame.camera_inside != 0u ? -1.0 : 1.0;
#endif
}


#ifdef SDFC_TRACE
// ---- path tracer ----
// Primary-hit data of the path traced with record_aov set.
#ifdef SDFC_NO_AOVS
// No features (a beauty render nothing denoises): the march steps only, which
// `render`'s step statistics read (docs/kernel_contract.md).
#else
vec3 g_aov_normal = vec3(0.0);
float g_aov_dist = -1.0;
vec3 g_aov_albedo = vec3(0.0);
#endif
int g_aov_steps = 0;
#ifndef SDFC_NO_AOVS
#if defined(SDFC_HAS_MIRROR) || defined(SDFC_HAS_GLASS) || defined(SDFC_HAS_METAL)

// FrameParams::skip_aov_ray == kAovSpecular (runtime/renderer.h, gpu::kAovSpecular):
// as kAovJittered, but where a sample's first hit is specular the features are
// those of the first non-specular vertex along the path it took, at most
// kAovSpecularDepth specular vertices deep (docs/denoise.md, "through specular
// bounces"): the reflected or refracted surface is what the colour shows.
const uint kAovSpecular = 3u;
const int kAovSpecularDepth = 3;
// GGX metal at most this rough passes the features on: its reflection lobe
// (about 2 alpha wide) still shows the reflected surface, not a blur of it.
const float kAovSpecularRoughness = 0.1;

// Whether a vertex of material m passes the features on to the next vertex.
bool aovThroughSpecular(Material m) {
  return m.model == MAT_MIRROR || m.model == MAT_GLASS ||
         (m.model == MAT_METAL && m.roughness <= kAovSpecularRoughness);
}
#endif
#endif

// Next-event estimation: with a light and a material that has a smooth lobe.
#if defined(SDFC_HAS_SUN) || defined(SDFC_HAS_SPHERE_LIGHTS) || defined(SDFC_HAS_ENVMAP)
#if defined(SDFC_HAS_DIFFUSE) || defined(SDFC_HAS_METAL)
const bool kNextEvent = true;
#else
const bool kNextEvent = false;
#endif
#else
const bool kNextEvent = false;
#endif

// Radiance along (ro, rd) with at most max_bounces scattering events.
//
// One loop marches every ray of the path through one march() call: the path's
// rays and, at each vertex that scatters, frame.light_samples shadow rays, one
// an iteration (every march() call site is a full inlined copy of the scene,
// which lavapipe JIT-compiles at the first draw: one site, not two). Random
// numbers are drawn in the order of a loop over the light samples followed by
// the BSDF sample, so images do not depend on this arrangement.
// Loops per call: the path loop <= (max_bounces + 1) + max_bounces * L
// iterations (L = frame.light_samples), each with march <= kSceneMaxSteps,
// sphere-light test <= kNumSphereLights,
// normal 4, and the light sample's sphere-light occlusion test <= kNumSphereLights.
vec3 tracePath(vec3 ro, vec3 rd, int max_bounces, bool record_aov) {
  vec3 radiance = vec3(0.0);
  vec3 throughput = vec3(1.0);
  // -1 while inside a solid (refracted into glass, or a camera placed inside
  // an object: it then sees the object's inside, not a hit at t = 0).
  // A camera on a surface (within float error of it) is outside: march() then
  // tells a ray leaving the surface from one entering it.
  float side = cameraSide(ro);
  float prev_pdf = 0.0;   // BSDF pdf of the last scattering; 0 = delta or camera
  vec3 prev_pos = ro;
  int depth = 0;
  // The vertex being shaded, kept while its shadow rays are marched.
  vec3 p = ro, n = vec3(0.0), nf = vec3(0.0);
  Material m;
  float offset = 0.0;
  bool entering = true;
  // The shadow ray this iteration marches (shadow_ray), if it may add light
  // (shadow_valid; else it takes no steps), and what it adds when unblocked.
  int light_j = 0;
  bool shadow_ray = false, shadow_valid = false;
  vec3 shadow_origin = vec3(0.0), shadow_dir = vec3(0.0), shadow_radiance = vec3(0.0);
  float shadow_dist = -1.0;
  bool escaped = false;  // the path left the scene along rd
  const int light_samples = kNextEvent ? int(frame.light_samples) : 0;
#ifndef SDFC_NO_AOVS
#if defined(SDFC_HAS_MIRROR) || defined(SDFC_HAS_GLASS) || defined(SDFC_HAS_METAL)
  // kAovSpecular: true while the path has met only specular vertices; the
  // features then follow it, their albedo tinted by its throughput, their
  // distance the length of the path (a plane mirror's virtual image's depth).
  bool aov_follow = record_aov && frame.skip_aov_ray == kAovSpecular;
  float aov_path = 0.0;
#endif
#endif
  for (int it = loopZero(); it < max_bounces + 1 + max_bounces * light_samples; it++) {
    g_loop_iterations++;
    int steps, surface_material;
    vec3 surface_normal;
#ifdef SDFC_COUNT_EVENTS
    // --count-event: the kind of ray marched (not the AOV ray's, max_bounces 0).
    g_event_kind = max_bounces == 0 ? -1 : (shadow_ray ? 2 : (depth == 0 ? 0 : 1));
    if (!shadow_ray || shadow_valid) countEvent(0);
#endif
#ifdef SDFC_HAS_SPHERE_HIT
    g_ray_any_hit = shadow_ray;
#endif
    float t = march(shadow_ray ? shadow_origin : ro, shadow_ray ? shadow_dir : rd,
                    shadow_ray ? (shadow_valid ? shadow_dist : -1.0) : 3.0e38, shadow_ray ? 1.0 : side,
                    !shadow_ray, steps, surface_normal, surface_material);
#ifdef SDFC_HAS_SPHERE_HIT
    g_ray_any_hit = false;
#endif
#ifdef SDFC_COUNT_EVENTS
    if (t >= 0.0) countEvent(5);
#endif
    if (shadow_ray) {
      if (shadow_valid && t < 0.0) radiance += shadow_radiance;
      light_j++;
    } else {
#ifdef SDFC_HAS_SPHERE_LIGHTS
      float t_light = t < 0.0 ? 3.0e38 : t;
      int light_hit = nearestSphereLight(ro, rd, t_light);
      if (light_hit >= 0) {
#ifdef SDFC_NO_AOVS
        if (record_aov && depth == 0) g_aov_steps = steps;
#else
        if (record_aov && depth == 0) {
          g_aov_normal = normalize(ro + rd * t_light - kSphereLights[light_hit].xyz);
          g_aov_dist = t_light;
          g_aov_steps = steps;
        }
#if defined(SDFC_HAS_MIRROR) || defined(SDFC_HAS_GLASS) || defined(SDFC_HAS_METAL)
        if (aov_follow && depth > 0) {
          g_aov_normal = normalize(ro + rd * t_light - kSphereLights[light_hit].xyz);
          g_aov_dist = aov_path + t_light;
          g_aov_albedo = vec3(0.0);  // as a light seen directly
        }
#endif
#endif
        radiance += throughput * kSphereLightRadiance[light_hit] *
                    misBsdfWeight(prev_pdf, lightPdf(kSunLights + light_hit, prev_pos));
        break;
      }
#endif
      if (t < 0.0) {
        if (record_aov && depth == 0) g_aov_steps = steps;
        escaped = true;  // its sky is added after the loop
        break;
      }

      p = ro + rd * t;
#ifdef SDFC_HAS_PLANES
      if (g_plane_hit >= 0) {
        int analytic_material;
        n = sdAnalyticNormal(g_plane_hit, p, analytic_material);
#ifdef SDFC_HAS_FIELDS
        m = sdMaterialAt(analytic_material, p, n);
#else
        m = sdMaterial(analytic_material);
#endif
      } else
#endif
      {
#ifdef SDFC_COUNT_EVENTS
        g_event_kind = g_event_kind < 0 ? -1 : 3;  // as march() counted the normal's taps
#endif
        n = surface_normal;  // march() evaluated it after the hit
#ifdef SDFC_HAS_FIELDS
        m = sdMaterialAt(surface_material, p, n);
#else
        m = sdMaterial(surface_material);
#endif
      }
#ifdef SDFC_NO_AOVS
      if (record_aov && depth == 0) g_aov_steps = steps;
#else
      if (record_aov && depth == 0) {
        g_aov_normal = n;
        g_aov_dist = t;
        g_aov_albedo = m.albedo;
        g_aov_steps = steps;
      }
#if defined(SDFC_HAS_MIRROR) || defined(SDFC_HAS_GLASS) || defined(SDFC_HAS_METAL)
      if (aov_follow) {
        aov_path += t;
        if (depth > 0) {
          g_aov_normal = n;
          g_aov_dist = aov_path;
          g_aov_albedo = throughput * m.albedo;
        }
        aov_follow = depth < kAovSpecularDepth && aovThroughSpecular(m);
      }
#endif
#endif
      radiance += throughput * m.emission;  // emitters found by BSDF sampling: weight 1
      if (depth >= max_bounces || m.model == MAT_EMISSIVE) break;

      entering = dot(rd, n) < 0.0;
      nf = entering ? n : -n;  // faces the incoming ray
      // New rays start off the surface by a few times its uncertainty: the hit's
      // |d|, float32 rounding of p, and 1/100 pixel at t (the normal taps' scale;
      // without it, the tolerance now being local, rays starting closer took 29%
      // more loop iterations on the castle). Not by the hit band: a quarter pixel
      // at distance would lift rays out of crevices and under contact points
      // (measured: +0.03% image mean against Mitsuba 3).
      offset = 4.0 * max(max(kSceneHitEps, g_hit_offness), max(maxComponent(abs(p)) * 4.0 * 1.1920929e-7, 0.01 * t * kScenePixelCone));
      // Next-event estimation at this vertex: frame.light_samples shadow rays to
      // uniformly chosen lights (smooth lobes only).
      light_j = m.model == MAT_DIFFUSE || m.model == MAT_METAL ? 0 : light_samples;
    }
    vec3 wo = -rd;

#if defined(SDFC_HAS_SUN) || defined(SDFC_HAS_SPHERE_LIGHTS) || defined(SDFC_HAS_ENVMAP)
#if defined(SDFC_HAS_DIFFUSE) || defined(SDFC_HAS_METAL)
    // Light sample light_j: its shadow ray is the next iteration's march.
    shadow_ray = light_j < light_samples;
    if (shadow_ray) {
      shadow_valid = false;
      vec3 origin = p + nf * offset;
      float n_light = float(frame.light_samples);
      vec2 u_pick = rand2();
      vec2 u_dir = rand2();
      int index = min(int(u_pick.x * float(kLightCount)), kLightCount - 1);
      vec3 wi, le;
      float dist;
      if (sampleLight(index, origin, u_dir, wi, dist, le)) {
        float bsdf_pdf;
        vec3 f_cos = evalBsdf(m, nf, wo, wi, bsdf_pdf);
        bool blocked = maxComponent(f_cos) <= 0.0;
#ifdef SDFC_HAS_SPHERE_LIGHTS
        // Sphere lights are opaque: one in front of the chosen light shadows it, as
        // a BSDF-sampled ray would find (MIS needs both strategies to agree).
        if (!blocked) {
          for (int k = loopZero(); k < kNumSphereLights; k++) {
            g_loop_iterations++;
            float tk = raySphere(origin, wi, kSphereLights[k]);
            blocked = blocked || (k != index - kSunLights && tk > 0.0 && tk < dist);
          }
        }
#endif
#ifdef SDFC_HAS_ENVMAP
        // The map's pdf of the drawn direction (0: nothing was drawn).
        float light_pdf = neeLightPdf(index, origin, wi);
        if (index == kLightCount - 1 && !blocked && light_pdf > 0.0) le = sdEnvRadianceUv(g_env_sample_uv);
        if (!blocked && light_pdf > 0.0) {
#else
        if (!blocked) {
          float light_pdf = lightPdf(index, origin);
#endif
          float w = powerHeuristic(n_light * light_pdf, bsdf_pdf);
          shadow_radiance = throughput * f_cos * le * (w / (n_light * light_pdf));
          shadow_valid = true;
          shadow_origin = origin;
          shadow_dir = wi;
          shadow_dist = dist;
        }
      }
      continue;
    }
#endif
#endif

    // Sample the BSDF: the new direction wi, throughput weight f cos / pdf, and pdf.
    vec3 wi = reflect(rd, nf);
    vec3 weight = vec3(0.0);
    float pdf = 0.0;
#ifdef SDFC_HAS_DIFFUSE
    if (m.model == MAT_DIFFUSE) {
      vec3 l = sampleCosineHemisphere(rand2());
      wi = toWorld(l, nf);
      pdf = l.z / kPi;
      weight = m.albedo;
    }
#endif
#ifdef SDFC_HAS_MIRROR
    if (m.model == MAT_MIRROR) weight = m.albedo;
#endif
#ifdef SDFC_HAS_GLASS
    if (m.model == MAT_GLASS) {
      // Choose reflection with probability F, so the weight is 1 (or the tint).
      float eta = entering ? 1.0 / m.ior : m.ior;
      float cos_i = dot(wo, nf);
      vec3 refracted = refract(rd, nf, eta);  // zero under total internal reflection
      float f = refracted == vec3(0.0) ? 1.0 : fresnelDielectric(cos_i, -dot(refracted, nf), eta);
      weight = vec3(1.0);
      if (rand2().x >= f) {
        wi = refracted;
        if (entering) weight = m.albedo;  // tint once per passage through the solid
      }
    }
#endif
#ifdef SDFC_HAS_METAL
    if (m.model == MAT_METAL) {
      vec3 b1, b2;
      orthonormalBasis(nf, b1, b2);
      vec3 wo_l = vec3(dot(wo, b1), dot(wo, b2), max(dot(wo, nf), 1e-6));
      float alpha = max(m.roughness, 1e-3);
      vec3 h = sampleGgxVndf(wo_l, alpha, rand2());
      vec3 wi_l = reflect(-wo_l, h);
      if (wi_l.z > 0.0) {
        float lambda_o = ggxLambda(wo_l.z, alpha);
        // f cos / pdf = F G2 / G1(wo) for VNDF sampling (Heitz 2018, eq. 19)
        weight = fresnelSchlick(m.albedo, dot(wo_l, h)) *
                 ((1.0 + lambda_o) / (1.0 + lambda_o + ggxLambda(wi_l.z, alpha)));
        pdf = ggxD(h.z, alpha) / ((1.0 + lambda_o) * 4.0 * wo_l.z);
        wi = wi_l.x * b1 + wi_l.y * b2 + wi_l.z * nf;
      }
    }
#endif
    if (maxComponent(weight) <= 0.0) break;
    throughput *= weight;
    prev_pdf = pdf;
    prev_pos = p;
    bool into_solid = dot(wi, n) < 0.0;
    // Reflected, the ray stays where it came from (inside a glass resting on the
    // ground after bouncing off the ground); transmitted, it crosses the surface.
    bool reflected = (dot(wi, n) < 0.0) != (dot(rd, n) < 0.0);
    side = reflected ? side : (into_solid ? -1.0 : 1.0);
    ro = p + (into_solid ? -n : n) * offset;
    rd = wi;

    // Russian roulette (Arvo & Kirk 1990) from the fifth bounce; unbiased.
    // Earlier, it doubles the noise of the short paths most scenes use
    // (measured: 3x the variance of Mitsuba behind glass at 3 bounces).
    if (depth >= 4) {
      float q = min(maxComponent(throughput), 1.0);
      if (rand2().x >= q) break;
      throughput /= q;
    }
    depth++;
  }
  // A path escapes at most once, so its sky is read here, once a path, not in
  // every iteration: lavapipe runs every branch of the loop's body under a mask.
  if (escaped) {
#ifdef SDFC_HAS_ENVMAP
    // The map is a light of next-event estimation too: MIS-weighted.
    float env_pdf;
    vec3 sky = sdEnvMiss(rd, prev_pdf > 0.0, env_pdf);
    if (prev_pdf > 0.0) sky *= misBsdfWeight(prev_pdf, env_pdf / float(kLightCount));
#else
    vec3 sky = sdSky(rd);
#endif
#ifdef SDFC_HAS_SUN
    // sdSky holds no sun disc: the kernel adds it, MIS-weighted against NEE.
    if (dot(rd, kSunDir) >= kSunCosAngle) sky += kSunRadiance * misBsdfWeight(prev_pdf, lightPdf(0, prev_pos));
#endif
    radiance += throughput * sky;
  }
  return radiance;
}

#endif

#ifdef SDFC_TRACE
// The path tracer's main: beauty, iterations, or (SDFC_ALL_VIEWS) every view
// chosen at run time by the push constants' view field.
void main() {
  // Absolute image pixel: the target may hold one band of the image (FrameParams).
  uvec2 pixel = uvec2(gl_FragCoord.xy) + uvec2(frame.tile_x, frame.tile_y);
#ifdef SDFC_ALL_VIEWS
  bool trace = frame.view == kViewBeauty || frame.view == kViewIterations;
  int count = trace ? int(frame.sample_count) : 0;
#else
  int count = int(frame.sample_count);
#endif
  vec3 sum = vec3(0.0);
#ifdef SDFC_NO_AOVS
  // kAovJittered (and the specular mode alike): the steps are the mean over the
  // samples' first rays, as the full kernel's; there is no AOV ray.
  bool jittered = frame.skip_aov_ray >= kAovJittered;
  float steps_sum = 0.0;
#else
  // kAovJittered: every sample records its first hit and the AOVs are their
  // means (misses count as 0; coverage = hit fraction), as the colour is
  // antialiased over the same jittered rays (docs/denoise.md).
#if defined(SDFC_HAS_MIRROR) || defined(SDFC_HAS_GLASS) || defined(SDFC_HAS_METAL)
  bool jittered = frame.skip_aov_ray == kAovJittered || frame.skip_aov_ray == kAovSpecular;
#else
  bool jittered = frame.skip_aov_ray == kAovJittered;
#endif
  vec4 aov_nd = vec4(0.0), aov_as = vec4(0.0);
  float coverage = 0.0;
#ifdef SDFC_LAYERS
  // --layers: the samples' squared luminance, whose mean a carries out (its
  // exact sums add across passes and shards): the variance layer (docs/layers.md).
  float sum_y2 = 0.0;
#endif
#endif
  // s = -1 is the unjittered primary ray for the AOVs (pass-split independent;
  // skipped on request when they are not read); sharing the loop keeps one
  // inlined copy of the tracer.
  for (int s = loopZero() - (frame.skip_aov_ray != 0u ? 0 : 1); s < count; s++) {
    g_loop_iterations++;
    bool aov = s < 0;
    beginSample(pixel, frame.sample_base + uint(max(s, 0)));
    vec2 jitter = aov ? vec2(0.5) : rand2();
    vec3 ro, rd;
    cameraRay(vec2(pixel) + jitter, !aov, ro, rd);
#ifdef SDFC_NO_AOVS
    vec3 l = tracePath(ro, rd, aov ? 0 : int(frame.max_bounces), aov || jittered);
    if (!aov && !any(isnan(l)) && !any(isinf(l))) sum += l;
    if (jittered) steps_sum += float(g_aov_steps);
#else
    if (jittered) {
      g_aov_normal = g_aov_albedo = vec3(0.0);
      g_aov_dist = -1.0;
    }
    vec3 l = tracePath(ro, rd, aov ? 0 : int(frame.max_bounces), aov || jittered);
    if (!aov && !any(isnan(l)) && !any(isinf(l))) sum += l;
#ifdef SDFC_LAYERS
    if (!aov && !any(isnan(l)) && !any(isinf(l))) {
      float y = dot(l, vec3(0.2126, 0.7152, 0.0722));
      sum_y2 += y * y;
    }
#endif
    if (jittered) {
      bool hit = g_aov_dist >= 0.0;
      aov_nd += vec4(g_aov_normal, hit ? g_aov_dist : 0.0);
      aov_as += vec4(g_aov_albedo, float(g_aov_steps));
      coverage += hit ? 1.0 : 0.0;
    }
#endif
  }

#ifdef SDFC_NO_AOVS
  out_normal_depth = vec4(0.0);
  out_albedo_steps = vec4(vec3(0.0), jittered ? steps_sum / float(max(count, 1)) : float(g_aov_steps));
  out_color = vec4(sum / float(max(count, 1)), 1.0);
#else
  out_normal_depth = vec4(g_aov_normal, g_aov_dist);
  out_albedo_steps = vec4(g_aov_albedo, float(g_aov_steps));
  vec3 color = sum / float(max(count, 1));
  if (jittered) {
    out_normal_depth = aov_nd / float(max(count, 1));
    out_albedo_steps = aov_as / float(max(count, 1));
  }
#ifdef SDFC_ALL_VIEWS
  if (frame.view == kViewNormal) color = g_aov_normal * 0.5 + 0.5;
  // Raw counts and distances: the runtime maps them for display (runtime/debug_view.h).
  if (frame.view == kViewSteps) color = vec3(float(g_aov_steps));
  if (frame.view == kViewDepth) color = vec3(g_aov_dist);
  if (frame.view == kViewAlbedo) color = g_aov_albedo;
  if (frame.view == kViewIterations) color = vec3(float(g_loop_iterations), 0.0, 0.0);
#ifdef SDFC_COUNT_EVENTS
  if (frame.view == kViewIterations) color.g = g_events;
#endif
#endif
#ifdef SDFC_VIEW_ITERATIONS
  color = vec3(float(g_loop_iterations), 0.0, 0.0);
#ifdef SDFC_COUNT_EVENTS
  color.g = g_events;
#endif
#endif
  out_color = vec4(color, jittered ? coverage / float(max(count, 1)) : 1.0);
#ifdef SDFC_LAYERS
  out_color.a = sum_y2 / float(max(count, 1));
#endif
#endif
}
#else
// A debug view's main (normal, steps, depth or albedo): the primary ray alone,
// the same unjittered ray as the path tracer's AOV ray and the same values,
// with no sampling, shading or bounces. Attachments 1 and 2 hold what this
// view computes (zero for the rest; the march steps always).
void main() {
  uvec2 pixel = uvec2(gl_FragCoord.xy) + uvec2(frame.tile_x, frame.tile_y);
  vec3 ro, rd;
  cameraRay(vec2(pixel) + vec2(0.5), false, ro, rd);
  // A camera inside a solid sees its inside (as the path tracer).
  float side = cameraSide(ro);
  int steps, surface_material;
  vec3 surface_normal;
  float t = march(ro, rd, 3.0e38, side, true, steps, surface_normal, surface_material);
  vec3 normal = vec3(0.0);
  float dist = -1.0;
  vec3 albedo = vec3(0.0);
#ifdef SDFC_HAS_SPHERE_LIGHTS
  float t_light = t < 0.0 ? 3.0e38 : t;
  int light_hit = nearestSphereLight(ro, rd, t_light);
  if (light_hit >= 0) {
    normal = normalize(ro + rd * t_light - kSphereLights[light_hit].xyz);
    dist = t_light;
  } else
#endif
  if (t >= 0.0) {
    dist = t;
#if defined(SDFC_VIEW_NORMAL) || defined(SDFC_VIEW_ALBEDO)
    int material = 0;
#ifdef SDFC_HAS_PLANES
    if (g_plane_hit >= 0) {
      normal = sdAnalyticNormal(g_plane_hit, ro + rd * t, material);
    } else
#endif
    {
      normal = surface_normal;  // a camera inside glass sees a contact as the path tracer does
      material = surface_material;
    }
#ifdef SDFC_VIEW_ALBEDO
#ifdef SDFC_HAS_FIELDS
    albedo = sdMaterialAt(material, ro + rd * t, normal).albedo;
#else
    albedo = sdMaterial(material).albedo;
#endif
#endif
#endif
  }
  out_normal_depth = vec4(normal, dist);
  out_albedo_steps = vec4(albedo, float(steps));
  vec3 color = vec3(0.0);
#ifdef SDFC_VIEW_NORMAL
  color = normal * 0.5 + 0.5;
#endif
#ifdef SDFC_VIEW_STEPS
  color = vec3(float(steps));  // raw, as depth: mapped for display by the runtime
#endif
#ifdef SDFC_VIEW_DEPTH
  color = vec3(dist);
#endif
#ifdef SDFC_VIEW_ALBEDO
  color = albedo;
#endif
  out_color = vec4(color, 1.0);
}
#endif
