#include "pipeline/stages/tessellate_launcher.h"

#include <algorithm>

namespace seamcl {
namespace {

constexpr size_t kGroup = 64;

template <typename T>
cl::Buffer upload(ClRuntime& runtime, const std::vector<T>& data) {
  // OpenCL refuses zero-sized buffers; one element of padding keeps empty arrays legal.
  const size_t bytes = std::max<size_t>(data.size(), 1) * sizeof(T);
  cl::Buffer buffer(runtime.context(), CL_MEM_READ_ONLY, bytes);
  if (!data.empty()) runtime.queue().enqueueWriteBuffer(buffer, CL_TRUE, 0, data.size() * sizeof(T), data.data());
  return buffer;
}

}  // namespace

void TessellateLauncher::load(PackedDisplacement packed) {
  release();
  packed_ = std::move(packed);
  params_ = upload(runtime_, std::vector<TessellationParams>{packed_.params});
  patches_ = upload(runtime_, packed_.patches);
  samples_ = upload(runtime_, packed_.samples);
  positions_ = upload(runtime_, packed_.positions);
  normals_ = upload(runtime_, packed_.normals);
  corner_offsets_ = upload(runtime_, packed_.corner_offsets);
  corner_copies_ = upload(runtime_, packed_.corner_copies);
  vertices_ = cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE, std::max<size_t>(packed_.vertex_count(), 1) * sizeof(TessVertex));
  vertex_normals_ = cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE, std::max<size_t>(packed_.vertex_count(), 1) * sizeof(cl_float4));
  loaded_ = true;
}

void TessellateLauncher::release() {
  loaded_ = false;
  packed_ = PackedDisplacement{};
  params_ = patches_ = samples_ = positions_ = normals_ = corner_offsets_ = corner_copies_ = vertices_ = vertex_normals_ =
      cl::Buffer();
}

TessellateLauncher::Kernels& TessellateLauncher::kernels() {
  if (!kernels_) {
    const cl::Program& program = runtime_.program(KernelProgram::Geometry);
    kernels_ = Kernels{cl::Kernel(program, "tessellate"), cl::Kernel(program, "tessellated_setup"),
                       cl::Kernel(program, "displaced_normals")};
  }
  return *kernels_;
}

void TessellateLauncher::enqueue_tessellate(Kernels& k, std::vector<cl::Event>* events) {
  const size_t vertices = packed_.vertex_count();
  if (vertices == 0) return;
  k.tessellate.setArg(0, params_);
  k.tessellate.setArg(1, patches_);
  k.tessellate.setArg(2, samples_);
  k.tessellate.setArg(3, positions_);
  k.tessellate.setArg(4, normals_);
  k.tessellate.setArg(5, vertices_);
  cl::Event* event = nullptr;
  if (events) event = &events->emplace_back();
  runtime_.queue().enqueueNDRangeKernel(k.tessellate, cl::NullRange, cl::NDRange(round_up(vertices, kGroup)), cl::NDRange(kGroup),
                                        nullptr, event);
}

void TessellateLauncher::enqueue_normals(Kernels& k, std::vector<cl::Event>* events) {
  const size_t vertices = packed_.vertex_count();
  if (vertices == 0) return;
  k.normals.setArg(0, params_);
  k.normals.setArg(1, patches_);
  k.normals.setArg(2, corner_offsets_);
  k.normals.setArg(3, corner_copies_);
  k.normals.setArg(4, vertices_);
  k.normals.setArg(5, static_cast<cl_int>(packed_.adaptive() ? 1 : 0));
  k.normals.setArg(6, vertex_normals_);
  cl::Event* event = nullptr;
  if (events) event = &events->emplace_back();
  runtime_.queue().enqueueNDRangeKernel(k.normals, cl::NullRange, cl::NDRange(round_up(vertices, kGroup)), cl::NDRange(kGroup),
                                        nullptr, event);
}

void TessellateLauncher::enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups,
                                const cl::Buffer& slot_counts, const cl::Buffer& stats, int input_triangles, bool normals,
                                std::vector<cl::Event>& tessellate_events, std::vector<cl::Event>& setup_events) {
  Kernels& k = kernels();
  enqueue_tessellate(k, &tessellate_events);
  if (normals) enqueue_normals(k, &tessellate_events);
  if (input_triangles <= 0) return;
  k.setup.setArg(0, frame_params);
  k.setup.setArg(1, params_);
  k.setup.setArg(2, vertices_);
  k.setup.setArg(3, setups);
  k.setup.setArg(4, slot_counts);
  k.setup.setArg(5, stats);
  k.setup.setArg(6, static_cast<cl_int>(packed_.adaptive() ? 1 : 0));
  const size_t setup_items = (static_cast<size_t>(input_triangles) + SEAMCL_SETUP_LANES - 1) / SEAMCL_SETUP_LANES;
  runtime_.queue().enqueueNDRangeKernel(k.setup, cl::NullRange, cl::NDRange(round_up(setup_items, SEAMCL_SETUP_GROUP)),
                                        cl::NDRange(SEAMCL_SETUP_GROUP), nullptr, &setup_events.emplace_back());
}

std::vector<TessVertex> TessellateLauncher::tessellate() {
  enqueue_tessellate(kernels(), nullptr);
  return read_vertices();
}

std::vector<cl_float4> TessellateLauncher::tessellate_normals() {
  Kernels& k = kernels();
  enqueue_tessellate(k, nullptr);
  enqueue_normals(k, nullptr);
  std::vector<cl_float4> out(packed_.vertex_count());
  if (!out.empty()) runtime_.queue().enqueueReadBuffer(vertex_normals_, CL_TRUE, 0, out.size() * sizeof(cl_float4), out.data());
  return out;
}

std::vector<TessVertex> TessellateLauncher::read_vertices() {
  std::vector<TessVertex> out(packed_.vertex_count());
  if (!out.empty()) runtime_.queue().enqueueReadBuffer(vertices_, CL_TRUE, 0, out.size() * sizeof(TessVertex), out.data());
  return out;
}

size_t TessellateLauncher::device_bytes() const {
  size_t bytes = 0;
  for (const cl::Buffer* b : {&params_, &patches_, &samples_, &positions_, &normals_, &corner_offsets_, &corner_copies_,
                              &vertices_, &vertex_normals_}) {
    if ((*b)() != nullptr) bytes += b->getInfo<CL_MEM_SIZE>();
  }
  return bytes;
}

}  // namespace seamcl
