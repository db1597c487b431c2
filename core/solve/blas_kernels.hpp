#pragma once
/// The BLAS kernels under CHOLMOD and MUMPS. Debian 12's OpenBLAS (0.3.21) picks its kernels by CPU model
/// and falls back to Prescott's (SSE3, 2004) on models newer than itself, such as this machine's Xeon
/// (family 6, model 207, with AVX-512): there the supernodal factorizations ran at about 60% of the
/// speed the CPU has (40,962-vertex sphere to x8: 2.8 s against 1.7 s; 100,002 vertices: 9.9 s against 5.4 s).
namespace balloon {

/// When OpenBLAS chose Prescott although the CPU has AVX-512 (or AVX2 and FMA), re-runs OpenBLAS's own
/// kernel selection with OPENBLAS_CORETYPE=SkylakeX (or Haswell), exactly as if the user had set it.
/// Nothing changes when the user set OPENBLAS_CORETYPE, when OpenBLAS knows the CPU, or when the BLAS is
/// not OpenBLAS. Runs once per process: before main (while the process has one thread, since it sets an
/// environment variable) and, should that not have run, from SparseSolver's constructor.
void use_the_cpus_blas_kernels();

/// The kernel set OpenBLAS uses ("SkylakeX", "Prescott", ...), or "" when the BLAS is not OpenBLAS.
const char* blas_kernel_name();

}  // namespace balloon
