#include <seamcl/cl/cl_runtime.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include "cl/kernel_sources.h"

namespace seamcl {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back())))) s.pop_back();
  return s;
}

std::string device_type_name(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "GPU";
  if (type & CL_DEVICE_TYPE_CPU) return "CPU";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

struct Candidate {
  cl::Platform platform;
  cl::Device device;
  DeviceInfo info;
};

std::vector<Candidate> all_devices() {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    // The ICD loader reports "no platforms" as an error; that is an empty list to us.
    if (e.err() == CL_PLATFORM_NOT_FOUND_KHR) return {};
    throw;
  }
  std::vector<Candidate> out;
  for (const cl::Platform& platform : platforms) {
    std::vector<cl::Device> devices;
    try {
      platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error& e) {
      if (e.err() == CL_DEVICE_NOT_FOUND) continue;
      throw;
    }
    for (const cl::Device& device : devices) {
      DeviceInfo info;
      info.platform = trimmed(platform.getInfo<CL_PLATFORM_NAME>());
      info.name = trimmed(device.getInfo<CL_DEVICE_NAME>());
      info.type = device_type_name(device.getInfo<CL_DEVICE_TYPE>());
      info.version = trimmed(device.getInfo<CL_DEVICE_VERSION>());
      info.compute_units = static_cast<int>(device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>());
      info.global_memory_bytes = static_cast<size_t>(device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>());
      info.host_unified_memory = device.getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>() == CL_TRUE;
      out.push_back({platform, device, info});
    }
  }
  return out;
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (const Candidate& c : all_devices()) out.push_back(c.info);
  return out;
}

std::string cl_error_name(int code) {
  switch (code) {
#define SEAMCL_CASE(name) \
  case name:              \
    return #name;
    SEAMCL_CASE(CL_SUCCESS)
    SEAMCL_CASE(CL_DEVICE_NOT_FOUND)
    SEAMCL_CASE(CL_DEVICE_NOT_AVAILABLE)
    SEAMCL_CASE(CL_COMPILER_NOT_AVAILABLE)
    SEAMCL_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    SEAMCL_CASE(CL_OUT_OF_RESOURCES)
    SEAMCL_CASE(CL_OUT_OF_HOST_MEMORY)
    SEAMCL_CASE(CL_PROFILING_INFO_NOT_AVAILABLE)
    SEAMCL_CASE(CL_MEM_COPY_OVERLAP)
    SEAMCL_CASE(CL_IMAGE_FORMAT_MISMATCH)
    SEAMCL_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    SEAMCL_CASE(CL_BUILD_PROGRAM_FAILURE)
    SEAMCL_CASE(CL_MAP_FAILURE)
    SEAMCL_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    SEAMCL_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    SEAMCL_CASE(CL_COMPILE_PROGRAM_FAILURE)
    SEAMCL_CASE(CL_LINKER_NOT_AVAILABLE)
    SEAMCL_CASE(CL_LINK_PROGRAM_FAILURE)
    SEAMCL_CASE(CL_DEVICE_PARTITION_FAILED)
    SEAMCL_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    SEAMCL_CASE(CL_INVALID_VALUE)
    SEAMCL_CASE(CL_INVALID_DEVICE_TYPE)
    SEAMCL_CASE(CL_INVALID_PLATFORM)
    SEAMCL_CASE(CL_INVALID_DEVICE)
    SEAMCL_CASE(CL_INVALID_CONTEXT)
    SEAMCL_CASE(CL_INVALID_QUEUE_PROPERTIES)
    SEAMCL_CASE(CL_INVALID_COMMAND_QUEUE)
    SEAMCL_CASE(CL_INVALID_HOST_PTR)
    SEAMCL_CASE(CL_INVALID_MEM_OBJECT)
    SEAMCL_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    SEAMCL_CASE(CL_INVALID_IMAGE_SIZE)
    SEAMCL_CASE(CL_INVALID_SAMPLER)
    SEAMCL_CASE(CL_INVALID_BINARY)
    SEAMCL_CASE(CL_INVALID_BUILD_OPTIONS)
    SEAMCL_CASE(CL_INVALID_PROGRAM)
    SEAMCL_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    SEAMCL_CASE(CL_INVALID_KERNEL_NAME)
    SEAMCL_CASE(CL_INVALID_KERNEL_DEFINITION)
    SEAMCL_CASE(CL_INVALID_KERNEL)
    SEAMCL_CASE(CL_INVALID_ARG_INDEX)
    SEAMCL_CASE(CL_INVALID_ARG_VALUE)
    SEAMCL_CASE(CL_INVALID_ARG_SIZE)
    SEAMCL_CASE(CL_INVALID_KERNEL_ARGS)
    SEAMCL_CASE(CL_INVALID_WORK_DIMENSION)
    SEAMCL_CASE(CL_INVALID_WORK_GROUP_SIZE)
    SEAMCL_CASE(CL_INVALID_WORK_ITEM_SIZE)
    SEAMCL_CASE(CL_INVALID_GLOBAL_OFFSET)
    SEAMCL_CASE(CL_INVALID_EVENT_WAIT_LIST)
    SEAMCL_CASE(CL_INVALID_EVENT)
    SEAMCL_CASE(CL_INVALID_OPERATION)
    SEAMCL_CASE(CL_INVALID_GL_OBJECT)
    SEAMCL_CASE(CL_INVALID_BUFFER_SIZE)
    SEAMCL_CASE(CL_INVALID_MIP_LEVEL)
    SEAMCL_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    SEAMCL_CASE(CL_INVALID_PROPERTY)
    SEAMCL_CASE(CL_INVALID_IMAGE_DESCRIPTOR)
    SEAMCL_CASE(CL_INVALID_COMPILER_OPTIONS)
    SEAMCL_CASE(CL_INVALID_LINKER_OPTIONS)
    SEAMCL_CASE(CL_INVALID_DEVICE_PARTITION_COUNT)
    SEAMCL_CASE(CL_PLATFORM_NOT_FOUND_KHR)
#undef SEAMCL_CASE
    default:
      return "CL_ERROR(" + std::to_string(code) + ")";
  }
}

std::string describe_cl_exception(const std::exception& error) {
  if (const auto* build = dynamic_cast<const cl::BuildError*>(&error)) {
    std::ostringstream out;
    out << "OpenCL " << build->what() << " failed: " << cl_error_name(build->err());
    for (const auto& [device, log] : build->getBuildLog()) {
      out << "\n--- build log for " << trimmed(device.getInfo<CL_DEVICE_NAME>()) << " ---\n" << trimmed(log);
    }
    return out.str();
  }
  if (const auto* cl_error = dynamic_cast<const cl::Error*>(&error)) {
    return std::string("OpenCL call ") + cl_error->what() + " failed: " + cl_error_name(cl_error->err());
  }
  return error.what();
}

ClRuntime::ClRuntime(const std::string& device_filter) {
  std::string filter = device_filter;
  if (filter.empty()) {
    if (const char* env = std::getenv("SEAMCL_DEVICE")) filter = env;
  }
  const std::vector<Candidate> candidates = all_devices();
  if (candidates.empty()) {
    throw std::runtime_error("no OpenCL device found (is an ICD such as pocl-opencl-icd installed?)");
  }
  const Candidate* chosen = nullptr;
  if (!filter.empty()) {
    for (const Candidate& c : candidates) {
      if (lower(c.info.platform + " " + c.info.name).find(lower(filter)) != std::string::npos) {
        chosen = &c;
        break;
      }
    }
    if (chosen == nullptr) {
      std::string known;
      for (const Candidate& c : candidates) known += (known.empty() ? "" : ", ") + c.info.name;
      throw InputError("device", "no OpenCL device matches '" + filter + "' (devices: " + known + ")");
    }
  } else {
    for (const char* wanted : {"GPU", "CPU"}) {
      for (const Candidate& c : candidates) {
        if (chosen == nullptr && c.info.type == wanted) chosen = &c;
      }
    }
    if (chosen == nullptr) chosen = &candidates.front();
  }
  device_ = chosen->device;
  info_ = chosen->info;
  context_ = cl::Context(device_);
  queue_ = cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE);
  driver_version_ = trimmed(device_.getInfo<CL_DRIVER_VERSION>());
  // PoCL keeps its own build cache, and asking it for CL_PROGRAM_BINARIES compiles every kernel of
  // the program, not only those a run launches (docs/performance.md has the cost), so on PoCL
  // seamcl writes binaries only when asked (seamcl warmup) or with SEAMCL_PROGRAM_CACHE=1 (or on),
  // and reads those there: a load skips PoCL's preprocessing of the source on every build.
  // 0 (or off): no program cache.
  const char* use = std::getenv("SEAMCL_PROGRAM_CACHE");
  const std::string wanted = use ? lower(use) : "";
  const bool pocl = info_.platform.find("Portable Computing Language") != std::string::npos;
  const bool none = wanted == "0" || wanted == "off";
  const std::string cache_dir = none ? "" : (std::filesystem::path(default_cache_dir()) / "programs").string();
  program_cache_ = std::make_unique<ProgramCache>(cache_dir);
  program_cache_writes_ = !none && (wanted == "1" || wanted == "on" || !pocl);
}

std::string ClRuntime::device_description() const {
  return info_.name + " (" + info_.platform + ", " + info_.version + ")";
}

std::string ClRuntime::full_build_options(const std::string& options) const {
  std::string all_options = "-cl-std=CL1.2 " + options;
  if (const char* extra = std::getenv("SEAMCL_EXTRA_BUILD_OPTIONS")) all_options += std::string(" ") + extra;
  return all_options;
}

ProgramCacheKey ClRuntime::program_cache_key(KernelProgram program, const std::string& options) const {
  return ProgramCacheKey{info_.platform, info_.name, info_.version, driver_version_, fnv64_hex(program_source(program)),
                         full_build_options(options)};
}

void ClRuntime::set_program_cache_dir(const std::string& directory) {
  std::lock_guard<std::mutex> lock(programs_mutex_);
  program_cache_ = std::make_unique<ProgramCache>(directory);
  program_cache_writes_ = true;
}

bool ClRuntime::program_cache_writes() const {
  std::lock_guard<std::mutex> lock(programs_mutex_);
  return program_cache_writes_ && program_cache_->enabled();
}

std::string ClRuntime::program_cache_dir() const {
  std::lock_guard<std::mutex> lock(programs_mutex_);
  return program_cache_->directory();
}

const cl::Program& ClRuntime::program(KernelProgram which, const std::string& options, CacheWrite write) {
  ProgramSlot* slot = nullptr;
  ProgramCache cache("");
  bool writes = false;
  {
    std::lock_guard<std::mutex> lock(programs_mutex_);
    std::unique_ptr<ProgramSlot>& held = programs_[{which, options}];
    if (!held) held = std::make_unique<ProgramSlot>();
    slot = held.get();  // slots are never removed: the pointer stays valid
    cache = *program_cache_;
    writes = program_cache_writes_ || write == CacheWrite::Always;
  }
  std::lock_guard<std::mutex> building(slot->mutex);
  if (slot->program) return *slot->program;
  const auto start = std::chrono::steady_clock::now();
  const ProgramCacheKey key = program_cache_key(which, options);
  const std::string all_options = key.build_options;
  ProgramStats counted;
  std::unique_ptr<cl::Program> program;
  if (std::optional<std::vector<unsigned char>> binary = cache.load(key)) {
    try {
      auto loaded = std::make_unique<cl::Program>(context_, std::vector<cl::Device>{device_},
                                                  cl::Program::Binaries{std::move(*binary)});
      loaded->build(std::vector<cl::Device>{device_}, all_options.c_str());
      program = std::move(loaded);
      counted.loaded = 1;
    } catch (const cl::Error&) {
      // A binary the driver refuses with an error (an entry from an older driver under the same
      // version string) is built again from source and replaced. One damaged inside a valid frame
      // never gets here by accident (the checksum); PoCL asserts on some (program_cache.h).
      counted.cache_rejected = 1;
    }
  } else if (cache.enabled()) {
    std::error_code ec;
    if (std::filesystem::exists(cache.path(key), ec)) counted.cache_rejected = 1;  // there, but not whole
  }
  if (!program) {
    program = std::make_unique<cl::Program>(context_, program_source(which));
    program->build(std::vector<cl::Device>{device_}, all_options.c_str());
    counted.built = 1;
    if (cache.enabled() && writes) {
      std::vector<std::vector<unsigned char>> binaries = program->getInfo<CL_PROGRAM_BINARIES>();
      if (binaries.size() == 1 && cache.store(key, binaries.front())) counted.stored = 1;
    }
  }
  counted.ms = ms_since(start);
  slot->program = std::move(program);
  std::lock_guard<std::mutex> lock(programs_mutex_);
  stats_.built += counted.built;
  stats_.loaded += counted.loaded;
  stats_.cache_rejected += counted.cache_rejected;
  stats_.stored += counted.stored;
  stats_.ms += counted.ms;
  return *slot->program;
}

double ClRuntime::program_build_ms() const {
  std::lock_guard<std::mutex> lock(programs_mutex_);
  return stats_.ms;
}

ClRuntime::ProgramStats ClRuntime::program_stats() const {
  std::lock_guard<std::mutex> lock(programs_mutex_);
  return stats_;
}

double event_milliseconds(const cl::Event& event) {
  const cl_ulong start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  const cl_ulong end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return static_cast<double>(end - start) * 1e-6;
}

}  // namespace seamcl
