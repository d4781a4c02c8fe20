#include <seamcl/batch/shard.h>

#include <cctype>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

// A positive decimal of at most 6 digits (no sign, no spaces), or -1.
int parse_count(const std::string& digits) {
  if (digits.empty() || digits.size() > 6) return -1;
  int value = 0;
  for (char c : digits) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
    value = value * 10 + (c - '0');
  }
  return value;
}

std::string quoted(const std::string& text) {
  std::string shown = text.size() > 40 ? text.substr(0, 40) + "..." : text;
  for (char& c : shown) {
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  }
  return "'" + shown + "'";
}

}  // namespace

Shard parse_shard(const std::string& text, const std::string& field) {
  const size_t slash = text.find('/');
  const int k = slash == std::string::npos ? -1 : parse_count(text.substr(0, slash));
  const int n = slash == std::string::npos ? -1 : parse_count(text.substr(slash + 1));
  if (k < 0 || n < 0) {
    throw InputError(field, "expected K/N, part K (1-based) of N parts, e.g. 2/4; got " + quoted(text));
  }
  if (n < 1 || n > kMaxShards) {
    throw InputError(field, "N must be in 1.." + std::to_string(kMaxShards) + ", got " + quoted(text));
  }
  if (k < 1 || k > n) throw InputError(field, "K must be in 1..N (1-based), got " + quoted(text));
  return Shard{k, n};
}

std::string to_string(const Shard& shard) { return std::to_string(shard.index) + "/" + std::to_string(shard.count); }

FrameRange shard_frames(const Shard& shard, int frames, const std::string& field) {
  if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) {
    throw InputError(field, "K must be in 1..N, got " + to_string(shard));
  }
  if (shard.count > frames) {
    throw InputError(field, std::to_string(shard.count) + " parts of " + std::to_string(frames) +
                                " frames would leave a part without frames: N must be at most the frames");
  }
  const long long f = frames;
  FrameRange range;
  range.first = static_cast<int>((shard.index - 1) * f / shard.count);
  range.end = static_cast<int>(shard.index * f / shard.count);
  return range;
}

}  // namespace seamcl
