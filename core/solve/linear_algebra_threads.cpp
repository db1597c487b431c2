#include "solve/linear_algebra_threads.hpp"

#include "solve/loaded_function.hpp"

#include <cstdlib>
#include <mutex>

namespace balloon {

void use_one_linear_algebra_thread() {
  static std::once_flag blas_once;
  std::call_once(blas_once, [] {
    if (std::getenv("OPENBLAS_NUM_THREADS") != nullptr) return;
    if (auto set_threads = loaded_function<void (*)(int)>("openblas_set_num_threads")) set_threads(1);
  });
  thread_local bool openmp_done = false;
  if (openmp_done) return;
  openmp_done = true;
  if (std::getenv("OMP_NUM_THREADS") != nullptr) return;
  if (auto set_threads = loaded_function<void (*)(int)>("omp_set_num_threads")) set_threads(1);
  // CHOLMOD asks for a fixed team size in its supernodal kernels (num_threads(4)); with dynamic
  // adjustment on, the runtime may give fewer threads than asked, down to what the machine has free.
  if (auto set_dynamic = loaded_function<void (*)(int)>("omp_set_dynamic")) set_dynamic(1);
}

}  // namespace balloon
