// Built only in the scratch tree of tests/schema/add_field.cmake, whose rpem_estimate_t.lcm has two fields
// more than ours: `double t_probe_C; // [T_probe] …` and `int16_t probe_counts[3];`. Only this probe names
// them, to set them in the mirror: the copy into the LCM message, the line and the CSV are lcm_types/'s
// generic code, and the encoding and decoding lcm-gen's.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "rpem/mirror/estimate_t.hpp"
#include "rpem/schema/text.hpp"

namespace {

int failures = 0;

void expect(bool ok, const std::string& what) {
  std::printf("%s  %s\n", ok ? "ok  " : "FAIL", what.c_str());
  if (!ok) ++failures;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out(1);
  for (const char c : s) {
    if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

}  // namespace

int main() {
  rpem::mirror::estimate_t mirror{};  // what rpemd's loop fills and queues
  mirror.t_probe_C = 42.25;
  mirror.probe_counts = {7, -8, 9};
  mirror.psi_m_Wb = 1.125;

  rpem::estimate_t m{};  // what its publisher copies it into and encodes
  rpem::schema::copy(mirror, m);
  m.algorithm = "sga";
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  const int size = m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  rpem::estimate_t heard{};  // what a listener decodes
  const int decoded = heard.decode(bytes.data(), 0, size);
  expect(size > 0 && decoded == size, "encoded and decoded " + std::to_string(size) + " bytes");
  expect(heard.t_probe_C == 42.25 && heard.probe_counts[0] == 7 && heard.probe_counts[1] == -8 &&
             heard.probe_counts[2] == 9 && heard.psi_m_Wb == 1.125,
         "the LCM encoding carries t_probe_C = 42.25 and probe_counts = {7, -8, 9}");

  const std::string line = rpem::schema::format_fields(heard);
  expect(line.find(" T_probe 42.25 C probe_counts [7 -8 9]") != std::string::npos, "the line: " + line);

  const std::vector<std::string> header = split(rpem::schema::csv_header<rpem::estimate_t>());
  const std::vector<std::string> row = split(rpem::schema::csv_row(heard));
  expect(header.size() == row.size(),
         "the CSV: " + std::to_string(header.size()) + " columns, " + std::to_string(row.size()) + " values");
  std::string found;
  for (std::size_t k = 0; k < header.size() && k < row.size(); ++k) {
    if (header[k] == "T_probe" || header[k].rfind("probe_counts[", 0) == 0) found += header[k] + "=" + row[k] + " ";
  }
  expect(found == "T_probe=42.25 probe_counts[0]=7 probe_counts[1]=-8 probe_counts[2]=9 ", "the CSV columns: " + found);
  return failures == 0 ? 0 : 1;
}
