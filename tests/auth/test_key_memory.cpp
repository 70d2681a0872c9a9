// Keys as libsodium intends (rpem/auth/key.hpp): one copy — not copyable, and a move hands over the
// owner, not the bytes — in locked memory, and wiped when dropped. The wipe is watched from outside the
// key: this test program interposes libsodium's sodium_free, which a key calls with its memory still
// valid, counts the keys it frees, records any whose 32 bytes are not zero, and passes them on to
// libsodium (dlsym RTLD_NEXT).
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <optional>
#include <string>
#include <type_traits>

#include "rpem/auth/key_file.hpp"
#include "rpem/auth/mac.hpp"

namespace {

int g_freed = 0;         ///< keys' memory handed back to libsodium
int g_freed_intact = 0;  ///< of them, with a byte not wiped

}  // namespace

extern "C" void sodium_free(void* ptr) {
  using Free = void (*)(void*);
  static const auto real = reinterpret_cast<Free>(dlsym(RTLD_NEXT, "sodium_free"));
  if (ptr != nullptr) {
    const auto* bytes = static_cast<const unsigned char*>(ptr);
    ++g_freed;
    if (!std::all_of(bytes, bytes + rpem::auth::kKeyBytes, [](unsigned char b) { return b == 0; })) ++g_freed_intact;
  }
  real(ptr);
}

namespace rpem::auth {
namespace {

static_assert(!std::is_copy_constructible_v<Key> && !std::is_copy_assignable_v<Key>, "one copy of each key");
static_assert(std::is_nothrow_move_constructible_v<Key> && std::is_nothrow_move_assignable_v<Key>);
static_assert(!std::is_copy_constructible_v<Keyring> && !std::is_copy_assignable_v<Keyring>);

std::array<std::uint8_t, kKeyBytes> pattern(std::uint8_t first) {
  std::array<std::uint8_t, kKeyBytes> b{};
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(first + i);
  return b;
}

/// The process's locked memory [kB] (/proc/self/status, VmLck).
long locked_kB() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmLck:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

TEST(KeyMemory, AKeyIsWipedWhenDropped) {
  const int freed = g_freed, intact = g_freed_intact;
  {
    const Key k(7, pattern(1));
    ASSERT_TRUE(std::ranges::equal(k.bytes(), pattern(1)));
  }
  EXPECT_EQ(g_freed - freed, 1);
  EXPECT_EQ(g_freed_intact - intact, 0);
  // Everywhere a key goes: a keyring, an optional (rpemd's publish key), a key file read and written.
  {
    Keyring ring;
    ASSERT_TRUE(ring.add(Key(1, pattern(10))));
    ASSERT_TRUE(ring.add(Key(2, pattern(20))));
    std::optional<Key> publish(Key(5, pattern(50)));
    const Key generated = generate_key(9);
  }
  EXPECT_EQ(g_freed - freed, 5);
  EXPECT_EQ(g_freed_intact - intact, 0);
}

TEST(KeyMemory, MovingHandsOverTheBytesWithoutACopy) {
  const int freed = g_freed;
  Key a(3, pattern(30));
  const std::uint8_t* where = a.bytes().data();
  Key b(std::move(a));
  EXPECT_TRUE(a.empty());  // NOLINT(bugprone-use-after-move): a moved-from key owns nothing
  EXPECT_EQ(a.id(), 0);    // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(b.bytes().data(), where);
  EXPECT_EQ(b.id(), 3);
  Keyring ring;
  ASSERT_TRUE(ring.add(std::move(b)));
  EXPECT_EQ(ring.find(3)->bytes().data(), where);
  EXPECT_EQ(g_freed - freed, 0);  // nothing copied, nothing freed
  Key refused(3, pattern(31));
  EXPECT_FALSE(ring.add(std::move(refused)));  // the same id: refused, and the key stays with its owner
  EXPECT_FALSE(refused.empty());               // NOLINT(bugprone-use-after-move)
}

TEST(KeyMemory, AKeysBytesAreLocked) {
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer intercepts mlock() and makes it a no-op (sanitizer_common's interceptors: "mlock is not
  // supported"), so under ASan nothing can be locked; the release and TSan builds run this check.
  GTEST_SKIP() << "mlock is a no-op under AddressSanitizer";
#endif
  const long before = locked_kB();
  ASSERT_GE(before, 0) << "no VmLck in /proc/self/status";
  const Key k(4, pattern(40));
  EXPECT_GE(locked_kB() - before, 4) << "sodium_malloc locks the page that holds the key";
}

}  // namespace
}  // namespace rpem::auth
