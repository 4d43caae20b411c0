#include "background_compiler.h"

#include <cstdio>

#include "cli_support.h"
#include "vk_check.h"

namespace sdfc::view {

BackgroundCompiler::BackgroundCompiler(const VulkanContext& context, CommandLine command_line,
                                       CompileOptions options)
    : context_(context), command_line_(std::move(command_line)), options_(std::move(options)) {
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

void BackgroundCompiler::request() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!pending_) pending_since_ = Clock::now();
    pending_ = true;
  }
  wake_.notify_all();
}

std::unique_ptr<BuiltScene> BackgroundCompiler::take() {
  std::deque<std::unique_ptr<BuiltScene>> ready;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ready.swap(ready_);
  }
  if (ready.empty()) return nullptr;
  return std::move(ready.back());  // older ones are destroyed here, on this thread
}

bool BackgroundCompiler::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return pending_ || working_ || !ready_.empty();
}

void BackgroundCompiler::run() {
  for (;;) {
    Clock::time_point requested;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return pending_ || stopping_; });
      if (stopping_) return;
      pending_ = false;
      working_ = true;
      requested = pending_since_;
    }
    auto built = std::make_unique<BuiltScene>();
    built->requested = requested;
    const auto start = Clock::now();
    Diagnostics diags;
    LoadedScene loaded = loadScene(command_line_, diags, true, true, options_, true);
    built->compile_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (loaded.exit_code != kExitOk) {
      built->error = loaded.exit_code == kExitIo ? "cannot read the file" : "the scene has errors";
    } else {
      built->compiled = std::make_unique<CompiledScene>(std::move(loaded.compiled));
      try {
        built->renderer = std::make_unique<Renderer>(context_, built->compiled->spirv);
        built->pipeline_seconds = built->renderer->pipelineSeconds();
        built->ok = true;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "sdfc: error: pipeline creation: %s\n", e.what());
        built->error = "pipeline creation failed";
      }
    }
    built->finished = Clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    working_ = false;
    ready_.push_back(std::move(built));
  }
}

}  // namespace sdfc::view
