// A row-parallel loop for per-pixel work on the CPU (the denoisers, the
// layers, the sRGB bytes of a PNG): rows are independent, and each row's
// result is the same whatever thread runs it.
#pragma once
#include <algorithm>
#include <system_error>
#include <thread>
#include <vector>

namespace sdfc {

// Runs body(y) for every row on up to hardware_concurrency threads (at most 8),
// thread t taking rows t, t + threads, ...; the rows of a thread that could not
// be started run on the caller's.
template <typename Body>
void forEachRow(int height, const Body& body) {
  const int threads = std::clamp<int>(int(std::thread::hardware_concurrency()), 1, 8);
  if (threads == 1 || height < 16) {
    for (int y = 0; y < height; ++y) body(y);
    return;
  }
  auto rows = [&](int t) {
    for (int y = t; y < height; y += threads) body(y);
  };
  std::vector<std::thread> pool;
  int started = 0;
  try {
    for (; started < threads; ++started) pool.emplace_back(rows, started);
  } catch (const std::system_error&) {  // no thread to be had: a failed render it is not
  }
  for (int t = started; t < threads; ++t) rows(t);
  for (std::thread& thread : pool) thread.join();
}

}  // namespace sdfc
