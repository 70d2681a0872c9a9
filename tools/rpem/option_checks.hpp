#pragma once
// What every subcommand's options are checked for, beyond each option's own check: numbers are finite, a file a
// command writes is none of the files it reads or writes otherwise, and its directory exists (main.cpp runs them for
// every subcommand).

#include <CLI/CLI.hpp>
#include <string>

namespace rpem::tools {

/// What a written option names: a file, or a file or a folder (as the command's input is one or the other).
enum class Written { kFile, kFileOrFolder };

/// Marks `option` as a file the command writes (returns it, to chain).
CLI::Option* writes_file(CLI::Option* option, Written kind = Written::kFile);

/// Adds a check to every number option of every subcommand: CLI11 reads "nan" and "inf" as numbers, and a NaN
/// passes any range check (each comparison is false), so without it `--max-p nan` would run with it.
void require_finite_numbers(CLI::App& app);

/// After parsing: "" if no file the selected command writes names a file it also reads or writes through another
/// option; else why (an input would be truncated before it is read: `--out run.csv --log run.csv`).
[[nodiscard]] std::string written_file_clash(const CLI::App& app);

/// After parsing: throws io::InputError where a file the selected command writes would go in a directory that does
/// not exist — before the command's work, which may take minutes (a folder output creates its own parents, so an
/// option that may name one is left to its command).
void require_output_directories();

}  // namespace rpem::tools
