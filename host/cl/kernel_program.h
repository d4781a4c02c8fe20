// The OpenCL programs seamcl builds from kernels/ (which files each holds: host/cl/kernel_sources.h).
#pragma once

namespace seamcl {

// Each program is built from only the files its kernels need: a sampler variant then rebuilds the
// stages that sample and nothing else, and the stages that never sample build once.
enum class KernelProgram {
  Geometry,    // triangle_setup, bin_*, raster, sample_pattern, tessellate, tessellated_setup: no options
  Shading,     // shade_resolve: one build per sampler variant (program_options)
  Sampling,    // texture_*_batch, aniso_*, cube_lookup_batch, neighbor_bytes_decoded: per sampler variant
  PtexFilter,  // ptex_filter_lookups: no options
  Downsample,  // downsample_rows, downsample_columns: no options
};

inline const char* kernel_program_name(KernelProgram program) {
  switch (program) {
    case KernelProgram::Geometry: return "geometry";
    case KernelProgram::Shading: return "shading";
    case KernelProgram::Sampling: return "sampling";
    case KernelProgram::PtexFilter: return "ptex-filter";
    case KernelProgram::Downsample: return "downsample";
  }
  return "unknown";
}

}  // namespace seamcl
