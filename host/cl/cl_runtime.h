// The OpenCL runtime: device choice, one context, one in-order profiling queue, the programs
// (host/cl/kernel_program.h).
// Errors carry the failing call, the CL error name and, for builds, each device's build log.
#pragma once
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <CL/opencl.hpp>

#include <seamcl/cl/kernel_program.h>
#include <seamcl/cl/program_cache.h>

namespace seamcl {

struct DeviceInfo {
  std::string platform;
  std::string name;
  std::string type;     // "GPU", "CPU", ...
  std::string version;  // OpenCL version string
  int compute_units = 0;
  size_t global_memory_bytes = 0;  // CL_DEVICE_GLOBAL_MEM_SIZE
  bool host_unified_memory = false;  // CL_DEVICE_HOST_UNIFIED_MEMORY: its buffers are host memory
};

// Every device of every platform, in platform order.
std::vector<DeviceInfo> list_devices();

// CL_SUCCESS -> "CL_SUCCESS", -5 -> "CL_OUT_OF_RESOURCES", unknown -> "CL_ERROR(<code>)".
std::string cl_error_name(int code);

// A cl::Error, cl::BuildError or other exception rewritten as one readable line (plus build logs).
std::string describe_cl_exception(const std::exception& error);

class ClRuntime {
 public:
  // device_filter: case-insensitive substring of "platform device" to pick; empty means
  // $SEAMCL_DEVICE, and when that is empty too the first GPU, else the first CPU device.
  // Throws InputError("device") naming the filter when nothing matches (bad input: exit 2 in the CLI).
  explicit ClRuntime(const std::string& device_filter = "");

  const cl::Context& context() const { return context_; }
  const cl::Device& device() const { return device_; }
  cl::CommandQueue& queue() { return queue_; }
  const DeviceInfo& info() const { return info_; }
  std::string device_description() const;  // "<device> (<platform>, <version>)"

  // Whether a program built from source is written to the program cache: where the runtime's
  // configuration says (program_cache_writes()), or always (a build ahead: seamcl warmup).
  enum class CacheWrite { AsConfigured, Always };

  // Builds program_source(program) with `options` (e.g. "-DSEAMCL_TEXELS_F32=1") once per
  // distinct program and options (plus $SEAMCL_EXTRA_BUILD_OPTIONS, for experiments); later calls
  // return the same program. Thread-safe: calls for different variants build at once where the
  // driver compiles in parallel (PoCL 3.1 does not: one compiler lock per process), and a call
  // for a variant being built waits for that build. With a program cache, the binary is loaded
  // from it when a whole entry for this device, driver, source and options is there, else built
  // from source and, as `write` says, stored (host/cl/program_cache.h).
  const cl::Program& program(KernelProgram program, const std::string& options = "",
                             CacheWrite write = CacheWrite::AsConfigured);
  double program_build_ms() const;  // wall time of every build and cache load so far

  // Where program binaries are kept: default_cache_dir()/programs, nowhere with
  // $SEAMCL_PROGRAM_CACHE "0" or "off"; empty: none. Binaries there are always read. Builds are
  // written there by default on drivers other than PoCL; on PoCL only with $SEAMCL_PROGRAM_CACHE
  // "1" or "on", or when the caller asks (CacheWrite::Always), because asking PoCL for a binary
  // compiles every kernel of the program (docs/performance.md). set_program_cache_dir reads and
  // writes there. Programs already built stay.
  void set_program_cache_dir(const std::string& directory);
  std::string program_cache_dir() const;
  bool program_cache_writes() const;
  // The cache key of `program` built with `options` on this device.
  ProgramCacheKey program_cache_key(KernelProgram program, const std::string& options) const;

  struct ProgramStats {
    int built = 0;           // from source
    int loaded = 0;          // from the program cache
    int cache_rejected = 0;  // entries there that failed to load (corrupt, truncated): built instead
    int stored = 0;          // entries written
    double ms = 0;           // as program_build_ms()
  };
  ProgramStats program_stats() const;

 private:
  struct ProgramSlot {
    std::mutex mutex;  // held while this variant is built or loaded
    std::unique_ptr<cl::Program> program;
  };
  std::string full_build_options(const std::string& options) const;

  cl::Context context_;
  cl::Device device_;
  cl::CommandQueue queue_;
  DeviceInfo info_;
  std::string driver_version_;
  std::map<std::pair<KernelProgram, std::string>, std::unique_ptr<ProgramSlot>> programs_;
  std::unique_ptr<ProgramCache> program_cache_;
  bool program_cache_writes_ = false;
  ProgramStats stats_;
  mutable std::mutex programs_mutex_;  // programs_, program_cache_, program_cache_writes_ and stats_
};

// Milliseconds between an event's start and end (from CL_QUEUE_PROFILING_ENABLE).
double event_milliseconds(const cl::Event& event);

}  // namespace seamcl
