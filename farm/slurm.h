// Slurm as the farm's engine: sbatch for the shard array and the dependent merge
// job, squeue for status. Only the command-line clients are used (no library), so
// any Slurm version with job arrays (>= 2.6) works.
#pragma once
#include <string>
#include <vector>

#include "shell.h"

namespace sdfc::farm {

// Options passed through to every sbatch call.
struct SlurmOptions {
  std::string partition, account, time_limit;
  std::vector<std::string> extra;  // --sbatch-arg, verbatim
  int max_running = 0;             // --array ...%N
};

// "0-3,5,7-9" for sorted task indices.
std::string arraySpec(const std::vector<uint32_t>& tasks);

// The sbatch command lines (argv) submit() runs; `dependency` = "" for none.
std::vector<std::string> arrayCommand(const SlurmOptions& o, const std::string& job_dir,
                                      const std::vector<uint32_t>& tasks);
std::vector<std::string> mergeCommand(const SlurmOptions& o, const std::string& job_dir,
                                      const std::string& dependency);

// Runs an sbatch command with --parsable; returns the job id. Throws FarmError
// with sbatch's output when it fails.
std::string submit(const std::vector<std::string>& command);

// squeue's view of these jobs: one "id state reason" line per job or array task
// still known to the controller; "" when none or Slurm is unreachable.
std::string queueState(const std::vector<std::string>& job_ids);

}  // namespace sdfc::farm
