// Subcommands that live in their own file register here: each adds its CLI11 subcommand to the
// app and returns it with the function main() runs when that subcommand was given. Errors follow main's rules:
// throw InputError for bad input (exit 2), anything else for other failures (exit 1).
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace seamcl::cli {

// "a, b, c": the names an option accepts, for --help and error messages (", " between them);
// "a,b,c" with separator "," is a default value the option itself parses back.
inline std::string join_names(const std::vector<std::string>& names, const std::string& separator = ", ") {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : separator) + name;
  return out;
}

struct GlobalOptions {
  std::string device;  // --device, before the subcommand
};

struct Command {
  CLI::App* subcommand = nullptr;
  std::function<int(const GlobalOptions&)> run;
};

// One line per command file: `Command add_<name>_command(CLI::App& app);`, and one call in main.
Command add_serve_command(CLI::App& app);    // cli/serve_command.cpp
Command add_compare_command(CLI::App& app);  // cli/compare_command.cpp
Command add_bench_command(CLI::App& app);    // cli/bench_command.cpp
Command add_merge_command(CLI::App& app);    // cli/merge_command.cpp
Command add_cube_command(CLI::App& app);     // cli/cube_command.cpp
Command add_displacement_command(CLI::App& app);  // cli/displacement_command.cpp

}  // namespace seamcl::cli
