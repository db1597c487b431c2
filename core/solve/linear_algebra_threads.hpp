#pragma once
/// One thread for the BLAS and OpenMP code under CHOLMOD. Our systems (up to ~1e5 unknowns) gain
/// nothing from threaded BLAS, whose spin-waiting threads cost up to a quarter of the run time on a
/// loaded 2-core machine; the service gets its parallelism from running jobs on several workers.
/// For the same reason the OpenMP parallel regions of the libraries this process loads run inline on
/// the calling thread (GOMP_parallel, defined in linear_algebra_threads.cpp), unless OMP_NUM_THREADS is set.
namespace balloon {

/// Limits OpenBLAS (process-wide) to one thread, unless the user set OPENBLAS_NUM_THREADS. Cheap to call
/// again. (OpenMP needs no call: its regions run inline, see above.)
void use_one_linear_algebra_thread();

}  // namespace balloon
