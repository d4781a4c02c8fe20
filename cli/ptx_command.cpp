// seamcl ptx: a .ptx file as seamcl reads it and filters it. `info` and `dump` show what the
// reader decoded (host/ptexfilter/ptex_inspect.h); `lookup` runs Ptex's own filters on the device
// (host/ptexfilter/ptex_lookup.h), one lookup from the flags or a JSON array of them from a file.
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/regular_file.h>
#include <seamcl/ptexfilter/ptex_inspect.h>
#include <seamcl/ptexfilter/ptex_lookup.h>
#include "commands.h"
#include "option_flags.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

// A query file of a few million lookups is tens of MiB; anything far larger is not one.
constexpr uint64_t kMaxQueryFileBytes = uint64_t(256) << 20;

struct PtxArgs {
  std::string file;
  std::unique_ptr<OptionFlags> options;
  std::optional<std::string> queries;
  bool scalar = false;
};

std::vector<PtexLookup> read_queries(const std::string& path) {
  RegularFile file(path);
  if (file.refusal() != RegularFile::Refusal::None) throw InputError("queries", path + ": " + file.refusal_text());
  if (file.size() > kMaxQueryFileBytes)
    throw InputError("queries", path + ": more than the " + std::to_string(kMaxQueryFileBytes >> 20) + " MiB a query file may have");
  std::string text;
  if (!file.read_all(text, kMaxQueryFileBytes)) throw InputError("queries", path + ": " + file.refusal_text());
  return parse_ptex_lookups_from_text(text, path);
}

int run_info(const PtxArgs& args) {
  std::cout << ptex_info_json(read_ptex_stored(args.file)).dump(2) << "\n";
  return 0;
}

int run_dump(const PtxArgs& args) {
  const json request = args.options->request();
  std::cout << ptex_dump_json(read_ptex_stored(args.file), request).dump() << "\n";
  return 0;
}

int run_lookup(const PtxArgs& args, const GlobalOptions& global) {
  const std::string queries_path = given_value(args.queries, "queries", "leave out --queries for one lookup from the flags");
  const json request = args.options->request();
  std::vector<PtexLookup> lookups;
  if (!queries_path.empty()) {
    if (!request.empty())
      throw InputError("queries", "give either --queries or one lookup's flags (--" + request.begin().key() + " was given too)");
    lookups = read_queries(queries_path);
  } else {
    lookups.push_back(parse_ptex_lookup(request));
  }
  const PtexFilterFile texture(args.file);
  for (size_t i = 0; i < lookups.size(); ++i)
    texture.check(lookups[i], queries_path.empty() ? "" : "queries[" + std::to_string(i) + "].");
  std::vector<std::vector<float>> values;
  if (args.scalar) {
    values = texture.lookup_scalar(lookups);
  } else {
    ClRuntime& runtime = cli::command_runtime(global.device);
    values = texture.lookup_device(runtime, lookups);
  }
  if (queries_path.empty()) {
    std::cout << json{{"value", values.front()}}.dump() << "\n";
  } else {
    std::cout << json{{"values", values}}.dump() << "\n";
  }
  return 0;
}

}  // namespace

Command add_ptx_command(CLI::App& app) {
  CLI::App* command = app.add_subcommand("ptx", "Inspect a .ptx file and filter it with Ptex's own filters");
  command->require_subcommand(1);
  auto info_args = std::make_shared<PtxArgs>();
  CLI::App* info = command->add_subcommand("info", "Print the header, metadata and every face's resolution, flags, adjacency and average as JSON");
  info->add_option("file", info_args->file, "The .ptx file")->required();
  auto dump_args = std::make_shared<PtxArgs>();
  CLI::App* dump = command->add_subcommand("dump", "Print one face's texels at one level as JSON (texels[v][u], channels)");
  dump->add_option("file", dump_args->file, "The .ptx file")->required();
  dump_args->options = std::make_unique<OptionFlags>(dump, ptex_dump_option_table());
  auto lookup_args = std::make_shared<PtxArgs>();
  CLI::App* lookup = command->add_subcommand("lookup", "Filter with Ptex's filters on the device: {\"value\": [...]} or, with --queries, {\"values\": [[...], ...]}");
  lookup->add_option("file", lookup_args->file, "The .ptx file")->required();
  lookup_args->options = std::make_unique<OptionFlags>(lookup, ptex_lookup_option_table());
  lookup->add_option("--queries", lookup_args->queries,
                     "A JSON file: an array of lookups, objects of the keys above (as the golden files' filtered entries)");
  lookup->add_flag("--scalar", lookup_args->scalar, "Compute on the host with the kernel's scalar twin instead of the device");
  return {command, [=](const GlobalOptions& global) {
            if (info->parsed()) return run_info(*info_args);
            if (dump->parsed()) return run_dump(*dump_args);
            return run_lookup(*lookup_args, global);
          }};
}

}  // namespace seamcl::cli
