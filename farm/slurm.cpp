#include "slurm.h"

#include "shard_plan.h"

namespace sdfc::farm {

std::string arraySpec(const std::vector<uint32_t>& tasks) {
  std::string spec;
  for (size_t i = 0; i < tasks.size();) {
    size_t j = i;
    while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1) ++j;
    if (!spec.empty()) spec += ",";
    spec += std::to_string(tasks[i]);
    if (j > i) spec += "-" + std::to_string(tasks[j]);
    i = j + 1;
  }
  return spec;
}

namespace {
std::vector<std::string> common(const SlurmOptions& o, const std::string& name) {
  std::vector<std::string> c = {"sbatch", "--parsable", "--job-name=" + name};
  if (!o.partition.empty()) c.push_back("--partition=" + o.partition);
  if (!o.account.empty()) c.push_back("--account=" + o.account);
  if (!o.time_limit.empty()) c.push_back("--time=" + o.time_limit);
  c.insert(c.end(), o.extra.begin(), o.extra.end());
  return c;
}
}  // namespace

std::vector<std::string> arrayCommand(const SlurmOptions& o, const std::string& job_dir,
                                      const std::vector<uint32_t>& tasks) {
  std::vector<std::string> c = common(o, "sdfc-shard");
  std::string array = "--array=" + arraySpec(tasks);
  if (o.max_running > 0) array += "%" + std::to_string(o.max_running);
  c.push_back(array);
  c.push_back("--output=" + job_dir + "/logs/shard_%a.log");
  c.push_back(job_dir + "/shard.sh");
  return c;
}

std::vector<std::string> mergeCommand(const SlurmOptions& o, const std::string& job_dir,
                                      const std::string& dependency) {
  std::vector<std::string> c = common(o, "sdfc-merge");
  if (!dependency.empty()) {
    // afterok: only when every shard succeeded; a failed shard cancels the merge
    // instead of leaving it pending forever.
    c.push_back("--dependency=afterok:" + dependency);
    c.push_back("--kill-on-invalid-dep=yes");
  }
  c.push_back("--output=" + job_dir + "/logs/merge_%j.log");
  c.push_back(job_dir + "/merge.sh");
  return c;
}

std::string submit(const std::vector<std::string>& command) {
  const CommandResult r = runProgram(command);
  // --parsable prints "id" or "id;cluster".
  std::string id = r.output.substr(0, r.output.find_first_of(";\n"));
  if (r.exit_code != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw FarmError("sbatch failed" + (r.exit_code >= 0 ? " (exit " + std::to_string(r.exit_code) + ")" : "") +
                    ": " + r.output + "\n  command: " + shellJoin(command));
  return id;
}

std::string queueState(const std::vector<std::string>& job_ids) {
  if (job_ids.empty()) return "";
  std::string list;
  for (const std::string& id : job_ids) list += (list.empty() ? "" : ",") + id;
  const CommandResult r =
      runProgram({"squeue", "--noheader", "--states=all", "--jobs=" + list, "--format=%i %T %r"});
  return r.exit_code == 0 ? r.output : "";
}

}  // namespace sdfc::farm
