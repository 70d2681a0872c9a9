#pragma once
// RPEM_FLATTEN: [[gnu::flatten]] on the per-sample steps (every call inlined into them: their speed in the optimised
// builds). A sanitized tree (RPEM_SANITIZED, the top CMakeLists.txt) leaves it out: it compiles its libraries at -O1,
// where ASan's and UBSan's instrumentation of the flattened bodies did not compile in 19 minutes (docs/benchmarks.md,
// "The README test command on a fresh clone"). A speed attribute only: no result depends on it.
#if defined(RPEM_SANITIZED)
#define RPEM_FLATTEN
#else
#define RPEM_FLATTEN [[gnu::flatten]]
#endif
