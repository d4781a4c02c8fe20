#include <seamcl/jobs/job_progress.h>
#include <seamcl/core/elapsed.h>

#include <algorithm>

namespace seamcl {

void JobProgressBoard::start(const std::string& id, JobControl& control) {
  {
    std::lock_guard lock(mutex_);
    if (!jobs_.count(id) && jobs_.size() >= max_jobs_ && !jobs_.empty()) {
      const auto first = std::min_element(jobs_.begin(), jobs_.end(),
                                          [](const auto& a, const auto& b) { return a.second.order < b.second.order; });
      jobs_.erase(first);
    }
    Entry& entry = jobs_[id];
    entry = Entry{};
    entry.started = Clock::now();
    entry.order = next_order_++;
  }
  // Whatever the front end had for progress still gets every line.
  auto progress = control.progress;
  control.progress = [this, id, progress](const std::string& line) {
    if (progress) progress(line);
    std::lock_guard lock(mutex_);
    if (const auto found = jobs_.find(id); found != jobs_.end()) found->second.line = line;
  };
  auto steps = control.steps;
  control.steps = [this, id, steps](int done, int total) {
    if (steps) steps(done, total);
    std::lock_guard lock(mutex_);
    if (const auto found = jobs_.find(id); found != jobs_.end()) {
      found->second.done = done;
      found->second.total = total;
    }
  };
}

void JobProgressBoard::finish(const std::string& id) {
  std::lock_guard lock(mutex_);
  if (const auto found = jobs_.find(id); found != jobs_.end() && found->second.finished_ms < 0)
    found->second.finished_ms = ms_since(found->second.started);
}

std::optional<nlohmann::json> JobProgressBoard::get(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const auto found = jobs_.find(id);
  if (found == jobs_.end()) return std::nullopt;
  const Entry& e = found->second;
  const bool running = e.finished_ms < 0;
  const double elapsed = running ? ms_since(e.started) : e.finished_ms;
  return nlohmann::json{{"id", id}, {"running", running}, {"line", e.line}, {"done", e.done}, {"total", e.total},
                        {"elapsed_ms", elapsed}};
}

}  // namespace seamcl
