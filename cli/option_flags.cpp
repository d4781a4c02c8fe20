#include "option_flags.h"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdlib>

namespace seamcl::cli {
namespace {

// What --help shows after a valued flag.
std::string type_name(const OptionSpec& spec) {
  switch (spec.type) {
    case OptionType::Integer: return "INT";
    case OptionType::Number: return "FLOAT";
    case OptionType::Size: return "WxH";
    case OptionType::Choice: return "NAME";
    case OptionType::List: return "LIST";
    default: return "TEXT";
  }
}

}  // namespace

OptionFlags::OptionFlags(CLI::App* command, const OptionTable& table, const std::vector<std::string>& skip) {
  for (const OptionSpec& spec : table) {
    if (std::find(skip.begin(), skip.end(), spec.key) != skip.end()) continue;
    Flag flag{&spec, nullptr, nullptr, nullptr};
    if (spec.type == OptionType::List) {
      flag.items = std::make_unique<std::vector<std::string>>();
      command->add_option(option_flag(spec), *flag.items, option_help_line(spec) + " (repeatable)")->type_name("LIST");
    } else if (spec.type == OptionType::Boolean) {
      flag.set = std::make_unique<bool>(false);
      command->add_flag(option_flag(spec), *flag.set, option_help_line(spec));
    } else {
      flag.text = std::make_unique<std::optional<std::string>>();
      command->add_option(option_flag(spec), *flag.text, option_help_line(spec))->type_name(type_name(spec));
    }
    flags_.push_back(std::move(flag));
  }
}

nlohmann::json OptionFlags::request() const {
  nlohmann::json request = nlohmann::json::object();
  for (const Flag& flag : flags_) {
    if (flag.set && *flag.set) request[flag.spec->key] = true;
    if (flag.text && flag.text->has_value()) request[flag.spec->key] = option_from_text(*flag.spec, **flag.text);
    if (flag.items && !flag.items->empty()) request[flag.spec->key] = joined_names(*flag.items, ",");
  }
  return request;
}

bool OptionFlags::given(const std::string& key) const {
  for (const Flag& flag : flags_) {
    if (flag.spec->key != key) continue;
    if (flag.set) return *flag.set;
    return flag.text ? flag.text->has_value() : !flag.items->empty();
  }
  return false;
}

namespace {
std::atomic<int> interrupts{0};
extern "C" void count_interrupt(int) {
  if (interrupts.fetch_add(1) >= 1) std::_Exit(130);
}
}  // namespace

std::function<bool()> stop_on_interrupt() {
  std::signal(SIGINT, count_interrupt);
  return [] { return interrupts.load() > 0; };
}

}  // namespace seamcl::cli
