// The one parallel primitive of Surge (after pbrt-v4's ParallelFor): a loop over [begin, end) cut into chunks
// of a fixed size, run by oneTBB. Chunk boundaries depend only on the range and the grain, never on the number
// of threads, so a body that writes only its own elements (gather, never scatter) gives the same bytes whatever
// the thread count. parallelSum builds a deterministic reduction on the same loop.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

namespace surge {

// Runs body(chunkBegin, chunkEnd) for chunks of `grain` items covering [begin, end).
void parallelFor(size_t begin, size_t end, const std::function<void(size_t, size_t)>& body, size_t grain = 1024);

// Runs `work` (on this thread) so that the parallel loops inside it, ours and OpenVDB's, finish even when an
// enclosing parallelFor is cancelled because another of its chunks threw. Without it they would return early
// with part of their work skipped, and a frame computed beside a failing one would be written wrong. Use it
// for each item of a loop whose items write their own outputs (the surfacer's frames).
void runIsolated(const std::function<void()>& work);

// Sums chunkSum(chunkBegin, chunkEnd) over fixed chunks, adding the partial sums in chunk order.
template <typename T, typename ChunkSum>
T parallelSum(size_t begin, size_t end, ChunkSum chunkSum, size_t grain = 4096) {
  if (end <= begin) return T{};
  const size_t chunks = (end - begin + grain - 1) / grain;
  std::vector<T> partial(chunks, T{});
  parallelFor(
      0, chunks,
      [&](size_t c0, size_t c1) {
        for (size_t c = c0; c < c1; ++c) {
          const size_t b = begin + c * grain;
          partial[c] = chunkSum(b, std::min(end, b + grain));
        }
      },
      1);
  T total{};
  for (const T& p : partial) total += p;
  return total;
}

// Limits the threads oneTBB may use while this object lives (--threads N); 0 means all cores.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  static int available();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surge
