// The process's OpenMP parallel regions (CHOLMOD's supernodal kernels open one per supernode) run inline
// on the calling thread: no libgomp team, so no barrier and no system call per region.
#include "solve/linear_algebra_threads.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <thread>

#include "solve/loaded_function.hpp"

namespace balloon {
namespace {

struct RegionSeen {
  int level = -1;  ///< omp_get_level() inside the region: 0 inline, 1 in a libgomp team
  std::thread::id thread;
};

void record_region(void* data) {
  auto* seen = static_cast<RegionSeen*>(data);
  seen->level = loaded_function<int (*)()>("omp_get_level")();
  seen->thread = std::this_thread::get_id();
}

TEST(LinearAlgebraThreads, OpenMpRegionsRunInlineOnTheCallingThread) {
  if (std::getenv("OMP_NUM_THREADS") != nullptr) GTEST_SKIP() << "OMP_NUM_THREADS is set: libgomp's own regions";
  use_one_linear_algebra_thread();
  ASSERT_NE(loaded_function<int (*)()>("omp_get_level"), nullptr) << "libgomp is not loaded (CHOLMOD loads it)";
  // Looked up as CHOLMOD's calls are resolved: the first definition in the process.
  using Parallel = void (*)(void (*)(void*), void*, unsigned, unsigned);
  const auto parallel = loaded_function<Parallel>("GOMP_parallel");
  ASSERT_NE(parallel, nullptr);
  RegionSeen seen;
  parallel(record_region, &seen, 4, 0);  // as `#pragma omp parallel num_threads(4)` calls it
  EXPECT_EQ(seen.level, 0) << "the region ran in a libgomp team";
  EXPECT_EQ(seen.thread, std::this_thread::get_id());
}

}  // namespace
}  // namespace balloon
