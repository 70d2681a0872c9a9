// rpemd — online identification of the PMSM's magnet flux linkage and stator resistance.
//
//   rpemd [--config FILE.yaml] [--can IFACE] [--check-config] [--latency-histogram FILE]
//
// Without arguments it runs the paper's machine on the built-in simulated drive. The threads, what each
// owns and the queues between them: daemon.hpp and docs/rpemd.md.

#include <CLI/CLI.hpp>
#include <cstdio>

#include "rpem/daemon/daemon.hpp"
#include "rpem/io/exit_codes.hpp"

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
  CLI11_PARSE(app, argc, argv);
  try {
    daemon::DaemonConfig config = daemon::load_configuration(options);
    if (check_only) {
      std::printf("rpemd: %s is valid\n", config.source_file.c_str());
      return io::kExitOk;
    }
    return daemon::Daemon(options, std::move(config)).run();
  } catch (const io::InputError& e) {
    std::fprintf(stderr, "rpemd: configuration error: %s\n", e.what());
    return io::kExitConfig;
  }
}
