// `sdfc farm submit` and `sdfc farm status`: Slurm as the engine for shards
// (farm/). Submit checks the scene before anything is written or submitted.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "farm_support.h"
#include "job_record.h"
#include "job_script.h"
#include "slurm.h"

namespace sdfc {
namespace fs = std::filesystem;
namespace {

std::string absolute(const std::string& path) { return fs::absolute(path).lexically_normal().string(); }

// This binary's path, which the nodes run from the shared file system.
std::string selfPath() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  return error ? std::string("sdfc") : self.string();
}

void writeScript(const std::string& path, const std::string& text) {
  writeFileAtomically(path, text);
  fs::permissions(path, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                            fs::perms::others_read | fs::perms::others_exec);
}

// The flags every shard's `sdfc render` gets (the scene and settings, not the index).
std::vector<std::string> renderArgs(const CommandLine& cl, const farm::ShardPlan& plan) {
  std::vector<std::string> a = {absolute(cl.input), "--spp", std::to_string(plan.spp), "--seed",
                                std::to_string(cl.seed)};
  if (!cl.size.empty()) a.insert(a.end(), {"--size", cl.size});
  if (cl.bounces >= 0) a.insert(a.end(), {"--bounces", std::to_string(cl.bounces)});
  if (cl.light_samples >= 0) a.insert(a.end(), {"--light-samples", std::to_string(cl.light_samples)});
  if (plan.animation()) {
    std::ostringstream fps;
    fps.precision(17);
    fps << plan.fps;
    a.insert(a.end(), {"--frames", cl.frames, "--fps", fps.str()});
  } else if (cl.time != 0) {
    std::ostringstream time;
    time.precision(17);
    time << cl.time;
    a.insert(a.end(), {"--time", time.str()});
  }
  for (const std::string& d : cl.defines) a.insert(a.end(), {"-D", d});
  if (cl.no_bounds) a.push_back("--no-bounds");
  if (cl.force_bounds) a.push_back("--bounds");
  if (cl.no_fuse) a.push_back("--no-fuse");
  if (cl.no_analytic_spheres) a.push_back("--no-analytic-spheres");
  if (!cl.mesh_mode.empty()) a.insert(a.end(), {"--mesh-mode", cl.mesh_mode});
  if (cl.prune) a.push_back("--prune");
  if (cl.optimize) a.push_back("-O");
  if (cl.paper_baseline) a.push_back("--paper-baseline");
  if (cl.white_noise) a.push_back("--white-noise");
  if (cl.layers) a.push_back("--layers");
  if (cl.count_evaluations) a.push_back("--count-evaluations");
  if (!cl.count_event.empty()) {
    a.push_back("--count-event");
    a.push_back(cl.count_event);
  }
  return a;
}

int submitJob(const CommandLine& cl) {
  RenderOverrides o;
  if (!renderOverridesFrom(cl, o)) return kExitUsage;
  if (cl.shards <= 0) {
    std::cerr << "sdfc: error: farm submit needs --shards N (shards per image)\n";
    return kExitUsage;
  }
  // Check (and emit, for the march limits that set the pass split) before anything
  // is written: a scene with errors submits nothing.
  CompileOptions options = compileOptionsFrom(cl);
  if (o.height) options.emit.march.image_height = *o.height;
  if (!cl.force_bounds) options.emit.bounding_volumes = false;  // as `render` on a CPU device
  Diagnostics diags;
  LoadedScene loaded = loadScene(cl, diags, true, false, options, true);
  if (loaded.exit_code != kExitOk) {
    std::cerr << "sdfc: farm: the scene has errors; nothing was submitted\n";
    return loaded.exit_code;
  }
  ShardJob job;
  try {
    job = shardJobFor(cl, o, loaded.compiled);
  } catch (const farm::FarmError& e) {
    std::cerr << "sdfc: error: " << e.what() << "\n";
    return kExitUsage;
  }
  if (!cl.video.empty() && !job.plan.animation()) {
    std::cerr << "sdfc: error: --video needs --frames A-B\n";
    return kExitUsage;
  }
  // The merge job runs ffmpeg last: without it every shard would render and the
  // job fail at its very end.
  if (!cl.video.empty() && !farm::onPath("ffmpeg")) {
    std::cerr << "sdfc: error: --video needs ffmpeg on PATH (the merge job runs it); install ffmpeg "
                 "or submit without --video\n";
    return kExitUsage;
  }

  const std::string dir = absolute(cl.output);
  fs::create_directories(farm::shardDir(dir));
  fs::create_directories(dir + "/logs");
  farm::JobScripts scripts;
  scripts.sdfc = selfPath();
  scripts.render_args = renderArgs(cl, job.plan);
  scripts.job_dir = dir;
  scripts.plan = job.plan;
  scripts.retries = cl.retries;
  scripts.video = cl.video.empty() ? "" : absolute(cl.video);
  writeScript(dir + "/shard.sh", farm::shardScript(scripts));
  writeScript(dir + "/merge.sh", farm::mergeScript(scripts));

  // Resume: tasks whose shard exists and matches are not submitted again.
  std::vector<uint32_t> missing;
  for (uint32_t i = 0; i < job.plan.taskCount(); ++i)
    if (!shardComplete(farm::shardDir(dir) + "/" + farm::shardFileName(i), expectedHeader(job, i), false))
      missing.push_back(i);

  // A finished job: every shard there and every output merged. Submitting it
  // again would only queue another merge of the same samples.
  if (missing.empty() && !cl.dry_run) {
    std::vector<std::string> outputs;
    const std::string image = farm::imagePath(dir, job.plan);
    if (job.plan.animation()) {
      for (int f = job.plan.first_frame; f <= job.plan.last_frame; ++f) outputs.push_back(farm::framePath(image, f));
    } else {
      outputs.push_back(image);
    }
    if (!scripts.video.empty()) outputs.push_back(scripts.video);
    if (std::all_of(outputs.begin(), outputs.end(), [](const std::string& p) { return fs::exists(p); })) {
      std::cerr << "sdfc: farm: the job in " << dir << " is finished (" << job.plan.taskCount()
                << " shards, merged into " << (job.plan.animation() ? dir + "/frames" : image)
                << "); nothing submitted. Remove "
                << (job.plan.animation() ? "a frame" : "the image") << " to merge again\n";
      return kExitOk;
    }
  }

  farm::JobRecord record;
  if (fs::exists(dir + "/farm.job")) record = farm::readJobRecord(dir + "/farm.job");
  record.values["scene"] = absolute(cl.input);
  record.values["tasks"] = std::to_string(job.plan.taskCount());
  record.values["slices"] = std::to_string(job.plan.slices);
  record.values["spp"] = std::to_string(job.plan.spp);
  record.values["size"] = std::to_string(job.settings.width) + "x" + std::to_string(job.settings.height);
  record.values["frames"] = job.plan.animation() ? cl.frames : "still";
  record.values["image"] = farm::imagePath(dir, job.plan);
  if (!scripts.video.empty()) record.values["video"] = scripts.video;

  farm::SlurmOptions slurm;
  slurm.partition = cl.partition;
  slurm.account = cl.account;
  slurm.time_limit = cl.time_limit;
  slurm.extra = cl.sbatch_args;
  slurm.max_running = cl.max_running;
  const auto array = farm::arrayCommand(slurm, dir, missing);
  std::cerr << "sdfc: farm: " << job.plan.taskCount() << " shards (" << job.plan.frameCount()
            << (job.plan.animation() ? " frames" : " image") << " x " << job.plan.slices << "; "
            << job.plan.spp << " spp are " << farm::passesText(job.plan.spp, job.plan.samples_per_pass) << "), " << job.plan.taskCount() - missing.size()
            << " already complete\n";
  try {
    std::string array_id;
    if (!missing.empty()) {
      if (cl.dry_run) std::cout << farm::shellJoin(array) << "\n";
      else array_id = farm::submit(array);
    }
    const auto merge = farm::mergeCommand(slurm, dir, array_id.empty() && !missing.empty() ? "ARRAY" : array_id);
    if (cl.dry_run) {
      std::cout << farm::shellJoin(merge) << "\n";
      return kExitOk;
    }
    const std::string merge_id = farm::submit(merge);
    if (!array_id.empty()) record.job_ids.push_back(array_id);
    record.job_ids.push_back(merge_id);
    farm::writeJobRecord(dir + "/farm.job", record);
    std::cout << "submitted";
    if (!array_id.empty()) std::cout << " shards " << array_id << " (array " << farm::arraySpec(missing) << ")";
    std::cout << " merge " << merge_id << "\n";
  } catch (const farm::FarmError& e) {
    std::cerr << "sdfc: error: farm: " << e.what() << "\n";
    return kExitDevice;
  }
  return kExitOk;
}

// Why a merged output is missing: " (not yet)" while the last merge job is queued
// or has not started, else that it ended without writing it, and where its log is.
std::string missingNote(const farm::JobRecord& record, const std::string& dir) {
  if (record.job_ids.empty()) return " (not yet)";
  const std::string merge_id = record.job_ids.back();
  const std::string log = dir + "/logs/merge_" + merge_id + ".log";
  if (!fs::exists(log)) return " (not yet)";
  const std::string queue = farm::queueState({merge_id});
  for (const char* state : {"PENDING", "RUNNING", "COMPLETING", "CONFIGURING", "REQUEUED"})
    if (queue.find(state) != std::string::npos) return " (not yet)";
  return " (not made: merge job " + merge_id + " ended without it; see " + log + ")";
}

int showStatus(const CommandLine& cl) {
  const std::string dir = absolute(cl.output);
  farm::JobRecord record;
  try {
    record = farm::readJobRecord(dir + "/farm.job");
  } catch (const farm::FarmError& e) {
    std::cerr << "sdfc: error: " << e.what() << "\n";
    return kExitIo;
  }
  const uint32_t tasks = uint32_t(std::stoul(record.values["tasks"]));
  std::vector<uint32_t> missing;
  for (uint32_t i = 0; i < tasks; ++i) {
    const std::string path = farm::shardDir(dir) + "/" + farm::shardFileName(i);
    bool ok = false;
    try {
      ok = fs::exists(path) && farm::readShardHeader(path).spp > 0;
    } catch (const farm::FarmError&) {
    }
    if (!ok) missing.push_back(i);
  }
  std::cout << "job " << dir << ": " << record.values["size"] << ", " << record.values["spp"] << " spp, "
            << record.values["frames"] << ", " << record.values["slices"] << " shards per image\n";
  std::cout << "shards done: " << tasks - missing.size() << "/" << tasks;
  if (!missing.empty()) std::cout << " (missing " << farm::arraySpec(missing) << ")";
  std::cout << "\n";
  const std::string image = record.values["image"];
  const bool animation = record.values["frames"] != "still";
  size_t frames_done = 0;
  if (animation) {
    if (fs::is_directory(dir + "/frames"))
      for (const auto& e : fs::directory_iterator(dir + "/frames"))
        if (e.path().extension() == ".exr") ++frames_done;
    std::cout << "merged frames: " << frames_done << " in " << dir << "/frames\n";
  } else {
    std::cout << "merged image: " << image << (fs::exists(image) ? "" : missingNote(record, dir)) << "\n";
  }
  if (record.values.count("video"))
    std::cout << "video: " << record.values["video"]
              << (fs::exists(record.values["video"]) ? "" : missingNote(record, dir)) << "\n";
  // squeue lines "id state reason" -> per job: state counts (array tasks grouped).
  std::map<std::string, std::map<std::string, int>> states;
  std::map<std::string, std::string> reasons;
  std::istringstream queue(farm::queueState(record.job_ids));
  std::string id, state, reason;
  while (queue >> id >> state >> reason) {
    const std::string job = id.substr(0, id.find('_'));
    const size_t open = id.find('[');  // "12_[3-7]": pending tasks not yet split
    int tasks = 1;
    if (open != std::string::npos) {
      std::string spec = id.substr(open + 1, id.find(']') - open - 1);
      spec = spec.substr(0, spec.find('%'));
      tasks = 0;
      std::istringstream parts(spec);
      for (std::string part; std::getline(parts, part, ',');) {
        const size_t dash = part.find('-');
        tasks += dash == std::string::npos ? 1 : std::stoi(part.substr(dash + 1)) - std::stoi(part.substr(0, dash)) + 1;
      }
    }
    states[job][state] += tasks;
    if (reason != "None") reasons[job] = reason;
  }
  if (states.empty()) std::cout << "slurm: no job of this directory is known to Slurm (finished long ago, or no Slurm here)\n";
  for (const std::string& job : record.job_ids) {
    if (!states.count(job)) continue;
    std::cout << "slurm job " << job << ":";
    for (const auto& [name, count] : states[job]) std::cout << " " << count << " " << name;
    if (reasons.count(job)) std::cout << " (" << reasons[job] << ")";
    std::cout << "\n";
  }
  return kExitOk;
}

}  // namespace

int runFarm(const CommandLine& cl) {
  if (cl.farm_command == "submit") return submitJob(cl);
  if (cl.farm_command == "status") return showStatus(cl);
  return kExitUsage;
}

}  // namespace sdfc
