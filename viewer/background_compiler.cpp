#include "background_compiler.h"

#include <algorithm>
#include <cstdio>
#include <future>

#include "spirv/glsl_to_spirv.h"
#include "spirv/spirv_cache.h"
#include <unistd.h>

#include "error_overlay.h"
#include "vk_check.h"

namespace sdfc::view {

BackgroundCompiler::BackgroundCompiler(const VulkanContext& context, std::string input,
                                       api::LoadOptions load, CompileOptions options,
                                       std::string diagnostics_format, int error_limit)
    : context_(context),
      input_(std::move(input)),
      load_(std::move(load)),
      diagnostics_format_(std::move(diagnostics_format)),
      error_limit_(error_limit),
      options_(std::move(options)) {
  thread_ = std::thread([this] { run(); });
}

BackgroundCompiler::~BackgroundCompiler() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void BackgroundCompiler::request(uint32_t view) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!pending_) pending_since_ = Clock::now();
    pending_ = true;
    pending_view_ = view;
  }
  wake_.notify_all();
}

void BackgroundCompiler::watch(const std::string& path) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    watcher_ = std::make_unique<FileWatcher>(path);
  }
  wake_.notify_all();
}

void BackgroundCompiler::requestVariant(std::shared_ptr<const CompiledScene> scene, uint32_t view) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    variants_.push_back({std::move(scene), view, Clock::now()});
  }
  wake_.notify_all();
}

std::vector<std::unique_ptr<BuiltScene>> BackgroundCompiler::take() {
  std::deque<std::unique_ptr<BuiltScene>> ready;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ready.swap(ready_);
  }
  // Only the newest reload matters; older ones are destroyed here, on this thread.
  std::vector<std::unique_ptr<BuiltScene>> out;
  for (auto it = ready.rbegin(); it != ready.rend(); ++it) {
    if (!(*it)->variant) {
      bool newer = false;
      for (const auto& kept : out) newer = newer || !kept->variant;
      if (newer) continue;
    }
    out.push_back(std::move(*it));
  }
  std::reverse(out.begin(), out.end());
  return out;
}

bool BackgroundCompiler::stop() {
  bool working = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
    working = working_;
  }
  wake_.notify_all();
  return working;
}

bool BackgroundCompiler::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pending_ || working_ || !variants_.empty() || !ready_.empty();
}

std::unique_ptr<BuiltScene> BackgroundCompiler::buildReload(uint32_t view) {
  auto built = std::make_unique<BuiltScene>();
  built->view = view;
  const auto start = Clock::now();
  api::LoadOptions load = load_;
  load.compile = options_;
  load.compile.emit.view = static_cast<KernelView>(view);
  if (image_height_ > 0) load.compile.emit.march.image_height = int(image_height_);
  load.emit = true;
  std::unique_ptr<api::Scene> loaded = api::loadFile(input_, load);
  if (!loaded->io_error.empty()) {
    std::fprintf(stderr, "sdfc: error: %s\n", loaded->io_error.c_str());
  } else {
    const std::string text = diagnostics_format_ == "json" ? loaded->diagnosticsJson(error_limit_)
                                                           : loaded->diagnosticsText(isatty(STDERR_FILENO), error_limit_);
    std::fputs(text.c_str(), stderr);
  }
  built->compile_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  {
    // A save of an imported file, a mesh or a texture reloads too (even when
    // this compile failed there).
    std::vector<std::string> imports;
    for (const auto& f : loaded->compiled.scene.imported_sources) imports.push_back(f->path);
    for (const auto& f : loaded->compiled.scene.data_files) imports.push_back(f);
    std::lock_guard<std::mutex> lock(mutex_);
    if (watcher_) watcher_->watchAlso(imports);
  }
  if (!loaded->ok()) {
    built->error = firstErrorText(loaded->diagnostics);
    if (built->error.empty())
      built->error = !loaded->io_error.empty() ? "cannot read the file" : "the scene has errors";
    return built;
  }
  // The scene travels with its diagnostics' source (the shared_ptr keeps both).
  std::shared_ptr<api::Scene> owner(std::move(loaded));
  auto compiled = std::shared_ptr<CompiledScene>(owner, &owner->compiled);
  built->compiled = compiled;
  createRenderer(*built, compiled->spirv, compiled->emitted.scene_data, compiled->emitted.limits);
  if (built->ok && !compiled->spirv_cache_key.empty() && !options_.validate_spirv &&
      !compiled->times.spirv_cached)
    storeCachedSpirv(compiled->spirv_cache_key, compiled->spirv);  // validated beside the pipeline
  compileKernel(*built);
  return built;
}

void BackgroundCompiler::createRenderer(BuiltScene& built, const std::vector<uint32_t>& spirv,
                                        const std::vector<float>& scene_data,
                                        const MarchLimits& limits) {
  // Unless the compile validated it, the SPIR-V is validated on a second thread
  // while this one has the driver build the pipeline (lavapipe does that on the
  // calling thread): on the castle they take about as long each, and the
  // renderer is kept, and so drawn with, only if the module is valid.
  std::future<std::string> validation;
  if (!options_.validate_spirv)
    validation = std::async(std::launch::async, [&spirv] { return validateSpirv(spirv); });
  try {
    built.renderer = std::make_unique<Renderer>(context_, spirv, scene_data);
    // built.compiled (shared) outlives the renderer it holds the scene for.
    built.renderer->setCameraInsideTest(cameraInsideTest(built.compiled->scene, limits));
    built.pipeline_seconds = built.renderer->pipelineSeconds();
    built.ok = true;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfc: error: pipeline creation: %s\n", e.what());
    built.error = "pipeline creation failed";
  }
  if (!validation.valid()) return;
  const auto waited = Clock::now();
  const std::string errors = validation.get();
  built.validation_wait_seconds = std::chrono::duration<double>(Clock::now() - waited).count();
  if (!errors.empty()) {
    std::fprintf(stderr, "sdfc: error: internal error: the generated shader is not valid SPIR-V:\n%s",
                 errors.c_str());
    built.renderer.reset();
    built.ok = false;
    built.error = "kernel compile failed";
  }
}

void BackgroundCompiler::compileKernel(BuiltScene& built) {
  if (!built.ok || !built.renderer || !pool_) return;
  // The driver's compile at the first draw (lavapipe: LLVM, seconds for scenes
  // of instances) happens here, while the frame loop keeps showing the last
  // image and reading input; it skips its frames while this holds the queue.
  std::fprintf(stderr, "sdfc: compiling the kernel (first draw)...\n");
  try {
    built.kernel_compile_seconds = built.renderer->compileKernel(built.view, pool_);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sdfc: error: the kernel's first draw: %s\n", e.what());
    built.renderer.reset();
    built.ok = false;
    built.error = "kernel compile failed";
  }
}

std::unique_ptr<BuiltScene> BackgroundCompiler::buildVariant(std::shared_ptr<const CompiledScene> scene,
                                                            uint32_t view) {
  auto built = std::make_unique<BuiltScene>();
  built->variant = true;
  built->view = view;
  built->compiled = scene;
  const auto start = Clock::now();
  EmitOptions emit = options_.emit;
  emit.view = static_cast<KernelView>(view);
  if (image_height_ > 0) emit.march.image_height = int(image_height_);
  const EmitResult emitted = emitGlsl(scene->scene, emit);
  SpirvResult spv =
      options_.spirv_cache
          ? cachedGlslToSpirv(emitted.glsl, ShaderStage::Fragment, scene->source->path + ".glsl",
                              options_.optimize_spirv, options_.validate_spirv, options_.cache_version)
          : glslToSpirv(emitted.glsl, ShaderStage::Fragment, scene->source->path + ".glsl",
                        options_.optimize_spirv, options_.validate_spirv);
  built->compile_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!spv.ok()) {
    std::fprintf(stderr, "sdfc: error: internal error: the %s kernel does not compile:\n%s\n",
                 kernelViewName(emit.view), spv.log.c_str());
    built->error = "kernel compile failed";
    return built;
  }
  createRenderer(*built, spv.words, emitted.scene_data, emitted.limits);
  if (built->ok && options_.spirv_cache && !options_.validate_spirv && !spv.from_cache)
    storeCachedSpirv(spv.cache_key, spv.words);
  compileKernel(*built);
  return built;
}

void BackgroundCompiler::run() {
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = context_.queue_family;
  if (vkCreateCommandPool(context_.device, &pool_info, nullptr, &pool_) != VK_SUCCESS) pool_ = VK_NULL_HANDLE;
  struct DestroyPool {
    const VulkanContext& context;
    VkCommandPool& pool;
    ~DestroyPool() {
      if (pool) vkDestroyCommandPool(context.device, pool, nullptr);
      pool = VK_NULL_HANDLE;
    }
  } destroy_pool{context_, pool_};
  for (;;) {
    Clock::time_point requested;
    bool reload = false;
    uint32_t view = 0;
    VariantRequest variant;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      const auto ready = [this] { return pending_ || !variants_.empty() || stopping_; };
      while (!ready()) {
        if (!watcher_) {
          wake_.wait(lock, ready);
          break;
        }
        if (wake_.wait_for(lock, kWatchInterval, ready)) break;
        if (watcher_->changed()) {  // a stat: cheap enough to do under the lock
          pending_ = true;
          pending_since_ = Clock::now();
          pending_view_ = view_;
        }
      }
      if (stopping_) return;
      reload = pending_;
      if (reload) {
        pending_ = false;
        view = pending_view_;
        requested = pending_since_;
      } else {
        variant = std::move(variants_.front());
        variants_.pop_front();
        requested = variant.since;
      }
      working_ = true;
    }
    std::unique_ptr<BuiltScene> built =
        reload ? buildReload(view) : buildVariant(std::move(variant.scene), variant.view);
    built->requested = requested;
    built->finished = Clock::now();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      working_ = false;
      ready_.push_back(std::move(built));
    }
    if (on_ready_) on_ready_();
  }
}

}  // namespace sdfc::view
