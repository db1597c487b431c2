#pragma once
/// A function of a library CHOLMOD loaded (OpenBLAS, libgomp), looked up at run time so that the build
/// does not depend on which BLAS the system has chosen. nullptr when no loaded library has it.
#include <dlfcn.h>

namespace balloon {

template <class Function>
Function loaded_function(const char* name) {
  return reinterpret_cast<Function>(dlsym(RTLD_DEFAULT, name));
}

}  // namespace balloon
