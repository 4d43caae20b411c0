// `sdfc export`: the scene as one self-contained web page that path-traces it
// in WebGL2 (runtime/web/page.html), or as code for a Shadertoy image tab
// (docs/export.md). The kernel is the one `sdfc render` runs, rewritten as
// GLSL ES 3.00 (emit/glsl_es.h) and checked by glslang before it is written.
#include <filesystem>
#include <cmath>
#include <cctype>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "cli_support.h"
#include "commands.h"
#include "emit/embedded_sources.h"
#include "emit/glsl_es.h"
#include "camera.h"
#include "camera_inside.h"
#include "image_io.h"
#include "scene_render.h"

namespace sdfc {
namespace {

// A JSON string literal that is also inert inside the <script> element it
// sits in: '<', '>' and '&' are written \u003c, \u003e and \u0026, so no
// "</script", "<!--" or "<script" in a file name or the kernel can end the
// element or switch the HTML parser into its escaped states (a name holding
// "<!--<script>" left the page blank). U+2028 and U+2029 are escaped too,
// for a reader that takes the block as JavaScript rather than JSON.
std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (size_t i = 0; i < s.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += char(c);
    } else if (c == '\n') {
      out += "\\n";
    } else if (c < 0x20 || c == '<' || c == '>' || c == '&' || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else if (c == 0xe2 && i + 2 < s.size() && static_cast<unsigned char>(s[i + 1]) == 0x80 &&
               (static_cast<unsigned char>(s[i + 2]) == 0xa8 || static_cast<unsigned char>(s[i + 2]) == 0xa9)) {
      out += static_cast<unsigned char>(s[i + 2]) == 0xa8 ? "\\u2028" : "\\u2029";
      i += 2;
    } else {
      out += char(c);
    }
  }
  return out + "\"";
}

// The file name as it may stand in a `//` comment of GLSL: a control
// character (a newline would end the comment and make the rest of the name
// code) and a backslash (one before the newline splices the next line in)
// are written as escapes: \n, \t, \r or \xNN.
std::string commentSafe(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c == '\r') out += "\\r";
    else if (c < 0x20 || c == 0x7f || c == '\\') {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else out += ch;
  }
  return out;
}

std::string htmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

std::string base64(const void* data, size_t size) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (size_t i = 0; i < size; i += 3) {
    const uint32_t n = uint32_t(p[i]) << 16 | (i + 1 < size ? uint32_t(p[i + 1]) << 8 : 0) |
                       (i + 2 < size ? uint32_t(p[i + 2]) : 0);
    out += kDigits[n >> 18 & 63];
    out += kDigits[n >> 12 & 63];
    out += i + 1 < size ? kDigits[n >> 6 & 63] : '=';
    out += i + 2 < size ? kDigits[n & 63] : '=';
  }
  return out;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string vec(const glm::vec3& v) { return "[" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + "]"; }

std::string glslVec(const glm::vec3& v) {
  return "vec3(" + glslFloat(v.x) + ", " + glslFloat(v.y) + ", " + glslFloat(v.z) + ")";
}

std::string stem(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  const size_t dot = name.rfind(".sdf");
  return dot != std::string::npos && dot + 4 == name.size() ? name.substr(0, dot) : name;
}

// The Shadertoy tab's entry point: the scene's camera orbited by the mouse
// (x: yaw, y: pitch, as `sdfc view`'s left drag), the normal view sRGB-encoded
// as `sdfc render --view normal` writes its PNG.
std::string glslVec4(const glm::vec4& v) {
  return "vec4(" + glslFloat(v.x) + ", " + glslFloat(v.y) + ", " + glslFloat(v.z) + ", " + glslFloat(v.w) + ")";
}

std::string shadertoyMain(const CameraDesc& c, const RenderSettings& s) {
  // The file's camera as makeFrameParams computes it in float, so the still image
  // is render's to the last bit of every ray.
  const gpu::FrameParams f = makeFrameParams(c, s.width, s.height, s.time);
  std::ostringstream o;
  o << "\n// ---- Shadertoy entry point (sdfc export --target shadertoy) ----\n"
       "void mainImage(out vec4 fragColor, in vec2 fragCoord) {\n"
       "  frame.cam_origin = " << glslVec4(f.cam_origin) << ";\n"
       "  frame.cam_right = " << glslVec4(f.cam_right) << ";\n"
       "  frame.cam_up = " << glslVec4(f.cam_up) << ";\n"
       "  frame.cam_forward = " << glslVec4(f.cam_forward) << ";\n"
       "  if (iMouse.z > 0.0) {  // dragging: orbit around the target\n"
       "    vec3 target = " << glslVec(c.target) << ", up = " << glslVec(c.up) << ";\n"
       "    vec3 offset = frame.cam_origin.xyz - target;\n"
       "    float r = length(offset);\n"
       "    float yaw = -(iMouse.x - iResolution.x * 0.5) * 0.005;\n"
       "    float pitch = (iMouse.y - iResolution.y * 0.5) * 0.005;\n"
       "    float el = clamp(asin(offset.y / r) + pitch, -1.55, 1.55), az = atan(offset.z, offset.x) + yaw;\n"
       "    vec3 eye = target + r * vec3(cos(el) * cos(az), sin(el), cos(el) * sin(az));\n"
       "    vec3 forward = normalize(target - eye), right = normalize(cross(forward, up));\n"
       "    frame.cam_origin.xyz = eye;\n"
       "    frame.cam_right.xyz = right;\n"
       "    frame.cam_up.xyz = cross(right, forward);\n"
       "    frame.cam_forward.xyz = forward;\n"
       "  }\n"
       "  frame.width = uint(iResolution.x);\n"
       "  frame.height = uint(iResolution.y);\n"
       "  frame.sample_base = 0u;\n"
       "  frame.sample_count = 1u;\n"
       "  frame.seed = 0u;\n"
       "  frame.view = kViewNormal;\n"
       "  frame.max_bounces = 0u;\n"
       "  frame.light_samples = 0u;\n"
       "  frame.tile_x = 0u;\n"
       "  frame.tile_y = 0u;\n"
       "  frame.traversal_visits = 0u;\n"
       "  frame.skip_aov_ray = 0u;\n"
       "  frame.camera_inside = 0u;\n"
       "  g_frag_coord = vec4(fragCoord.x, iResolution.y - fragCoord.y, 0.0, 1.0);\n"
       "  sdfcKernel();\n"
       "  vec3 v = clamp(out_color.rgb, 0.0, 1.0);\n"
       "  fragColor = vec4(mix(12.92 * v, 1.055 * pow(v, vec3(1.0 / 2.4)) - 0.055, "
       "step(0.0031308, v)), 1.0);\n"
       "}\n";
  return o.str();
}

}  // namespace

int runExport(const CommandLine& cl) {
  const bool shadertoy = cl.export_target == "shadertoy";
  RenderOverrides o;
  if (!renderOverridesFrom(cl, o)) return kExitUsage;
  // The extension, as render and mesh check theirs: `-o scene.sdf` or a name
  // without one is a mistake (the scene itself was overwritten that way).
  const std::string want = shadertoy ? ".glsl" : ".html";
  std::string ext = std::filesystem::path(cl.output).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (!isStreamPath(cl.output) && ext != want && !(ext == ".htm" && !shadertoy)) {
    std::cerr << "sdfc: error: export " << (shadertoy ? "--target shadertoy writes GLSL" : "writes a web page")
              << ": -o must end in " << want << ", got '" << cl.output << "'\n";
    return kExitUsage;
  }
  checkWritablePath(cl.output);  // before the work, not after

  CompileOptions options = compileOptionsFrom(cl);
  if (o.height) options.emit.march.image_height = *o.height;
  // As `sdfc render` on this machine's CPU device, so the page draws its image;
  // --bounds for GPUs, which jump over a bounded subtree.
  if (!cl.force_bounds) options.emit.bounding_volumes = false;
  // The page switches views at run time; Shadertoy gets the normal view alone.
  options.emit.view = shadertoy ? KernelView::Normal : KernelView::All;
  options.produce_spirv = false;
  Diagnostics diags;
  LoadedScene loaded = loadScene(cl, diags, true, false, options, true);
  if (loaded.exit_code != kExitOk) return loaded.exit_code;
  const CompiledScene& c = loaded.compiled;
  if (c.scene.sky.map) {
    // The page has no importance sampling of its own, nor room for a large map.
    std::cerr << "sdfc: error: the scene is lit by an environment map (sky(map: \""
              << std::filesystem::path(c.scene.sky.map->path).filename().string()
              << "\")), which sdfc export does not support yet; render it with sdfc render, or give "
                 "the exported scene sky(color: ...) or sky(top: ..., bottom: ...)\n";
    return kExitScene;
  }
  const std::vector<float>& data = c.emitted.scene_data;
  const size_t vec4s = data.size() / 4;

  if (shadertoy && !data.empty()) {
    std::cerr << "sdfc: error: the scene's instances are data (" << vec4s
              << " vec4), and a Shadertoy image tab has no way to load data; export it as a "
                 "page (without --target shadertoy), or write the copies out in the scene\n";
    return kExitScene;
  }
  const size_t max_vec4s = size_t(kEsDataWidth) * size_t(cl.max_data_rows);
  if (vec4s > max_vec4s) {
    char mib[32];
    std::snprintf(mib, sizeof mib, "%.1f", double(data.size()) * 4 / (1 << 20));
    std::cerr << "sdfc: error: the scene's instance data is " << vec4s << " vec4 (" << mib
              << " MiB); a WebGL2 page holds at most "
              << max_vec4s << " (a " << kEsDataWidth << " x " << cl.max_data_rows
              << " RGBA32F texture; every browser takes " << kEsMaxDataRows
              << " rows, --max-data-rows sets more); the export would have to cut it, so nothing "
                 "was written\n";
    return kExitScene;
  }

  const GlslEsResult es = toGlslEs(c.emitted.glsl, shadertoy ? EsTarget::Shadertoy : EsTarget::WebGl2);
  if (!es.ok()) {
    std::cerr << "sdfc: error: cannot export this kernel: " << es.error << "\n";
    return kExitUsage;
  }
  const RenderSettings settings = renderSettingsFor(c, o);
  const CameraDesc camera = cameraFor(c.scene);
  std::string kernel = es.glsl;
  if (shadertoy) kernel += shadertoyMain(camera, settings);
  // Our own text, so a failure here is sdfc's bug, not the user's: say so.
  const std::string invalid = validateGlslEs(kernel, shadertoy ? EsTarget::Shadertoy : EsTarget::WebGl2);
  if (!invalid.empty()) {
    std::cerr << "sdfc: error: internal: the GLSL ES kernel does not compile (please report):\n"
              << invalid;
    return kExitDevice;
  }

  std::string out;
  if (shadertoy) {
    out = "// " + commentSafe(stem(cl.input)) + ": written by `sdfc export --target shadertoy` (docs/export.md).\n"
          "// Paste into a Shadertoy image tab: the scene's normal view; drag to orbit.\n" + kernel;
  } else {
    const CameraInsideTest inside = cameraInsideTest(c.scene, c.emitted.limits);
    ToneMap tone;
    tone.curve = cl.aces ? ToneCurve::AcesFit : *toneCurveFromName(cl.tonemap);
    const int curve = tone.curve == ToneCurve::PbrNeutral ? 0 : tone.curve == ToneCurve::AcesFit ? 1 : 2;
    std::ostringstream json;
    json << "{\"name\": " << jsonString(stem(cl.input)) << ", \"width\": " << settings.width
         << ", \"height\": " << settings.height << ", \"spp\": " << settings.spp
         << ", \"bounces\": " << settings.max_bounces << ", \"light_samples\": " << settings.light_samples
         << ", \"seed\": " << settings.seed << ", \"time\": " << num(settings.time)
         << ", \"traversal_visits\": " << traversalVisitsFor(settings, 1)
         << ", \"camera_inside\": " << (inside && inside(camera.position, settings.time) ? 1 : 0)
         << ", \"max_steps\": " << c.emitted.limits.max_steps << ", \"tonemap\": " << curve
         << ", \"exposure\": " << num(cl.exposure) << ", \"camera\": {\"position\": " << vec(camera.position)
         << ", \"target\": " << vec(camera.target) << ", \"up\": " << vec(camera.up)
         << ", \"fov\": " << num(camera.fov_degrees) << ", \"aperture\": " << num(camera.aperture)
         << ", \"focus\": " << num(camera.focus_distance) << "}";
    const Aabb& b = c.scene.root ? c.scene.root->bounds : Aabb();
    if (c.scene.root && !b.empty() && b.finite())
      json << ", \"bounds\": [" << vec(glm::vec3(b.lo)) << ", " << vec(glm::vec3(b.hi)) << "]";
    json << ", \"data_width\": " << kEsDataWidth << ", \"data\": "
         << (data.empty() ? std::string("null") : "\"" + base64(data.data(), data.size() * 4) + "\"")
         << ",\n\"kernel\": " << jsonString(kernel) << "}";
    std::string page(embeddedSource("web/page.html"));
    const size_t title = page.find("@SDFC_TITLE@");
    page.replace(title, 12, htmlEscape(stem(cl.input)) + " (sdfc)");
    const size_t scene = page.find("@SDFC_SCENE@");
    page.replace(scene, 12, json.str());
    out = std::move(page);
  }
  writeFileAtomically(cl.output, out);
  if (!cl.quiet)
    std::fprintf(stderr, "sdfc: wrote %s (%.1f KB%s)\n", cl.output.c_str(), out.size() / 1000.0,
                 shadertoy ? ", the normal view" : "");
  return kExitOk;
}

}  // namespace sdfc
