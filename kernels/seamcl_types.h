/* Structs that cross the host/kernel boundary. Compiled both as OpenCL C 1.2 (first file of the
 * program) and as C++ (host/gpu_types.h adds static_asserts on every size and offset).
 * Only 4- and 8-byte scalars, no vector types: the layout is then the same on both sides. */
#ifndef SEAMCL_TYPES_H
#define SEAMCL_TYPES_H

#ifdef __OPENCL_C_VERSION__
/* No fused multiply-add contraction: the scalar C++ twins (built with -ffp-contract=off) then
 * round exactly as the kernels do. Where a kernel wants a fused multiply-add it calls fma(), and
 * its twin std::fma (texture_sample.cl's add_texel). */
#pragma OPENCL FP_CONTRACT OFF
/* Every helper inlined: a helper left as a call (LLVM's inliner gives up on the larger sampler
 * functions) stops PoCL from vectorising the work-group loop around it. */
#define SEAMCL_INLINE inline __attribute__((always_inline))
/* Except a large helper called from many places in a kernel whose work-group loop does not
 * vectorise anyway (data-dependent loops per work-item): inlined at every call, it multiplies
 * PoCL's compile time and the code's size (docs/performance.md has the Ptex filter's and the
 * shading kernel's figures). */
#define SEAMCL_CALLED __attribute__((noinline))
/* A prefetch of the cache line at p, to read it or to write it: clang's builtin is the one PoCL
 * turns into an instruction; everywhere else OpenCL C's own prefetch(). Only under PoCL
 * (POCL_DEVICE_ADDRESS_BITS is its macro): the builtin is a clang extension, and for SPIR-V it
 * becomes an LLVM intrinsic the translator refuses (tests/kernel_portability_test.sh). */
#if defined(__has_builtin) && defined(POCL_DEVICE_ADDRESS_BITS)
#if __has_builtin(__builtin_prefetch)
#define SEAMCL_PREFETCH(p) __builtin_prefetch(p)
#define SEAMCL_PREFETCH_WRITE(p) __builtin_prefetch(p, 1)
#endif
#endif
#ifndef SEAMCL_PREFETCH
#define SEAMCL_PREFETCH(p) prefetch((__global const char*)(p), 64)
#define SEAMCL_PREFETCH_WRITE(p) prefetch((__global const char*)(p), 64)
#endif
typedef uchar cl_uchar;
typedef uint cl_uint;
typedef int cl_int;
typedef long cl_long;
typedef float cl_float;
#else
#include <CL/cl_platform.h>
#endif

#define SEAMCL_TILE_SIZE 16          /* pixels per side of a binning tile */
#define SEAMCL_SUBPIXEL_BITS 8       /* fixed-point vertex snapping: 1/256 pixel */
#define SEAMCL_SUBPIXEL_ONE 256
#define SEAMCL_MAX_SAMPLES 16
#define SEAMCL_CLIP_SLOTS 6          /* a triangle clipped by 5 planes is a fan of at most 6 */
#define SEAMCL_SETUP_LANES 16        /* triangles per work-item of triangle_setup (vectors) */
#define SEAMCL_SETUP_GROUP 4         /* triangle_setup's work-group size (it sums visible slots per group) */
#define SEAMCL_MAX_PROBES 16         /* an aniso lookup's most probes (max_aniso's bound) */
/* approx_log2(N) for N = 1..SEAMCL_MAX_PROBES probes, the bits its polynomial gives without
 * contraction (kernels and twins alike; Sampler.ProbeCountLog2TableIsTheKernelsPolynomial checks
 * each entry). An aniso lookup's lod is log2(major) - log2(N), and N, the last step of a chain of
 * divide, square root and ceiling, is on the path from the footprint to the first texel's address:
 * a table read there in place of six dependent multiply-adds shortens that path (measured in
 * docs/performance.md, "lookups" rows). */
#define SEAMCL_LOG2_PROBE_COUNTS                                                                  \
  {0x0p+0f,        0x1p+0f,        0x1.95c02p+0f,  0x1p+1f,        0x1.2934f6p+1f, 0x1.4ae01p+1f,  \
   0x1.67575ep+1f, 0x1.8p+1f,      0x1.95c02p+1f,  0x1.a934f6p+1f, 0x1.bace9ap+1f, 0x1.cae01p+1f,  \
   0x1.d9a80cp+1f, 0x1.e7575ep+1f, 0x1.f415p+1f,   0x1p+2f}
#define SEAMCL_NO_TRIANGLE 0xffffffffu
/* Seam mask (shade_resolve built with -DSEAMCL_SEAM_MASK=1): a footprint crosses an edge when a
 * filter puts more than this weight beyond it. Float rounding of weights that sum to 1 stays
 * below 1e-6; a tap weighing less than this changes a colour by less than it too. */
#define SEAMCL_SEAM_WEIGHT_TOLERANCE 1e-5f
/* Seam mask values, per pixel */
#define SEAMCL_MASK_NONE 0     /* no footprint crosses a face edge: every seam method agrees */
#define SEAMCL_MASK_SEAM 1     /* a footprint crosses an edge shared by two faces */
#define SEAMCL_MASK_BOUNDARY 2 /* footprints cross mesh boundary edges only (silhouette rims) */

/* shading_mode */
#define SEAMCL_SHADE_PIXEL 0    /* once per pixel and triangle, at the pixel centre */
#define SEAMCL_SHADE_CENTROID 1 /* as PIXEL, but a partly covered pixel at the mean of its covered samples */
#define SEAMCL_SHADE_SAMPLE 2   /* every sample (supersampling) */

/* SamplerParams.filter */
#define SEAMCL_FILTER_BILINEAR 0  /* one level: 0, or the one nearest lod_bias */
#define SEAMCL_FILTER_TRILINEAR 1 /* two levels around log2 of the longer screen axis */
#define SEAMCL_FILTER_ANISO 2     /* up to max_aniso trilinear probes along the major axis */
#define SEAMCL_FILTER_EWA 3       /* elliptical Gaussian over the texels of two levels */
#define SEAMCL_FILTER_PTEX 4      /* Ptex's own filters (ptex_filter.cl, PtexShading): the shading program only */
/* SamplerParams.address: where taps outside the level read */
#define SEAMCL_ADDRESS_CLAMP 0    /* the nearest edge texel */
#define SEAMCL_ADDRESS_WRAP 1     /* the texture repeats */
#define SEAMCL_ADDRESS_BORDER 2   /* colour 0 and weight 0 (border-zero) */
/* SamplerParams.zero_coverage: a renormalised lookup whose taps all fall outside */
#define SEAMCL_ZERO_COVERAGE_CLAMP 0 /* clamped trilinear lookup at the centre clamped to the face */
#define SEAMCL_ZERO_COVERAGE_NAN 1   /* the raw division 0/0 (the paper's failure case) */

/* SamplerParams.traverse: which neighbouring faces a lookup also reads */
#define SEAMCL_TRAVERSE_NONE 0    /* the face alone */
#define SEAMCL_TRAVERSE_EDGES 1   /* and its four edge neighbours (McDonald 2013, the paper's) */
#define SEAMCL_TRAVERSE_CORNERS 2 /* and, past a valence-4 corner, the diagonal face (Ptex) */

/* How one texture lookup filters. The seam methods are settings of it: clamp = address clamp;
 * black = address border; discard = address border + renormalize; traverse-edges = discard + the
 * same lookup on each edge neighbour through its uv transform, all summed before renormalising;
 * traverse = traverse-edges + the diagonal faces at valence-4 corners; guardband = address clamp
 * on textures stored with a band filled from the neighbours. */
typedef struct {
  cl_int filter;         /* SEAMCL_FILTER_* */
  cl_int address;        /* SEAMCL_ADDRESS_* */
  cl_int renormalize;    /* 1: divide by the summed weight of the taps inside */
  cl_int max_aniso;      /* 1..16, for aniso and ewa */
  cl_int zero_coverage;  /* SEAMCL_ZERO_COVERAGE_*, when renormalize and no tap is inside */
  cl_int traverse;       /* SEAMCL_TRAVERSE_*: also filter the neighbours (FaceNeighbors) */
  cl_int guard_band;     /* band texels stored around every level (guardband); the kernels take it
                            from the build option SEAMCL_SAMPLER_GUARD_BAND, this is the host's copy */
  cl_float lod_bias;     /* added to every lookup's mip level, -4..4 (RenderOptions::lod_bias) */
} SamplerParams;

/* A uv map from one face's unit square to another's, in one byte: (u', v') = (t0 u + t1 v + t2,
 * t3 u + t4 v + t5), derivatives by the linear part. Both uv spaces are unit squares, so the linear
 * part is a signed permutation (a rotation by a multiple of 90 degrees or a reflection) and the
 * offset whole numbers, -1 to 2 for any face that touches this one (its square lies within one
 * unit of this one's). SEAMCL_MAP_SWAP: u' reads v and v' reads u (t0 = t4 = 0); the NEGATE bits
 * give the signs of u' and v''s term; bits 3-4 and 5-6 hold t2 + 1 and t5 + 1. The kernels and
 * the host (host/pipeline/adjacency.h, uv_map) decode it to the same exact floats. */
#define SEAMCL_MAP_SWAP 1
#define SEAMCL_MAP_NEGATE_U 2
#define SEAMCL_MAP_NEGATE_V 4
#define SEAMCL_MAP_OFFSET_U_SHIFT 3
#define SEAMCL_MAP_OFFSET_V_SHIFT 5

/* A texture side for traverse's early-out (a power of two, as every face side is) in a byte:
 * 2^(stored - SEAMCL_SIDE_BIAS); SEAMCL_SIDE_NONE (so a zeroed record too) stands for 0: not
 * filled, or no face, never skips. */
#define SEAMCL_SIDE_NONE 0
#define SEAMCL_SIDE_BIAS 128

/* A face's neighbours, for traverse: 48 bytes, packed for every face of the scene, so kept small
 * (six floats a map and float sides took 256 bytes a face). Edge k runs from corner k to corner
 * k+1 (uv (0,0), (1,0), (1,1), (0,1)): edge 0 is v = 0, 1 is u = 1, 2 is v = 1, 3 is u = 0.
 * neighbor[k] is the face across it (-1 at a boundary or a non-manifold edge); edge_map[k] maps this face's uv to the
 * neighbour's (SEAMCL_MAP_*).
 * corner[k] is the diagonal face past corner k when that corner's vertex has valence 4 (four
 * faces around it, a closed ring), else -1: at any other valence, or at a mesh boundary, there is
 * no one face past the corner, and the part of a footprint there is dropped (renormalised away).
 * corner_map[k] maps this face's uv to the diagonal face's, as the two edge maps composed
 * (host/pipeline/adjacency.h). A map without its face is 0 and never read.
 * Traverse's early-out per edge k, filled when the scene is packed (fill_edge_reach): over the
 * faces a lookup reaches across edge k (neighbor[k]) and past its two ends (corner[k],
 * corner[(k + 1) & 3]), their sides as they lie in this face's uv (a map may swap u and v):
 * reach_min_side[k] is the smallest side along the axis that crosses edge k (v for edges 0 and 2,
 * u for 1 and 3), reach_max_side[k] that times the largest ratio of a face's side along the other
 * axis to its side along this one (SEAMCL_SIDE_NONE: not filled, or no such face; never skips). A
 * lookup too far inside edge k for faces of these sides skips all three without reading them
 * (texture_sample.cl, accumulate_neighbors). They come first: an interior lookup reads nothing
 * else of the record. */
typedef struct {
  cl_uchar reach_min_side[4];
  cl_uchar reach_max_side[4];
  cl_uchar edge_map[4];
  cl_uchar corner_map[4];
  cl_int neighbor[4];
  cl_int corner[4];
} FaceNeighbors;

/* CubeSampler.method: how a cube-map lookup treats its filter taps at the faces' edges. */
#define SEAMCL_CUBE_CLAMP 0    /* per-face clamp: the seams of D3D9 */
#define SEAMCL_CUBE_SEAMLESS 1 /* taps past an edge read the adjacent face; corners: mean of 3 texels */
#define SEAMCL_CUBE_STRETCH 2  /* faces baked with map_2 (edge texels shared), clamp */
#define SEAMCL_CUBE_WARP 3     /* faces baked with the cubic warp, clamp */
#define SEAMCL_CUBE_FIXUP 4    /* stretch-baked faces, coordinates scaled by 1 - exp2(lod)/n, clamp */
#define SEAMCL_CUBE_DISCARD 5  /* border-zero taps renormalised per face (Toth 2013 on a cube) */
/* Not a seam method: shade writes the lookup direction instead of the lookup (host/eval's
 * analytic reference evaluates the environment along it). */
#define SEAMCL_CUBE_DIRECTION 6
/* More seam methods (after DIRECTION, whose value stays). */
#define SEAMCL_CUBE_FOV 7          /* faces baked with the post's FOV 2 atan(m / (m - 0.5)) per level; lookups
                                    * scaled by (m - 0.5) / m per level to match, clamp */
#define SEAMCL_CUBE_AVERAGE 8      /* texel-centre faces whose edge texels are averaged across the edge (corners:
                                    * the three) after the bake, CubeMapGen-style; clamp */
#define SEAMCL_CUBE_FIXUP_LEVEL 9  /* fixup with each trilinear level's own scale (m - 1) / m */
#define SEAMCL_CUBE_BORDER 10      /* faces stored with a one-texel border of their neighbours' texels
                                    * (layout below); taps read within the bordered face */

/* A cube map's lookup. Texels: linear RGBA32F, face-major (+X, -X, +Y, -Y, +Z, -Z), each face's
 * levels n, n/2, .., 1 in turn, rows top to bottom (t = 0 first): face f, level l starts at
 * texel f * (4 n^2 - 1) / 3 + 4 (n^2 - (n >> l)^2) / 3. SEAMCL_CUBE_BORDER: each m x m level is stored
 * as (m + 2) x (m + 2) with its one-texel border, texel (i, j), i, j in -1..m, at (j + 1) (m + 2) + i + 1;
 * a face holds (4 n^2 - 1) / 3 + 8 n - 4 + 4 (log2 n + 1) texels and level l starts
 * 4 (n^2 - m^2) / 3 + 8 (n - m) + 4 l into it. */
typedef struct {
  cl_int size;          /* level-0 face size n, a power of two; 0: the scene has no cube map */
  cl_int level_count;   /* log2(n) + 1 */
  cl_int method;        /* SEAMCL_CUBE_* */
  cl_int filter;        /* SEAMCL_FILTER_BILINEAR, _TRILINEAR or _ANISO */
  cl_int max_aniso;     /* 1..16 */
  cl_int pad0;
} CubeSampler;

/* The environment's per-frame part. A view ray through pixel-space point (x, y) has the
 * (unnormalised) direction ray_corner + x ray_dx + y ray_dy: linear for a pinhole camera, so its
 * screen derivatives are ray_dx and ray_dy. */
typedef struct {
  CubeSampler sampler;
  cl_float eye[3];        /* world space */
  cl_float ray_corner[3];
  cl_float ray_dx[3];
  cl_float ray_dy[3];
  cl_int skybox;          /* 1: samples no triangle covers show the environment */
  cl_int pad0;
} EnvironmentParams;

/* A face that reflects the environment (FaceGpu.reflective indexes these): its corners (uv (0,0),
 * (1,0), (1,1), (0,1)) and unit shading normals there, interpolated bilinearly in uv. */
typedef struct {
  cl_float position[4][3];
  cl_float normal[4][3];
  cl_float roughness;     /* 0: a mirror; > 0 widens the lookup's footprint (glossy) */
  cl_int pad0[3];
} ReflectiveFace;

/* Per frame, read-only in every kernel. Screen space: pixels, origin at the top-left corner of
 * the image, y down; pixel (x, y) spans [x, x+1) x [y, y+1), its centre at (x+0.5, y+0.5). */
typedef struct {
  cl_float view_proj[16];   /* world -> clip, column-major (glm layout) */
  cl_int width, height;     /* image size in pixels */
  cl_int tiles_x, tiles_y;  /* ceil(size / SEAMCL_TILE_SIZE) */
  cl_int sample_count;      /* 1, 2, 4, 8 or 16 */
  cl_int shading_mode;      /* SEAMCL_SHADE_* */
  cl_int input_triangles;   /* 2 per face: (v0,v1,v2) and (v0,v2,v3) */
  cl_uint bin_capacity;     /* entries in the tile lists buffer */
  cl_float near_w;          /* clip plane w >= near_w (view-space distance) */
  cl_float guard_x, guard_y;/* clip planes |x| <= guard_x * w, |y| <= guard_y * w */
  cl_float light_dir[3];    /* unit vector towards the light, world space */
  cl_float light_color[3];
  cl_float ambient;         /* lighting = light_color * (ambient + (1-ambient) * max(0, n.l)) */
  cl_float background[3];   /* linear RGB of samples no triangle covers */
  cl_int mask_only;         /* with SEAMCL_SEAM_MASK: 1 shades no fragment (black), the mask alone is wanted */
  SamplerParams sampler;
  EnvironmentParams environment; /* cube-map lookups (reflective faces, skybox); size 0: none */
} FrameParams;

/* One quad patch. Texture texels of all faces live in one buffer; level l of a face starts at
 * level_offsets[level_table + l] and holds max(w >> l, 1) x max(h >> l, 1) texels, row-major,
 * row 0 at v = 0. Texel (i, j) of a level of size W x H has its centre at ((i+.5)/W, (j+.5)/H).
 * The host stores the levels level-major: level 0 of every face, then level 1, ... */
typedef struct {
  cl_uint vertex[4];        /* uv (0,0), (1,0), (1,1), (0,1); counter-clockwise seen from the front */
  cl_uint level_table;      /* index of level 0's entry in level_offsets */
  cl_int width, height;     /* level 0 size in texels, powers of two */
  cl_int level_count;       /* down to 1x1 */
  cl_float normal[3];       /* unit, world space, towards the front */
  cl_int reflective;        /* index into the ReflectiveFace table; -1: a diffuse, textured face */
} FaceGpu;

/* Output of triangle setup, one per clip slot: slot k of input triangle t at index
 * k * input_triangles + t (slot-major: the records of unclipped triangles, slot 0, lie dense and in
 * input order, so setup's stores and later stages' reads share cache lines and pages). Tile lists
 * and sample winners hold these indices; the tie order (raster) and the host's read-backs use input
 * order, t * SEAMCL_CLIP_SLOTS + k.
 * Edge functions over fixed-point positions P (SEAMCL_SUBPIXEL_BITS fraction bits):
 *   E_i(P) = edge_a[i] * P.x + edge_b[i] * P.y + edge_c[i]
 * with the top-left rule folded into edge_c (non-top-left edges are biased by -1), so a sample
 * is covered iff E_i >= 0 for i = 0, 1, 2. An empty slot has bbox_max_x < bbox_min_x.
 * Planes over float pixel coordinates: value(x, y) = p[0] + p[1] * (x - ref_x) + p[2] * (y - ref_y)
 * for 1/w, u/w and v/w (perspective-correct interpolation). */
typedef struct {
  cl_long edge_c[3];
  cl_int edge_a[3];
  cl_int edge_b[3];
  cl_int bbox_min_x, bbox_min_y, bbox_max_x, bbox_max_y; /* pixels, inclusive, inside the image */
  cl_uint face;
  cl_float ref_x, ref_y;
  cl_float inv_w[3];
  cl_float u_over_w[3];
  cl_float v_over_w[3];
} TriangleSetup;

/* Counters the host reads back after a frame. */
typedef struct {
  cl_uint bin_entries;      /* tile-list entries needed (may exceed bin_capacity: then re-run) */
  cl_uint fragments;        /* (pixel, triangle) pairs shaded; samples in SEAMCL_SHADE_SAMPLE */
  cl_uint visible_triangles;/* clip slots that produced a non-empty triangle */
  cl_uint early_culled;     /* input triangles triangle_setup's early cull stopped */
} FrameStats;

/* The pixel inspector's record of one sample (kernels/shade_inspect.cl, a shading program built
 * with -DSEAMCL_INSPECT=1): the fragment that colours the sample and its texture lookup as the
 * frame's seam method reads it. With pixel or centroid shading the samples of one triangle share
 * one fragment (its shading point, coverage and lookup). */
typedef struct {
  cl_uint triangle;         /* the sample's winning clip slot; SEAMCL_NO_TRIANGLE: background */
  cl_int face;              /* the slot's face; -1 for the background */
  cl_uint coverage;         /* bit s: sample s has this sample's triangle (the fragment's samples) */
  cl_int probes;            /* aniso probes (1 for the other filters); 0 without a lookup */
  cl_float x, y;            /* shading point, pixels */
  cl_float u, v;            /* at the shading point */
  cl_float dudx, dvdx, dudy, dvdy;
  cl_float axis_x, axis_y;  /* the footprint's screen axes, level-0 texels */
  cl_float lod;             /* the level read, bias included, clamped to the chain */
  cl_int level0, level1;    /* the levels whose texels are read (equal for one level) */
  cl_int reflective;        /* 1: a cube-map lookup (no patch taps; weights stay 0) */
  cl_float own_weight;      /* summed tap weight inside the own face (the method's address mode) */
  cl_int edge_face[4];      /* face across edge k (v = 0, u = 1, v = 1, u = 0); -1 none */
  cl_float edge_weight[4];  /* its taps' weight as traverse reads it; 0 when the method does not */
  cl_int corner_face[4];    /* diagonal face past corner k (valence 4); -1 none */
  cl_float corner_weight[4];
  cl_float color[4];        /* the fragment's shaded colour, linear RGB, alpha 1 */
} InspectSample;

/* ---- Displacement (kernels/tessellate.cl; host/pipeline/displacement_packing.h) ---- */
/* TessellationParams.method: how a patch's vertices take their displacement */
#define SEAMCL_DISPLACEMENT_NAIVE 0     /* float domain points, each patch samples its own map */
#define SEAMCL_DISPLACEMENT_ZIPPER 1    /* edges: mean of both sides' samples; corners: one snapped value */
#define SEAMCL_DISPLACEMENT_OWNERSHIP 2 /* one sample through the owner's texcoord (4 per corner) */
#define SEAMCL_DISPLACEMENT_FIXED 3     /* fixed-point domain points, own map, exact integer filtering */
#define SEAMCL_DISPLACEMENT_PTEX_FILTER 4 /* a 3x3 tent of one own-texel spacing, taps past an edge read the neighbour */
#define SEAMCL_DOMAIN_ONE 65536         /* fixed-point domain coordinates: 16 fraction bits */
#define SEAMCL_MAX_TESSELLATION 64

/* A texture coordinate that names the face whose map it addresses (ownership). */
typedef struct {
  cl_int face;     /* -1: none */
  cl_float u, v;
} DisplacementTexcoord;

/* One quad patch for the tessellator. Corner k is at uv (0,0), (1,0), (1,1), (0,1); edge k runs
 * from corner k to corner k+1. The map is a grid of columns x rows samples spanning the face from
 * corner to corner (sample (0,0) at uv (0,0), (columns-1, rows-1) at uv (1,1)); columns == 0:
 * the face has no displacement. */
typedef struct {
  cl_uint vertex[4];              /* mesh vertices: positions and normals */
  cl_int neighbor[4];             /* face across edge k, -1 at a boundary */
  cl_int neighbor_edge[4];        /* that face's index of the shared edge */
  cl_int neighbor_same_way[4];    /* 1: its edge runs the same way as ours (a mirrored neighbour) */
  cl_float corner_value[4];       /* zipper: the displacement every patch uses at corner k */
  DisplacementTexcoord texcoord[4][4]; /* ownership: corner k; 0 own, 1 edge k's owner, 2 edge (k+3)%4's, 3 the corner's */
  cl_uint map_offset;             /* first sample in the samples buffer */
  cl_int columns, rows;
  cl_int inner_factor;            /* 0: uniform, every edge and the inside at T; else the inside's factor */
  cl_int edge_factor[4];          /* adaptive: edge k's factor 1..T, the same in both patches of the edge */
} DisplacementPatch;

/* Per tessellation, read-only. */
typedef struct {
  cl_int tessellation;   /* T: every patch is a (T+1)^2 grid of slots, 1..SEAMCL_MAX_TESSELLATION */
  cl_int method;         /* SEAMCL_DISPLACEMENT_* */
  cl_int patches;        /* patches in the buffer */
  cl_float scale;        /* world units per unit of displacement (samples / 65535) */
} TessellationParams;

/* One tessellated vertex: displaced world position and the patch's own uv (for colour). */
typedef struct {
  cl_float position[3];
  cl_float u, v;
  cl_float displacement; /* in [0, 1], before scale */
  cl_uint samples;       /* map samples taken for it (cost) */
  cl_uint pad0;
} TessVertex;

/* Shading of a displacement render with the displaced surface's normals (kernels/shade_resolve.cl):
 * a micro-triangle's normal at a point is its three vertices' normals (tessellate.cl's
 * displaced_normals) interpolated by the point's barycentrics in the domain, renormalised. */
typedef struct {
  cl_int tessellation;   /* T of the slot grid (TessellationParams.tessellation); 0: the face's own normal */
  cl_int adaptive;       /* 1: cells (T-1, 0) and (0, T-1) split on their 10-01 diagonal (tessellated_setup) */
  cl_int pad0, pad1;
} DisplacedShading;

/* Ptex's own separable filters (ptex_filter.cl): a texture as the Ptex library filters it. Every
 * face holds every resolution 2^i x 2^j (i <= ulog2, j <= vlog2) that the library would read, made
 * by its own reduction rules, in the file's units and channel order. */
#define SEAMCL_PTEX_KMAX 10          /* taps per axis of a kernel (Ptex's PtexSeparableKernel::kmax) */
/* Bytes of padding after the last texel value: the filter reads rows 16 values at a time, up to 15
 * values (of up to 4 bytes) past a row's end. */
#define SEAMCL_PTEX_TEXEL_TAIL 64
/* Queries a work-item of ptex_filter_lookups looks up (vector lanes; its fast path's vectors are 16 wide). */
#define SEAMCL_PTEX_LOOKUP_LANES 16
#define SEAMCL_PTEX_MAX_VALENCE 10   /* faces walked around a corner (Ptex's MaxValence) */
#define SEAMCL_PTEX_POINT 0
#define SEAMCL_PTEX_BILINEAR 1
#define SEAMCL_PTEX_BOX 2
#define SEAMCL_PTEX_GAUSSIAN 3
#define SEAMCL_PTEX_BICUBIC 4        /* sharpness 0: B-spline, 1: Catmull-Rom, 2/3: Mitchell */
#define SEAMCL_PTEX_FLAG_CONSTANT 1u
#define SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT 4u
#define SEAMCL_PTEX_FLAG_SUBFACE 8u
typedef struct {
  cl_int adj_faces[4];   /* bottom, right, top, left; -1 none */
  cl_int ulog2;
  cl_int vlog2;
  cl_uint adj_edges;     /* 2 bits per edge: the neighbour's edge */
  cl_uint flags;         /* SEAMCL_PTEX_FLAG_* */
  cl_uint level_base;    /* index of the face's first level offset; level (i, j) at + i * (vlog2 + 1) + j */
  cl_uint pad0;
} PtexFilterFace;

typedef struct {
  cl_int data_type;        /* 0 uint8, 1 uint16, 2 float16, 3 float32 */
  cl_int channels;         /* 1 to 4 */
  cl_int u_border_mode;    /* 0 clamp, 1 black, 2 periodic */
  cl_int v_border_mode;
  cl_int edge_filter_mode; /* 0 none, 1 tanvec */
  cl_int face_count;
  cl_float one_value;      /* 255, 65535 or 1: a texel's value for 1.0 */
  cl_int seams;            /* SEAMCL_PTEX_SEAMS_*: 0 (Ptex's own) for lookups; a render's seam method */
} PtexFilterTexture;

/* How a Ptex filter treats face edges. PTEX: the library's rules (neighbours, corners, the file's
 * border modes). The others walk no neighbour: every face edge is a boundary whose taps are merged
 * onto the edge texels (CLAMP), dropped (BLACK: the edge darkens) or dropped with the rest
 * renormalised (DISCARD), and a point outside the face is clamped into it. */
#define SEAMCL_PTEX_SEAMS_PTEX 0
#define SEAMCL_PTEX_SEAMS_CLAMP 1
#define SEAMCL_PTEX_SEAMS_BLACK 2
#define SEAMCL_PTEX_SEAMS_DISCARD 3

/* A render's Ptex filter (shade_resolve.cl built with SEAMCL_SAMPLER_FILTER = SEAMCL_FILTER_PTEX):
 * every fragment looks up (face, u, v, uw, vw) with uw = (|du/dx| + |du/dy|) * width_scale and
 * vw = (|dv/dx| + |dv/dy|) * width_scale, as PtexFilter::eval sums a renderer's derivatives. */
typedef struct {
  PtexFilterTexture texture; /* with seams: the render's seam method */
  cl_int filter;             /* SEAMCL_PTEX_* */
  cl_float sharpness;        /* SEAMCL_PTEX_BICUBIC only */
  cl_float width_scale;      /* Ptex's `width` option: 2^lod_bias */
  cl_int rgb_source[3];      /* the file's channel shown as red, green, blue; -1: 0 */
} PtexShading;

typedef struct {
  cl_int face;
  cl_int filter;           /* SEAMCL_PTEX_* */
  cl_float u, v;           /* in the face, 0..1 */
  cl_float uw, vw;         /* filter widths in face units */
  cl_float sharpness;      /* SEAMCL_PTEX_BICUBIC only */
  cl_int pad0;
} PtexFilterQuery;

#endif
