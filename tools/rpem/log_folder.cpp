#include "log_folder.hpp"

#include <algorithm>
#include <cctype>
#include <regex>
#include <system_error>

#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::tools {
namespace {

namespace fs = std::filesystem;

bool is_csv_name(const std::string& name) {
  if (name.empty() || name.front() == '.' || name.size() <= 4) return false;
  std::string tail = name.substr(name.size() - 4);
  std::transform(tail.begin(), tail.end(), tail.begin(), [](unsigned char c) { return std::tolower(c); });
  return tail == ".csv";
}

/// RFC 4180: a cell holding a separator, a quote or a line break is quoted, its quotes doubled.
std::string csv_cell(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + '"';
}

void append_optional(std::string& line, const std::optional<double>& v) {
  line += ',';
  if (v) io::append_number(line, *v);
}

void append_optional(std::string& line, const std::optional<bool>& v) {
  line += ',';
  if (v) line += *v ? "yes" : "no";
}

}  // namespace

std::vector<fs::path> logs_in_folder(const std::string& folder) {
  std::error_code ec;
  fs::directory_iterator it(folder, ec);
  if (ec) throw io::InputError(folder, 0, 0, "", "cannot read the folder: " + ec.message());
  std::vector<fs::path> logs;
  for (const fs::directory_entry& entry : it) {
    if (entry.is_regular_file(ec) && is_csv_name(entry.path().filename().string())) logs.push_back(entry.path());
  }
  if (logs.empty()) throw io::InputError(folder, 0, 0, "", "no log in this folder: no file whose name ends in .csv");
  std::sort(logs.begin(), logs.end(), [](const fs::path& a, const fs::path& b) { return a.filename() < b.filename(); });
  return logs;
}

std::string session_start(const fs::path& log) {
  static const std::regex kName(R"(^(\d{4}-\d{2}-\d{2})_(\d{2})([-:])(\d{2})\3(\d{2})$)");
  std::smatch m;
  const std::string stem = log.stem().string();
  if (!std::regex_match(stem, m, kName)) return "";
  return m.str(1) + "T" + m.str(2) + ":" + m.str(4) + ":" + m.str(5);
}

std::string estimate_path(const std::string& out_dir, const fs::path& log) {
  return (fs::path(out_dir) / (log.stem().string() + ".estimate.csv")).string();
}

FolderSummary::FolderSummary(const std::string& path) : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw io::InputError(path, 0, 0, "", "cannot create file");
  out_ << "log,started,status,kind,samples,t_first_s,t_last_s,psi_m_Wb,r_s_Ohm,psi_m_adapted,r_s_adapted,resyncs,outliers,"
          "excluded,psi_m_identifiable,r_s_identifiable,t_magnet_peak_C,t_magnet_peak_2sd_C,t_winding_peak_C,"
          "t_winding_peak_2sd_C,error\n"
       << std::flush;
}

void FolderSummary::add(const LogOutcome& o) {
  std::string line = csv_cell(o.log) + ',' + o.started;
  line += o.error.empty() ? ",estimated," : ",skipped,";
  line += o.kind;
  line += ',';
  if (o.error.empty()) line += std::to_string(o.samples);
  for (const auto& v : {o.t_first_s, o.t_last_s, o.psi_m_Wb, o.r_s_Ohm}) append_optional(line, v);
  for (const std::uint64_t n : {o.adapted[0], o.adapted[1], o.resyncs, o.outliers, o.excluded}) {
    line += ',';
    if (o.error.empty()) line += std::to_string(n);
  }
  for (const auto& v : o.identifiable) append_optional(line, v);
  for (const auto& v : {o.magnet.t_C, o.magnet.t_2sd_C, o.winding.t_C, o.winding.t_2sd_C}) append_optional(line, v);
  line += ',' + csv_cell(o.error) + '\n';
  out_ << line << std::flush;
  if (!out_) throw io::InputError(path_, 0, 0, "", "cannot write the summary");
}

}  // namespace rpem::tools
