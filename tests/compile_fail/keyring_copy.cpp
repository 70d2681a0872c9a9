// A keyring holds its keys once: it cannot be copied either (rpemd hands its command keys to the command
// gate, its publish key to the publisher).
#include <utility>

#include "rpem/auth/mac.hpp"

int main() {
  rpem::auth::Keyring keys;
#ifdef RPEM_COMPILE_FAIL
  rpem::auth::Keyring gate = keys;  // a second copy of every key
#else
  rpem::auth::Keyring gate = std::move(keys);  // handed over
#endif
  return gate.empty() ? 0 : 1;
}
