#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>

namespace surge {

void parallelFor(size_t begin, size_t end, const std::function<void(size_t, size_t)>& body, size_t grain) {
  if (end <= begin) return;
  grain = std::max<size_t>(grain, 1);
  const size_t chunks = (end - begin + grain - 1) / grain;
  if (chunks == 1) {
    body(begin, end);
    return;
  }
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, chunks, 1),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
          const size_t b = begin + c * grain;
          body(b, std::min(end, b + grain));
        }
      },
      tbb::simple_partitioner());
}

void runIsolated(const std::function<void()>& work) {
  // A loop of one item with a context of its own: the tasks spawned inside bind to it, not to the enclosing
  // loop's context, so that loop's cancellation does not reach them; an exception from `work` still
  // propagates to the caller.
  tbb::task_group_context isolated(tbb::task_group_context::isolated);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, 1, 1), [&](const tbb::blocked_range<int>&) { work(); },
      tbb::simple_partitioner(), isolated);
}

struct ThreadLimit::Impl {
  std::unique_ptr<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : impl_(std::make_unique<Impl>()) {
  if (threads > 0)
    impl_->control = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                           static_cast<size_t>(threads));
}

ThreadLimit::~ThreadLimit() = default;

int ThreadLimit::available() { return tbb::info::default_concurrency(); }

}  // namespace surge
