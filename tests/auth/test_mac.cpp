// rpem/auth/mac.hpp: the tag against an independent computation, and every verdict of verify().
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "rpem/auth/mac.hpp"

namespace rpem::auth {
namespace {

std::vector<std::uint8_t> from_hex(const std::string& hex) {
  std::vector<std::uint8_t> out;
  for (std::size_t k = 0; k + 1 < hex.size(); k += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(k, 2), nullptr, 16)));
  return out;
}

// The test vector, computed by tests/auth/make_test_vector.py without any of our C++: an rpem.command_t
// (utime 1700000000000000, seq 42, command 4, psi_m 1.05 Wb, r_s 2.4 Ohm, key_id 7, mac zero) encoded
// by LCM's own Python generator (lcm-gen --python on lcm_types/rpem_command_t.lcm), and the tag by
// Python's hmac.new(bytes(range(32)), b"rpem-auth-1\0RPEM_COMMAND\0" + E[:-32], hashlib.sha256).
const std::string kEncodingHex =
    "1508b5fe54b54dd200060a24181e4000000000000000002a043ff0cccccccccccd4003333333333333000000070000000000000000"
    "000000000000000000000000000000000000000000000000";
const std::string kTagHex = "2eacff3d58d9336c3e4e33577f74ce636dc162e8ea56731e4429f777d79bfa98";

std::array<std::uint8_t, kKeyBytes> test_bytes() {
  std::array<std::uint8_t, kKeyBytes> b{};
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint8_t>(i);
  return b;
}

Key test_key(std::int32_t id = 7) { return {id, test_bytes()}; }

std::vector<std::uint8_t> signed_vector() {
  std::vector<std::uint8_t> e = from_hex(kEncodingHex);
  EXPECT_TRUE(sign(test_key(), "RPEM_COMMAND", e));
  return e;
}

TEST(Mac, MatchesPythonsHmacOverLcmsPythonEncoding) {
  const std::vector<std::uint8_t> e = from_hex(kEncodingHex);
  ASSERT_EQ(e.size(), 77u);
  EXPECT_EQ(key_id_of(e), 7);
  const Tag tag = compute_tag(test_key(), "RPEM_COMMAND", std::span(e).first(e.size() - kMacBytes));
  EXPECT_EQ(std::vector<std::uint8_t>(tag.begin(), tag.end()), from_hex(kTagHex));
  const std::vector<std::uint8_t> s = signed_vector();
  EXPECT_EQ(std::vector<std::uint8_t>(s.end() - kMacBytes, s.end()), from_hex(kTagHex));
}

TEST(Mac, SignRefusesAKeyIdOtherThanTheEncodingsAndTooShortInput) {
  std::vector<std::uint8_t> e = from_hex(kEncodingHex);
  EXPECT_FALSE(sign(test_key(8), "RPEM_COMMAND", e));
  std::vector<std::uint8_t> tiny(kTrailerBytes - 1);
  EXPECT_FALSE(sign(test_key(), "RPEM_COMMAND", tiny));
}

TEST(Verify, EachVerdict) {
  Keyring keys;
  ASSERT_TRUE(keys.add(test_key()));
  const std::vector<std::uint8_t> good = signed_vector();
  EXPECT_EQ(verify(keys, "RPEM_COMMAND", good), Verdict::kVerified);
  // Another channel — an estimate's, another instance's prefix — is another message.
  EXPECT_EQ(verify(keys, "RPEM_ESTIMATE", good), Verdict::kBadMac);
  EXPECT_EQ(verify(keys, "B_RPEM_COMMAND", good), Verdict::kBadMac);
  EXPECT_EQ(verify(keys, "RPEM_COMMAND", from_hex(kEncodingHex)), Verdict::kBadMac);  // tag zero
  std::vector<std::uint8_t> unsigned_message = from_hex(kEncodingHex);
  unsigned_message[unsigned_message.size() - kTrailerBytes + 3] = 0;  // key id 0
  EXPECT_EQ(verify(keys, "RPEM_COMMAND", unsigned_message), Verdict::kUnsigned);
  Keyring other;
  ASSERT_TRUE(other.add(test_key(9)));
  EXPECT_EQ(verify(other, "RPEM_COMMAND", good), Verdict::kUnknownKey);
  EXPECT_EQ(verify(Keyring{}, "RPEM_COMMAND", good), Verdict::kUnknownKey);
  EXPECT_EQ(verify(keys, "RPEM_COMMAND", std::span(good).first(kTrailerBytes - 1)), Verdict::kMalformed);
}

// One flipped bit anywhere — a field, the fingerprint, the key id, the tag — and it no longer verifies.
TEST(Verify, EveryFlippedBitIsCaught) {
  Keyring keys;
  ASSERT_TRUE(keys.add(test_key()));
  const std::vector<std::uint8_t> good = signed_vector();
  for (std::size_t byte = 0; byte < good.size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<std::uint8_t> m = good;
      m[byte] ^= static_cast<std::uint8_t>(1u << bit);
      const Verdict v = verify(keys, "RPEM_COMMAND", m);
      EXPECT_NE(v, Verdict::kVerified) << byte << ":" << bit;
      const bool in_key_id = byte >= good.size() - kTrailerBytes && byte < good.size() - kMacBytes;
      EXPECT_EQ(v, in_key_id ? Verdict::kUnknownKey : Verdict::kBadMac) << byte << ":" << bit;
    }
  }
}

TEST(Keyring, HoldsTwoDistinctPositiveIdsForARotation) {
  Keyring keys;
  EXPECT_FALSE(keys.add(test_key(0)));
  EXPECT_FALSE(keys.add(test_key(-1)));
  EXPECT_TRUE(keys.add(test_key(7)));
  EXPECT_FALSE(keys.add(test_key(7)));
  std::array<std::uint8_t, kKeyBytes> next_bytes = test_bytes();
  next_bytes[0] ^= 0xFF;
  const Key next(8, next_bytes);  // the signer's copy
  EXPECT_TRUE(keys.add(Key(8, next_bytes)));
  EXPECT_FALSE(keys.add(test_key(9)));
  EXPECT_EQ(keys.size(), 2);
  // Both verify their own messages during the change.
  std::vector<std::uint8_t> e = from_hex(kEncodingHex);
  e[e.size() - kTrailerBytes + 3] = 8;
  ASSERT_TRUE(sign(next, "RPEM_COMMAND", e));
  EXPECT_EQ(verify(keys, "RPEM_COMMAND", e), Verdict::kVerified);
  EXPECT_EQ(verify(keys, "RPEM_COMMAND", signed_vector()), Verdict::kVerified);
}

}  // namespace
}  // namespace rpem::auth
