#include "solve/linear_algebra_threads.hpp"

#include "solve/loaded_function.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>

namespace balloon {

void use_one_linear_algebra_thread() {
  static std::once_flag blas_once;
  std::call_once(blas_once, [] {
    if (std::getenv("OPENBLAS_NUM_THREADS") != nullptr) return;
    if (auto set_threads = loaded_function<void (*)(int)>("openblas_set_num_threads")) set_threads(1);
  });
}

}  // namespace balloon

using OpenMpRegionBody = void (*)(void*);
using OpenMpParallel = void (*)(OpenMpRegionBody, void*, unsigned, unsigned);

/// GCC's entry to `#pragma omp parallel` (libgomp's ABI), defined in this process so that it is found
/// before libgomp's for every library loaded: linked into an executable whose shared libraries call it,
/// the linker exports it, and the executable comes first in symbol lookup.
///
/// Why: CHOLMOD 3 (Debian 12) opens a parallel region for every supernode it factorizes and for every
/// descendant's update of it. With one thread each region still costs libgomp a team, a barrier and a
/// futex system call (with dynamic adjustment, a getloadavg and a sched_getaffinity besides): about
/// 700,000 regions per design iteration at 4,000 vertices, 8-10% of the run time in system calls alone.
/// The linear algebra runs on one thread here anyway (above), so a region's body runs on the calling
/// thread as a plain call, with the same results. (It is the only OpenMP entry the loaded libraries call,
/// so no team size or dynamic adjustment needs setting.) A user who set OMP_NUM_THREADS gets libgomp's
/// own, found with RTLD_NEXT: loaded_function's RTLD_DEFAULT would find this one.
extern "C" void GOMP_parallel(OpenMpRegionBody body, void* data, unsigned num_threads, unsigned flags) {
  static const OpenMpParallel libgomp_parallel =
      std::getenv("OMP_NUM_THREADS") != nullptr ? reinterpret_cast<OpenMpParallel>(dlsym(RTLD_NEXT, "GOMP_parallel"))
                                                : nullptr;
  if (libgomp_parallel != nullptr) {
    libgomp_parallel(body, data, num_threads, flags);
    return;
  }
  body(data);
}
