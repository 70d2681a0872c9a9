#include "option_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

#include "rpem/io/errors.hpp"

namespace rpem::tools {
namespace {

std::vector<const CLI::Option*>& written_options() {
  static std::vector<const CLI::Option*> options;  // filled while the subcommands register, before parsing
  return options;
}

/// The written options that may name a folder (Written::kFileOrFolder).
std::vector<const CLI::Option*>& maybe_folders() {
  static std::vector<const CLI::Option*> options;
  return options;
}

/// The same file: both exist and are one inode (links included), or their absolute normal forms are equal.
bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec) && !ec;
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec) && !ec;
}

/// The options of `app` and of its selected subcommands, selected ones only.
void collect_given(const CLI::App& app, std::vector<const CLI::Option*>& given) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() > 0) given.push_back(opt);
  }
  for (const CLI::App* sub : app.get_subcommands()) collect_given(*sub, given);
}

}  // namespace

CLI::Option* writes_file(CLI::Option* option, Written kind) {
  written_options().push_back(option);
  if (kind == Written::kFileOrFolder) maybe_folders().push_back(option);
  return option;
}

void require_output_directories() {
  for (const CLI::Option* out : written_options()) {
    if (out->count() == 0) continue;
    if (std::find(maybe_folders().begin(), maybe_folders().end(), out) != maybe_folders().end()) continue;
    io::require_output_directory(out->as<std::string>());
  }
}

void require_finite_numbers(CLI::App& app) {
  static const CLI::Validator finite(
      [](const std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end != text.c_str() && !std::isfinite(value)) return "'" + text + "' is not a finite number";
        return "";  // a finite number, or not a number at all (the option's own conversion says so)
      },
      "");
  for (CLI::App* sub : app.get_subcommands({})) {
    for (CLI::Option* opt : sub->get_options()) {
      if (opt->get_type_name().rfind("FLOAT", 0) == 0) opt->check(finite);
    }
    require_finite_numbers(*sub);
  }
}

std::string written_file_clash(const CLI::App& app) {
  std::vector<const CLI::Option*> given;
  collect_given(app, given);
  for (const CLI::Option* out : written_options()) {
    if (out->count() == 0) continue;
    const std::string path = out->as<std::string>();
    for (const CLI::Option* other : given) {
      // Paths are text: a number option's value ("--every 2") is never one, whatever file it happens to name.
      if (other == out || other->get_type_name().rfind("TEXT", 0) != 0) continue;
      for (const std::string& value : other->results()) {
        if (value.empty() || !same_file(path, value)) continue;
        const bool written = std::find(written_options().begin(), written_options().end(), other) != written_options().end();
        std::string clash = out->get_name();
        std::error_code ec;
        if (std::filesystem::is_directory(path, ec)) {  // rpem estimate --log FOLDER --out FOLDER
          clash += " " + path + " names the same folder as " + other->get_name();
          clash += " " + value + ": what is written there would be read with it: give another folder";
          return clash;
        }
        clash += " " + path + " names the same file as " + other->get_name();
        clash += " " + value + ": it would be overwritten ";
        clash += written ? "by both" : "before it is read";
        return clash;
      }
    }
  }
  return "";
}

}  // namespace rpem::tools
