#include "log_sessions.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <vector>

#include "log_folder.hpp"

namespace rpem::tools {

analysis::LogData load_log_or_sessions(const std::string& path, const core::MachineSi& machine,
                                       const analysis::LogOptions& options,
                                       const std::function<void(std::uint64_t, std::uint64_t)>& progress) {
  if (!std::filesystem::is_directory(path)) return analysis::load_log(path, machine, options, progress);
  std::vector<std::string> logs;
  for (const std::filesystem::path& p : logs_in_folder(path)) logs.push_back(p.string());
  return analysis::load_sessions(path, logs, machine, options, progress);
}

void print_log_read(const char* tool, const analysis::LogData& log) {
  std::istringstream formats(log.format);
  for (std::string line; std::getline(formats, line);) std::fprintf(stderr, "%s: read %s\n", tool, line.c_str());
  if (log.sessions() < 2) return;
  std::fprintf(stderr, "%s: %zu logs joined as one machine's sessions, each from the configuration:\n", tool,
               log.sessions());
  for (std::size_t j = 0; j < log.sessions(); ++j) {
    std::fprintf(stderr, "%s:   %s: %zu samples from t = %.6g s\n", tool, log.session_logs[j].c_str(),
                 log.session_end(j) - log.session_first[j], log.t_s(log.session_first[j]));
  }
}

}  // namespace rpem::tools
