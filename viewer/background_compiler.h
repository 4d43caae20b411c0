// Recompiles the scene off the frame loop: a worker thread runs parse, check,
// emit, glslang and pipeline creation (the slow part on lavapipe) and hands back
// a ready Renderer; the loop swaps it in between frames. Kernels are specialised
// per view: a reload builds the view on screen, and another view's kernel is
// built for the same scene on its first use (requestVariant). Diagnostics print
// exactly as `sdfc check` prints them (api::Scene).
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "api/scene.h"
#include "file_watcher.h"
#include "driver/compile.h"
#include "renderer.h"

namespace sdfc::view {

using Clock = std::chrono::steady_clock;

struct BuiltScene {
  bool ok = false;  // false: the file has errors (already printed) or pipeline creation failed
  // True: another view's kernel for the already loaded scene `compiled` (a view
  // switch), not a reload.
  bool variant = false;
  uint32_t view = 0;  // the view `renderer`'s kernel draws (gpu::kView*)
  std::shared_ptr<const CompiledScene> compiled;
  std::unique_ptr<Renderer> renderer;
  // Why it failed, for the title bar and the image's overlay: the first error
  // ("scene.sdf:7:3: message", error_overlay.h), or a short reason.
  std::string error;
  Clock::time_point requested, finished;
  double compile_seconds = 0, pipeline_seconds = 0;
  // How long the build waited, after pipeline creation, for the SPIR-V
  // validation running beside it (CompileOptions::validate_spirv off).
  double validation_wait_seconds = 0;
  // The first draw, on the worker (Renderer::compileKernel): the driver's
  // compile of the kernel, done before the build is handed to the frame loop.
  double kernel_compile_seconds = 0;
};

class BackgroundCompiler {
 public:
  // `load` gives the defines and warnings; `options` the compiler's options.
  BackgroundCompiler(const VulkanContext& context, std::string input, api::LoadOptions load,
                     CompileOptions options, std::string diagnostics_format = "text",
                     int error_limit = kDefaultErrorLimit);
  ~BackgroundCompiler();  // finishes the compile under way, drops its result

  // Compiles the file again, with the kernel for `view`; a request during a
  // compile is served after it (requests in between collapse into one, the
  // last view wins). Reloads go before variants.
  void request(uint32_t view);
  // Builds the kernel for `view` of an already compiled scene (emission,
  // glslang and pipeline; no parsing): a view not used before.
  void requestVariant(std::shared_ptr<const CompiledScene> scene, uint32_t view);
  // Watches `path` from the worker thread (every kWatchInterval while idle) and
  // reloads on a save with the view last given to setView: a save is seen and
  // compiled while the frame loop is still inside a long pass.
  void watch(const std::string& path);
  void setView(uint32_t view) { view_ = view; }
  // The window's height in pixels: the march's hit band is a fraction of a pixel
  // (EmitOptions::march.image_height), so builds after a resize use the new one.
  void setImageHeight(uint32_t height) { image_height_ = height; }
  // Called on the worker thread when a build is ready (before the first
  // request): the frame loop, asleep while idle, wakes at once to take it.
  void setOnReady(std::function<void()> on_ready) { on_ready_ = std::move(on_ready); }
  // The newest finished reload and every finished variant, oldest first. Call
  // from the thread that uses the queue.
  std::vector<std::unique_ptr<BuiltScene>> take();
  bool busy() const;
  // Starts no further build; true when one is under way on the worker (not
  // merely queued or finished), which the destructor would then wait for.
  bool stop();

 private:
  void run();
  std::unique_ptr<BuiltScene> buildReload(uint32_t view);
  std::unique_ptr<BuiltScene> buildVariant(std::shared_ptr<const CompiledScene> scene, uint32_t view);
  // The pipeline for `built` (its ok, renderer and pipeline time, or its error).
  // `limits`: the kernel's, for the camera-inside test (built.compiled's scene).
  void createRenderer(BuiltScene& built, const std::vector<uint32_t>& spirv,
                      const std::vector<float>& scene_data, const MarchLimits& limits);
  // Draws the new kernel once (Renderer::compileKernel) with the worker's pool.
  void compileKernel(BuiltScene& built);

  const VulkanContext& context_;
  VkCommandPool pool_ = VK_NULL_HANDLE;  // the worker's own (a pool is externally synchronised)
  const std::string input_;
  const api::LoadOptions load_;
  const std::string diagnostics_format_;
  const int error_limit_;
  const CompileOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool pending_ = false, working_ = false, stopping_ = false;
  uint32_t pending_view_ = 0;
  Clock::time_point pending_since_;
  struct VariantRequest {
    std::shared_ptr<const CompiledScene> scene;
    uint32_t view = 0;
    Clock::time_point since;
  };
  std::deque<VariantRequest> variants_;
  // Finished builds in order; take() keeps the newest reload and drops the
  // older ones on the caller's (the frame loop's) thread, where Vulkan objects may be destroyed.
  std::deque<std::unique_ptr<BuiltScene>> ready_;
  std::function<void()> on_ready_;
  std::unique_ptr<FileWatcher> watcher_;  // used by the worker thread only
  std::atomic<uint32_t> view_{0};
  std::atomic<uint32_t> image_height_{0};  // 0: options_'s
  std::thread thread_;
};

constexpr std::chrono::milliseconds kWatchInterval{5};

}  // namespace sdfc::view
