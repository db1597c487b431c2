#include "solve/blas_kernels.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <mutex>

namespace balloon {

namespace {

/// A function of the BLAS CHOLMOD loaded, looked up at run time so that the build does not depend on
/// which BLAS the system has chosen (as in linear_algebra_threads.cpp).
template <class Function>
Function loaded_function(const char* name) {
  return reinterpret_cast<Function>(dlsym(RTLD_DEFAULT, name));
}

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
    // BLAS call has run yet (the first SparseSolver calls this), so re-selecting is what loading with the
    // variable set does. The variable is removed again: the environment stays as the user left it.
    setenv("OPENBLAS_CORETYPE", kernels, 0);
    quit();
    init();
    unsetenv("OPENBLAS_CORETYPE");
  });
}

}  // namespace balloon
