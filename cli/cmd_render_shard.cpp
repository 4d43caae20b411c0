// `sdfc render --shards K --shard-index I -o DIR`: one task of a farm job. Renders
// its frame's sample range with the whole image's pass split and writes
// DIR/shard_IIIII.exr (farm/shard_file.h); an existing matching shard is kept.
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "farm_support.h"
#include "progress.h"

namespace sdfc {
namespace {

// Fault injection for the farm tests: SDFC_FAULT_KILL_SHARD=I makes task I kill
// itself (SIGKILL, as a node failure or OOM kill would) after its first pass,
// once: SDFC_FAULT_MARKER names a file created first, and its presence disarms it.
bool faultArmed(uint32_t index) {
  const char* shard = std::getenv("SDFC_FAULT_KILL_SHARD");
  const char* marker = std::getenv("SDFC_FAULT_MARKER");
  if (!shard || !marker || std::to_string(index) != shard) return false;
  if (std::filesystem::exists(marker)) return false;
  std::ofstream(marker) << "killed shard " << index << "\n";
  return true;
}

// -o DIR is the folder the shards go in, made when missing (a farm's tasks
// share it). Before any work: an -o that is a file, or a folder that cannot
// be made or written into, is an unwritable output (exit 4), said in our
// words ("filesystem error: cannot create directories" reached the user).
bool prepareShardFolder(const std::string& dir) {
  auto refuse = [&](const std::string& why) {
    std::cerr << "sdfc: error: cannot write shards into '" << dir << "': " << why << "\n";
    return false;
  };
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(dir, error);
  if (std::filesystem::exists(status) && !std::filesystem::is_directory(status))
    return refuse("it is a file, not a folder (with --shards, -o names the folder that holds the shards)");
  if (!std::filesystem::exists(status)) {
    // status() fails with ENOENT (nothing there) or ENOTDIR (a file on the way);
    // anything else (a link that loops, no permission to look) is said as it is.
    if (error && error != std::errc::no_such_file_or_directory && error != std::errc::not_a_directory)
      return refuse("cannot look at it (" + error.message() + ")");
    error.clear();
    std::filesystem::create_directories(dir, error);
    if (error) return refuse("the folder cannot be made (" + error.message() + ")");
  }
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    return refuse(std::string("the folder is not writable (") + std::strerror(errno) + ")");
  return true;
}

}  // namespace

int runRenderShard(const CommandLine& cl, const RenderOverrides& o) {
  if (cl.shards <= 0 || cl.shard_index < 0) {
    std::cerr << "sdfc: error: --shards and --shard-index go together\n";
    return kExitUsage;
  }
  if (!cl.frames.empty() && cl.frames.find(':') != std::string::npos) {
    std::cerr << "sdfc: error: with --shards, --frames takes frame numbers A-B (time = frame / --fps)\n";
    return kExitUsage;
  }
  if (!prepareShardFolder(cl.output)) return kExitIo;
  ContextOptions context_options;
  context_options.device_index = cl.device;
  ScopedContext scoped_context(context_options);
  VulkanContext& context = scoped_context.get();
  LoadedScene loaded = compileForDevice(cl, context, o);
  if (loaded.exit_code != kExitOk) return loaded.exit_code;
  const CompiledScene& compiled = loaded.compiled;

  ShardJob job;
  farm::ShardHeader header;
  try {
    job = shardJobFor(cl, o, compiled);
    header = expectedHeader(job, uint32_t(cl.shard_index));
  } catch (const farm::FarmError& e) {
    std::cerr << "sdfc: error: " << e.what() << "\n";
    return kExitUsage;
  }
  header.device = deviceText(context);
  header.driver = driverText(context);
  const std::string path = (std::filesystem::path(cl.output) / farm::shardFileName(cl.shard_index)).string();
  if (shardComplete(path, header, true)) {
    if (!cl.quiet) std::cerr << "sdfc: " << path << " is complete; skipped\n";
    return kExitOk;
  }

  Renderer renderer(context, compiled);
  const bool fault = faultArmed(uint32_t(cl.shard_index));
  ProgressCallback progress = cl.quiet ? ProgressCallback{} : makeTerminalProgress("shard");
  if (fault)
    progress = [](const ProgressInfo& info) {
      if (info.passes_done >= 1 && !info.finished) std::raise(SIGKILL);
    };
  farm::ShardImage shard;
  shard.header = header;
  // An interrupted shard is never written: a Ctrl-C ends the process at once,
  // also inside the driver's kernel compile, until the write starts.
  const RenderOutput out = renderShard(renderer, compiled, job, shard, progress, installInterruptHandler(true));
  if (fault) std::raise(SIGKILL);  // a one-pass shard: killed before its file is written
  if (out.interrupted) {
    std::cerr << "sdfc: interrupted; shard " << cl.shard_index << " not written\n";
    return kExitInterrupted;
  }
  noteSamplesTaken();  // the write is not cut short: a signal now only sets the flag
  const auto write_start = std::chrono::steady_clock::now();
  farm::writeShard(path, shard);
  const double write_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count();
  // Milliseconds: bench/farm_bench.py reads this line for the per-shard overhead.
  if (!cl.quiet)
    std::fprintf(stderr, "sdfc: wrote %s (samples [%u, %u) of %u%s; compile %.0f ms, pipeline %.0f ms, render %.0f ms, write %.0f ms)\n",
                 path.c_str(), header.samples.begin, header.samples.end, header.spp,
                 header.frame == farm::kNoFrame ? "" : (", frame " + std::to_string(header.frame)).c_str(),
                 compiled.times.total() * 1000, renderer.pipelineSeconds() * 1000, out.seconds * 1000,
                 write_seconds * 1000);
  return kExitOk;
}

}  // namespace sdfc
