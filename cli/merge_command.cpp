// seamcl merge: the parts of a sharded bench (`seamcl bench --shard K/N --json`, one file each)
// combined into the JSON one unsharded run gives (host/batch/bench_merge.h says which statistics
// merge exactly, which are recomputed from the merged samples and which are not exact).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/batch/bench_merge.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/json_document.h>
#include <seamcl/core/regular_file.h>
#include "commands.h"

namespace seamcl::cli {
namespace {

namespace fs = std::filesystem;

// A part of 1000 frames x 40 entries is a few MiB; anything far larger is not a part.
constexpr std::uintmax_t kMaxPartBytes = 256ull << 20;

struct MergeArgs {
  std::vector<std::string> parts;
  std::optional<std::string> output;
};

BenchPart read_part(const std::string& path) {
  if (path.empty()) throw InputError("parts", "a part's path is empty");
  RegularFile file(path);  // opened and checked as one file: a FIFO swapped in cannot block the read
  if (file.refusal() != RegularFile::Refusal::None) throw InputError("parts", path + ": " + file.refusal_text());
  const auto too_large = [&] {
    return InputError("parts", path + ": more than the " + std::to_string(kMaxPartBytes >> 20) + " MiB a part may have");
  };
  if (file.size() > kMaxPartBytes) throw too_large();  // before any of it is read
  std::string text;
  if (!file.read_all(text, kMaxPartBytes)) throw InputError("parts", path + ": " + file.refusal_text());
  if (text.size() > kMaxPartBytes) throw too_large();  // grown since it was opened
  try {
    return BenchPart{path, parse_json_document(text)};
  } catch (const nlohmann::json::exception& error) {
    throw InputError("parts", path + ": not valid JSON: " + error.what());
  } catch (const std::invalid_argument& error) {  // parse_json_document's refusals
    throw InputError("parts", path + ": not valid JSON: " + error.what());
  }
}

// Written next to the target and renamed over it, so a reader never sees half a file.
void write_atomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".part-" + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError("output", path + ": cannot be written");
    out << text;
    if (!out.flush()) throw std::runtime_error("writing " + temporary + " failed");
  }
  fs::rename(temporary, path);
}

int run_merge(const MergeArgs& args) {
  const std::string output = given_value(args.output, "output", "give - or leave out -o for stdout");
  if (!output.empty() && output != "-") check_output_parent(output, "output");
  std::vector<BenchPart> parts;
  for (const std::string& path : args.parts) parts.push_back(read_part(path));
  const nlohmann::json merged = merge_bench_parts(parts);
  const std::string text = merged.dump(2) + "\n";
  if (output.empty() || output == "-") {
    std::cout << text;
  } else {
    write_atomically(output, text);
  }
  return 0;
}

}  // namespace

Command add_merge_command(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Combine the parts of a sharded bench (bench --shard K/N --json, one file each) into one run's JSON");
  cmd->add_option("parts", args->parts, "The parts' JSON files, in any order; all N parts of one batch")->required();
  cmd->add_option("-o,--output", args->output, "Write the merged JSON here (- or none: stdout)");
  return Command{cmd, [args](const GlobalOptions&) { return run_merge(*args); }};
}

}  // namespace seamcl::cli
