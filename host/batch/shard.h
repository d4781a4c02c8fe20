// A share of a batch: `--shard K/N` names part K (1-based) of N, and a part of an orbit is one
// contiguous block of its frames, so each part can carry the frame before its block (for the
// temporal measure, which compares consecutive frames) and the parts merge back in frame order
// (host/batch/bench_merge.h).
#pragma once
#include <string>

namespace seamcl {

struct Shard {
  int index = 1;  // K, 1..count
  int count = 1;  // N; 1/1 is the whole batch
  bool whole() const { return count == 1; }
};

// "K/N" with 1 <= K <= N <= kMaxShards, digits only; anything else is an InputError naming `field`.
inline constexpr int kMaxShards = 100000;
Shard parse_shard(const std::string& text, const std::string& field = "shard");
std::string to_string(const Shard& shard);

// Frames [first, end) of part K of N of an orbit of `frames` frames: first = floor((K-1) F / N),
// end = floor(K F / N), so the blocks tile 0..F-1 in order and differ in length by at most one.
// N above F would leave a part without frames: an InputError naming `field`.
struct FrameRange {
  int first = 0;
  int end = 0;
  int size() const { return end - first; }
};
FrameRange shard_frames(const Shard& shard, int frames, const std::string& field = "shard");

}  // namespace seamcl
