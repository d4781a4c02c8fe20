// Subcommands that live in their own file register here: each adds its CLI11 subcommand to the
// app and returns it with the function main() runs when that subcommand was given. Errors follow main's rules:
// throw InputError for bad input (exit 2), anything else for other failures (exit 1).
#pragma once
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>

namespace seamcl::cli {

// "a, b, c": the names an option accepts, for --help and error messages (", " between them);
// "a,b,c" with separator "," is a default value the option itself parses back.
inline std::string join_names(const std::vector<std::string>& names, const std::string& separator = ", ") {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : separator) + name;
  return out;
}

// Where output goes, checked before any work so that a bad path fails at once and names its option:
// the directory of an output file must exist (InputError(field) otherwise)...
inline void check_output_parent(const std::string& path, const std::string& field) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code error;
  if (!parent.empty() && !std::filesystem::is_directory(parent, error))
    throw InputError(field, "the directory '" + parent.string() + "' of '" + path + "' does not exist");
}

// ... and an output directory is made (with its parents) or is refused (InputError(field)).
inline void make_output_directory(const std::string& dir, const std::string& field) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir))
    throw InputError(field, "cannot make the directory '" + dir + "'" + (error ? ": " + error.message() : ""));
}

// An option given an empty value (a shell variable that expanded to nothing, say) is refused rather
// than read as the option left out, which would quietly fall back to the default: write nothing
// where a file was meant, or use a cache, device or file other than the one meant. Returns the
// value given, "" when the option was left out; `without_it` says what leaving it out does.
inline std::string given_value(const std::optional<std::string>& given, const std::string& field,
                               const std::string& without_it) {
  if (given && given->empty()) throw InputError(field, "must not be empty (" + without_it + ")");
  return given.value_or("");
}

// The OpenCL runtime a command runs on, never destroyed: the process's exit frees what it holds,
// so a command's end does not wait for PoCL to release the programs it built or loaded (destroying
// their LLVM modules took 20-30 ms at the end of every compare, docs/performance.md). A process runs
// one command: a second call is a bug (std::logic_error). Held by a static pointer: still reachable
// to a leak checker. A --device that matches none throws InputError, before any work.
inline ClRuntime& command_runtime(const std::string& device) {
  static ClRuntime* runtime = nullptr;
  if (runtime != nullptr) throw std::logic_error("command_runtime: a command's runtime is made once");
  runtime = new ClRuntime(device);
  return *runtime;
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
Command add_ptx_command(CLI::App& app);      // cli/ptx_command.cpp
Command add_warmup_command(CLI::App& app);   // cli/warmup_command.cpp

}  // namespace seamcl::cli
