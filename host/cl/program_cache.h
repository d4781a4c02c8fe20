// Built OpenCL programs kept on disk (CL_PROGRAM_BINARIES), so that a process builds each program
// variant once per machine rather than once per start: building a variant from source costs far
// more than loading its binary, and a start on an empty cache builds every variant
// (docs/benchmarks.md#compare-and-start has the figures and the commands that measured them).
//
// An entry is keyed by everything the binary depends on: the device's name, its platform, its
// OpenCL and driver versions (CL_DRIVER_VERSION), a hash of the kernel source and the full build
// options. The key text is stored in the entry and compared on load, so a hash collision reads
// as a miss. An entry is written to a temporary file and renamed into place (a reader never sees
// half a file); on load a wrong magic, key, length or checksum (a truncated or corrupt file)
// is a miss, and the caller builds from source and writes the entry again. The checksum finds a
// damaged file, not a made one: the cache is trusted as the driver's own is (PoCL's holds the
// shared objects it runs), and a payload changed with its checksum mended can stop the process
// inside the driver (PoCL 3.1 asserts on some) instead of failing its load.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace seamcl {

// $SEAMCL_CACHE_DIR, else $HOME/.cache/seamcl, else <temp>/seamcl-cache: references and program
// binaries (under programs/) live there.
std::string default_cache_dir();

// FNV-1a, 64 bit, as 16 hex digits: stable across runs and compilers (std::hash is not).
std::string fnv64_hex(const void* data, size_t bytes);
inline std::string fnv64_hex(const std::string& text) { return fnv64_hex(text.data(), text.size()); }

// What a program binary depends on; key() is the canonical text that names an entry.
struct ProgramCacheKey {
  std::string platform;
  std::string device;
  std::string device_version;  // CL_DEVICE_VERSION
  std::string driver_version;  // CL_DRIVER_VERSION
  std::string source_hash;     // fnv64_hex of the program's text (program_source)
  std::string build_options;   // exactly as passed to clBuildProgram
  std::string key() const;
  std::string file_name() const;  // "program-<fnv64 of key()>.bin"
};

class ProgramCache {
 public:
  // `directory` is made on the first store; empty: a cache that never hits and never stores.
  explicit ProgramCache(std::string directory);
  const std::string& directory() const { return directory_; }
  bool enabled() const { return !directory_.empty(); }
  std::string path(const ProgramCacheKey& key) const;

  // The stored binary, or nullopt when there is none or it is not a whole, matching entry.
  std::optional<std::vector<unsigned char>> load(const ProgramCacheKey& key) const;
  // Writes through a temporary file and rename; false (and nothing left behind) when it cannot.
  // Then trims the directory to max_bytes: every source change makes new entries, so the oldest
  // (by last use: a load touches its entry) go first.
  bool store(const ProgramCacheKey& key, const std::vector<unsigned char>& binary) const;
  // Removes the least recently used entries beyond `bytes` and temporary files of writers that
  // died (older than an hour); returns the entries removed. Errors are ignored (an optimisation).
  size_t trim(std::uintmax_t bytes) const;
  static constexpr std::uintmax_t kMaxBytes = std::uintmax_t{512} << 20;

 private:
  std::string directory_;
};

}  // namespace seamcl
