// Running the cluster's commands (sbatch, squeue) and quoting for the job scripts.
#pragma once
#include <string>
#include <vector>

namespace sdfc::farm {

// 'text' for a POSIX shell (single quotes; embedded ' as '\'').
std::string shellQuote(const std::string& text);
std::string shellJoin(const std::vector<std::string>& words);

struct CommandResult {
  int exit_code = -1;  // -1: could not run (e.g. not installed)
  std::string output;  // stdout and stderr
};

// Runs argv[0] found on PATH with no shell in between; captures its output.
CommandResult runProgram(const std::vector<std::string>& argv);

// True when `program` is an executable on PATH.
bool onPath(const std::string& program);

}  // namespace sdfc::farm
