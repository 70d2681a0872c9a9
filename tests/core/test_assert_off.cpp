// test_assert.cpp's other half: with assertions off, a false condition neither aborts nor is evaluated.
#undef RPEM_ASSERTIONS
#define RPEM_ASSERTIONS 0
#include "rpem/core/assert.hpp"

namespace rpem::core {

int evaluations_with_assertions_off() {
  int evaluated = 0;
  RPEM_ASSERT(++evaluated < 0, "false, and not evaluated");
  return evaluated;
}

}  // namespace rpem::core
