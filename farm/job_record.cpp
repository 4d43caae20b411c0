#include "job_record.h"

#include <fstream>
#include <sstream>

#include "shard_plan.h"

namespace sdfc::farm {

void writeJobRecord(const std::string& path, const JobRecord& record) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary);
    out << "# sdfc farm job (docs/farm.md)\n";
    for (const auto& [key, value] : record.values) out << key << " " << value << "\n";
    for (const std::string& id : record.job_ids) out << "job " << id << "\n";
    if (!out.flush()) throw FarmError("cannot write " + path);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) throw FarmError("cannot write " + path);
}

JobRecord readJobRecord(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FarmError(path + ": no farm job here (run `sdfc farm submit ... -o DIR` first)");
  JobRecord record;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const size_t space = line.find(' ');
    const std::string key = line.substr(0, space), value = space == std::string::npos ? "" : line.substr(space + 1);
    if (key == "job") record.job_ids.push_back(value);
    else record.values[key] = value;
  }
  return record;
}

}  // namespace sdfc::farm
