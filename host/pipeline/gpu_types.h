// The host view of kernels/seamcl_types.h, with its layout pinned: a change on one side that the
// other does not make fails to compile here rather than corrupting buffers at run time.
#pragma once
#include <cstddef>

#include <seamcl/kernels/seamcl_types.h>

static_assert(sizeof(SamplerParams) == 32, "SamplerParams layout");
static_assert(sizeof(FrameParams) == 264, "FrameParams layout");
static_assert(offsetof(FrameParams, environment) == 184);
static_assert(offsetof(FrameParams, sampler) == 152);
static_assert(offsetof(FrameParams, width) == 64);
static_assert(offsetof(FrameParams, near_w) == 96);
static_assert(offsetof(FrameParams, light_dir) == 108);
static_assert(offsetof(FrameParams, background) == 136);
static_assert(sizeof(FaceGpu) == 48, "FaceGpu layout");
static_assert(offsetof(FaceGpu, normal) == 32);
static_assert(offsetof(FaceGpu, reflective) == 44);
static_assert(sizeof(TriangleSetup) == 112, "TriangleSetup layout");
static_assert(offsetof(TriangleSetup, edge_a) == 24);
static_assert(offsetof(TriangleSetup, bbox_min_x) == 48);
static_assert(offsetof(TriangleSetup, face) == 64);
static_assert(offsetof(TriangleSetup, inv_w) == 76);
static_assert(offsetof(TriangleSetup, v_over_w) == 100);
static_assert(sizeof(FrameStats) == 16, "FrameStats layout");
static_assert(sizeof(InspectSample) == 156, "InspectSample layout");
static_assert(offsetof(InspectSample, own_weight) == 72);
static_assert(offsetof(InspectSample, color) == 140);
static_assert(sizeof(FaceNeighbors) == 48, "FaceNeighbors layout");
static_assert(offsetof(FaceNeighbors, reach_max_side) == 4);
static_assert(offsetof(FaceNeighbors, edge_map) == 8);
static_assert(offsetof(FaceNeighbors, corner_map) == 12);
static_assert(offsetof(FaceNeighbors, neighbor) == 16);
static_assert(offsetof(FaceNeighbors, corner) == 32);
static_assert(offsetof(SamplerParams, traverse) == 20);
static_assert(offsetof(SamplerParams, lod_bias) == 28);
static_assert(sizeof(CubeSampler) == 24, "CubeSampler layout");
static_assert(sizeof(EnvironmentParams) == 80, "EnvironmentParams layout");
static_assert(offsetof(EnvironmentParams, ray_dy) == 60);
static_assert(sizeof(ReflectiveFace) == 112, "ReflectiveFace layout");
static_assert(offsetof(ReflectiveFace, roughness) == 96);
static_assert(sizeof(PtexFilterFace) == 40, "PtexFilterFace layout");
static_assert(offsetof(PtexFilterFace, level_base) == 32);
static_assert(sizeof(PtexFilterTexture) == 32, "PtexFilterTexture layout");
static_assert(sizeof(PtexFilterQuery) == 32, "PtexFilterQuery layout");
static_assert(offsetof(PtexFilterTexture, seams) == 28);
static_assert(sizeof(PtexShading) == 56, "PtexShading layout");
static_assert(offsetof(PtexShading, width_scale) == 40);
static_assert(offsetof(PtexShading, rgb_source) == 44);
static_assert(offsetof(PtexFilterQuery, sharpness) == 24);
static_assert(sizeof(DisplacedShading) == 16, "DisplacedShading layout");
static_assert(offsetof(DisplacedShading, adaptive) == 4);
