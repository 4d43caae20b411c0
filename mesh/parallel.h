// A tiny work-sharing loop over [0, count) on std::threads: workers take
// chunks from a shared counter, so uneven chunks (surface vs empty slabs)
// balance themselves.
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace sdfc {

inline int workerCount(int requested) {
  if (requested > 0) return requested;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Calls body(begin, end, worker) on chunks of at most `chunk` indices.
template <typename Body>
void parallelFor(size_t count, size_t chunk, int threads, Body body) {
  const int workers = static_cast<int>(std::min<size_t>(workerCount(threads), (count + chunk - 1) / std::max<size_t>(chunk, 1)));
  std::atomic<size_t> next{0};
  auto run = [&](int worker) {
    for (;;) {
      const size_t begin = next.fetch_add(chunk);
      if (begin >= count) return;
      body(begin, std::min(count, begin + chunk), worker);
    }
  };
  if (workers <= 1) {
    run(0);
    return;
  }
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(run, w);
  run(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace sdfc
