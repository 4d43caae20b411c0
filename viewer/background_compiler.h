// Recompiles the scene off the frame loop: a worker thread runs parse, check,
// emit, glslang and pipeline creation (the slow part on lavapipe) and hands back
// a ready Renderer; the loop swaps it in between frames. Diagnostics print
// exactly as `sdfc check` prints them (cli's loadScene).
#pragma once
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "commands.h"
#include "driver/compile.h"
#include "renderer.h"

namespace sdfc::view {

using Clock = std::chrono::steady_clock;

struct BuiltScene {
  bool ok = false;  // false: the file has errors (already printed) or pipeline creation failed
  std::unique_ptr<CompiledScene> compiled;
  std::unique_ptr<Renderer> renderer;
  std::string error;  // a short reason for the title bar
  Clock::time_point requested, finished;
  double compile_seconds = 0, pipeline_seconds = 0;
};

class BackgroundCompiler {
 public:
  BackgroundCompiler(const VulkanContext& context, CommandLine command_line,
                     CompileOptions options);
  ~BackgroundCompiler();  // finishes the compile under way, drops its result

  // Compiles the file again; a request during a compile is served after it
  // (requests in between collapse into one).
  void request();
  // The newest finished build, or null. Call from the thread that uses the queue.
  std::unique_ptr<BuiltScene> take();
  bool busy() const;

 private:
  void run();

  const VulkanContext& context_;
  const CommandLine command_line_;
  const CompileOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool pending_ = false, working_ = false, stopping_ = false;
  Clock::time_point pending_since_;
  // Finished builds in order; take() keeps the newest and drops the rest on the
  // caller's (the frame loop's) thread, where Vulkan objects may be destroyed.
  std::deque<std::unique_ptr<BuiltScene>> ready_;
  std::thread thread_;
};

}  // namespace sdfc::view
