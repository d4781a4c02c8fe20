/* Stage 0 (displacement renders only): tessellation. Three kernels.
 *
 * tessellate: one work-item per output vertex, patch p's vertex (i, j) at
 * p * (T+1)^2 + j * (T+1) + i (T = params->tessellation, 1..SEAMCL_MAX_TESSELLATION).
 *   1. Domain point (u, v). naive: i/T, j/T in float. The other methods: fixed point
 *      (SEAMCL_DOMAIN_ONE = 1); a point on edge e is computed from the edge's end with the lower
 *      mesh vertex index and mirrored at the other end, so both patches on the edge make the same
 *      point (the D3D11 tessellator's rule). Uniform (inner_factor 0): every edge at T.
 *      Adaptive (inner_factor > 0): the (T+1)^2 slots stay, T the largest factor; slot k of edge e
 *      (counted from the lower end) is step tess_step(k, edge_factor[e], T) of that edge, a step
 *      0 or F being the corner itself; slot (i, j) inside is point (a, b) / F_in of the inner
 *      grid, a = tess_step(i, F_in, T) clamped to 1..F_in-1. Slots that land on one point make
 *      degenerate micro-triangles (setup culls them); the ring of cells along the edges is the
 *      transition strip from each edge's factor to the inside's.
 *   2. Base surface: bilinear in the patch's corner positions and vertex normals.
 *   3. Displacement h in [0, 1] by the method (SEAMCL_DISPLACEMENT_*): naive and fixed sample the
 *      patch's own map (float bilinear / exact integer bilinear), zipper averages both sides'
 *      samples on an edge and takes corner_value at a corner, ownership interpolates the owners'
 *      texcoords with the post's index formulas and samples once, ptex-filter filters across
 *      edges into the neighbours' maps (disp_sample_across_edges).
 *   4. position = base + unit normal * (scale * h); uv = the domain point (for colour textures).
 * Host guarantees: patches, samples, positions, normals as packed by
 * host/pipeline/displacement_packing.cpp; output holds patches * (T+1)^2 TessVertex.
 *
 * tessellated_setup: triangle setup (kernels/triangle_setup.cl's clipping, snapping, culling and
 * planes, whose helpers it calls) of micro-triangle t: patch t / (2 T^2), cell c = (t / 2) % T^2
 * at (c % T, c / T), split as the quads are: (00, 10, 11) for even t and (00, 11, 01) for odd t;
 * adaptive, the cells (T-1, 0) and (0, T-1) split the other way, (00, 10, 01) and (10, 11, 01): there
 * the inner grid's corner point may lie on the patch corner's side of the 00-11 diagonal, which
 * would turn a triangle over, while 10-01 passes through that point.
 * Every record's face is the patch, so shading reads the patch's colour texture and seam method.
 *
 * displaced_normals: one work-item per tessellated vertex, after tessellate; the unit normal of the
 * displaced surface there, which shading interpolates across each micro-triangle. The sum of the
 * cross products (v1 - v0) x (v2 - v0) (twice the area-weighted normal) of the micro-triangles
 * around the slot, split as tessellated_setup splits them, summed over every copy of the point in
 * (patch, j, i) order: inside a patch only its own slot; on a shared edge also the neighbour's slot
 * at the same step; at a patch corner the corner of every patch at that mesh vertex (corner_copies
 * from corner_offsets[vertex], packed in that order). Each copy's ring is read at that patch's own
 * vertices except the point itself, which is this slot's position, so two patches whose copies of
 * a point and of its ring agree bit for bit (the watertight methods) get the same bits. Then
 * divided by its length; a zero or non-finite sum gives (0, 0, 0). w = 0.
 * Twin: displaced_normal (host/eval/displacement_metrics.cpp): the sums are bit-exact (no
 * contraction, the same order); the normalisation is exact where sqrt and division are correctly
 * rounded (PoCL), else within their OpenCL 1.2 bounds (3 and 2.5 ulp).
 * Host guarantees (displaced_normals): vertices from tessellate of these patches; corner_offsets
 * holds positions + 1 entries; corner_copies entries patch * 4 + corner.
 * Twins: host/pipeline/stages/tessellate_twin.cpp (tessellate); tessellated_setup at T = 1
 * without displacement equals triangle_setup exactly (tests/test_displacement.cpp). */

SEAMCL_INLINE float disp_texel(__global const ushort* s, int columns, int i, int j) {
  return (float)s[j * columns + i];
}

SEAMCL_INLINE float disp_sample_float(__global const ushort* s, int columns, int rows, float u, float v) {
  if (columns == 0) return 0.0f;
  const float x = u * (float)(columns - 1);
  const float y = v * (float)(rows - 1);
  int i0 = (int)x, j0 = (int)y;
  i0 = i0 > columns - 2 ? columns - 2 : i0;
  j0 = j0 > rows - 2 ? rows - 2 : j0;
  i0 = i0 < 0 ? 0 : i0;
  j0 = j0 < 0 ? 0 : j0;
  const int i1 = columns > 1 ? i0 + 1 : 0, j1 = rows > 1 ? j0 + 1 : 0;
  const float fx = columns > 1 ? x - (float)i0 : 0.0f;
  const float fy = rows > 1 ? y - (float)j0 : 0.0f;
  const float bottom = (1.0f - fx) * disp_texel(s, columns, i0, j0) + fx * disp_texel(s, columns, i1, j0);
  const float top = (1.0f - fx) * disp_texel(s, columns, i0, j1) + fx * disp_texel(s, columns, i1, j1);
  return ((1.0f - fy) * bottom + fy * top) * (1.0f / 65535.0f);
}

SEAMCL_INLINE float disp_sample_exact(__global const ushort* s, int columns, int rows, long u, long v) {
  if (columns == 0) return 0.0f;
  const long one = SEAMCL_DOMAIN_ONE;
  const long xn = u * (long)(columns - 1), yn = v * (long)(rows - 1);
  long i0 = xn >> 16, j0 = yn >> 16, fx = xn & (one - 1), fy = yn & (one - 1);
  if (columns == 1) { i0 = 0; fx = 0; } else if (i0 >= columns - 1) { i0 = columns - 2; fx = one; }
  if (rows == 1) { j0 = 0; fy = 0; } else if (j0 >= rows - 1) { j0 = rows - 2; fy = one; }
  const long i1 = columns > 1 ? i0 + 1 : 0, j1 = rows > 1 ? j0 + 1 : 0;
  const long bottom = (long)s[j0 * columns + i0] * (one - fx) + (long)s[j0 * columns + i1] * fx;
  const long top = (long)s[j1 * columns + i0] * (one - fx) + (long)s[j1 * columns + i1] * fx;
  const long numerator = bottom * (one - fy) + top * fy;
  return (float)numerator * (1.0f / 4294967296.0f) * (1.0f / 65535.0f);
}

/* Adaptive factors: slot k of T slots at factor f (1..T) is step k * f / T, rounded half up, so
 * slots 0 and T are steps 0 and f and neighbouring slots differ by at most one step. */
SEAMCL_INLINE int tess_step(int k, int f, int t) { return (2 * k * f + t) / (2 * t); }

/* Adaptive: a slot on edge e whose step is 0 or the edge's factor is that corner's slot. */
SEAMCL_INLINE void tess_collapse_to_corner(__global const DisplacementPatch* p, int t, int* i, int* j) {
  int e = -1, step = 0;
  if ((*i == 0 || *i == t) && (*j == 0 || *j == t)) return;
  if (*j == 0) { e = 0; step = *i; }
  else if (*i == t) { e = 1; step = *j; }
  else if (*j == t) { e = 2; step = t - *i; }
  else if (*i == 0) { e = 3; step = t - *j; }
  if (e < 0) return;
  const int f = p->edge_factor[e];
  const int lower_first = p->vertex[e] < p->vertex[(e + 1) % 4];
  const int m = tess_step(lower_first ? step : t - step, f, t);
  const int from_e = lower_first ? m : f - m;
  if (from_e != 0 && from_e != f) return;
  const int c = from_e == 0 ? e : (e + 1) % 4;
  *i = (c == 1 || c == 2) ? t : 0;
  *j = c >= 2 ? t : 0;
}

SEAMCL_INLINE void disp_edge_uv(int e, long s, long* u, long* v) {
  const long one = SEAMCL_DOMAIN_ONE;
  if (e == 0) { *u = s; *v = 0; }
  else if (e == 1) { *u = one; *v = s; }
  else if (e == 2) { *u = one - s; *v = one; }
  else { *u = 0; *v = one - s; }
}

/* ptex-filter: a 3x3 tent (1/4, 1/2, 1/4 per axis) of taps one own sample spacing apart; a tap
 * past edge e reads the neighbour at the same depth past its side; taps past a corner or a
 * boundary are dropped; the sum is renormalised. */
SEAMCL_INLINE float disp_sample_across_edges(__global const DisplacementPatch* patches, __global const ushort* samples,
                                             int face, float u, float v, uint* taken) {
  __global const DisplacementPatch* p = &patches[face];
  const int columns = p->columns, rows = p->rows;
  if (columns == 0) return 0.0f;
  __global const ushort* own = samples + p->map_offset;
  const float rx = columns > 1 ? 1.0f / (float)(columns - 1) : 0.0f;
  const float ry = rows > 1 ? 1.0f / (float)(rows - 1) : 0.0f;
  const float tent[3] = {0.25f, 0.5f, 0.25f};
  float sum = 0.0f, weight = 0.0f;
  for (int b = 0; b < 3; ++b) {
    for (int a = 0; a < 3; ++a) {
      const float w = tent[a] * tent[b];
      const float tu = u + (float)(a - 1) * rx, tv = v + (float)(b - 1) * ry;
      const int out_u = tu < 0.0f ? 3 : tu > 1.0f ? 1 : -1, out_v = tv < 0.0f ? 0 : tv > 1.0f ? 2 : -1;
      if (out_u < 0 && out_v < 0) {
        sum = sum + w * disp_sample_float(own, columns, rows, tu, tv);
        weight = weight + w;
        *taken += 1;
        continue;
      }
      if (out_u >= 0 && out_v >= 0) continue;
      const int e = out_u >= 0 ? out_u : out_v;
      const int n = p->neighbor[e];
      if (n < 0) continue;
      const float s = e == 0 ? tu : e == 1 ? tv : e == 2 ? 1.0f - tu : 1.0f - tv;
      const float depth = e == 0 ? -tv : e == 1 ? tu - 1.0f : e == 2 ? tv - 1.0f : -tu;
      const float sn = p->neighbor_same_way[e] ? s : 1.0f - s;
      const int m = p->neighbor_edge[e];
      const float nu = m == 0 ? sn : m == 1 ? 1.0f - depth : m == 2 ? 1.0f - sn : depth;
      const float nv = m == 0 ? depth : m == 1 ? sn : m == 2 ? 1.0f - depth : 1.0f - sn;
      __global const DisplacementPatch* q = &patches[n];
      if (q->columns == 0) continue;
      sum = sum + w * disp_sample_float(samples + q->map_offset, q->columns, q->rows, nu, nv);
      weight = weight + w;
      *taken += 1;
    }
  }
  return weight > 0.0f ? sum / weight : 0.0f;
}

__kernel void tessellate(__constant TessellationParams* params, __global const DisplacementPatch* patches,
                         __global const ushort* samples, __global const float4* positions,
                         __global const float4* normals, __global TessVertex* out) {
  const int t = params->tessellation;
  const int side = t + 1;
  const int id = (int)get_global_id(0);
  if (id >= params->patches * side * side) return;
  const int patch = id / (side * side);
  int i = (id % (side * side)) % side, j = (id % (side * side)) / side;
  __global const DisplacementPatch* p = &patches[patch];
  const long one = SEAMCL_DOMAIN_ONE;
  const float inv_one = 1.0f / (float)SEAMCL_DOMAIN_ONE;
  const int method = params->method;
  const int adaptive = p->inner_factor > 0;

  /* 1. Domain point */
  if (adaptive) tess_collapse_to_corner(p, t, &i, &j);
  int edge = -1, step = 0;
  const int corner = (i == 0 || i == t) && (j == 0 || j == t);
  if (!corner) {
    if (j == 0) { edge = 0; step = i; }
    else if (i == t) { edge = 1; step = j; }
    else if (j == t) { edge = 2; step = t - i; }
    else if (i == 0) { edge = 3; step = t - j; }
  }
  long uf = (long)i * one / t, vf = (long)j * one / t;
  float naive_u = (float)i / (float)t, naive_v = (float)j / (float)t;
  long s = 0;
  if (edge >= 0) {
    const int lower_first = p->vertex[edge] < p->vertex[(edge + 1) % 4];
    if (adaptive) {
      const int f = p->edge_factor[edge];
      const int m = tess_step(lower_first ? step : t - step, f, t);
      s = lower_first ? (long)m * one / f : one - (long)m * one / f;
      const float ns = (float)(lower_first ? m : f - m) / (float)f;
      naive_u = edge == 0 ? ns : edge == 1 ? 1.0f : edge == 2 ? 1.0f - ns : 0.0f;
      naive_v = edge == 0 ? 0.0f : edge == 1 ? ns : edge == 2 ? 1.0f : 1.0f - ns;
    } else {
      s = lower_first ? (long)step * one / t : one - (long)(t - step) * one / t;
    }
    disp_edge_uv(edge, s, &uf, &vf);
  } else if (adaptive && !corner) {
    const int f = p->inner_factor;
    const int a = clamp(tess_step(i, f, t), 1, f - 1), b = clamp(tess_step(j, f, t), 1, f - 1);
    uf = (long)a * one / f;
    vf = (long)b * one / f;
    naive_u = (float)a / (float)f;
    naive_v = (float)b / (float)f;
  }
  const int naive = method == SEAMCL_DISPLACEMENT_NAIVE;
  const float u = naive ? naive_u : (float)uf * inv_one;
  const float v = naive ? naive_v : (float)vf * inv_one;

  /* 2. Base surface */
  float w[4];
  w[0] = (1.0f - u) * (1.0f - v);
  w[1] = u * (1.0f - v);
  w[2] = u * v;
  w[3] = (1.0f - u) * v;
  float px = 0.0f, py = 0.0f, pz = 0.0f, nx = 0.0f, ny = 0.0f, nz = 0.0f;
  for (int k = 0; k < 4; ++k) {
    const float4 P = positions[p->vertex[k]];
    const float4 N = normals[p->vertex[k]];
    px = px + w[k] * P.x;
    py = py + w[k] * P.y;
    pz = pz + w[k] * P.z;
    nx = nx + w[k] * N.x;
    ny = ny + w[k] * N.y;
    nz = nz + w[k] * N.z;
  }
  const float length = sqrt(nx * nx + ny * ny + nz * nz);
  const float inv_length = length > 0.0f ? 1.0f / length : 0.0f;

  /* 3. Displacement */
  __global const ushort* own = samples + p->map_offset;
  const int columns = p->columns, rows = p->rows;
  float h = 0.0f;
  uint taken = 0;
  if (method == SEAMCL_DISPLACEMENT_NAIVE) {
    h = disp_sample_float(own, columns, rows, u, v);
    taken = columns > 0;
  } else if (method == SEAMCL_DISPLACEMENT_FIXED) {
    h = disp_sample_exact(own, columns, rows, uf, vf);
    taken = columns > 0;
  } else if (method == SEAMCL_DISPLACEMENT_PTEX_FILTER) {
    h = disp_sample_across_edges(patches, samples, patch, u, v, &taken);
  } else if (method == SEAMCL_DISPLACEMENT_ZIPPER) {
    if (corner) {
      h = p->corner_value[i == 0 ? (j == 0 ? 0 : 3) : (j == 0 ? 1 : 2)];
    } else if (edge >= 0 && p->neighbor[edge] >= 0) {
      __global const DisplacementPatch* q = &patches[p->neighbor[edge]];
      long ou = 0, ov = 0;
      disp_edge_uv(p->neighbor_edge[edge], p->neighbor_same_way[edge] ? s : one - s, &ou, &ov);
      const float mine = disp_sample_float(own, columns, rows, u, v);
      const float theirs = disp_sample_float(samples + q->map_offset, q->columns, q->rows, (float)ou * inv_one, (float)ov * inv_one);
      h = (mine + theirs) * 0.5f;
      taken = (uint)(columns > 0) + (uint)(q->columns > 0);
    } else {
      h = disp_sample_float(own, columns, rows, u, v);
      taken = columns > 0;
    }
  } else {
    /* ownership: the post's index formulas over corners (0,0), (1,0), (1,1), (0,1) */
    const int x0 = uf == 0, x1 = uf == one, y0 = vf == 0, y1 = vf == one;
    int index[4];
    index[0] = 2 * x0 + y0;
    index[1] = 2 * y0 + x1;
    index[2] = 2 * x1 + y1;
    index[3] = 2 * y1 + x0;
    float tu = 0.0f, tv = 0.0f, heaviest = 0.0f;
    int face = -1;
    for (int k = 0; k < 4; ++k) {
      const DisplacementTexcoord tc = p->texcoord[k][index[k]];
      tu = tu + w[k] * tc.u;
      tv = tv + w[k] * tc.v;
      if (w[k] > heaviest) {
        heaviest = w[k];
        face = tc.face;
      }
    }
    if (face >= 0) {
      __global const DisplacementPatch* q = &patches[face];
      h = disp_sample_float(samples + q->map_offset, q->columns, q->rows, tu, tv);
      taken = q->columns > 0;
    }
  }

  /* 4. Displace along the unit normal */
  const float offset = params->scale * h;
  TessVertex r;
  r.position[0] = px + (nx * inv_length) * offset;
  r.position[1] = py + (ny * inv_length) * offset;
  r.position[2] = pz + (nz * inv_length) * offset;
  r.u = u;
  r.v = v;
  r.displacement = h;
  r.samples = taken;
  r.pad0 = 0;
  out[id] = r;
}

/* The setup of micro-triangles, SEAMCL_SETUP_LANES per work-item: the same cull and setup of the
 * ones inside all planes on vectors as triangle_setup (setup_lanes), the clipped ones one by one
 * through clip_and_setup, with the patch as the record's face. Each writes its fan's slots and
 * slot_counts[tri] (its fan's size) as triangle_setup does; writing all six slots, and binning
 * reading them, was most of the frame at T = 32. */
__kernel __attribute__((reqd_work_group_size(SEAMCL_SETUP_GROUP, 1, 1)))
void tessellated_setup(__constant FrameParams* frame, __constant TessellationParams* params,
                       __global const TessVertex* vertices, __global TriangleSetup* out,
                       __global uint* slot_counts, __global FrameStats* stats, int adaptive) {
  __local uint group_visible[SEAMCL_SETUP_GROUP];
  const int triangles = frame->input_triangles; /* > 0: the host runs no setup without triangles */
  const int t = params->tessellation;
  const int t0 = (int)get_global_id(0) * SEAMCL_SETUP_LANES;
  const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const int16 tri = t0 + lane;
  const int16 in_range = tri < triangles;
  /* Lanes past the last micro-triangle read the last one and count for nothing. */
  const int16 read_tri = min(tri, triangles - 1);
  /* Cell (ci, cj) of the patch's (T+1)^2 grid, corners 0 = (ci, cj), 1 = (ci+1, cj),
   * 2 = (ci+1, cj+1), 3 = (ci, cj+1); an even micro-triangle takes corners 0, 1, 2, an odd one 0, 2, 3. */
  const int side = t + 1;
  const int16 patch = read_tri / (2 * t * t);
  const int16 cell = (read_tri / 2) % (t * t);
  const int16 odd = (read_tri & 1) != 0;
  const int16 base = patch * (side * side) + (cell / t) * side + cell % t;
  const int16 cx = cell % t, cy = cell / t;
  const int16 flip = (((cx == t - 1) & (cy == 0)) | ((cx == 0) & (cy == t - 1))) & (int16)(adaptive && t >= 2 ? -1 : 0);
  const int16 vertex0 = base + select((int16)(0), (int16)(1), odd & flip);
  const int16 vertex1 = base + select((int16)(1), (int16)(side + 1), odd);
  const int16 vertex2 = select(base + select((int16)(side + 1), (int16)(side), odd), base + side, flip);
#define TESS_X0(i) vertices[vertex0[i]].position[0]
#define TESS_Y0(i) vertices[vertex0[i]].position[1]
#define TESS_Z0(i) vertices[vertex0[i]].position[2]
#define TESS_U0(i) vertices[vertex0[i]].u
#define TESS_V0(i) vertices[vertex0[i]].v
#define TESS_X1(i) vertices[vertex1[i]].position[0]
#define TESS_Y1(i) vertices[vertex1[i]].position[1]
#define TESS_Z1(i) vertices[vertex1[i]].position[2]
#define TESS_U1(i) vertices[vertex1[i]].u
#define TESS_V1(i) vertices[vertex1[i]].v
#define TESS_X2(i) vertices[vertex2[i]].position[0]
#define TESS_Y2(i) vertices[vertex2[i]].position[1]
#define TESS_Z2(i) vertices[vertex2[i]].position[2]
#define TESS_U2(i) vertices[vertex2[i]].u
#define TESS_V2(i) vertices[vertex2[i]].v
  int16 clipped, early_culled;
  uint visible = setup_lanes(
      frame, tri, in_range, (float16)SETUP_LANES_OF(TESS_X0), (float16)SETUP_LANES_OF(TESS_Y0),
      (float16)SETUP_LANES_OF(TESS_Z0), (float16)SETUP_LANES_OF(TESS_X1), (float16)SETUP_LANES_OF(TESS_Y1),
      (float16)SETUP_LANES_OF(TESS_Z1), (float16)SETUP_LANES_OF(TESS_X2), (float16)SETUP_LANES_OF(TESS_Y2),
      (float16)SETUP_LANES_OF(TESS_Z2), (float16)SETUP_LANES_OF(TESS_U0), (float16)SETUP_LANES_OF(TESS_V0),
      (float16)SETUP_LANES_OF(TESS_U1), (float16)SETUP_LANES_OF(TESS_V1), (float16)SETUP_LANES_OF(TESS_U2),
      (float16)SETUP_LANES_OF(TESS_V2), convert_uint16(patch), out, slot_counts, &clipped,
      &early_culled);
#undef TESS_X0
#undef TESS_Y0
#undef TESS_Z0
#undef TESS_U0
#undef TESS_V0
#undef TESS_X1
#undef TESS_Y1
#undef TESS_Z1
#undef TESS_U1
#undef TESS_V1
#undef TESS_X2
#undef TESS_Y2
#undef TESS_Z2
#undef TESS_U2
#undef TESS_V2
  /* Micro-triangles that cross a plane: clipped one by one, only the fan's slots written. */
  for (int i = 0; i < SEAMCL_SETUP_LANES; ++i) {
    if (!clipped[i]) continue;
    const int id[3] = {vertex0[i], vertex1[i], vertex2[i]};
    ClipVertex polygon[3 + 5];
    for (int k = 0; k < 3; ++k) {
      const TessVertex tv = vertices[id[k]];
      const __constant float* m = frame->view_proj;
      polygon[k].x = m[0] * tv.position[0] + m[4] * tv.position[1] + m[8] * tv.position[2] + m[12];
      polygon[k].y = m[1] * tv.position[0] + m[5] * tv.position[1] + m[9] * tv.position[2] + m[13];
      polygon[k].w = m[3] * tv.position[0] + m[7] * tv.position[1] + m[11] * tv.position[2] + m[15];
      polygon[k].u = tv.u;
      polygon[k].v = tv.v;
    }
    uint fan = 0;
    visible += clip_and_setup(polygon, (uint)patch[i], frame, out + tri[i], (size_t)triangles, 0, &fan);
    slot_counts[tri[i]] = fan;
  }
  group_visible[get_local_id(0)] = visible;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) {
    uint sum = 0;
    for (int i = 0; i < SEAMCL_SETUP_GROUP; ++i) sum += group_visible[i];
    if (sum > 0) atomic_add(&stats->visible_triangles, sum);
  }
}


/* Adds the cross products of the micro-triangles of patch q around its slot (qi, qj), cells in
 * (cj, ci) order, each cell's two triangles in split order, the slot itself read as `own`. */
SEAMCL_INLINE void normal_ring_sum(__global const TessVertex* vertices, const float* own, int q, int qi, int qj,
                                   int t, int adaptive, float* n) {
  for (int cj = qj - 1; cj <= qj; ++cj) {
    for (int ci = qi - 1; ci <= qi; ++ci) {
      if (ci < 0 || cj < 0 || ci >= t || cj >= t) continue;
      const int flipped = tess_cell_flipped(ci, cj, t, adaptive);
      for (int odd = 0; odd < 2; ++odd) {
        float p[3][3];
        int touches = 0;
        for (int k = 0; k < 3; ++k) {
          int di = 0, dj = 0;
          tess_cell_corner(odd, k, flipped, &di, &dj);
          const int gi = ci + di, gj = cj + dj;
          const int centre = gi == qi && gj == qj;
          touches |= centre;
          __global const float* at = vertices[tess_vertex_index(q, gi, gj, t)].position;
          for (int c = 0; c < 3; ++c) p[k][c] = centre ? own[c] : at[c];
        }
        if (!touches) continue;
        const float ax = p[1][0] - p[0][0], ay = p[1][1] - p[0][1], az = p[1][2] - p[0][2];
        const float bx = p[2][0] - p[0][0], by = p[2][1] - p[0][1], bz = p[2][2] - p[0][2];
        n[0] = n[0] + (ay * bz - az * by);
        n[1] = n[1] + (az * bx - ax * bz);
        n[2] = n[2] + (ax * by - ay * bx);
      }
    }
  }
}

/* Whether copy (pa, ja, ia) comes before (pb, jb, ib): by patch, then row, then column. */
SEAMCL_INLINE int grid_point_before(int pa, int ia, int ja, int pb, int ib, int jb) {
  return pa != pb ? pa < pb : (ja != jb ? ja < jb : ia < ib);
}

__kernel void displaced_normals(__constant TessellationParams* params, __global const DisplacementPatch* patches,
                                __global const uint* corner_offsets, __global const uint* corner_copies,
                                __global const TessVertex* vertices, int adaptive, __global float4* normals) {
  const int t = params->tessellation;
  const int side = t + 1;
  const int id = (int)get_global_id(0);
  if (id >= params->patches * side * side) return;
  const int patch = id / (side * side);
  const int i = (id % (side * side)) % side, j = (id % (side * side)) / side;
  __global const DisplacementPatch* p = &patches[patch];
  float own[3];
  for (int c = 0; c < 3; ++c) own[c] = vertices[id].position[c];
  float n[3] = {0.0f, 0.0f, 0.0f};
  const int corner = (i == 0 || i == t) && (j == 0 || j == t);
  if (corner) {
    const int c = j == 0 ? (i == 0 ? 0 : 1) : (i == t ? 2 : 3);
    const uint vertex = p->vertex[c];
    for (uint e = corner_offsets[vertex]; e < corner_offsets[vertex + 1]; ++e) {
      const int q = (int)(corner_copies[e] / 4u), qc = (int)(corner_copies[e] % 4u);
      normal_ring_sum(vertices, own, q, (qc == 1 || qc == 2) ? t : 0, qc >= 2 ? t : 0, t, adaptive, n);
    }
  } else {
    int e = -1, k = 0;
    if (j == 0) { e = 0; k = i; }
    else if (i == t) { e = 1; k = j; }
    else if (j == t) { e = 2; k = t - i; }
    else if (i == 0) { e = 3; k = t - j; }
    int q = -1, qi = 0, qj = 0;
    if (e >= 0 && p->neighbor[e] >= 0) {
      q = p->neighbor[e];
      const int step = p->neighbor_same_way[e] ? k : t - k;
      const int qe = p->neighbor_edge[e];
      qi = qe == 0 ? step : qe == 1 ? t : qe == 2 ? t - step : 0;
      qj = qe == 0 ? 0 : qe == 1 ? step : qe == 2 ? t : t - step;
    }
    const int neighbour_first = q >= 0 && grid_point_before(q, qi, qj, patch, i, j);
    if (neighbour_first) normal_ring_sum(vertices, own, q, qi, qj, t, adaptive, n);
    normal_ring_sum(vertices, own, patch, i, j, t, adaptive, n);
    if (q >= 0 && !neighbour_first) normal_ring_sum(vertices, own, q, qi, qj, t, adaptive, n);
  }
  const float length = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const int usable = length > 0.0f && isfinite(length);
  normals[id] = usable ? (float4)(n[0] / length, n[1] / length, n[2] / length, 0.0f) : (float4)(0.0f);
}
