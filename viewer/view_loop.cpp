#include "view_loop.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <optional>
#include <thread>

#include "atomic_file.h"
#include "background_compiler.h"
#include "camera_controller.h"
#include "debug_view.h"
#include "display_pass.h"
#include "denoise.h"
#include "render_defaults.h"
#include "error_overlay.h"
#include "file_watcher.h"
#include "image_io.h"
#include "scene_render.h"
#include "script.h"
#include "pipeline_cache.h"
#include "spirv/spirv_cache.h"
#include "stage_timings.h"
#include "status.h"
#include "swapchain.h"
#include "vk_check.h"
#include "window.h"

namespace sdfc::view {
namespace {

// The camera counts as moving until it has been still for this many frames; while
// moving, frames are drawn at 1/preview_scale of the resolution.
constexpr int kSettleFrames = 2;
constexpr uint32_t kMinPreviewScale = 2, kMaxPreviewScale = 8;
// Preview frames aim between these times (the scale adapts one step a frame).
constexpr double kPreviewSlowMs = 60, kPreviewFastMs = 20;
// The window is drawn as one band up to this many pixels (a 2048 x 1024 window):
// a band is a submission and a wait, and the 640 x 360 castle took two at the
// renderer's default.
constexpr uint64_t kViewBandPixels = 1u << 21;
constexpr uint32_t kReloadPreviewScale = kMaxPreviewScale;
constexpr double kTimeStep = 1.0 / 30.0;  // the step key, and play speed is real time
constexpr double kScriptWaitSeconds = 600;  // a wait-* command longer than this fails

const char* const kViewNames[] = {"beauty", "normal", "steps", "depth", "albedo", "iterations"};

uint32_t viewFromName(const std::string& name) {
  for (uint32_t i = 0; i < 6; ++i)
    if (name == kViewNames[i]) return i;
  return gpu::kViewBeauty;
}

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// Finite bounds of the scene: the root's, or the union of its finite parts (an
// infinite ground plane would otherwise make every scene unbounded).
Aabb finiteBounds(const ir::Node& node) {
  if (node.bounds.finite()) return node.bounds;
  Aabb box;
  if (node.kind == ir::NodeKind::Union)
    for (const ir::NodeRef& child : node.children)
      if (child) box = box.unite(finiteBounds(*child));
  return box;
}

// Nearest-neighbour enlargement of an RGB8 image by an integer factor, cut to w x h.
void upscale(const std::vector<uint8_t>& small, uint32_t sw, uint32_t sh, uint32_t scale,
             uint32_t w, uint32_t h, std::vector<uint8_t>& out) {
  out.resize(size_t(w) * h * 3);
  for (uint32_t y = 0; y < h; ++y) {
    const uint8_t* row = small.data() + size_t(std::min(y / scale, sh - 1)) * sw * 3;
    uint8_t* o = out.data() + size_t(y) * w * 3;
    for (uint32_t x = 0; x < w; ++x) {
      const uint8_t* p = row + size_t(std::min(x / scale, sw - 1)) * 3;
      o[3 * x] = p[0];
      o[3 * x + 1] = p[1];
      o[3 * x + 2] = p[2];
    }
  }
}

// What an accumulation depends on: any difference restarts it.
struct AccumulationKey {
  uint64_t scene = 0, camera = 0;
  uint32_t view = 0, scale = 1;
  uint32_t width = 0, height = 0;  // the window's: a resize starts again
  double time = 0;
  bool operator==(const AccumulationKey& o) const {
    return scene == o.scene && camera == o.camera && view == o.view && scale == o.scale &&
           width == o.width && height == o.height && time == o.time;
  }
};

// --timings: one frame's parts (ms): the pass; the mean (and the denoiser or a
// debug view's mapping) into the display pass's input; the commands of the tone
// map and the copy and their submission; the acquire; the present (lavapipe's
// present waits there for the tone map and the copy on the device); and the time
// since the last frame (input, the title, the frame log, idle sleeps).
struct FrameParts {
  double pass = 0, tone = 0, copy = 0, acquire = 0, present = 0, wait = 0;
  double interval() const { return pass + tone + copy + acquire + present + wait; }
};

// Frames' parts, printed as medians (each part's own, and the interval's).
struct FrameSplit {
  Clock::time_point since = Clock::now();
  std::vector<FrameParts> frames;
  void add(const FrameParts& parts) { frames.push_back(parts); }
  std::string line(const char* what) const {
    // The median over the frames of f(frame): a part, or the whole interval.
    auto median = [&](auto f) {
      std::vector<double> v;
      for (const FrameParts& frame : frames) v.push_back(f(frame));
      if (v.empty()) return 0.0;
      std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
      return v[v.size() / 2];
    };
    auto part = [&](double FrameParts::*p) { return median([p](const FrameParts& f) { return f.*p; }); };
    const double interval = median([](const FrameParts& f) { return f.interval(); });
    char text[320];
    std::snprintf(text, sizeof text,
                  "%s (median of %zu, ms): interval %.2f = pass %.2f + mean %.2f + tone map and copy "
                  "submitted %.2f + acquire %.2f + present %.2f + wait %.2f",
                  what, frames.size(), interval, part(&FrameParts::pass), part(&FrameParts::tone),
                  part(&FrameParts::copy), part(&FrameParts::acquire), part(&FrameParts::present),
                  part(&FrameParts::wait));
    return text;
  }
};

class Viewer : public InputHandler {
 public:
  explicit Viewer(const ViewOptions& options) : cl_(options) {}
  ~Viewer() override;
  int run();

  void onKey(int key, int mods) override;
  void onMouseButton(int button, bool down, int mods) override;
  void onCursor(double x, double y) override;
  void onScroll(double dy) override;

 private:
  void open();
  void swapIn(std::unique_ptr<BuiltScene> built);
  bool drawFrame();
  void presentBlack();
  // Follows the window's size; false while it has none (minimised).
  bool followWindowSize();
  bool stepScript();  // false while the current command waits
  void saveImage(const std::string& path);
  void logEvent(const std::string& text);
  void updateTitle(bool force);

  const ViewOptions cl_;
  uint32_t width_ = 0, height_ = 0;
  std::unique_ptr<Window> window_;
  VulkanContext context_;
  bool context_created_ = false;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  std::unique_ptr<Swapchain> swapchain_;
  std::unique_ptr<BackgroundCompiler> compiler_;

  std::unique_ptr<BuiltScene> active_;  // the last good reload (its scene, timings)
  // The scene's kernels by view, built on first use (BackgroundCompiler::requestVariant).
  std::map<uint32_t, std::unique_ptr<Renderer>> renderers_;
  std::set<uint32_t> variants_requested_;
  uint64_t scene_generation_ = 0;
  CameraController controller_;
  CameraDesc file_camera_;
  glm::dvec3 origin_{0.0};  // the active scene's frame in the world (ir::Scene::origin)
  std::string error_;

  uint32_t view_ = gpu::kViewBeauty;
  bool denoise_ = false;
  bool dynamic_resolution_ = true;
  bool playing_ = false;
  double time_ = 0;
  std::optional<uint32_t> spp_override_;
  ToneMap tone_;

  std::optional<Accumulation> acc_;
  AccumulationKey acc_key_;
  uint64_t last_camera_generation_ = ~0ull;
  int frames_still_ = 0;
  uint32_t preview_scale_ = kMinPreviewScale;
  std::unique_ptr<DisplayPass> display_;  // the tone map on the device
  FloatImage displayed_;  // the shown floats when formed on the CPU (saveImage forms them otherwise)
  bool displayed_is_mean_ = false;
  ToneMap displayed_tone_;
  uint32_t shown_width_ = 0, shown_height_ = 0;
  std::vector<uint8_t> rgb_, upscaled_;
  RateMeter rate_;
  FrameSplit split_, whole_split_;  // this second's frames; all frames but the first
  Status status_;
  Clock::time_point last_title_{}, last_frame_end_{};  // the frame split's wait
  std::optional<Clock::time_point> played_until_;  // when time_ last advanced while playing
  double last_frame_ms_ = 0;

  Clock::time_point start_ = Clock::now();
  uint64_t frames_ = 0;  // presented
  bool quit_ = false;
  bool reload_unpresented_ = false;
  bool redisplay_ = false;
  bool reload_full_unpresented_ = false;  // no full-resolution frame of the new scene yet
  Clock::time_point reload_start_{};      // what the save-to-image figures count from
  Clock::time_point reload_since_{};  // the save (script write) or its detection
  std::optional<Clock::time_point> script_write_;
  std::ofstream frame_log_;

  // Script state.
  std::vector<ScriptCommand> script_;
  size_t script_at_ = 0;
  int wait_frames_ = -1;
  Clock::time_point wait_since_{};
  uint64_t reloads_seen_ = 0, reloads_at_wait_ = 0;
  // Loop iterations; a wait-* command completes only after one has passed since it
  // began, so the state set by the commands before it (a key) has been drawn.
  uint64_t iterations_ = 0, iteration_at_wait_ = 0;
  int drag_steps_left_ = 0;
  double drag_x_ = 0, drag_y_ = 0, drag_dx_ = 0, drag_dy_ = 0;
  int drag_button_ = 0;
};

Viewer::~Viewer() {
  compiler_.reset();  // joins the worker before its renderer's device goes
  renderers_.clear();
  active_.reset();
  swapchain_.reset();
  display_.reset();
  if (surface_) vkDestroySurfaceKHR(context_.instance, surface_, nullptr);
  if (context_created_) destroyContext(context_);
  window_.reset();
}

void Viewer::open() {
  // The window size is the render size: the scene's, or --size.
  width_ = 640;
  height_ = 360;
  {
    Diagnostics quiet;
    std::unique_ptr<SourceFile> file = readSourceFile(cl_.input);
    if (!file) {
      const std::string why = sourceFileProblem(cl_.input);
      throw std::runtime_error("cannot read '" + cl_.input + "'" + (why.empty() ? "" : ": " + why));
    }
    CompileOptions options;
    CompiledScene checked = checkSource(cl_.input, file->text, options, quiet);
    width_ = uint32_t(checked.scene.render.width);
    height_ = uint32_t(checked.scene.render.height);
  }
  if (const auto size = parseImageSize(cl_.size)) {  // checked by the command line
    width_ = uint32_t(size->first);
    height_ = uint32_t(size->second);
  }
  width_ = std::clamp<uint32_t>(width_, 16, 4096);
  height_ = std::clamp<uint32_t>(height_, 16, 4096);

  const auto window_start = Clock::now();
  window_ = std::make_unique<Window>(int(width_), int(height_),
                                     "sdfc view: " + cl_.input + " | compiling", this);
  const auto device_start = Clock::now();
  ContextOptions options;
  options.device_index = cl_.device;
  options.instance_extensions = Window::requiredInstanceExtensions();
  options.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  createContext(context_, options);
  context_created_ = true;
  const auto swapchain_start = Clock::now();
  surface_ = window_->createSurface(context_.instance);
  swapchain_ = std::make_unique<Swapchain>(context_, surface_, width_, height_);
  if (cl_.stage_timings)
    std::fprintf(stderr,
                 "sdfc: timings (ms): process start to main %.0f, to the window %.1f, window %.1f, "
                 "device creation %.1f, swapchain %.1f\n",
                 processStartToMainSeconds() * 1000,
                 secondsSinceMain() * 1000 - msBetween(window_start, Clock::now()),
                 msBetween(window_start, device_start), msBetween(device_start, swapchain_start),
                 msBetween(swapchain_start, Clock::now()));

  CompileOptions compile = cl_.load.compile;
  if (!cl_.no_cache) setPipelineCacheDirectory(sdfcCacheDirectory());
  // After the cache directory: its shader comes from the SPIR-V cache.
  const auto display_start = Clock::now();
  display_ = std::make_unique<DisplayPass>(context_);
  if (cl_.stage_timings)
    std::fprintf(stderr, "sdfc: timings (ms): display pass (the tone map on the device) %.1f\n",
                 msBetween(display_start, Clock::now()));
  compile.emit.march.image_height = int(height_);
  // As `render`: lavapipe runs lanes in lockstep, so a bound check pays only
  // where whole groups skip; the compiler keeps the checks that do (planned_bounds).
  if (context_.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU && !cl_.force_bounds)
    compile.emit.bounding_volumes = false;
  // SPIR-V is validated beside pipeline creation, off the save's critical path.
  compile.validate_spirv = false;
  // Before the worker exists: a present waits for the queue, which the worker
  // holds while the driver compiles a kernel.
  presentBlack();
  compiler_ = std::make_unique<BackgroundCompiler>(context_, cl_.input, cl_.load, compile,
                                                   cl_.diagnostics_format, cl_.error_limit);
  view_ = viewFromName(cl_.view);
  compiler_->setView(view_);
  compiler_->setOnReady([] { glfwPostEmptyEvent(); });  // thread-safe in GLFW
  compiler_->watch(cl_.input);  // saves are seen by the worker, within kWatchInterval
  reload_since_ = Clock::now();
  reload_unpresented_ = true;
  compiler_->request(view_);

  denoise_ = cl_.denoise;
  dynamic_resolution_ = cl_.dynamic_resolution;
  if (cl_.spp > 0) spp_override_ = uint32_t(cl_.spp);
  tone_ = cl_.tone;
  time_ = cl_.time;
  status_.file = std::filesystem::path(cl_.input).filename().string();
  std::fprintf(stderr, "sdfc: view %ux%u on %s (present mode %s)\n", width_, height_,
               context_.deviceName().c_str(), swapchain_->presentModeName());
}

void Viewer::logEvent(const std::string& text) {
  if (frame_log_.is_open()) frame_log_ << "event " << frames_ << " " << text << "\n";
}

void Viewer::swapIn(std::unique_ptr<BuiltScene> built) {
  if (built->variant) {  // another view's kernel for the scene on screen
    if (built->ok && active_ && built->compiled == active_->compiled) {
      renderers_[built->view] = std::move(built->renderer);
      logEvent(std::string("variant ") + kViewNames[built->view] + " ready in " +
               std::to_string(int(msBetween(built->requested, built->finished))) + " ms");
    } else if (!built->ok) {
      error_ = built->error;
      redisplay_ = true;
      updateTitle(true);
    }
    return;
  }
  ++reloads_seen_;
  if (!built->ok) {
    error_ = built->error;
    std::fprintf(stderr, "sdfc: the scene did not compile; still showing the last good one\n");
    reload_unpresented_ = false;
    redisplay_ = true;  // the last image again, with the error drawn on it
    if (!active_) presentBlack();  // no image yet: the error on black
    updateTitle(true);
    logEvent("reload error; title: " + titleFor(status_));
    return;
  }
  const bool first = !active_;
  // The old scene's kernels are destroyed here, on the queue's thread.
  renderers_.clear();
  variants_requested_.clear();
  renderers_[built->view] = std::move(built->renderer);
  active_ = std::move(built);
  ++scene_generation_;
  error_.clear();
  file_camera_ = cameraFor(active_->compiled->scene);
  // The scene's frame is at its file camera when that is far from the origin
  // (passes/rebase.cpp): a moved camera keeps its world place across reloads.
  const glm::dvec3 origin = active_->compiled->scene.origin;
  if (!first && origin != origin_) controller_.translate(origin_ - origin);
  origin_ = origin;
  if (first) {
    controller_.reset(file_camera_);
    last_camera_generation_ = controller_.generation();  // the first view is not a motion
    frames_still_ = kSettleFrames;
  }
  status_.uses_time = active_->compiled->scene.uses_time;
  reload_unpresented_ = true;
  reload_full_unpresented_ = true;
  // Like a camera motion: the new scene's first frames are drawn at the preview
  // resolution, so it shows up one small pass after its pipeline is ready.
  if (!first) {
    frames_still_ = 0;
    // Its first frame also pays the driver's shader compile (lavapipe JITs at the
    // first draw): draw it at the smallest preview size, so the new scene shows
    // as soon as possible (castle, after the compile: 4 ms at 80x45, 15 at 160x90).
    preview_scale_ = kReloadPreviewScale;
  }
  if (!script_write_) reload_since_ = active_->requested;
}

bool Viewer::drawFrame() {
  const CompiledScene& compiled = *active_->compiled;
  const auto kernel = renderers_.find(view_);
  if (kernel == renderers_.end()) {
    // This view's kernel is not built yet: ask once, keep the last image meanwhile.
    if (variants_requested_.insert(view_).second) compiler_->requestVariant(active_->compiled, view_);
    last_frame_end_ = Clock::now();
    return false;
  }
  Renderer& renderer = *kernel->second;
  const uint64_t camera_generation = controller_.generation();
  if (camera_generation != last_camera_generation_) {
    last_camera_generation_ = camera_generation;
    frames_still_ = 0;
  }
  const bool moving = dynamic_resolution_ && frames_still_ < kSettleFrames;
  const auto frame_start = Clock::now();
  // Play advances time by the wall clock since the last advance (rendering
  // included); a pause, or a scene without time, restarts the clock.
  if (playing_ && compiled.scene.uses_time) {
    if (played_until_) time_ += std::chrono::duration<double>(frame_start - *played_until_).count();
    played_until_ = frame_start;
  } else {
    played_until_.reset();
  }
  const Clock::time_point previous_frame_end = last_frame_end_;

  AccumulationKey key{scene_generation_, camera_generation, view_, moving ? preview_scale_ : 1,
                      width_, height_, compiled.scene.uses_time ? time_ : 0.0};
  // The primary-ray attachments are read back only for the denoiser.
  const bool need_aovs = denoise_ && view_ == gpu::kViewBeauty;
  if (!acc_ || !(key == acc_key_) || (need_aovs && !acc_->keep_aovs)) {
    RenderOverrides o;
    o.width = int(std::max<uint32_t>(1, (width_ + key.scale - 1) / key.scale));
    o.height = int(std::max<uint32_t>(1, (height_ + key.scale - 1) / key.scale));
    if (cl_.bounces >= 0) o.bounces = cl_.bounces;
    if (cl_.light_samples >= 0) o.light_samples = cl_.light_samples;
    o.view = view_;
    o.seed = cl_.seed;
    o.time = time_;
    RenderSettings settings = renderSettingsFor(compiled, o);
    settings.band_pixels = kViewBandPixels;
    acc_ = renderer.startAccumulation(controller_.camera(), settings, need_aovs);
    acc_key_ = key;
    rate_.reset();
  }
  // The same samples as `sdfc render` (api/render_defaults.h); the denoiser is
  // the viewer's own: atrous on a key, since it runs on every frame.
  RenderRequest request;
  if (spp_override_) request.spp = int(*spp_override_);
  request.view = view_;
  const uint32_t target = viewTargetSpp(request, compiled.scene.render);
  status_.target_spp = target;
  ++frames_still_;
  if (acc_->samples_done >= target && !reload_unpresented_ && !redisplay_) {
    last_frame_end_ = Clock::now();
    return false;  // converged: nothing new to show
  }
  if (acc_->samples_done < target) renderer.addPass(*acc_, 1);
  const auto rendered = Clock::now();
  // The display pass's input is free once the last frame's submission is done
  // (the pass just drawn waited for the queue, so this is mostly no wait).
  swapchain_->waitForLastFrame();
  const ToneMap tone = view_ == gpu::kViewBeauty ? tone_ : ToneMap{0.0f, ToneCurve::Clamp};
  const bool denoised = denoise_ && view_ == gpu::kViewBeauty && !moving;
  const bool cpu_image = denoised || debugViewNeedsMapping(view_) || !error_.empty();
  if (cpu_image) {
    acc_->meanInto(displayed_);  // reuses last frame's storage
    if (denoised)
      displayed_ = sdfc::denoise(Denoiser::ATrous, displayed_, acc_->normal_depth, acc_->albedo_steps);
    // Debug views as `sdfc render` writes their PNGs: mapped for display, no tone curve.
    if (debugViewNeedsMapping(view_))
      displayed_ = debugViewForDisplay(
          view_, displayed_, debugViewBudget(uint32_t(compiled.emitted.limits.max_steps), acc_->settings));
  }
  displayed_is_mean_ = !cpu_image;  // saveImage forms the mean when it is asked for
  displayed_tone_ = tone;
  shown_width_ = acc_->width;
  shown_height_ = acc_->height;
  Clock::time_point shaded;
  if (error_.empty()) {
    // The tone map on the device, straight into the swapchain's staging: the
    // CPU writes only the frame's floats (the mean, or the mapped image).
    float* input = display_->input(acc_->width, acc_->height);
    if (cpu_image)
      std::copy(displayed_.rgba.begin(), displayed_.rgba.end(), input);
    else
      acc_->meanInto(input);
    shaded = Clock::now();
    swapchain_->present(*display_, tone, acc_->width, acc_->height, key.scale, width_, height_);
  } else {
    // The error band is drawn on bytes: this frame is tone-mapped on the CPU.
    rgb_ = toSrgb8(displayed_, tone);
    std::vector<uint8_t>* shown = &rgb_;
    if (key.scale > 1) {
      upscale(rgb_, displayed_.width, displayed_.height, key.scale, width_, height_, upscaled_);
      shown = &upscaled_;
    }
    drawErrorOverlay(*shown, width_, height_, error_);
    shaded = Clock::now();
    swapchain_->present(shown->data(), width_, height_);
  }
  ++frames_;
  redisplay_ = false;
  const auto frame_end = Clock::now();
  last_frame_ms_ = msBetween(frame_start, frame_end);
  rate_.add(last_frame_ms_ / 1000, 1);
  last_frame_end_ = frame_end;
  if (moving) {  // adapt the preview resolution to keep the view interactive
    if (last_frame_ms_ > kPreviewSlowMs && preview_scale_ < kMaxPreviewScale) ++preview_scale_;
    if (last_frame_ms_ < kPreviewFastMs && preview_scale_ > kMinPreviewScale) --preview_scale_;
  }
  // The frame's split (--timings, the frame log): the pass, the mean and tone
  // map, the swapchain's acquire, copy and present, and the wait since the last
  // frame (input, the title, idle sleeps).
  const Swapchain::Times& swap = swapchain_->lastTimes();
  const double wait_ms =
      last_frame_end_ != Clock::time_point{} && frames_ > 1 ? msBetween(previous_frame_end, frame_start) : 0;
  if (cl_.stage_timings) {
    const FrameParts parts{msBetween(frame_start, rendered), msBetween(rendered, shaded), swap.copy,
                           swap.acquire, swap.present, wait_ms};
    split_.add(parts);
    if (frames_ > 1) whole_split_.add(parts);  // the first frame pays the driver's compile
    if (msBetween(split_.since, frame_end) >= 1000) {
      std::fprintf(stderr, "%s\n", split_.line("sdfc: frames").c_str());
      split_ = FrameSplit{};
      split_.since = frame_end;
    }
  }
  if (frame_log_.is_open()) {
    char line[384];
    std::snprintf(line, sizeof line,
                  "frame %" PRIu64 " t_ms %.1f scene %" PRIu64 " camera %" PRIu64
                  " res %ux%u spp %u view %s moving %d ms %.1f render_ms %.1f display_ms %.1f"
                  " present_ms %.1f acquire_ms %.2f copy_ms %.2f queue_present_ms %.2f wait_ms %.2f"
                  " hash %016" PRIx64 " time %.4f\n",
                  frames_, msBetween(start_, frame_end), scene_generation_, camera_generation,
                  acc_->width, acc_->height, acc_->samples_done, kViewNames[view_], moving ? 1 : 0,
                  last_frame_ms_, msBetween(frame_start, rendered), msBetween(rendered, shaded),
                  msBetween(shaded, frame_end), swap.acquire, swap.copy, swap.present, wait_ms,
                  swapchain_->lastFrameHash(), key.time);
    frame_log_ << line << std::flush;
  }
  if (reload_unpresented_) {
    reload_unpresented_ = false;
    const Clock::time_point since = script_write_.value_or(reload_since_);
    reload_start_ = since;
    script_write_.reset();
    char line[256];
    std::snprintf(line, sizeof line,
                  "save-to-image %.0f ms (compile %.0f ms, pipeline %.0f ms, kernel compile at the "
                  "first draw %.0f ms, first frame %.0f ms at %ux%u; waited %.0f ms for SPIR-V "
                  "validation)",
                  msBetween(since, frame_end), active_->compile_seconds * 1000,
                  active_->pipeline_seconds * 1000, active_->kernel_compile_seconds * 1000,
                  last_frame_ms_, acc_->width, acc_->height, active_->validation_wait_seconds * 1000);
    std::fprintf(stderr, "sdfc: %s %s\n", scene_generation_ == 1 ? "loaded:" : "reloaded:", line);
    logEvent(std::string("reload ok ") + line);
  }
  if (reload_full_unpresented_ && key.scale == 1) {
    reload_full_unpresented_ = false;
    char line[128];
    std::snprintf(line, sizeof line, "save-to-full-resolution %.0f ms", msBetween(reload_start_, frame_end));
    logEvent(std::string("reload full ") + line);
  }
  status_.spp = acc_->samples_done;
  status_.width = acc_->width;
  status_.height = acc_->height;
  status_.preview = moving;
  return true;
}

bool Viewer::followWindowSize() {
  uint32_t w = 0, h = 0;
  window_->framebufferSize(w, h);
  if (w == 0 || h == 0) return false;
  if (w == width_ && h == height_) return true;
  width_ = w;
  height_ = h;
  // A new swapchain at the new size before the next present; the accumulation
  // key holds the size, so the image starts again; like a camera motion, the
  // frames drawn while the border is dragged are previews.
  swapchain_->resize(w, h);
  compiler_->setImageHeight(h);
  frames_still_ = 0;
  redisplay_ = true;
  logEvent("resize " + std::to_string(w) + "x" + std::to_string(h));
  return true;
}

void Viewer::presentBlack() {
  rgb_.assign(size_t(width_) * height_ * 3, 0);
  drawErrorOverlay(rgb_, width_, height_, error_);
  swapchain_->present(rgb_.data(), width_, height_);
}

void Viewer::saveImage(const std::string& path) {
  // The device tone-mapped the mean: the same floats again, from the same samples.
  if (displayed_is_mean_ && acc_) acc_->meanInto(displayed_);
  if (displayed_.empty() || shown_width_ == 0) {
    std::fprintf(stderr, "sdfc: nothing to save yet\n");
    return;
  }
  try {
    // What the window shows (debug views are mapped already, no tone curve).
    writeImage(path, displayed_, displayed_tone_);
    std::fprintf(stderr, "sdfc: wrote %s (%ux%u, %u spp)\n", path.c_str(), displayed_.width,
                 displayed_.height, acc_ ? acc_->samples_done : 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfc: error: %s\n", e.what());
  }
}

void Viewer::onKey(int key, int mods) {
  const std::string stem = std::filesystem::path(cl_.input).stem().string();
  switch (key) {
    case GLFW_KEY_1: case GLFW_KEY_2: case GLFW_KEY_3: case GLFW_KEY_4: case GLFW_KEY_5:
      view_ = uint32_t(key - GLFW_KEY_1);
      break;
    case GLFW_KEY_F:
      if (active_ && active_->compiled->scene.root) {
        const Aabb box = finiteBounds(*active_->compiled->scene.root);
        if (box.finite()) controller_.frame(box.lo, box.hi, float(width_) / float(height_));
      }
      break;
    case GLFW_KEY_R: controller_.reset(file_camera_); break;
    case GLFW_KEY_C:
      std::printf("%s\n", controller_.cameraLine(origin_).c_str());
      std::fflush(stdout);
      break;
    case GLFW_KEY_SPACE: playing_ = !playing_; break;
    case GLFW_KEY_PERIOD:
      playing_ = false;
      time_ += kTimeStep;
      break;
    case GLFW_KEY_D: denoise_ = !denoise_; break;
    case GLFW_KEY_S: saveImage(stem + "_view.png"); break;
    case GLFW_KEY_E: saveImage(stem + "_view.exr"); break;
    case GLFW_KEY_Q: case GLFW_KEY_ESCAPE: quit_ = true; break;
    default: break;
  }
  if (key == GLFW_KEY_D) redisplay_ = true;  // show the same samples with(out) the denoiser
}

void Viewer::onMouseButton(int button, bool down, int mods) {
  controller_.mouseButton(button, down, mods & GLFW_MOD_SHIFT);
}
void Viewer::onCursor(double x, double y) { controller_.cursor(x, y, height_); }
void Viewer::onScroll(double dy) { controller_.scroll(dy); }

void Viewer::updateTitle(bool force) {
  const auto now = Clock::now();
  if (!force && msBetween(last_title_, now) < 250) return;
  last_title_ = now;
  status_.view = kViewNames[view_];
  status_.spp_per_second = rate_.samplesPerSecond();
  status_.frame_ms = last_frame_ms_;
  status_.denoise = denoise_;
  status_.playing = playing_;
  status_.time = time_;
  status_.compiling = compiler_ && compiler_->busy();
  status_.error = error_;
  window_->setTitle(titleFor(status_));
}

bool Viewer::stepScript() {
  if (script_at_ >= script_.size()) return true;
  const ScriptCommand& c = script_[script_at_];
  auto timedOut = [&] {
    if (msBetween(wait_since_, Clock::now()) < kScriptWaitSeconds * 1000) return false;
    std::fprintf(stderr, "sdfc: script line %d: '%s' timed out\n", c.line, c.verb.c_str());
    return true;
  };
  auto next = [&] {
    ++script_at_;
    wait_frames_ = -1;
    wait_since_ = Clock::now();
    reloads_at_wait_ = reloads_seen_;
    iteration_at_wait_ = iterations_;
    return true;
  };
  const bool drawn_since = iterations_ > iteration_at_wait_;
  if (c.verb == "wait") {
    if (wait_frames_ < 0) wait_frames_ = std::max(0, std::atoi(c.args[0].c_str()));
    if (wait_frames_ == 0) return next();
    --wait_frames_;
    return false;
  }
  if (c.verb == "wait-spp") {
    const bool settled = drawn_since && acc_ && acc_key_.scale == 1 && !reload_unpresented_;
    if ((settled && acc_->samples_done >= uint32_t(std::atoi(c.args[0].c_str()))) || timedOut())
      return next();
    return false;
  }
  if (c.verb == "wait-reload") {
    if ((drawn_since && reloads_seen_ > reloads_at_wait_ && !reload_unpresented_) || timedOut())
      return next();
    return false;
  }
  if (c.verb == "wait-idle") {
    const bool idle = drawn_since && active_ && acc_ && !compiler_->busy() && !reload_unpresented_ &&
                      acc_key_.scale == 1 && acc_->samples_done >= status_.target_spp;
    if (idle || timedOut()) return next();
    return false;
  }
  if (c.verb == "drag") {
    if (drag_steps_left_ == 0) {
      drag_button_ = c.args[0] == "left" ? 0 : c.args[0] == "right" ? 1 : 2;
      const int steps = c.args.size() > 3 ? std::max(1, std::atoi(c.args[3].c_str())) : 1;
      drag_dx_ = std::atof(c.args[1].c_str()) / steps;
      drag_dy_ = std::atof(c.args[2].c_str()) / steps;
      drag_x_ = width_ / 2.0;
      drag_y_ = height_ / 2.0;
      onCursor(drag_x_, drag_y_);
      onMouseButton(drag_button_, true, 0);
      drag_steps_left_ = steps;
    }
    drag_x_ += drag_dx_;
    drag_y_ += drag_dy_;
    onCursor(drag_x_, drag_y_);
    logEvent("input drag");
    if (--drag_steps_left_ == 0) {
      onMouseButton(drag_button_, false, 0);
      return next();
    }
    return false;  // one step a frame
  }
  if (c.verb == "key") {
    onKey(keyCodeForName(c.args[0]), 0);
    logEvent("input key " + c.args[0]);
  } else if (c.verb == "scroll") {
    onScroll(std::atof(c.args[0].c_str()));
    logEvent("input scroll");
  } else if (c.verb == "spp") {
    spp_override_ = uint32_t(std::max(1, std::atoi(c.args[0].c_str())));
  } else if (c.verb == "save") {
    saveImage(c.args[0]);
  } else if (c.verb == "write-file") {
    // As an editor saving: write a temporary beside the scene, rename it over.
    std::ifstream in(c.args[0], std::ios::binary);
    if (!in) throw std::runtime_error("script: cannot read '" + c.args[0] + "'");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    script_write_ = Clock::now();
    writeFileAtomically(cl_.input, text);
    logEvent("write " + c.args[0]);
  } else if (c.verb == "run") {
    std::string command = c.rest;
    const std::string id = std::to_string(window_->nativeId());
    for (size_t at; (at = command.find("${WINDOW}")) != std::string::npos;)
      command.replace(at, 9, id);
    std::fflush(stdout);
    const int status = std::system(command.c_str());
    if (status != 0) std::fprintf(stderr, "sdfc: script line %d: command exited with %d\n", c.line, status);
  } else if (c.verb == "resize") {
    window_->setSize(std::max(1, std::atoi(c.args[0].c_str())), std::max(1, std::atoi(c.args[1].c_str())));
    logEvent("input resize " + c.args[0] + "x" + c.args[1]);
  } else if (c.verb == "log") {
    logEvent("log " + c.rest);
  } else if (c.verb == "quit") {
    quit_ = true;
  }
  return next();
}

int Viewer::run() {
  if (!cl_.script.empty()) {
    try {
      script_ = loadScript(cl_.script);
    } catch (const std::runtime_error& e) {
      std::fprintf(stderr, "%s\n", e.what());
      return kExitUsage;
    }
  }
  if (!cl_.frame_log.empty()) {
    frame_log_.open(cl_.frame_log);
    if (!frame_log_) throw std::runtime_error("cannot write '" + cl_.frame_log + "'");
  }
  open();
  wait_since_ = Clock::now();
  while (!quit_ && !window_->shouldClose()) {
    window_->pollEvents();
    // Commands that do not wait run back to back; a waiting one ends the step.
    while (!quit_ && script_at_ < script_.size() && stepScript()) {
    }
    if (quit_) break;
    compiler_->setView(view_);  // what the next reload builds
    bool drew = false;
    // While the worker has the queue (the driver compiling a new kernel at its
    // first draw), this frame is skipped: the window keeps the last image and
    // input, Q included, is still read.
    std::unique_lock<std::recursive_mutex> queue(*context_.queue_lock, std::try_to_lock);
    if (queue.owns_lock()) {
      for (std::unique_ptr<BuiltScene>& built : compiler_->take()) swapIn(std::move(built));
      const bool sized = followWindowSize();
      drew = active_ && sized ? drawFrame() : false;
      queue.unlock();
    }
    ++iterations_;
    updateTitle(false);
    // Idle (converged, waiting for a build, or the queue busy): sleep on input, not spin.
    if (!drew) window_->waitEvents(0.01);
  }
  logEvent("quit");
  if (cl_.stage_timings && !whole_split_.frames.empty())
    std::fprintf(stderr, "%s\n", whole_split_.line("sdfc: all frames but the first").c_str());
  const int messages = validationMessageCount();
  const int code = context_.validation_enabled && messages > 0 ? kExitDevice : kExitOk;
  if (code != kExitOk) std::fprintf(stderr, "sdfc: %d Vulkan validation messages\n", messages);
  if (compiler_->stop()) {
    // A build is under way (glslang, or the driver's compile, which cannot be
    // cancelled and may take seconds): quit now instead of joining it. Nothing
    // on disk depends on it (cache entries are written by rename).
    std::fprintf(stderr, "sdfc: quit during a build; not waiting for it\n");
    if (frame_log_.is_open()) frame_log_.flush();
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(code);
  }
  return code;
}

}  // namespace

int runView(const ViewOptions& options) {
  try {
    Viewer viewer(options);
    return viewer.run();
  } catch (const NoDisplayError& e) {
    std::fprintf(stderr,
                 "sdfc: error: `sdfc view` needs a display: %s\n"
                 "sdfc: to render without one: sdfc render %s -o image.png\n",
                 e.what(), options.input.c_str());
    return kExitDevice;
  } catch (const RuntimeError& e) {
    std::fprintf(stderr, "sdfc: error: device: %s\n", e.what());
    return kExitDevice;
  }
}

}  // namespace sdfc::view
