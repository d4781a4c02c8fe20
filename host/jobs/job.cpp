#include <seamcl/jobs/job.h>

#include <algorithm>

#include <seamcl/core/input_error.h>

namespace seamcl {

nlohmann::json JobPlan::to_json() const {
  // The fields a share can be named after (MemoryShares' callers use these).
  auto shares_json = [](const MemoryShares& shares) {
    nlohmann::json out = nlohmann::json::object();
    for (const char* field : {"scene", "size", "msaa", "frames"})
      if (shares.share(field) > 0) out[field] = shares.share(field);
    return out;
  };
  return {{"what", what},
          {"device_bytes", device.total()},
          {"host_bytes", host.total()},
          {"device_shares", shares_json(device)},
          {"host_shares", shares_json(host)}};
}

void refuse_unknown_keys(const nlohmann::json& request, const std::vector<std::string>& known) {
  for (const auto& [key, value] : request.items())
    if (std::find(known.begin(), known.end(), key) == known.end()) throw InputError(key, "unknown option");
}

}  // namespace seamcl
