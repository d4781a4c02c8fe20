#include "pipeline/stages/ptex_filter_launcher.h"

#include <algorithm>

namespace seamcl {
namespace {

constexpr size_t kGroup = 64;
const cl_int kNoOtherFilter = 0;  // not_point_'s value before a point kernel runs

template <typename T>
cl::Buffer upload(ClRuntime& runtime, const std::vector<T>& data, size_t& bytes_total) {
  // OpenCL refuses zero-sized buffers; one element of padding keeps empty arrays legal.
  const size_t bytes = std::max<size_t>(data.size(), 1) * sizeof(T);
  cl::Buffer buffer(runtime.context(), CL_MEM_READ_ONLY, bytes);
  if (!data.empty()) runtime.queue().enqueueWriteBuffer(buffer, CL_TRUE, 0, data.size() * sizeof(T), data.data());
  bytes_total += bytes;
  return buffer;
}

// ptex_filter_lookups looks up SEAMCL_PTEX_LOOKUP_LANES queries per work-item, in work-groups of
// kGroup queries as the point kernel's, so that a batch of a few hundred still spreads over the
// cores (PoCL runs a work-group on one).
constexpr size_t kGeneralGroup = kGroup / SEAMCL_PTEX_LOOKUP_LANES;
size_t general_work_items(size_t queries) {
  return round_up((queries + SEAMCL_PTEX_LOOKUP_LANES - 1) / SEAMCL_PTEX_LOOKUP_LANES, kGeneralGroup);
}

}  // namespace

PtexFilterLauncher::PtexFilterLauncher(ClRuntime& runtime)
    : runtime_(runtime),
      kernel_(runtime.program(KernelProgram::PtexFilter), "ptex_filter_lookups"),
      point_kernel_(runtime.program(KernelProgram::PtexFilter), "ptex_point_lookups"),
      not_point_(runtime.context(), CL_MEM_READ_WRITE, sizeof(cl_int)) {}

void PtexFilterLauncher::load(const PtexFilterData& data) {
  device_bytes_ = 0;
  texture_ = data.texture;
  faces_ = upload(runtime_, data.faces, device_bytes_);
  level_offsets_ = upload(runtime_, data.level_offsets, device_bytes_);
  texels_ = upload(runtime_, data.texels, device_bytes_);
}

cl::Kernel& PtexFilterLauncher::with_args(cl::Kernel& kernel, const cl::Buffer& in, size_t count,
                                          const cl::Buffer& out) {
  kernel.setArg(0, texture_);
  kernel.setArg(1, faces_);
  kernel.setArg(2, level_offsets_);
  kernel.setArg(3, texels_);
  kernel.setArg(4, in);
  kernel.setArg(5, static_cast<int>(count));
  kernel.setArg(6, out);
  if (&kernel == &point_kernel_) kernel.setArg(7, not_point_);
  return kernel;
}

std::vector<float> PtexFilterLauncher::run(const std::vector<PtexFilterQuery>& queries) {
  std::vector<float> values(queries.size() * 4);
  run(queries, values.data());
  return values;
}

void PtexFilterLauncher::run(const std::vector<PtexFilterQuery>& queries, float* values) {
  if (queries.empty()) return;
  // The queries and the values stay in the caller's memory: PoCL on the CPU reads and writes them
  // where they are (for point lookups the copies in and out had taken as long as the kernel); a
  // device with memory of its own copies them or reads them across the bus, as its driver chooses.
  const size_t out_bytes = queries.size() * 4 * sizeof(float);
  const cl::Buffer in(runtime_.context(), CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR,
                      queries.size() * sizeof(PtexFilterQuery), const_cast<PtexFilterQuery*>(queries.data()));
  const cl::Buffer out(runtime_.context(), CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, out_bytes, values);
  const cl::NDRange global(round_up(queries.size(), kGroup)), local(kGroup);
  const cl::NDRange general_global(general_work_items(queries.size()));
  cl::CommandQueue& queue = runtime_.queue();
  // A batch that opens with a point lookup is taken for points alone and checked by the point
  // kernel itself as it reads each query: reading every query here first, on one thread before the
  // kernel, had held 7% of a point batch's CPU samples. Where another filter shows up, the general
  // kernel runs after it.
  bool general = queries.front().filter != SEAMCL_PTEX_POINT;
  if (!general) {
    queue.enqueueWriteBuffer(not_point_, CL_FALSE, 0, sizeof(cl_int), &kNoOtherFilter);
    queue.enqueueNDRangeKernel(with_args(point_kernel_, in, queries.size(), out), cl::NullRange, global, local);
    cl_int not_point = 0;
    queue.enqueueReadBuffer(not_point_, CL_TRUE, 0, sizeof(cl_int), &not_point);
    general = not_point != 0;
  }
  if (general)
    queue.enqueueNDRangeKernel(with_args(kernel_, in, queries.size(), out), cl::NullRange, general_global,
                               cl::NDRange(kGeneralGroup));
  void* mapped = queue.enqueueMapBuffer(out, CL_TRUE, CL_MAP_READ, 0, out_bytes);
  queue.enqueueUnmapMemObject(out, mapped);
  queue.finish();
}

std::vector<double> PtexFilterLauncher::time(const std::vector<PtexFilterQuery>& queries, int repeats) {
  std::vector<double> ms;
  if (queries.empty()) return ms;
  size_t ignored = 0;
  const cl::Buffer in = upload(runtime_, queries, ignored);
  const cl::Buffer out(runtime_.context(), CL_MEM_WRITE_ONLY, queries.size() * 4 * sizeof(float));
  const bool points = std::all_of(queries.begin(), queries.end(),
                                  [](const PtexFilterQuery& q) { return q.filter == SEAMCL_PTEX_POINT; });
  if (points) runtime_.queue().enqueueWriteBuffer(not_point_, CL_FALSE, 0, sizeof(cl_int), &kNoOtherFilter);
  cl::Kernel& kernel = with_args(points ? point_kernel_ : kernel_, in, queries.size(), out);
  std::vector<cl::Event> events(static_cast<size_t>(std::max(repeats, 0)));
  for (cl::Event& event : events)
    runtime_.queue().enqueueNDRangeKernel(
        kernel, cl::NullRange,
        cl::NDRange(points ? round_up(queries.size(), kGroup) : general_work_items(queries.size())),
        cl::NDRange(points ? kGroup : kGeneralGroup), nullptr, &event);
  runtime_.queue().finish();
  for (const cl::Event& event : events) ms.push_back(event_milliseconds(event));
  return ms;
}

}  // namespace seamcl
