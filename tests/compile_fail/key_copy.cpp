// Each key exists once: a key cannot be copied, only handed over (moved), so its bytes are in one place.
#include <array>
#include <cstdint>
#include <utility>

#include "rpem/auth/key.hpp"

int main() {
  const std::array<std::uint8_t, rpem::auth::kKeyBytes> bytes{};
  rpem::auth::Key key(1, bytes);
#ifdef RPEM_COMPILE_FAIL
  rpem::auth::Key second = key;  // a second copy of the key
#else
  rpem::auth::Key second = std::move(key);  // the one key, handed over
#endif
  return second.id() == 1 ? 0 : 1;
}
