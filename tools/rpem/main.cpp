// rpem — the offline tool of rpem-drive. `rpem --help` lists the subcommands.

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "commands.hpp"
#include "option_checks.hpp"
#include "rpem/auth/key.hpp"
#include "rpem/can/socketcan.hpp"
#include "rpem/io/errors.hpp"

int main(int argc, char** argv) {  // NOLINT(bugprone-exception-escape): only a defect escapes; terminate() shows it
  using namespace rpem::tools;
  CLI::App app{"rpem: offline tools of rpem-drive (online identification of PMSM psi_m and R_s)"};
  app.require_subcommand(1);
  std::vector<Runner> runners;
  runners.push_back(add_estimate_command(app));
  runners.push_back(add_sim_command(app));
  runners.push_back(add_reproduce_command(app));
  runners.push_back(add_figures_command(app));
  runners.push_back(add_diagnose_command(app));
  runners.push_back(add_thermal_command(app));
  runners.push_back(add_replay_command(app));
  runners.push_back(add_record_command(app));
  runners.push_back(add_listen_command(app));
  runners.push_back(add_command_command(app));
  runners.push_back(add_publish_estimate_command(app));
  runners.push_back(add_keygen_command(app));
  require_finite_numbers(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  }
  if (const std::string clash = written_file_clash(app); !clash.empty()) {
    std::fprintf(stderr, "rpem: %s\n", clash.c_str());
    return kExitUsage;
  }
  try {
    require_output_directories();
    rpem::auth::initialise();  // libsodium, once, before any key exists
    for (const Runner& run : runners) {
      const int code = run();
      if (code >= 0) return code;
    }
  } catch (const rpem::io::ConfigError& e) {
    std::fprintf(stderr, "rpem: configuration error: %s\n", e.what());
    return kExitConfig;
  } catch (const rpem::io::DriveLogError& e) {
    std::fprintf(stderr, "rpem: drive-log error: %s\n", e.what());
    return kExitDataError;
  } catch (const rpem::io::DataError& e) {
    std::fprintf(stderr, "rpem: data error: %s\n", e.what());
    return kExitDataError;
  } catch (const rpem::io::InputError& e) {
    std::fprintf(stderr, "rpem: %s\n", e.what());
    return kExitIoError;
  } catch (const rpem::can::InterfaceError& e) {
    std::fprintf(stderr, "rpem: %s\n", e.what());
    return kExitIoError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rpem: error: %s\n", e.what());
    return 1;
  }
  return kExitUsage;
}
