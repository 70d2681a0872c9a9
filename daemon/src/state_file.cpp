#include "rpem/daemon/state_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rpem/core/errno_text.hpp"

namespace rpem::daemon {
namespace fs = std::filesystem;

namespace {

/// A temporary file in the same directory, fsync, rename, fsync of the directory: a crash leaves the
/// old or the new file, never a torn one. Returns an empty string or the reason it failed.
std::string write_atomically(const std::string& path, const std::string& text) {
  const fs::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return "open " + tmp + ": " + core::errno_text(errno);
  const char* p = text.data();
  std::size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string why = core::errno_text(errno);
      ::close(fd);
      return std::string("write ").append(tmp).append(": ").append(why);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) return "fsync " + tmp + ": " + core::errno_text(errno);
  if (::rename(tmp.c_str(), path.c_str()) != 0) return "rename to " + path + ": " + core::errno_text(errno);
  const std::string dir = target.has_parent_path() ? target.parent_path().string() : ".";
  if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
  return "";
}

}  // namespace

std::string write_state_file(const std::string& path, const PersistedEstimates& e) {
  nlohmann::json j;
  j["format"] = "rpemd-estimates-1";
  j["written_unix_s"] = e.written_unix_s;
  j["psi_m_Wb"] = e.psi_m_Wb ? nlohmann::json(*e.psi_m_Wb) : nlohmann::json(nullptr);
  j["r_s_Ohm"] = e.r_s_Ohm ? nlohmann::json(*e.r_s_Ohm) : nlohmann::json(nullptr);
  if (e.psi_m_Wb) j["psi_m_adapted_unix_s"] = e.psi_m_adapted_unix_s;
  if (e.r_s_Ohm) j["r_s_adapted_unix_s"] = e.r_s_adapted_unix_s;
  return write_atomically(path, j.dump(2) + "\n");
}

std::string command_sequence_file(const std::string& state_file) {
  const fs::path p(state_file);
  return (p.has_parent_path() ? p.parent_path() / "commands.json" : fs::path("commands.json")).string();
}

std::string write_command_sequence(const std::string& path, std::int64_t last_accepted_seq) {
  return write_atomically(
      path, "{\"format\": \"rpemd-commands-1\", \"last_accepted_seq\": " + std::to_string(last_accepted_seq) + "}\n");
}

std::int64_t load_command_sequence(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    if (!fs::exists(path)) return 0;
    throw std::runtime_error(path + ": cannot read the last accepted command sequence number");
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (!j.is_object() || j.value("format", "") != "rpemd-commands-1")
      throw std::runtime_error("not an rpemd commands file");
    return j.at("last_accepted_seq").get<std::int64_t>();
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": corrupt (" + e.what() +
                             "); it holds the last accepted command's sequence number, "
                             "which replay protection needs: restore it, or remove it to start again from 0");
  }
}

LoadedState load_state_file(const std::string& path, double max_age_s, double psi_min, double psi_max, double rs_min,
                            double rs_max) {
  LoadedState s;
  std::ifstream in(path);
  if (!in) {
    s.message = "no state file at " + path;
    return s;
  }
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (!j.is_object() || j.value("format", "") != "rpemd-estimates-1") throw std::runtime_error("not an rpemd state file");
    s.estimates.written_unix_s = j.at("written_unix_s").get<std::int64_t>();
    if (!j.at("psi_m_Wb").is_null()) s.estimates.psi_m_Wb = j.at("psi_m_Wb").get<double>();
    if (!j.at("r_s_Ohm").is_null()) s.estimates.r_s_Ohm = j.at("r_s_Ohm").get<double>();
    s.estimates.psi_m_adapted_unix_s = j.value("psi_m_adapted_unix_s", s.estimates.written_unix_s);
    s.estimates.r_s_adapted_unix_s = j.value("r_s_adapted_unix_s", s.estimates.written_unix_s);
  } catch (const std::exception& e) {
    s.status = StateFileStatus::kCorrupt;
    s.message = path + ": corrupt state file ignored (" + e.what() + ")";
    return s;
  }
  const double age = static_cast<double>(std::time(nullptr) - s.estimates.written_unix_s);
  if (age < -60.0 || age > max_age_s) {
    s.status = StateFileStatus::kTooOld;
    s.message = path + ": state file is " + std::to_string(static_cast<long>(age)) + " s old (limit " +
                std::to_string(static_cast<long>(max_age_s)) + " s), ignored";
    return s;
  }
  auto plausible = [](const std::optional<double>& v, double lo, double hi) {
    return !v || (std::isfinite(*v) && *v >= lo && *v <= hi);
  };
  if (!plausible(s.estimates.psi_m_Wb, psi_min, psi_max) || !plausible(s.estimates.r_s_Ohm, rs_min, rs_max) ||
      (!s.estimates.psi_m_Wb && !s.estimates.r_s_Ohm)) {
    s.status = StateFileStatus::kImplausible;
    s.message = path + ": state file values outside the configured bounds, ignored";
    return s;
  }
  s.status = StateFileStatus::kLoaded;
  s.message = path + ": resuming from estimates " + std::to_string(static_cast<long>(age)) + " s old";
  return s;
}

}  // namespace rpem::daemon
