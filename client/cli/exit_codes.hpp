#pragma once
/// Process exit codes of `balloon`, one per class of outcome, so scripts can branch on them.

namespace balloon::cli {

inline constexpr int EXIT_OK = 0;                  ///< done
inline constexpr int EXIT_INTERNAL = 1;            ///< unexpected failure (a bug, an I/O error writing output)
inline constexpr int EXIT_BAD_INPUT = 2;           ///< bad usage, flag, file, mesh, material or option
inline constexpr int EXIT_NOT_CONVERGED = 3;       ///< the run finished but did not reach its tolerance
inline constexpr int EXIT_NOT_FOUND = 4;           ///< no such job or material
inline constexpr int EXIT_UNAVAILABLE = 5;         ///< server unreachable, queue full or a limit exceeded
inline constexpr int EXIT_DENIED = 6;              ///< missing or wrong token, or not allowed
inline constexpr int EXIT_NOT_READY = 7;           ///< the job has not finished (no result yet)
inline constexpr int EXIT_JOB_FAILED = 8;          ///< the job failed or was cancelled
inline constexpr int EXIT_INTERRUPTED = 130;       ///< stopped by Ctrl-C

/// The exit-code table as printed by `balloon --help`.
inline constexpr const char* EXIT_CODE_HELP =
    "Exit codes:\n"
    "  0    success\n"
    "  1    internal error (a bug, or output could not be written)\n"
    "  2    bad input: usage, flags, files, mesh, material or options\n"
    "  3    the run finished but did not converge (the result is still printed)\n"
    "  4    no such job or material\n"
    "  5    server unreachable, queue full, or a size limit exceeded\n"
    "  6    missing or wrong token, or not allowed\n"
    "  7    the job has not finished yet (no result)\n"
    "  8    the job failed or was cancelled\n"
    "  130  interrupted (Ctrl-C)\n";

}  // namespace balloon::cli
