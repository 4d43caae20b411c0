#include "job_script.h"

#include <cstdio>

#include "shell.h"

namespace sdfc::farm {

std::string shardDir(const std::string& job_dir) { return job_dir + "/shards"; }

std::string imagePath(const std::string& job_dir, const ShardPlan& plan) {
  return plan.animation() ? job_dir + "/frames/frame.exr" : job_dir + "/image.exr";
}

std::string shardScript(const JobScripts& job) {
  std::vector<std::string> command = {job.sdfc, "render"};
  command.insert(command.end(), job.render_args.begin(), job.render_args.end());
  command.insert(command.end(), {"--shards", std::to_string(job.plan.slices), "-o", shardDir(job.job_dir), "-q"});
  std::string s;
  s += "#!/bin/bash\n";
  s += "# One shard of an sdfc farm job (written by `sdfc farm submit`; docs/farm.md).\n";
  s += "#SBATCH --requeue\n";
  s += "#SBATCH --open-mode=append\n";
  s += "index=\"${SLURM_ARRAY_TASK_ID:-${JOB_COMPLETION_INDEX:-${1:?task index}}}\"\n";
  s += "retries=" + std::to_string(job.retries) + "\n";
  s += "attempt=0\n";
  s += "while :; do\n";
  s += "  " + shellJoin(command) + " --shard-index \"$index\"\n";
  s += "  status=$?\n";
  s += "  [ \"$status\" -eq 0 ] && exit 0\n";
  s += "  # Scene (1) and usage (2) errors fail the same way every time.\n";
  s += "  if [ \"$status\" -eq 1 ] || [ \"$status\" -eq 2 ] || [ \"$attempt\" -ge \"$retries\" ]; then\n";
  s += "    echo \"sdfc farm: shard $index failed (exit $status) after $((attempt + 1)) attempt(s)\" >&2\n";
  s += "    exit \"$status\"\n";
  s += "  fi\n";
  s += "  attempt=$((attempt + 1))\n";
  s += "  echo \"sdfc farm: shard $index failed (exit $status); retry $attempt of $retries\" >&2\n";
  s += "done\n";
  return s;
}

std::string mergeScript(const JobScripts& job) {
  const std::string image = imagePath(job.job_dir, job.plan);
  std::vector<std::string> merge = {job.sdfc, "merge", shardDir(job.job_dir), "-o", image};
  if (job.plan.animation()) {
    merge.push_back("--frames");
    merge.push_back(std::to_string(job.plan.first_frame) + "-" + std::to_string(job.plan.last_frame));
    if (!job.video.empty()) merge.push_back("--png");
  }
  std::string s;
  s += "#!/bin/bash\n";
  s += "# Merges an sdfc farm job's shards (written by `sdfc farm submit`; docs/farm.md).\n";
  s += "set -euo pipefail\n";
  if (job.plan.animation()) s += "mkdir -p " + shellQuote(job.job_dir + "/frames") + "\n";
  s += shellJoin(merge) + "\n";
  if (job.plan.animation() && !job.video.empty()) {
    char rate[32];
    std::snprintf(rate, sizeof rate, "%.9g", job.plan.fps);
    s += shellJoin({"ffmpeg", "-y", "-loglevel", "error", "-framerate", rate, "-start_number",
                    std::to_string(job.plan.first_frame), "-i", job.job_dir + "/frames/frame_%04d.png",
                    // yuv420p needs even sides: pad odd ones by a pixel.
                    "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", job.video}) +
         "\n";
  }
  s += "echo \"sdfc farm: merged\" >&2\n";
  return s;
}

}  // namespace sdfc::farm
