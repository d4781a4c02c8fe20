#include <seamcl/jobs/job.h>

#include <algorithm>
#include <cstdio>

#include <seamcl/core/input_error.h>
#include <seamcl/core/over_budget.h>

namespace seamcl {

nlohmann::json JobPlan::estimate_json(bool unified_device) const {
  MemoryShares separate = device;
  separate.add(host);
  // A plan without a unified figure counts device and host apart on any device (conservative).
  const bool has_unified = unified.total() > 0;
  return seamcl::estimate_json(device, host, unified_device && has_unified ? unified : separate, unified_device);
}

void refuse_beyond_machine(const JobPlan& plan, const DeviceInfo& device) {
  const size_t physical = physical_memory_bytes();
  if (device.host_unified_memory && plan.unified.total() > 0) {
    if (physical != 0 && plan.unified.total() > physical)
      throw OverBudget(plan.unified.field(), plan.what, plan.unified.total(), physical);
    return;
  }
  refuse_beyond_machine(plan.device, plan.host, device, plan.what);
}

void refuse_unknown_keys(const nlohmann::json& request, const std::vector<std::string>& known) {
  for (const auto& [key, value] : request.items())
    if (std::find(known.begin(), known.end(), key) == known.end()) throw InputError(key, "unknown option");
}

std::string step_of(size_t step, size_t total) {
  char text[48];
  std::snprintf(text, sizeof text, "[%zu/%zu] ", step, total);
  return text;
}

std::vector<std::string> strings_of(const nlohmann::json& items) {
  std::vector<std::string> out;
  for (const nlohmann::json& item : items) out.push_back(item.get<std::string>());
  return out;
}

}  // namespace seamcl
