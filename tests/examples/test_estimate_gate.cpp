// Which estimates the supervisor acts on (estimate_gate.hpp, docs/supervisor.md "What is ignored"):
// unverified ones (unsigned, unknown key, a guessed key under the right id, one bit flipped), stale ones
// and ones from the future (utime against the supervisor's clock), and — per key id — ones whose utime
// or sample time is not past the last accepted one's: a genuine message replayed, or reordered. Messages
// are encoded by lcm-gen's class and signed with auth/ under a test key, as rpemd signs them; a replay
// re-submits the very bytes an eavesdropper captured.
#include <gtest/gtest.h>

#include "rpem/supervisor/estimate_gate.hpp"
#include "rpem/supervisor/supervisor.hpp"
#include "signed_estimate.hpp"

namespace rpem::supervisor {
namespace {

using test::kT0;
constexpr Freshness kFreshness{500'000, 50'000};  // 0.5 s, 0.05 s

struct Gate : ::testing::Test {
  auth::Keyring keys;
  auth::Key key = test::test_key(2);
  Gate() { keys.add(test::test_key(2)); }
  EstimateGate gate{keys, kFreshness};

  Admission send(const std::vector<std::uint8_t>& bytes, std::int64_t now_us, std::string_view channel = "RPEM_ESTIMATE") {
    rpem::estimate_t m{};
    return gate.admit(channel, bytes, now_us, m);
  }
  Admission send(const rpem::estimate_t& m, std::int64_t now_us) { return send(test::encode_signed(m, &key), now_us); }
};

TEST_F(Gate, AcceptsAGenuineFreshEstimate) {
  EXPECT_EQ(send(test::raw_estimate(kT0, 60.0, 70.0), kT0 + 2'000), Admission::kAccepted);
  EXPECT_EQ(gate.count(Admission::kAccepted), 1);
}

TEST_F(Gate, RefusesWhatDoesNotVerify) {
  const rpem::estimate_t m = test::raw_estimate(kT0, 20.0, 20.0);  // a cold magnet: what a forger would send
  EXPECT_EQ(send(test::encode_signed(m, nullptr), kT0), Admission::kUnsigned);
  const auth::Key other_id = test::test_key(9);
  EXPECT_EQ(send(test::encode_signed(m, &other_id), kT0), Admission::kUnknownKey);
  const auth::Key guessed = test::test_key(2, 1);  // the right id, not the key
  EXPECT_EQ(send(test::encode_signed(m, &guessed), kT0), Admission::kBadMac);
  EXPECT_EQ(send(test::encode_signed(m, &key, "OTHER_RPEM_ESTIMATE"), kT0), Admission::kBadMac);  // another channel's
  // Every bit of a genuine message flipped in turn: a bad MAC (or, in the key id, another verdict) — the
  // bytes are not decoded, so a flipped string length cannot reach lcm-gen's decoder.
  const std::vector<std::uint8_t> genuine = test::encode_signed(m, &key);
  for (std::size_t bit = 0; bit < 8 * genuine.size(); ++bit) {
    std::vector<std::uint8_t> b = genuine;
    b[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    const Admission a = send(b, kT0);
    const bool in_key_id = bit / 8 >= genuine.size() - auth::kTrailerBytes && bit / 8 < genuine.size() - auth::kMacBytes;
    // In the key id (2): 0 is unsigned, any other id unknown.
    const Admission expected = !in_key_id                                          ? Admission::kBadMac
                               : bit == 8 * (genuine.size() - auth::kMacBytes) - 7 ? Admission::kUnsigned
                                                                                   : Admission::kUnknownKey;
    ASSERT_EQ(a, expected) << "bit " << bit;
  }
  EXPECT_EQ(gate.count(Admission::kAccepted), 0);
}

TEST_F(Gate, AnAuthenticMessageThatIsNoEstimateIsMalformedNotACrash) {
  // Signed with the key, but its string's length field is 0 (lcm-gen's decoder throws on it) or the
  // bytes are not an estimate_t at all: malformed, counted.
  std::vector<std::uint8_t> b = test::encode_signed(test::raw_estimate(kT0, 60.0, 70.0), &key);
  // After the string (its int32 length, then "sga" and its 0): the thermal fields, 6 doubles and 3 bytes.
  const std::size_t length_at = b.size() - auth::kTrailerBytes - (6 * 8 + 3) - 4 - 4;
  ASSERT_EQ(b[length_at + 3], 4);
  b[length_at + 3] = 0;
  auth::sign(key, "RPEM_ESTIMATE", b);
  rpem::estimate_t out{};
  EXPECT_EQ(gate.admit("RPEM_ESTIMATE", b, kT0, out), Admission::kMalformed);
  std::vector<std::uint8_t> short_one(b.begin() + 20, b.end());
  auth::sign(key, "RPEM_ESTIMATE", short_one);
  EXPECT_EQ(gate.admit("RPEM_ESTIMATE", short_one, kT0, out), Admission::kMalformed);
  EXPECT_EQ(gate.count(Admission::kMalformed), 2);
}

TEST_F(Gate, RefusesStaleAndFutureEstimatesAtTheBoundsOfAgeAndSkew) {
  // Accepted while now − utime ≤ max_age + max_skew = 550 ms and utime − now ≤ max_skew = 50 ms.
  EXPECT_EQ(send(test::raw_estimate(kT0, 60.0, 70.0), kT0 + 550'001), Admission::kStale);
  EXPECT_EQ(send(test::raw_estimate(kT0, 60.0, 70.0), kT0 + 550'000), Admission::kAccepted);
  EXPECT_EQ(send(test::raw_estimate(kT0 + 1'000'000, 60.0, 70.0), kT0 + 949'999), Admission::kFromFuture);
  EXPECT_EQ(send(test::raw_estimate(kT0 + 1'000'000, 60.0, 70.0), kT0 + 950'000), Admission::kAccepted);
}

TEST_F(Gate, AReplayedGenuineEstimateIsStaleLaterAndNotNewerWithinTheWindow) {
  // An eavesdropper captures a genuine estimate of a cold magnet …
  const std::vector<std::uint8_t> cold = test::encode_signed(test::raw_estimate(kT0, 25.0, 30.0), &key);
  EXPECT_EQ(send(cold, kT0 + 1'000), Admission::kAccepted);
  // … the magnet heats up, rpemd says so …
  EXPECT_EQ(send(test::raw_estimate(kT0 + 100'000, 130.0, 120.0), kT0 + 101'000), Admission::kAccepted);
  // … and the captured bytes are re-sent: at once (inside the freshness window), and an hour later.
  EXPECT_EQ(send(cold, kT0 + 150'000), Admission::kNotNewer);
  EXPECT_EQ(send(cold, kT0 + 3'600'000'000), Admission::kStale);
  // The newest genuine one, re-sent at once: not newer than itself.
  EXPECT_EQ(send(test::raw_estimate(kT0 + 100'000, 130.0, 120.0), kT0 + 160'000), Admission::kNotNewer);
  EXPECT_EQ(gate.count(Admission::kAccepted), 2);
  EXPECT_EQ(gate.count(Admission::kNotNewer), 2);
  EXPECT_EQ(gate.count(Admission::kStale), 1);
}

TEST_F(Gate, ReorderedEstimatesAreRefusedByUtimeAndBySampleTime) {
  rpem::estimate_t first = test::raw_estimate(kT0, 60.0, 70.0);
  rpem::estimate_t second = test::raw_estimate(kT0 + 100'000, 61.0, 71.0);
  EXPECT_EQ(send(second, kT0 + 101'000), Admission::kAccepted);
  EXPECT_EQ(send(first, kT0 + 102'000), Admission::kNotNewer);  // arrived after a later one
  // A newer utime but no newer sample (rpemd stale, or the drive's clock went back): not newer either.
  rpem::estimate_t same_sample = test::raw_estimate(kT0 + 200'000, 61.0, 71.0);
  same_sample.sample_time_us = second.sample_time_us;
  EXPECT_EQ(send(same_sample, kT0 + 201'000), Admission::kNotNewer);
  rpem::estimate_t older_sample = same_sample;
  older_sample.sample_time_us -= 1;
  EXPECT_EQ(send(older_sample, kT0 + 201'000), Admission::kNotNewer);
  rpem::estimate_t next = test::raw_estimate(kT0 + 300'000, 62.0, 72.0);
  EXPECT_EQ(send(next, kT0 + 301'000), Admission::kAccepted);
}

TEST_F(Gate, AfterASilenceRpemdsRestartedDriveClockIsAcceptedButNotAnOldUtime) {
  EXPECT_EQ(send(test::raw_estimate(kT0, 60.0, 70.0), kT0 + 1'000), Admission::kAccepted);
  // rpemd restarts: 3 s later, its drive time starts again near 0 (utime, wall clock, goes on).
  rpem::estimate_t restarted = test::raw_estimate(kT0 + 3'000'000, 60.0, 70.0);
  restarted.sample_time_us = 125;
  EXPECT_EQ(send(restarted, kT0 + 3'001'000), Admission::kAccepted);
  // Without the silence the same step back in drive time is refused (previous test); and the silence
  // never lets an older utime in: the first estimate re-sent is stale.
  EXPECT_EQ(send(test::raw_estimate(kT0, 60.0, 70.0), kT0 + 3'002'000), Admission::kStale);
}

TEST(GateKeys, EachKeyIdHasItsOwnOrderDuringARotation) {
  auth::Keyring keys;
  keys.add(test::test_key(2));
  keys.add(test::test_key(3, 7));
  EstimateGate gate(keys, kFreshness);
  const auth::Key old_key = test::test_key(2), new_key = test::test_key(3, 7);
  const auto admit = [&](const rpem::estimate_t& m, const auth::Key& k, std::int64_t now) {
    const auto b = test::encode_signed(m, &k);
    rpem::estimate_t out{};
    return gate.admit("RPEM_ESTIMATE", b, now, out);
  };
  EXPECT_EQ(admit(test::raw_estimate(kT0 + 200'000, 60.0, 70.0), old_key, kT0 + 201'000), Admission::kAccepted);
  EXPECT_EQ(admit(test::raw_estimate(kT0 + 100'000, 60.0, 70.0), new_key, kT0 + 202'000), Admission::kAccepted);
  EXPECT_EQ(admit(test::raw_estimate(kT0 + 100'000, 60.0, 70.0), new_key, kT0 + 203'000), Admission::kNotNewer);
  EXPECT_EQ(admit(test::raw_estimate(kT0 + 150'000, 60.0, 70.0), old_key, kT0 + 203'000), Admission::kNotNewer);
}

}  // namespace
}  // namespace rpem::supervisor
