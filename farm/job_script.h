// The two batch scripts of a farm job, written into its directory.
//
// shard.sh runs one array task: `sdfc render --shards K --shard-index $TASK`
// (Slurm's SLURM_ARRAY_TASK_ID), retrying a failed render up to `retries` times in
// place (scene and usage errors are not retried); `#SBATCH --requeue` lets Slurm
// rerun it after a node failure. A completed shard is skipped by sdfc itself, so
// requeues and resubmissions redo only what is missing.
// merge.sh runs `sdfc merge`, then optionally ffmpeg for an animation.
#pragma once
#include <string>
#include <vector>

#include "shard_plan.h"

namespace sdfc::farm {

struct JobScripts {
  std::string sdfc;                     // absolute path of the sdfc binary (shared file system)
  std::vector<std::string> render_args; // scene and flags shared by every shard (absolute paths)
  std::string job_dir;                  // absolute
  ShardPlan plan;
  int retries = 1;
  std::string video;                    // "" = no encode
};

std::string shardScript(const JobScripts& job);
std::string mergeScript(const JobScripts& job);

// Where the job's outputs go inside job_dir.
std::string shardDir(const std::string& job_dir);  // job_dir/shards
std::string imagePath(const std::string& job_dir, const ShardPlan& plan);  // image.exr or frames/frame.exr

}  // namespace sdfc::farm
