// The command line's flags of a job, made from its option table (host/options/option_table.h):
// one flag per option, named --key with '-' for '_', its --help line (choices or bounds, default)
// from the table, its text turned into the JSON value the job's parser reads. A flag left out is
// left out of the request, so the job's own default applies, as it does over HTTP.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/options/option_table.h>

namespace seamcl::cli {

class OptionFlags {
 public:
  // Adds a flag for every option of `table` but those in `skip` (a front end's own, or ones it
  // does not offer) to `command`.
  OptionFlags(CLI::App* command, const OptionTable& table, const std::vector<std::string>& skip = {});

  // The flags given, as the job's JSON request; InputError naming the option for text that is not
  // of its type ("--msaa four").
  nlohmann::json request() const;
  // Whether the option of `key` was given.
  bool given(const std::string& key) const;

 private:
  struct Flag {
    const OptionSpec* spec;
    std::unique_ptr<std::optional<std::string>> text;  // valued options
    std::unique_ptr<bool> set;                         // boolean ones
    std::unique_ptr<std::vector<std::string>> items;   // lists: repeatable, each a comma list
  };
  std::vector<Flag> flags_;
};

// Ctrl-C while a job runs: the first asks the job to stop at its next unit of work (it ends with
// "cancelled", exit code 130); a second ends the process at once. The returned hook is the
// job's ShouldStop.
std::function<bool()> stop_on_interrupt();

}  // namespace seamcl::cli
