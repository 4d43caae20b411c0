// Image textures for colour fields: texels are vec4s of the scene data from
// `base`, rows from the top. Bilinear between texel centres, repeating; the
// definition and its float64 twin are in compiler/eval/color_field.h.

vec3 sdTextureBilinear(int base, int w, int h, vec2 uv) {
  vec2 size = vec2(w, h);
  vec2 st = uv * size - 0.5;
  vec2 c = floor(st);
  vec2 f = st - c;
  // Wrapped before the integer conversion (GLSL's % is undefined below 0).
  ivec2 i0 = min(ivec2(c - size * floor(c / size)), ivec2(w - 1, h - 1));
  ivec2 i1 = ivec2(i0.x + 1 == w ? 0 : i0.x + 1, i0.y + 1 == h ? 0 : i0.y + 1);
  int r0 = base + (h - 1 - i0.y) * w, r1 = base + (h - 1 - i1.y) * w;
  vec3 bottom = mix(sd_data[r0 + i0.x].rgb, sd_data[r0 + i1.x].rgb, f.x);
  vec3 top = mix(sd_data[r1 + i0.x].rgb, sd_data[r1 + i1.x].rgb, f.x);
  return mix(bottom, top, f.y);
}

vec3 sdTextureTriplanar(int base, int w, int h, vec3 p, vec3 n, float size) {
  vec3 wt = n * n;
  wt *= wt;
  wt /= wt.x + wt.y + wt.z;
  vec3 q = p / size;
  return sdTextureBilinear(base, w, h, q.zy) * wt.x + sdTextureBilinear(base, w, h, q.xz) * wt.y +
         sdTextureBilinear(base, w, h, q.xy) * wt.z;
}
