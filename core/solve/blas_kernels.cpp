#include "solve/blas_kernels.hpp"

#include "solve/loaded_function.hpp"

#include <cstdlib>
#include <cstring>
#include <mutex>

namespace balloon {

namespace {

/// The kernel set this CPU can run best among those OpenBLAS 0.3.21 has for x86-64, or nullptr.
const char* best_kernels_for_this_cpu() {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
  return nullptr;
}

}  // namespace

const char* blas_kernel_name() {
  auto corename = loaded_function<char* (*)()>("openblas_get_corename");
  return corename != nullptr ? corename() : "";
}

void use_the_cpus_blas_kernels() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return;  // the user's choice, applied when OpenBLAS loaded
    if (std::strcmp(blas_kernel_name(), "Prescott") != 0) return;
    const char* kernels = best_kernels_for_this_cpu();
    auto quit = loaded_function<void (*)()>("gotoblas_dynamic_quit");
    auto init = loaded_function<void (*)()>("gotoblas_dynamic_init");
    if (kernels == nullptr || quit == nullptr || init == nullptr) return;
    // OpenBLAS's selection reads OPENBLAS_CORETYPE when it runs; quit only forgets the chosen table, and no
    // BLAS call has run yet (this runs before main), so re-selecting is what loading with the
    // variable set does. The variable is removed again: the environment stays as the user left it.
    setenv("OPENBLAS_CORETYPE", kernels, 0);
    quit();
    init();
    unsetenv("OPENBLAS_CORETYPE");
  });
}

namespace {

// Done before main as well, while the process has one thread: setenv is not safe beside threads that read
// the environment (gRPC's, the server's workers). SparseSolver's constructor calls it again (a no-op then),
// which is also what links this file into every program that factorizes.
[[maybe_unused]] const bool g_kernels_chosen_before_main = (use_the_cpus_blas_kernels(), true);

}  // namespace

}  // namespace balloon
