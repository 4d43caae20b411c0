// A row-parallel loop for per-pixel work on the CPU (the denoisers, the
// layers, the sRGB bytes of a PNG): rows are independent, and each row's
// result is the same whatever thread runs it.
#pragma once
#include <algorithm>
#include <atomic>
#include <system_error>
#include <thread>
#include <vector>

namespace sdfc {

// Runs body(y) for every row on up to hardware_concurrency threads (at most 8),
// the caller's among them. A thread takes the next row not yet taken, so one
// that meets slow rows (a denoiser's surfaces beside its sky) does not leave
// the others waiting at the end; with no further thread to be had, the
// caller's takes them all.
template <typename Body>
void forEachRow(int height, const Body& body) {
  const int threads = std::clamp<int>(int(std::thread::hardware_concurrency()), 1, 8);
  if (threads == 1 || height < 16) {
    for (int y = 0; y < height; ++y) body(y);
    return;
  }
  std::atomic<int> next{0};
  auto rows = [&] {
    for (int y = next.fetch_add(1, std::memory_order_relaxed); y < height;
         y = next.fetch_add(1, std::memory_order_relaxed))
      body(y);
  };
  std::vector<std::thread> pool;
  try {
    for (int t = 1; t < threads; ++t) pool.emplace_back(rows);
  } catch (const std::system_error&) {  // no thread to be had: a failed render it is not
  }
  rows();
  for (std::thread& thread : pool) thread.join();
}

}  // namespace sdfc
