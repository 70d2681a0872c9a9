// rpemd — online identification of the PMSM's magnet flux linkage and stator resistance.
//
//   rpemd [--config FILE.yaml] [--can IFACE] [--check-config] [--latency-histogram FILE]
//
// Without arguments it runs the paper's machine on the built-in simulated drive. The threads, what each
// owns and the queues between them: daemon.hpp and docs/rpemd.md.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "rpem/auth/key.hpp"
#include "rpem/daemon/credentials.hpp"
#include "rpem/daemon/daemon.hpp"
#include "rpem/io/exit_codes.hpp"

namespace {

/// --check-config: the file, and the command keys as the service will see them (systemd's LoadCredential= puts
/// them in $CREDENTIALS_DIRECTORY, which a shell outside the service does not have: then said, not guessed).
int check_configuration(const rpem::daemon::DaemonConfig& config) {
  using namespace rpem;
  const char* directory = std::getenv("CREDENTIALS_DIRECTORY");
  const bool has_credentials = directory != nullptr && *directory != '\0';
  try {
    auth::initialise();
    if (const std::string problem = daemon::check_credentials(config.live, directory).problem; !problem.empty()) {
      if (has_credentials) {
        std::fprintf(stderr, "rpemd: configuration error: %s\n", problem.c_str());
        return io::kExitConfig;
      }
      std::fprintf(stderr,
                   "rpemd: note: the command keys are not checked here (CREDENTIALS_DIRECTORY is not set; the "
                   "service gets them from LoadCredential=): without one rpemd will refuse to start: %s\n",
                   problem.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rpemd: configuration error: %s\n", e.what());
    return io::kExitConfig;
  }
  std::printf("rpemd: %s is valid\n", config.source_file.c_str());
  return io::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {  // NOLINT(bugprone-exception-escape): only a defect escapes; terminate() shows it
  using namespace rpem;
  CLI::App app{"rpemd: online identification of PMSM magnet flux linkage and stator resistance (docs/rpemd.md)"};
  daemon::DaemonOptions options;
  bool check_only = false;
  app.add_option("--config", options.config_path, "configuration YAML (default: built-in, simulated drive)");
  app.add_option("--can", options.can_interface, "use this CAN interface as the source (overrides the configuration)");
  app.add_flag("--check-config", check_only, "validate the configuration and exit");
  app.add_option("--latency-histogram", options.histogram_path,
                 "at exit, write the loop's wake-up latency histogram (µs, count; as cyclictest -h) to this file");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);  // the help, or the error and the usage
    return code == 0 ? io::kExitOk : io::kExitUsage;
  }
  try {
    daemon::DaemonConfig config = daemon::load_configuration(options);
    for (const std::string& note : config.notes) std::fprintf(stderr, "rpemd: note: %s\n", note.c_str());
    if (check_only) return check_configuration(config);
    return daemon::Daemon(options, std::move(config)).run();
  } catch (const io::InputError& e) {
    std::fprintf(stderr, "rpemd: configuration error: %s\n", e.what());
    return io::kExitConfig;
  }
}
