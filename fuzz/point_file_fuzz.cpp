// libFuzzer target: the point list reader (check/point_file.cpp) on arbitrary
// bytes. A row it keeps must be finite; an error's byte range must lie in the
// text kept for its diagnostic.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "check/point_file.h"
#include "fuzz/input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const sdfc::PointFile f = sdfc::readPointFile(sdfc::fuzz::writeInput(data, size, "csv"));
  if (!f.readable) return 0;
  for (const sdfc::PositionRow& r : f.rows)
    if (!std::isfinite(r.position.x) || !std::isfinite(r.position.y) || !std::isfinite(r.position.z) ||
        !std::isfinite(r.scale)) {
      std::fprintf(stderr, "point_file_fuzz: a row that is not finite was kept\n");
      std::abort();
    }
  for (const sdfc::PointFileError& e : f.errors)
    if (e.begin > e.end || e.end > f.text.size()) {
      std::fprintf(stderr, "point_file_fuzz: an error's range [%zu, %zu) lies outside the %zu bytes kept\n", e.begin,
                   e.end, f.text.size());
      std::abort();
    }
  return 0;
}
