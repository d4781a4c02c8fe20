#include <seamcl/cl/program_cache.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <thread>
#include <unistd.h>

namespace seamcl {
namespace {

namespace fs = std::filesystem;

// An entry: magic, key length, key, binary length, binary, FNV-64 of the binary. Lengths are
// little-endian u64.
constexpr char kCacheFileMagic[8] = {'S', 'C', 'L', 'P', 'R', 'O', 'G', '1'};
// A binary larger than this is not one of ours (PoCL's are a few MB): refused rather than read.
constexpr uint64_t kMaxBinaryBytes = uint64_t{1} << 30;
constexpr uint64_t kMaxKeyBytes = uint64_t{1} << 16;

uint64_t fnv64(const void* data, size_t n) {
  uint64_t h = 0xcbf29ce484222325ULL;
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

void put_u64(std::string& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

bool get_u64(const std::vector<unsigned char>& in, size_t& at, uint64_t& v) {
  if (at > in.size() || in.size() - at < 8) return false;
  v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t{in[at + static_cast<size_t>(i)]} << (8 * i);
  at += 8;
  return true;
}

}  // namespace

std::string default_cache_dir() {
  if (const char* dir = std::getenv("SEAMCL_CACHE_DIR"); dir && *dir) return dir;
  if (const char* home = std::getenv("HOME"); home && *home) return (fs::path(home) / ".cache" / "seamcl").string();
  return (fs::temp_directory_path() / "seamcl-cache").string();
}

std::string fnv64_hex(const void* data, size_t bytes) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(fnv64(data, bytes)));
  return text;
}

std::string ProgramCacheKey::key() const {
  return "seamcl program binary 1\nplatform: " + platform + "\ndevice: " + device + "\ndevice version: " +
         device_version + "\ndriver version: " + driver_version + "\nsource: " + source_hash +
         "\nbuild options: " + build_options + "\n";
}

std::string ProgramCacheKey::file_name() const { return "program-" + fnv64_hex(key()) + ".bin"; }

ProgramCache::ProgramCache(std::string directory) : directory_(std::move(directory)) {}

std::string ProgramCache::path(const ProgramCacheKey& key) const {
  return (fs::path(directory_) / key.file_name()).string();
}

std::optional<std::vector<unsigned char>> ProgramCache::load(const ProgramCacheKey& key) const {
  if (!enabled()) return std::nullopt;
  std::error_code ec;
  const std::string file = path(key);
  const std::uintmax_t size = fs::file_size(file, ec);
  if (ec || size > kMaxBinaryBytes + kMaxKeyBytes + 64) return std::nullopt;
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::vector<unsigned char> bytes(static_cast<size_t>(size));
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()))) return std::nullopt;
  if (bytes.size() < sizeof kCacheFileMagic || std::memcmp(bytes.data(), kCacheFileMagic, sizeof kCacheFileMagic) != 0) return std::nullopt;
  size_t at = sizeof kCacheFileMagic;
  uint64_t key_bytes = 0, binary_bytes = 0, checksum = 0;
  const std::string expected = key.key();
  if (!get_u64(bytes, at, key_bytes) || key_bytes != expected.size() || bytes.size() - at < key_bytes) return std::nullopt;
  if (std::memcmp(bytes.data() + at, expected.data(), expected.size()) != 0) return std::nullopt;
  at += static_cast<size_t>(key_bytes);
  if (!get_u64(bytes, at, binary_bytes) || binary_bytes == 0 || binary_bytes > kMaxBinaryBytes) return std::nullopt;
  // Exactly the binary and its checksum must follow: a truncated or extended file is not ours.
  if (bytes.size() - at != binary_bytes + 8) return std::nullopt;
  const size_t binary_at = at;
  at += static_cast<size_t>(binary_bytes);
  if (!get_u64(bytes, at, checksum) || checksum != fnv64(bytes.data() + binary_at, static_cast<size_t>(binary_bytes))) {
    return std::nullopt;
  }
  fs::last_write_time(file, fs::file_time_type::clock::now(), ec);  // its last use, for trim()
  return std::vector<unsigned char>(bytes.begin() + static_cast<std::ptrdiff_t>(binary_at),
                                    bytes.begin() + static_cast<std::ptrdiff_t>(binary_at + binary_bytes));
}

bool ProgramCache::store(const ProgramCacheKey& key, const std::vector<unsigned char>& binary) const {
  if (!enabled() || binary.empty() || binary.size() > kMaxBinaryBytes) return false;
  std::error_code ec;
  fs::create_directories(directory_, ec);
  const std::string file = path(key);
  // Unique per process and thread: two writers of one entry never share a temporary file, and
  // the last rename wins with a whole entry either way.
  const std::string temp = file + ".tmp" + std::to_string(::getpid()) + "-" +
                           std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id()));
  std::string header(kCacheFileMagic, sizeof kCacheFileMagic);
  const std::string text = key.key();
  put_u64(header, text.size());
  header += text;
  put_u64(header, binary.size());
  std::string trailer;
  put_u64(trailer, fnv64(binary.data(), binary.size()));
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(reinterpret_cast<const char*>(binary.data()), static_cast<std::streamsize>(binary.size()));
    out.write(trailer.data(), static_cast<std::streamsize>(trailer.size()));
    out.close();
    if (!out) {
      fs::remove(temp, ec);
      return false;
    }
  }
  fs::rename(temp, file, ec);
  if (ec) {
    fs::remove(temp, ec);
    return false;
  }
  trim(kMaxBytes);
  return true;
}

size_t ProgramCache::trim(std::uintmax_t bytes) const {
  struct Entry {
    fs::path path;
    std::uintmax_t bytes;
    fs::file_time_type used;
  };
  std::vector<Entry> entries;
  std::error_code ec;
  const fs::file_time_type now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(directory_, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code entry_ec;
    const std::string name = it->path().filename().string();
    if (name.rfind("program-", 0) != 0 || !it->is_regular_file(entry_ec)) continue;
    const fs::file_time_type used = it->last_write_time(entry_ec);
    if (entry_ec) continue;
    if (name.find(".tmp") != std::string::npos) {
      if (now - used > std::chrono::hours(1)) fs::remove(it->path(), entry_ec);
      continue;
    }
    const std::uintmax_t size = it->file_size(entry_ec);
    if (!entry_ec) entries.push_back({it->path(), size, used});
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.used != b.used ? a.used > b.used : a.path < b.path;
  });
  std::uintmax_t kept = 0;
  size_t removed = 0;
  for (const Entry& e : entries) {
    if (kept + e.bytes <= bytes) {
      kept += e.bytes;
      continue;
    }
    kept = bytes;  // once one does not fit, no older one is kept either
    std::error_code remove_ec;
    if (fs::remove(e.path, remove_ec)) ++removed;
  }
  return removed;
}

}  // namespace seamcl
