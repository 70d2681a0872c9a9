#pragma once
// The project's assertion: an invariant the code relies on ("never", "always", "room was checked") stated
// in code where it must hold, not in a comment. RPEM_ASSERT(condition, why) prints file:line, the
// condition and why, and aborts — when assertions are on: in builds without NDEBUG (Debug) and in the
// sanitizer builds (RPEM_SANITIZE defines RPEM_ASSERTIONS=1, CMakeLists.txt). In the optimised builds, which
// run the real-time path, they are off and the condition is not evaluated: none is kept on there, so none
// has a cost to measure. Bad input is not an invariant: it gets an error or a counter, never an assertion.
//
// Define RPEM_ASSERTIONS (0 or 1) to choose for a whole build; a translation unit that forces it must not
// share an inline function or class whose definition depends on it with others (tests/core/test_assert.cpp).

#include <cstdio>
#include <cstdlib>

#ifndef RPEM_ASSERTIONS
#ifdef NDEBUG
#define RPEM_ASSERTIONS 0
#else
#define RPEM_ASSERTIONS 1
#endif
#endif

namespace rpem::core {

/// Prints where and which invariant failed, then aborts. Allocates nothing.
[[noreturn]] inline void assertion_failed(const char* condition, const char* why, const char* file, int line) noexcept {
  std::fprintf(stderr, "%s:%d: invariant violated: %s (%s)\n", file, line, condition, why);
  std::abort();
}

}  // namespace rpem::core

#if RPEM_ASSERTIONS
#define RPEM_ASSERT(condition, why) \
  (static_cast<bool>(condition) ? void(0) : ::rpem::core::assertion_failed(#condition, why, __FILE__, __LINE__))
#else
#define RPEM_ASSERT(condition, why) static_cast<void>(sizeof(static_cast<bool>(condition)))  // not evaluated
#endif
