#pragma once
/// The process's peak resident memory, per bench row: reset before the row, read after it (Linux).

namespace balloon::bench {

/// Resets the process's peak resident set (Linux: writing 5 to /proc/self/clear_refs), so each row reports
/// its own; memory the allocator still holds from earlier rows is given back first (else it would count again).
void reset_peak_memory();

/// Peak resident set since the last reset (MB): VmHWM, or getrusage's maximum where /proc is missing.
double peak_memory_mb();

}  // namespace balloon::bench
