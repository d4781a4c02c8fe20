// The OpenCL runtime layer: device choice and errors that say what failed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <seamcl/cl/cl_runtime.h>
#include "cl/kernel_sources.h"

using namespace seamcl;

namespace {

// Sets an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace

TEST(ClRuntime, ErrorNames) {
  EXPECT_EQ(cl_error_name(CL_SUCCESS), "CL_SUCCESS");
  EXPECT_EQ(cl_error_name(CL_OUT_OF_RESOURCES), "CL_OUT_OF_RESOURCES");
  EXPECT_EQ(cl_error_name(CL_BUILD_PROGRAM_FAILURE), "CL_BUILD_PROGRAM_FAILURE");
  EXPECT_EQ(cl_error_name(-12345), "CL_ERROR(-12345)");
}

TEST(ClRuntime, PicksADeviceAndListsIt) {
  const std::vector<DeviceInfo> devices = list_devices();
  ASSERT_FALSE(devices.empty());
  ClRuntime runtime;
  const std::string description = runtime.device_description();
  EXPECT_NE(description.find(runtime.info().name), std::string::npos);
  bool listed = false;
  for (const DeviceInfo& d : devices) listed |= d.name == runtime.info().name;
  EXPECT_TRUE(listed);
  // No GPU here means the default must be a CPU device; with one, a GPU.
  bool has_gpu = false;
  for (const DeviceInfo& d : devices) has_gpu |= d.type == "GPU";
  EXPECT_EQ(runtime.info().type, has_gpu ? "GPU" : "CPU");
}

TEST(ClRuntime, DeviceFilterIsASubstringAndNamesWhatFailedToMatch) {
  const DeviceInfo first = list_devices().front();
  // Case-insensitive substring of the device name.
  std::string part = first.name.substr(0, std::min<size_t>(first.name.size(), 6));
  for (char& c : part) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(ClRuntime(part).info().name, first.name);
  try {
    ClRuntime runtime("no-such-device-xyz");
    FAIL() << "a filter matching nothing was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-device-xyz"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(first.name), std::string::npos) << e.what();
  }
  // SEAMCL_DEVICE is the default filter.
  ScopedEnv env("SEAMCL_DEVICE", "no-such-device-xyz");
  EXPECT_THROW(ClRuntime runtime, std::runtime_error);
}

TEST(ClRuntime, BuildFailureCarriesTheCallTheErrorNameAndTheBuildLog) {
  // A copy of the kernels with one syntax error, loaded through SEAMCL_KERNEL_DIR.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "seamcl-broken-kernels";
  std::filesystem::remove_all(dir);
  std::filesystem::copy(SEAMCL_SOURCE_KERNEL_DIR, dir);
  {
    std::ofstream broken(dir / "raster.cl", std::ios::app);
    broken << "\n__kernel void broken_kernel(__global int* x) { x[0] = undeclared_name; }\n";
  }
  ScopedEnv env("SEAMCL_KERNEL_DIR", dir.string());
  ClRuntime runtime;
  try {
    runtime.program(KernelProgram::Geometry);
    FAIL() << "a broken program built";
  } catch (const std::exception& e) {
    const std::string message = describe_cl_exception(e);
    EXPECT_NE(message.find("clBuildProgram"), std::string::npos) << message;
    EXPECT_NE(message.find("CL_BUILD_PROGRAM_FAILURE"), std::string::npos) << message;
    EXPECT_NE(message.find("build log for " + runtime.info().name), std::string::npos) << message;
    EXPECT_NE(message.find("undeclared_name"), std::string::npos) << message;
    EXPECT_NE(message.find("raster.cl"), std::string::npos) << "the #line markers name the file: " << message;
  }
  std::filesystem::remove_all(dir);
}

TEST(ClRuntime, KernelDirMustHoldEveryFile) {
  ScopedEnv env("SEAMCL_KERNEL_DIR", "/nonexistent-seamcl-dir");
  try {
    program_source(KernelProgram::Geometry);
    FAIL() << "a missing kernel dir was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-seamcl-dir/seamcl_types.h"), std::string::npos) << e.what();
  }
}

TEST(ClRuntime, EmbeddedSourcesAreTheKernelFiles) {
  // The build embeds the real files: each embedded text equals the file on disk.
  for (const KernelSourceFile& file : embedded_kernel_sources()) {
    std::ifstream in(std::filesystem::path(SEAMCL_SOURCE_KERNEL_DIR) / file.name);
    ASSERT_TRUE(in) << file.name;
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text, file.text) << file.name;
  }
  EXPECT_GE(embedded_kernel_sources().size(), 6u);
}

TEST(KernelPrograms, EveryFileIsInAProgramAndEachProgramKeepsTheBuildOrder) {
  const std::vector<KernelSourceFile>& files = embedded_kernel_sources();
  std::set<std::string> used;
  for (KernelProgram program : {KernelProgram::Geometry, KernelProgram::Shading, KernelProgram::Sampling,
                                KernelProgram::PtexFilter, KernelProgram::Downsample}) {
    SCOPED_TRACE(kernel_program_name(program));
    const std::vector<std::string> names = kernel_program_files(program);
    ASSERT_FALSE(names.empty());
    EXPECT_EQ(names.front(), "seamcl_types.h") << "the shared structs come first";
    size_t last = 0;
    for (const std::string& name : names) {
      const auto it = std::find_if(files.begin(), files.end(), [&](const KernelSourceFile& f) { return name == f.name; });
      ASSERT_NE(it, files.end()) << name << " is not embedded";
      const size_t position = static_cast<size_t>(it - files.begin());
      EXPECT_GE(position, last) << name << " comes before a file listed ahead of it";
      last = position;
      used.insert(name);
    }
    const std::string source = program_source(program);
    for (const std::string& name : names) EXPECT_NE(source.find("#line 1 \"" + name + "\""), std::string::npos) << name;
  }
  for (const KernelSourceFile& file : files) EXPECT_EQ(used.count(file.name), 1u) << file.name << " is in no program";
}

// Each program builds on its own, from only its files, and holds the kernels its launchers create:
// a kernel moved to another file, or a file that needs one it is not built with, fails here.
TEST(KernelPrograms, EachBuildsAloneWithItsKernels) {
  ClRuntime runtime;
  runtime.set_program_cache_dir("");
  const std::map<KernelProgram, std::pair<std::string, std::set<std::string>>> expected = {
      {KernelProgram::Geometry,
       {"",
        {"triangle_setup", "bin_count", "bin_scan", "bin_fill", "raster", "sample_pattern", "tessellate", "displaced_normals",
         "tessellated_setup"}}},
      {KernelProgram::Shading, {"-DSEAMCL_CUBE=1 -DSEAMCL_SEAM_MASK=1 -DSEAMCL_INSPECT=1", {"shade_resolve", "shade_inspect"}}},
      {KernelProgram::Sampling,
       {"", {"neighbor_bytes_decoded", "texture_lookup_batch", "texture_filter_batch", "cube_lookup_batch"}}},
      {KernelProgram::PtexFilter, {"", {"ptex_filter_lookups", "ptex_point_lookups"}}},
      {KernelProgram::Downsample, {"", {"downsample_rows", "downsample_columns"}}},
  };
  for (const auto& [program, wanted] : expected) {
    SCOPED_TRACE(kernel_program_name(program));
    const cl::Program& built = runtime.program(program, wanted.first);
    std::set<std::string> kernels;
    std::stringstream names(built.getInfo<CL_PROGRAM_KERNEL_NAMES>());
    for (std::string name; std::getline(names, name, ';');) {
      if (!name.empty()) kernels.insert(name);
    }
    EXPECT_EQ(kernels, wanted.second);
  }
}
