#pragma once
// The thread count of the CPU tracers (the reference, light and volume tracers, photon tracing): their
// options' `threads` > 0 runs `work` (which parallelises itself with tbb::parallel_for) in a TBB arena of
// that many threads; 0 in the calling context's (all cores by default).

#include <utility>

#include <tbb/task_arena.h>

namespace radiant::rt {

template <class Work>
void withThreads(int threads, Work&& work) {
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(std::forward<Work>(work));
  } else {
    work();
  }
}

}  // namespace radiant::rt
