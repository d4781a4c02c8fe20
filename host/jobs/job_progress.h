// What the jobs a service runs have reported so far, by an id their clients chose: for a client
// that polls it while its request runs (the request itself answers only at the end). Each id
// holds the job's last progress line (JobControl::progress), its steps (JobControl::steps: done of
// total), the milliseconds since it started and whether it still runs. Bounded: past max_jobs
// ids, the one started first goes.
#pragma once
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/jobs/job.h>

namespace seamcl {

class JobProgressBoard {
 public:
  explicit JobProgressBoard(size_t max_jobs = 256) : max_jobs_(max_jobs) {}

  // Starts recording `id` (again, if it was used before) and points control's progress and
  // steps at it; finish() when the job has ended, however it ended.
  void start(const std::string& id, JobControl& control);
  void finish(const std::string& id);
  // {"id", "running", "line", "done", "total", "elapsed_ms"}; nullopt for an id not recorded.
  std::optional<nlohmann::json> get(const std::string& id) const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Entry {
    std::string line;
    int done = 0, total = 0;
    Clock::time_point started;
    double finished_ms = -1;  // < 0 while it runs
    uint64_t order = 0;
  };
  size_t max_jobs_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry> jobs_;
  uint64_t next_order_ = 0;
};

}  // namespace seamcl
