// The generated field lists (lcm_types/schema_gen.py) and the generic code over them (rpem/schema/):
//   - each list is lcm-gen's reading of the same .lcm file: the LCM fingerprint recomputed from the list's
//     names, types and array sizes (the algorithm of lcm-gen's lcm_struct_hash, lcm-proj/lcm
//     lcmgen/lcmgen.c) equals the one lcm-gen compiled into the class;
//   - copy() writes every field of the mirror, and nothing else;
//   - the printed line and the CSV follow text.hpp's rules, numbers formatted as std::ostream formats them
//     (what `rpem listen` wrote before the CSV was generic).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include "rpem/mirror/command_t.hpp"
#include "rpem/mirror/diagnostics_t.hpp"
#include "rpem/mirror/estimate_t.hpp"
#include "rpem/mirror/measurement_t.hpp"
#include "rpem/schema/text.hpp"

namespace rpem {
namespace {

// LCM's type fingerprint (lcm-gen, lcm_struct_hash): over each member in order, its name, its primitive
// type's name and its dimensions (count; per dimension its mode, 0 for a fixed size, and the size as text).
std::int64_t hash_update(std::int64_t v, char c) {
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(v) << 8) ^ static_cast<std::uint64_t>(v >> 55)) + c;
}
std::int64_t hash_string_update(std::int64_t v, std::string_view s) {
  v = hash_update(v, static_cast<char>(s.size()));
  for (const char c : s) v = hash_update(v, c);
  return v;
}
std::int64_t hash_member(std::int64_t v, std::string_view name, std::string_view lcm_type) {
  const std::size_t bracket = lcm_type.find('[');
  v = hash_string_update(v, name);
  v = hash_string_update(v, lcm_type.substr(0, bracket));
  if (bracket == std::string_view::npos) return hash_update(v, 0);
  v = hash_update(v, 1);
  v = hash_update(v, 0);  // LCM_CONST: a fixed size
  return hash_string_update(v, lcm_type.substr(bracket + 1, lcm_type.size() - bracket - 2));
}

/// The fingerprint as lcm-gen's C++ getHash() returns it (rotated left by one bit), from the field list.
template <class Message>
std::int64_t fingerprint_of_list() {
  std::int64_t v = 0x12345678;
  schema::for_each_field<Message>([&](const auto& f) { v = hash_member(v, f.info.name, f.info.lcm_type); });
  if (schema::Schema<Message>::kAuthenticated) {  // the two fields the list leaves to auth/
    v = hash_member(v, "key_id", "int32_t");
    v = hash_member(v, "mac", "byte[32]");
  }
  const auto u = static_cast<std::uint64_t>(v);
  return static_cast<std::int64_t>((u << 1) + ((u >> 63) & 1));
}

TEST(Schema, EachFieldListIsLcmGensReadingOfTheSameFile) {
  EXPECT_EQ(fingerprint_of_list<estimate_t>(), estimate_t::getHash());
  EXPECT_EQ(fingerprint_of_list<measurement_t>(), measurement_t::getHash());
  EXPECT_EQ(fingerprint_of_list<diagnostics_t>(), diagnostics_t::getHash());
  EXPECT_EQ(fingerprint_of_list<command_t>(), command_t::getHash());
  EXPECT_EQ(schema::kFieldCount<estimate_t>, 30u);        // 21, and 9 of thermal fusion
  EXPECT_EQ(schema::kFieldCount<measurement_t>, 17u);     // 11, and the drive's three temperature sensors with their ages
  EXPECT_EQ(schema::spelled_count<diagnostics_t>(), 2u);  // source, source_name
}

/// Sets every field of the mirror to a value of its own (k-th field: k + 0.5, k, or k odd for booleans).
template <class Mirror>
void fill_distinct(Mirror& m) {
  int k = 0;
  schema::for_each_field<typename Mirror::Message>([&](const auto& f) {
    ++k;
    if constexpr (schema::kMirrored<std::remove_cvref_t<decltype(f)>>) {
      using U = std::remove_cvref_t<decltype(m.*f.mirror)>;
      if constexpr (std::is_same_v<U, bool>) {
        m.*f.mirror = k % 2 == 1;
      } else if constexpr (std::is_floating_point_v<U>) {
        m.*f.mirror = static_cast<U>(k) + static_cast<U>(0.5);
      } else {
        m.*f.mirror = static_cast<U>(k);
      }
    }
  });
}

template <class Mirror>
void expect_copied_every_field() {
  Mirror from{};
  fill_distinct(from);
  typename Mirror::Message to{};
  schema::copy(from, to);
  int k = 0, checked = 0;
  schema::for_each_field<typename Mirror::Message>([&](const auto& f) {
    ++k;
    if constexpr (schema::kMirrored<std::remove_cvref_t<decltype(f)>>) {
      const double expected = static_cast<double>(from.*f.mirror);  // k + 0.5, k, or k % 2 for a boolean
      EXPECT_EQ(static_cast<double>(to.*f.member), expected) << f.info.name;
      ++checked;
    } else {
      EXPECT_TRUE((to.*f.member).empty()) << f.info.name << ": a string is the caller's";
    }
  });
  EXPECT_EQ(static_cast<std::size_t>(checked),
            schema::kFieldCount<typename Mirror::Message> - schema::spelled_count<typename Mirror::Message>());
}

TEST(Schema, CopyWritesEveryFieldOfTheMirrorAndLeavesStringsAndKeysToTheCaller) {
  expect_copied_every_field<mirror::estimate_t>();
  expect_copied_every_field<mirror::measurement_t>();
  expect_copied_every_field<mirror::diagnostics_t>();
  expect_copied_every_field<mirror::command_t>();
  estimate_t m{};
  m.key_id = 7;
  schema::copy(mirror::estimate_t{}, m);
  EXPECT_EQ(m.key_id, 7);  // authentication: not in the list, not touched
}

TEST(Schema, TheMirrorsAreCopyableDataOfFixedSize) {
  EXPECT_TRUE(std::is_trivially_copyable_v<mirror::estimate_t>);
  EXPECT_TRUE(std::is_trivially_copyable_v<mirror::measurement_t>);
  EXPECT_TRUE(std::is_trivially_copyable_v<mirror::diagnostics_t>);
  EXPECT_TRUE(std::is_trivially_copyable_v<mirror::command_t>);
  EXPECT_EQ(mirror::command_t::RESET, command_t::RESET);  // the .lcm's constants
  EXPECT_EQ(mirror::command_t::SET_VALUES, command_t::SET_VALUES);
}

TEST(Schema, ALineShowsEachFieldByNameOrLabelWithGroupsApart) {
  measurement_t m{};
  m.utime = 1'700'000'000'123'456;
  m.sample_time_us = 42;
  m.theta_el_rad = 1.0 / 3.0;
  m.omega_el_rad_s = 314.159265;
  m.u_dc_V = 560.0;
  m.i_d_A = -1.25;
  m.i_q_A = 1e-7;
  m.t_winding_sensor_C = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(schema::format_fields(m),
            "utime 1700000000123456 sample_time_us 42 theta_el_rad 0.333333 omega_el_rad_s 314.159 u_dc_V 560 i_d_A -1.25 "
            "i_q_A 1e-07 i_hat_d_A 0 i_hat_q_A 0 epsilon_d_A 0 epsilon_q_A 0 | t_winding_sensor_C nan "
            "t_winding_sensor_age_s 0 t_drive_sensor_C 0 t_drive_sensor_age_s 0 t_coolant_sensor_C 0 "
            "t_coolant_sensor_age_s 0");

  estimate_t e{};
  e.psi_m_Wb = 1.0987;
  e.t_magnet_C = 51.25;
  e.psi_m_valid = 1;
  e.state = 2;
  e.algorithm = "gna";
  // A label drops the name's unit, which follows the value; a comment line in the .lcm opens a group.
  EXPECT_EQ(schema::format_fields(e),
            "utime 0 sample_time_us 0 samples 0 psi_m 1.0987 Wb r_s 0 Ohm psi_m_pu 0 r_s_pu 0 T_magnet 51.25 C "
            "T_winding 0 C speed_pu 0 | psi_m_valid 1 r_s_valid 0 psi_m_converged 0 r_s_converged 0 psi_m_adapting 0 "
            "r_s_adapting 0 psi_m_age_s 0 r_s_age_s 0 frozen 0 state 2 algorithm \"gna\" | thermal_active 0 "
            "t_magnet_fused_C 0 t_magnet_fused_sd_C 0 t_magnet_source 0 t_magnet_observed_age_s 0 t_winding_fused_C 0 "
            "t_winding_fused_sd_C 0 t_winding_source 0 t_winding_observed_age_s 0");
  constexpr std::array<std::string_view, 3> kShownElsewhere{"utime", "samples", "algorithm"};
  static_assert(schema::has_fields<estimate_t>(kShownElsewhere));
  static_assert(!schema::has_fields<estimate_t>(std::array<std::string_view, 1>{"psi_m"}));  // a label is not a name
  const std::string rest = schema::format_fields(e, kShownElsewhere);
  EXPECT_TRUE(rest.starts_with("sample_time_us 0 psi_m 1.0987 Wb r_s 0 Ohm")) << rest;
  EXPECT_TRUE(
      rest.ends_with("frozen 0 state 2 | thermal_active 0 t_magnet_fused_C 0 t_magnet_fused_sd_C 0 "
                     "t_magnet_source 0 t_magnet_observed_age_s 0 t_winding_fused_C 0 t_winding_fused_sd_C 0 "
                     "t_winding_source 0 t_winding_observed_age_s 0"))
      << rest;
}

TEST(Schema, TheCsvHasAColumnPerNumberFormattedAsAStreamFormatsIt) {
  // The thermal fusion's fields label the fused temperatures [T_magnet] and [T_winding], as the raw ones
  // are: a label is a unique key, so the raw ones keep it and the fused ones their names (schema_gen.py).
  EXPECT_EQ(schema::csv_header<estimate_t>(),
            "utime,sample_time_us,samples,psi_m,r_s,psi_m_pu,r_s_pu,T_magnet,T_winding,speed_pu,psi_m_valid,r_s_valid,"
            "psi_m_converged,r_s_converged,psi_m_adapting,r_s_adapting,psi_m_age_s,r_s_age_s,frozen,state,"
            "thermal_active,t_magnet_fused_C,t_magnet_fused_sd_C,t_magnet_source,t_magnet_observed_age_s,"
            "t_winding_fused_C,t_winding_fused_sd_C,t_winding_source,t_winding_observed_age_s");
  estimate_t e{};
  e.utime = 1'700'000'000'123'456;
  e.psi_m_Wb = 1.09872345;
  e.r_s_age_s = -1.0;
  e.frozen = 1;
  e.state = 3;
  e.algorithm = "sga";  // not a column: every column is a number
  EXPECT_EQ(schema::csv_row(e), "1700000000123456,0,0,1.09872,0,0,0,0,0,0,0,0,0,0,0,0,0,-1,1,3,0,0,0,0,0,0,0,0,0");

  // Each number as `std::ostream << double` writes it (6 significant digits, %g), over seeded random values.
  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-12, 12);
  for (int i = 0; i < 2000; ++i) {
    measurement_t m{};
    m.u_dc_V = mantissa(rng) * std::pow(10.0, exponent(rng));
    std::ostringstream expected;
    expected << m.u_dc_V;
    const std::string row = schema::csv_row(m);
    const std::size_t begin = row.find(',', row.find(',', row.find(',', row.find(',') + 1) + 1) + 1) + 1;  // 5th column
    ASSERT_EQ(row.substr(begin, row.find(',', begin) - begin), expected.str()) << "seed 20261124, value " << i;
  }
}

}  // namespace
}  // namespace rpem
