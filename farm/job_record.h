// DIR/farm.job: what `sdfc farm submit` decided, for `sdfc farm status` and for
// people: "key value" lines, the submissions appended one per line.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace sdfc::farm {

struct JobRecord {
  std::map<std::string, std::string> values;  // tasks, slices, spp, frames, image, ...
  std::vector<std::string> job_ids;           // every array and merge job submitted
};

void writeJobRecord(const std::string& path, const JobRecord& record);
// Throws FarmError when missing or unreadable.
JobRecord readJobRecord(const std::string& path);

}  // namespace sdfc::farm
