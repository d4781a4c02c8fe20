/* Stage 1: triangle setup. One work-item per SEAMCL_SETUP_LANES input triangles t (face t/2; t
 * even: quad corners 0,1,2, t odd: 0,2,3), side by side in vectors; each triangle owns
 * SEAMCL_CLIP_SLOTS TriangleSetup records, slot k at k * input_triangles + t (slot-major,
 * kernels/seamcl_types.h: unclipped triangles' records dense).
 *
 * slot_counts[t]: how many of t's slots were written (0 .. SEAMCL_CLIP_SLOTS; later ones hold
 * stale data and count as empty): 1 or 0 for a triangle that needs no clipping, the size of its
 * fan for a clipped one; binning reads only those (tessellate.cl's tessellated_setup writes it the
 * same way, its fan's size).
 * Inputs: positions (world, xyz of float4), faces, frame (view_proj, image size, clip planes).
 * Steps: transform to clip space; clip against w >= near_w and the guard band |x| <= guard_x w,
 * |y| <= guard_y w (Sutherland-Hodgman; the host sizes the guard band so that snapped coordinates
 * and edge-function products fit in 64 bits); project to screen (pixels, y down); snap to
 * 1/SEAMCL_SUBPIXEL_ONE pixel; cull back faces (front = counter-clockwise in NDC, y up), zero
 * area and triangles whose bounding box holds no sample position of the frame's pattern; build
 * edge functions with the top-left rule and perspective-correct attribute planes.
 * An early cull (back faces, zero area, boxes past an image side, for triangles inside all
 * planes; triangles wholly outside one plane) and the whole setup of triangles inside all planes
 * (the common case) run on the vectors, with the same steps as the scalar setup_snapped_triangle;
 * only triangles that cross a plane take the scalar clip_and_setup, one by one.
 * stats->early_culled counts the triangles the early cull stopped (its twin:
 * early_culled_reference), stats->visible_triangles the visible slots.
 * A new vertex on an edge is always computed from the edge's inside end, so two triangles that
 * share the edge create bit-identical vertices: clipping keeps the mesh watertight.
 * Twin: host/pipeline/stages/triangle_setup_twin.cpp. */

typedef struct {
  float x, y, w; /* clip space (z is not needed: depth is 1/w) */
  float u, v;
} ClipVertex;

SEAMCL_INLINE float clip_distance(ClipVertex p, int plane, __constant FrameParams* frame) {
  switch (plane) {
    case 0: return p.w - frame->near_w;
    case 1: return frame->guard_x * p.w - p.x;
    case 2: return frame->guard_x * p.w + p.x;
    case 3: return frame->guard_y * p.w - p.y;
    default: return frame->guard_y * p.w + p.y;
  }
}

SEAMCL_INLINE ClipVertex clip_lerp(ClipVertex inside, ClipVertex outside, float d_inside, float d_outside) {
  const float t = d_inside / (d_inside - d_outside);
  ClipVertex r;
  r.x = inside.x + t * (outside.x - inside.x);
  r.y = inside.y + t * (outside.y - inside.y);
  r.w = inside.w + t * (outside.w - inside.w);
  r.u = inside.u + t * (outside.u - inside.u);
  r.v = inside.v + t * (outside.v - inside.v);
  return r;
}

SEAMCL_INLINE long floor_div_subpixel(long value) {
  /* floor(value / SEAMCL_SUBPIXEL_ONE) for negative values too */
  return value >= 0 ? value / SEAMCL_SUBPIXEL_ONE : -((-value + SEAMCL_SUBPIXEL_ONE - 1) / SEAMCL_SUBPIXEL_ONE);
}



/* Whether the fixed-point box [min_x, max_x] x [min_y, max_y] holds a sample position of the
 * frame's pattern inside the image. A box is a product of ranges, so sample s lies in it at some
 * pixel iff some column puts its x in [min_x, max_x] and some row its y in [min_y, max_y].
 * A triangle whose box holds no sample covers none: setup culls it, so binning and raster never
 * see it. (Few are culled on paper at 99,037 faces, 85,305 -> 82,220 visible slots: most of
 * setup's saving there comes from writing only the slots it fills.) */
SEAMCL_INLINE int box_holds_sample(long min_x, long max_x, long min_y, long max_y, __constant FrameParams* frame) {
  const int row = sample_pattern_row(frame->sample_count);
  for (int s = 0; s < frame->sample_count; ++s) {
    /* Sample s of pixel p is at p * ONE + centre: the first and last pixel inside the range. */
    const long centre_x = SEAMCL_SUBPIXEL_ONE / 2 + sample_offsets[row][s][0] * (SEAMCL_SUBPIXEL_ONE / 16);
    const long centre_y = SEAMCL_SUBPIXEL_ONE / 2 + sample_offsets[row][s][1] * (SEAMCL_SUBPIXEL_ONE / 16);
    const long first_x = max(-floor_div_subpixel(centre_x - min_x), 0L);
    const long last_x = min(floor_div_subpixel(max_x - centre_x), (long)frame->width - 1);
    const long first_y = max(-floor_div_subpixel(centre_y - min_y), 0L);
    const long last_y = min(floor_div_subpixel(max_y - centre_y), (long)frame->height - 1);
    if (first_x <= last_x && first_y <= last_y) return 1;
  }
  return 0;
}

/* Writes the empty record (bbox_max < bbox_min) of a slot that holds no triangle. */
SEAMCL_INLINE void store_empty_setup(__global TriangleSetup* out, uint face) {
  for (int i = 0; i < 3; ++i) {
    out->edge_a[i] = 0;
    out->edge_b[i] = 0;
    out->edge_c[i] = -1;
    out->inv_w[i] = 0.0f;
    out->u_over_w[i] = 0.0f;
    out->v_over_w[i] = 0.0f;
  }
  out->bbox_min_x = 0;
  out->bbox_min_y = 0;
  out->bbox_max_x = -1;
  out->bbox_max_y = -1;
  out->face = face;
  out->ref_x = 0.0f;
  out->ref_y = 0.0f;
}

/* Screen position of a clip-space vertex in 1/SEAMCL_SUBPIXEL_ONE pixels, before rounding (setup
 * and the early cull round it the same way). */
SEAMCL_INLINE float subpixel_x(float x, float inv_w, __constant FrameParams* frame) {
  const float sx = (x * inv_w * 0.5f + 0.5f) * (float)frame->width;
  return sx * (float)SEAMCL_SUBPIXEL_ONE;
}
SEAMCL_INLINE float subpixel_y(float y, float inv_w, __constant FrameParams* frame) {
  const float sy = (0.5f - y * inv_w * 0.5f) * (float)frame->height;
  return sy * (float)SEAMCL_SUBPIXEL_ONE;
}

/* Edge function i of a setup, from vertex (Xi, Yi) to (Xj, Yj), the top-left rule folded in. */
SEAMCL_INLINE void setup_edge(__global TriangleSetup* s, int i, long Xi, long Yi, long Xj, long Yj) {
  const long a = Yi - Yj;
  const long b = Xj - Xi;
  const int top_left = a > 0 || (a == 0 && b > 0);
  s->edge_a[i] = (int)a;
  s->edge_b[i] = (int)b;
  s->edge_c[i] = -(a * Xi + b * Yi) - (top_left ? 0 : 1);
}

/* The plane of an attribute with values a0, a1, a2 at the three vertices: the value at vertex 0
 * and the screen gradient. */
SEAMCL_INLINE void setup_plane(__global float* plane, float a0, float a1, float a2, float dx1, float dy1, float dx2, float dy2,
                               float inv_det) {
  const float d1 = a1 - a0;
  const float d2 = a2 - a0;
  plane[0] = a0;
  plane[1] = (d1 * dy2 - d2 * dy1) * inv_det;
  plane[2] = (d2 * dx1 - d1 * dx2) * inv_det;
}

/* Setup of one screen triangle from its snapped vertices (X, Y in 1/SEAMCL_SUBPIXEL_ONE pixels),
 * their 1/w and uv, written to *out field by field; returns whether it is visible. A culled one
 * writes the empty record if write_empty, else nothing. setup_screen_triangle snaps clipped
 * triangles and comes here; triangle_setup's vectors take the same steps for the others. Scalars and
 * direct stores only: PoCL keeps a private array or struct that lives in a work-item loop in
 * memory, and narrow stores read back by wider loads stalled (a vertex swap through private
 * arrays, then the record copied whole from a private struct: 24% and 43% of this stage's
 * samples at 99,037 faces, varying from run to run). */
SEAMCL_INLINE int setup_snapped_triangle(__global TriangleSetup* out, int write_empty, long X0, long Y0, long X1,
                                         long Y1, long X2, long Y2, float inv_w0, float inv_w1, float inv_w2, float u0,
                                         float v0, float u1, float v1, float u2, float v2, uint face,
                                         __constant FrameParams* frame) {
  const long area2 = (X1 - X0) * (Y2 - Y0) - (Y1 - Y0) * (X2 - X0);
  /* Vertices 0, 2, 1 in turn (a, b, c) make the interior positive for all three edge functions. */
  const long Xa = X0, Ya = Y0, Xb = X2, Yb = Y2, Xc = X1, Yc = Y1;
  const long min_x = min(min(Xa, Xb), Xc), max_x = max(max(Xa, Xb), Xc);
  const long min_y = min(min(Ya, Yb), Yc), max_y = max(max(Ya, Yb), Yc);
  /* Counter-clockwise in NDC (y up) is clockwise on screen (y down): negative area. A box that
   * holds no sample covers none. */
  if (area2 >= 0 || !box_holds_sample(min_x, max_x, min_y, max_y, frame)) {
    if (write_empty) store_empty_setup(out, face);
    return 0;
  }
  out->face = face;
  setup_edge(out, 0, Xa, Ya, Xb, Yb);
  setup_edge(out, 1, Xb, Yb, Xc, Yc);
  setup_edge(out, 2, Xc, Yc, Xa, Ya);
  /* Samples of pixel p lie in [p*ONE, p*ONE + ONE - 16] (D3D offsets are -8..7 sixteenths). */
  const int sample_span = SEAMCL_SUBPIXEL_ONE - 16;
  out->bbox_min_x = (int)max(floor_div_subpixel(min_x - sample_span + SEAMCL_SUBPIXEL_ONE - 1), 0L);
  out->bbox_min_y = (int)max(floor_div_subpixel(min_y - sample_span + SEAMCL_SUBPIXEL_ONE - 1), 0L);
  out->bbox_max_x = (int)min(floor_div_subpixel(max_x), (long)frame->width - 1);
  out->bbox_max_y = (int)min(floor_div_subpixel(max_y), (long)frame->height - 1);
  /* Attribute planes over the snapped positions, relative to vertex a for precision. */
  const float scale = 1.0f / (float)SEAMCL_SUBPIXEL_ONE;
  const float dx1 = (float)(Xb - Xa) * scale, dy1 = (float)(Yb - Ya) * scale;
  const float dx2 = (float)(Xc - Xa) * scale, dy2 = (float)(Yc - Ya) * scale;
  const float inv_det = 1.0f / ((float)(-area2) * scale * scale);
  out->ref_x = (float)Xa * scale;
  out->ref_y = (float)Ya * scale;
  setup_plane(out->inv_w, inv_w0, inv_w2, inv_w1, dx1, dy1, dx2, dy2, inv_det);
  setup_plane(out->u_over_w, u0 * inv_w0, u2 * inv_w2, u1 * inv_w1, dx1, dy1, dx2, dy2, inv_det);
  setup_plane(out->v_over_w, v0 * inv_w0, v2 * inv_w2, v1 * inv_w1, dx1, dy1, dx2, dy2, inv_det);
  return 1;
}

/* Setup of one screen triangle from three clip-space vertices, written to *out (a culled one: the
 * empty record if write_empty, else nothing); returns whether it is visible. */
SEAMCL_INLINE int setup_screen_triangle(__global TriangleSetup* out, int write_empty, ClipVertex c0, ClipVertex c1,
                                        ClipVertex c2, uint face, __constant FrameParams* frame) {
  const float inv_w0 = 1.0f / c0.w, inv_w1 = 1.0f / c1.w, inv_w2 = 1.0f / c2.w;
  return setup_snapped_triangle(out, write_empty, (long)rint(subpixel_x(c0.x, inv_w0, frame)),
                                (long)rint(subpixel_y(c0.y, inv_w0, frame)), (long)rint(subpixel_x(c1.x, inv_w1, frame)),
                                (long)rint(subpixel_y(c1.y, inv_w1, frame)), (long)rint(subpixel_x(c2.x, inv_w2, frame)),
                                (long)rint(subpixel_y(c2.y, inv_w2, frame)), inv_w0, inv_w1, inv_w2, c0.u, c0.v, c1.u,
                                c1.v, c2.u, c2.v, face, frame);
}

/* Clips the triangle polygon[0..2] (clip space, with uv) against the five planes and writes the
 * fan of the clipped polygon as setups to out[k * slot_stride], k = 0 .. fan - 1 (slot-major
 * records: slot_stride is the frame's input triangles), and with write_empty_slots empty ones past
 * it up to SEAMCL_CLIP_SLOTS - 1; *fan receives the fan's size (0 when nothing is left); returns
 * how many are visible. triangle_setup and tessellate.cl's tessellated_setup both call it, so
 * their micro-triangles and faces clip and snap identically. */
SEAMCL_INLINE uint clip_and_setup(ClipVertex* polygon, uint face_index, __constant FrameParams* frame,
                                  __global TriangleSetup* out, size_t slot_stride, int write_empty_slots, uint* fan) {
  int count = 3;
  for (int plane = 0; plane < 5 && count > 0; ++plane) {
    float d[8];
    int outside = 0;
    for (int i = 0; i < count; ++i) {
      d[i] = clip_distance(polygon[i], plane, frame);
      outside += d[i] < 0.0f;
    }
    if (outside == 0) continue;
    ClipVertex clipped[3 + 5];
    int n = 0;
    for (int i = 0; i < count; ++i) {
      const int j = (i + 1) % count;
      if (d[i] >= 0.0f) clipped[n++] = polygon[i];
      if ((d[i] >= 0.0f) != (d[j] >= 0.0f)) {
        clipped[n++] = d[i] >= 0.0f ? clip_lerp(polygon[i], polygon[j], d[i], d[j])
                                    : clip_lerp(polygon[j], polygon[i], d[j], d[i]);
      }
    }
    count = n;
    for (int i = 0; i < count; ++i) polygon[i] = clipped[i];
  }

  uint visible = 0;
  *fan = (uint)max(count - 2, 0);
  for (int k = 0; k < SEAMCL_CLIP_SLOTS; ++k) {
    if (k + 2 < count) {
      visible += (uint)setup_screen_triangle(out + k * slot_stride, 1, polygon[0], polygon[k + 1], polygon[k + 2],
                                             face_index, frame);
    } else if (write_empty_slots) {
      store_empty_setup(out + k * slot_stride, face_index);
    } else {
      break;
    }
  }
  return visible;
}

/* Sets up input triangle t (the slots it fills, and slot_counts[t]: how many); returns its visible slots. */
SEAMCL_INLINE uint setup_input_triangle(__constant FrameParams* frame, __global const float4* positions,
                                        __global const FaceGpu* faces, __global TriangleSetup* out,
                                        __global uint* slot_counts, int t) {
  const uint face_index = (uint)(t / 2);
  const FaceGpu face = faces[face_index];
  const int corner[3] = {0, (t & 1) ? 2 : 1, (t & 1) ? 3 : 2};
  const float corner_u[4] = {0.0f, 1.0f, 1.0f, 0.0f};
  const float corner_v[4] = {0.0f, 0.0f, 1.0f, 1.0f};

  ClipVertex polygon[3 + 5];
  for (int i = 0; i < 3; ++i) {
    const float4 p = positions[face.vertex[corner[i]]];
    const __constant float* m = frame->view_proj;
    /* column-major: clip = M * (p, 1) */
    polygon[i].x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
    polygon[i].y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
    polygon[i].w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
    polygon[i].u = corner_u[corner[i]];
    polygon[i].v = corner_v[corner[i]];
  }

  /* Most triangles need no clipping: then the polygon stays the triangle and the fan is its one
   * setup, as clip_and_setup would make it. Only a visible one is written: storing the empty
   * slots was most of this stage's time (6 records of 112 bytes per triangle). */
  int inside = 1;
  for (int plane = 0; plane < 5; ++plane) {
    for (int i = 0; i < 3; ++i) inside &= clip_distance(polygon[i], plane, frame) >= 0.0f;
  }
  __global TriangleSetup* slots = out + t; /* slot k at slots[k * input_triangles] */
  uint visible;
  if (inside) {
    visible = (uint)setup_screen_triangle(slots, 0, polygon[0], polygon[1], polygon[2], face_index, frame);
    slot_counts[t] = visible;
  } else {
    /* Only the fan's slots: binning reads no more than slot_counts[t]. */
    uint fan = 0;
    visible = clip_and_setup(polygon, face_index, frame, slots, (size_t)frame->input_triangles, 0, &fan);
    slot_counts[t] = fan;
  }
  return visible;
}

/* The early cull and the setup of triangles that need no clipping, SEAMCL_SETUP_LANES triangles
 * side by side in vectors (lane i: input triangle t0 + i). Written with vectors because PoCL's
 * work-item loop left this stage scalar: LLVM's SLP pass paired the x and y of each vertex into
 * 2-wide vectors, which the loop vectoriser cannot widen, and the sample test is a loop of its
 * own. Every lane takes the scalar path's steps in the same order (setup_snapped_triangle,
 * box_holds_sample; floor_div_subpixel is an arithmetic shift for the power-of-two
 * SEAMCL_SUBPIXEL_ONE), so the records are those of the twin bit for bit. */
#if SEAMCL_SETUP_LANES != 16
#error "SETUP_LANES_OF lists 16 lanes"
#endif
#if SEAMCL_SUBPIXEL_ONE != (1 << SEAMCL_SUBPIXEL_BITS)
#error "the vector setup divides by SEAMCL_SUBPIXEL_ONE with a shift"
#endif
#define SETUP_LANES_OF(F) (F(0), F(1), F(2), F(3), F(4), F(5), F(6), F(7), F(8), F(9), F(10), F(11), F(12), F(13), F(14), F(15))

/* One vertex of every lane: snapped screen position (1/SEAMCL_SUBPIXEL_ONE pixels; 0 where the
 * vertex lies outside the near plane or the guard band, or is NaN) and 1/w; *inside &= lies inside
 * all five planes (mask), *outside_all &= bit k set where it lies outside plane k (clip_distance
 * < 0, clip_and_setup's test: NaN is not outside). The transform and snapping are those of
 * setup_input_triangle and setup_screen_triangle. */
SEAMCL_INLINE void cull_vertices(__constant FrameParams* frame, float16 px, float16 py, float16 pz, int16* inside,
                                 int16* outside_all, int16* X, int16* Y, float16* inv_w_out) {
  const __constant float* m = frame->view_proj;
  /* column-major: clip = M * (p, 1) */
  const float16 x = m[0] * px + m[4] * py + m[8] * pz + m[12];
  const float16 y = m[1] * px + m[5] * py + m[9] * pz + m[13];
  const float16 w = m[3] * px + m[7] * py + m[11] * pz + m[15];
  const int16 in = (w - frame->near_w >= 0.0f) & (frame->guard_x * w - x >= 0.0f) & (frame->guard_x * w + x >= 0.0f) &
                   (frame->guard_y * w - y >= 0.0f) & (frame->guard_y * w + y >= 0.0f);
  *inside &= in;
  *outside_all &= ((w - frame->near_w < 0.0f) & 1) | ((frame->guard_x * w - x < 0.0f) & 2) |
                  ((frame->guard_x * w + x < 0.0f) & 4) | ((frame->guard_y * w - y < 0.0f) & 8) |
                  ((frame->guard_y * w + y < 0.0f) & 16);
  const float16 inv_w = 1.0f / w;
  /* subpixel_x and subpixel_y, lane by lane. Inside the guard band the snapped coordinates lie in
   * [-W, 2W] pixels: 25 bits. */
  const float16 sx = ((x * inv_w * 0.5f + 0.5f) * (float)frame->width) * (float)SEAMCL_SUBPIXEL_ONE;
  const float16 sy = ((0.5f - y * inv_w * 0.5f) * (float)frame->height) * (float)SEAMCL_SUBPIXEL_ONE;
  *X = select((int16)(0), convert_int16(rint(sx)), in);
  *Y = select((int16)(0), convert_int16(rint(sy)), in);
  *inv_w_out = inv_w;
}

/* box_holds_sample for every lane, with int arithmetic (the boxes of snapped vertices inside the
 * guard band fit 27 bits). */
SEAMCL_INLINE int16 boxes_hold_sample(int16 min_x, int16 max_x, int16 min_y, int16 max_y, __constant FrameParams* frame) {
  const int row = sample_pattern_row(frame->sample_count);
  int16 found = (int16)(0);
  for (int s = 0; s < frame->sample_count; ++s) {
    const int centre_x = SEAMCL_SUBPIXEL_ONE / 2 + sample_offsets[row][s][0] * (SEAMCL_SUBPIXEL_ONE / 16);
    const int centre_y = SEAMCL_SUBPIXEL_ONE / 2 + sample_offsets[row][s][1] * (SEAMCL_SUBPIXEL_ONE / 16);
    const int16 first_x = max(-((centre_x - min_x) >> SEAMCL_SUBPIXEL_BITS), 0);
    const int16 last_x = min((max_x - centre_x) >> SEAMCL_SUBPIXEL_BITS, frame->width - 1);
    const int16 first_y = max(-((centre_y - min_y) >> SEAMCL_SUBPIXEL_BITS), 0);
    const int16 last_y = min((max_y - centre_y) >> SEAMCL_SUBPIXEL_BITS, frame->height - 1);
    found |= (first_x <= last_x) & (first_y <= last_y);
  }
  return found;
}

/* Edge function from vertex (Xi, Yi) to (Xj, Yj) for every lane, the top-left rule folded in
 * (setup_edge). */
SEAMCL_INLINE void edges_of(int16 Xi, int16 Yi, int16 Xj, int16 Yj, int16* a, int16* b, long16* c) {
  *a = Yi - Yj;
  *b = Xj - Xi;
  const int16 top_left = (*a > 0) | ((*a == 0) & (*b > 0));
  *c = -(convert_long16(*a) * convert_long16(Xi) + convert_long16(*b) * convert_long16(Yi)) -
       convert_long16(select((int16)(1), (int16)(0), top_left));
}

/* setup_plane for every lane. */
SEAMCL_INLINE void planes_of(float16 a0, float16 a1, float16 a2, float16 dx1, float16 dy1, float16 dx2, float16 dy2,
                             float16 inv_det, float16* p0, float16* p1, float16* p2) {
  const float16 d1 = a1 - a0;
  const float16 d2 = a2 - a0;
  *p0 = a0;
  *p1 = (d1 * dy2 - d2 * dy1) * inv_det;
  *p2 = (d2 * dx1 - d1 * dx2) * inv_det;
}

/* The early cull and the setup of SEAMCL_SETUP_LANES triangles, lane i input triangle t[i], with
 * vertices (p*0, p*1, p*2) (world space) and uv (u0, v0) .. (u2, v2), face `face` for the record
 * (a patch for tessellate.cl). Lanes that are not in_range read valid data and count for nothing.
 * For triangles inside all planes it writes the visible ones' records (slot 0) and slot_counts
 * (0 or 1); it returns, in *clipped, the lanes that cross a plane and may be visible, which the
 * caller sets up one by one (their slot_counts too), in *early_culled the lanes the cull stopped,
 * and the visible slots it wrote. */
SEAMCL_INLINE uint setup_lanes(__constant FrameParams* frame, int16 t, int16 in_range, float16 px0, float16 py0,
                               float16 pz0, float16 px1, float16 py1, float16 pz1, float16 px2, float16 py2,
                               float16 pz2, float16 u0, float16 v0, float16 u1, float16 v1, float16 u2, float16 v2,
                               uint16 face, __global TriangleSetup* out, __global uint* slot_counts, int16* clipped,
                               int16* early_culled) {
  int16 inside = (int16)(-1), outside_all = (int16)(31);
  int16 X0, Y0, X1, Y1, X2, Y2;
  float16 inv_w0, inv_w1, inv_w2;
  cull_vertices(frame, px0, py0, pz0, &inside, &outside_all, &X0, &Y0, &inv_w0);
  cull_vertices(frame, px1, py1, pz1, &inside, &outside_all, &X1, &Y1, &inv_w1);
  cull_vertices(frame, px2, py2, pz2, &inside, &outside_all, &X2, &Y2, &inv_w2);
  /* The early cull (the twin's early_culled_reference): for triangles inside all planes, a back
   * face or zero area (the snapped vertices' area sign) or a bounding box past an image side, where
   * no sample lies; for the others, all three vertices outside one plane (the near plane is
   * clipped first, so its test is exact; a guard plane's clipped vertices could only round back
   * onto the plane, an image width or height beyond the image). */
  const long16 area2 = convert_long16(X1 - X0) * convert_long16(Y2 - Y0) - convert_long16(Y1 - Y0) * convert_long16(X2 - X0);
  const int16 back_or_flat = convert_int16(area2 >= (long16)(0));
  /* Samples of pixel p lie in [p*ONE, p*ONE + ONE - 16]. */
  const int last_x = (frame->width - 1) * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE - 16;
  const int last_y = (frame->height - 1) * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE - 16;
  const int16 off_image = ((X0 < 0) & (X1 < 0) & (X2 < 0)) | ((Y0 < 0) & (Y1 < 0) & (Y2 < 0)) |
                          ((X0 > last_x) & (X1 > last_x) & (X2 > last_x)) | ((Y0 > last_y) & (Y1 > last_y) & (Y2 > last_y));
  const int16 may_be_visible = in_range & select(outside_all == 0, ~back_or_flat & ~off_image, inside);
  *clipped = may_be_visible & ~inside;
  *early_culled = in_range & ~may_be_visible;

  /* setup_snapped_triangle for the lanes inside all planes: vertices 0, 2, 1 in turn (a, b, c)
   * make the interior positive for all three edge functions. */
  const int16 min_x = min(min(X0, X2), X1), max_x = max(max(X0, X2), X1);
  const int16 min_y = min(min(Y0, Y2), Y1), max_y = max(max(Y0, Y2), Y1);
  const int16 visible = may_be_visible & inside & ~back_or_flat & boxes_hold_sample(min_x, max_x, min_y, max_y, frame);
  int16 edge_a0, edge_a1, edge_a2, edge_b0, edge_b1, edge_b2;
  long16 edge_c0, edge_c1, edge_c2;
  edges_of(X0, Y0, X2, Y2, &edge_a0, &edge_b0, &edge_c0);
  edges_of(X2, Y2, X1, Y1, &edge_a1, &edge_b1, &edge_c1);
  edges_of(X1, Y1, X0, Y0, &edge_a2, &edge_b2, &edge_c2);
  /* Samples of pixel p lie in [p*ONE, p*ONE + ONE - 16] (D3D offsets are -8..7 sixteenths). */
  const int sample_span = SEAMCL_SUBPIXEL_ONE - 16;
  const int16 bbox_min_x = max((min_x - sample_span + SEAMCL_SUBPIXEL_ONE - 1) >> SEAMCL_SUBPIXEL_BITS, 0);
  const int16 bbox_min_y = max((min_y - sample_span + SEAMCL_SUBPIXEL_ONE - 1) >> SEAMCL_SUBPIXEL_BITS, 0);
  const int16 bbox_max_x = min(max_x >> SEAMCL_SUBPIXEL_BITS, frame->width - 1);
  const int16 bbox_max_y = min(max_y >> SEAMCL_SUBPIXEL_BITS, frame->height - 1);
  /* Attribute planes over the snapped positions, relative to vertex a for precision. */
  const float scale = 1.0f / (float)SEAMCL_SUBPIXEL_ONE;
  const float16 dx1 = convert_float16(X2 - X0) * scale, dy1 = convert_float16(Y2 - Y0) * scale;
  const float16 dx2 = convert_float16(X1 - X0) * scale, dy2 = convert_float16(Y1 - Y0) * scale;
  const float16 inv_det = 1.0f / (convert_float16(-area2) * scale * scale);
  const float16 ref_x = convert_float16(X0) * scale, ref_y = convert_float16(Y0) * scale;
  float16 w_p0, w_p1, w_p2, u_p0, u_p1, u_p2, v_p0, v_p1, v_p2;
  planes_of(inv_w0, inv_w2, inv_w1, dx1, dy1, dx2, dy2, inv_det, &w_p0, &w_p1, &w_p2);
  planes_of(u0 * inv_w0, u2 * inv_w2, u1 * inv_w1, dx1, dy1, dx2, dy2, inv_det, &u_p0, &u_p1, &u_p2);
  planes_of(v0 * inv_w0, v2 * inv_w2, v1 * inv_w1, dx1, dy1, dx2, dy2, inv_det, &v_p0, &v_p1, &v_p2);

  /* Only a visible triangle's record is written (slot 0); storing the empty slots was most of this
   * stage's time (6 records of 112 bytes per triangle): binning reads no more than slot_counts[t]. */
  uint visible_slots = 0;
#pragma unroll
  for (int i = 0; i < SEAMCL_SETUP_LANES; ++i) {
    if (in_range[i] && !(*clipped)[i]) slot_counts[t[i]] = visible[i] ? 1u : 0u;
    if (!visible[i]) continue;
    ++visible_slots;
    __global TriangleSetup* r = out + t[i]; /* slot 0 */
    r->edge_c[0] = edge_c0[i];
    r->edge_c[1] = edge_c1[i];
    r->edge_c[2] = edge_c2[i];
    r->edge_a[0] = edge_a0[i];
    r->edge_a[1] = edge_a1[i];
    r->edge_a[2] = edge_a2[i];
    r->edge_b[0] = edge_b0[i];
    r->edge_b[1] = edge_b1[i];
    r->edge_b[2] = edge_b2[i];
    r->bbox_min_x = bbox_min_x[i];
    r->bbox_min_y = bbox_min_y[i];
    r->bbox_max_x = bbox_max_x[i];
    r->bbox_max_y = bbox_max_y[i];
    r->face = face[i];
    r->ref_x = ref_x[i];
    r->ref_y = ref_y[i];
    r->inv_w[0] = w_p0[i];
    r->inv_w[1] = w_p1[i];
    r->inv_w[2] = w_p2[i];
    r->u_over_w[0] = u_p0[i];
    r->u_over_w[1] = u_p1[i];
    r->u_over_w[2] = u_p2[i];
    r->v_over_w[0] = v_p0[i];
    r->v_over_w[1] = v_p1[i];
    r->v_over_w[2] = v_p2[i];
  }
  return visible_slots;
}

/* The number of set lanes of a mask. */
SEAMCL_INLINE uint lanes_set(int16 mask) {
  uint n = 0;
  for (int i = 0; i < SEAMCL_SETUP_LANES; ++i) n += mask[i] ? 1u : 0u;
  return n;
}

__kernel __attribute__((reqd_work_group_size(SEAMCL_SETUP_GROUP, 1, 1)))
void triangle_setup(__constant FrameParams* frame, __global const float4* positions, __global const FaceGpu* faces,
                    __global TriangleSetup* out, __global uint* slot_counts, __global FrameStats* stats) {
  /* Visible slots and early-culled triangles are summed per work-group, without atomics: a locked
   * add per triangle waits for the triangle's record stores to drain, and cost a quarter of this
   * stage. */
  __local uint group_visible[SEAMCL_SETUP_GROUP];
  __local uint group_early_culled[SEAMCL_SETUP_GROUP];
  const int triangles = frame->input_triangles; /* > 0: the host runs no setup without triangles */
  const int t0 = (int)get_global_id(0) * SEAMCL_SETUP_LANES;
  const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const int16 t = t0 + lane;
  const int16 in_range = t < triangles;
  /* Lanes past the last triangle read the last one and count for nothing. */
  const int16 read_t = min(t, triangles - 1);
  const int16 odd = read_t & 1;
  const int16 face = read_t >> 1;
  /* The face records two work-items ahead (8 faces: 6 lines), and the record lines this
   * work-item may write (16 records: 28 lines). */
  if (t0 + 3 * SEAMCL_SETUP_LANES <= triangles) {
    __global const char* ahead = (__global const char*)(faces + (t0 + 2 * SEAMCL_SETUP_LANES) / 2);
    for (int k = 0; k < (int)((SEAMCL_SETUP_LANES / 2 * sizeof(FaceGpu) + 63) / 64); ++k) SEAMCL_PREFETCH(ahead + 64 * k);
  }
  if (t0 + SEAMCL_SETUP_LANES <= triangles) {
    __global const char* records = (__global const char*)(out + t0);
    for (int k = 0; k < (int)((SEAMCL_SETUP_LANES * sizeof(TriangleSetup) + 63) / 64); ++k) {
      SEAMCL_PREFETCH_WRITE(records + 64 * k);
    }
  }
#define SETUP_VERTEX0(i) faces[face[i]].vertex[0]
#define SETUP_VERTEX1(i) faces[face[i]].vertex[odd[i] ? 2 : 1]
#define SETUP_VERTEX2(i) faces[face[i]].vertex[odd[i] ? 3 : 2]
  const uint16 vertex0 = (uint16)SETUP_LANES_OF(SETUP_VERTEX0);
  const uint16 vertex1 = (uint16)SETUP_LANES_OF(SETUP_VERTEX1);
  const uint16 vertex2 = (uint16)SETUP_LANES_OF(SETUP_VERTEX2);
#undef SETUP_VERTEX0
#undef SETUP_VERTEX1
#undef SETUP_VERTEX2
  __global const float* xyzw = (__global const float*)positions;
#define SETUP_X0(i) xyzw[4 * (size_t)vertex0[i]]
#define SETUP_Y0(i) xyzw[4 * (size_t)vertex0[i] + 1]
#define SETUP_Z0(i) xyzw[4 * (size_t)vertex0[i] + 2]
#define SETUP_X1(i) xyzw[4 * (size_t)vertex1[i]]
#define SETUP_Y1(i) xyzw[4 * (size_t)vertex1[i] + 1]
#define SETUP_Z1(i) xyzw[4 * (size_t)vertex1[i] + 2]
#define SETUP_X2(i) xyzw[4 * (size_t)vertex2[i]]
#define SETUP_Y2(i) xyzw[4 * (size_t)vertex2[i] + 1]
#define SETUP_Z2(i) xyzw[4 * (size_t)vertex2[i] + 2]
  /* Corner uv: t even takes corners 0, 1, 2 ((0,0), (1,0), (1,1)), odd 0, 2, 3 ((0,0), (1,1), (0,1)). */
  int16 clipped, early_culled;
  uint visible_slots = setup_lanes(
      frame, t, in_range, (float16)SETUP_LANES_OF(SETUP_X0), (float16)SETUP_LANES_OF(SETUP_Y0),
      (float16)SETUP_LANES_OF(SETUP_Z0), (float16)SETUP_LANES_OF(SETUP_X1), (float16)SETUP_LANES_OF(SETUP_Y1),
      (float16)SETUP_LANES_OF(SETUP_Z1), (float16)SETUP_LANES_OF(SETUP_X2), (float16)SETUP_LANES_OF(SETUP_Y2),
      (float16)SETUP_LANES_OF(SETUP_Z2), (float16)(0.0f), (float16)(0.0f), (float16)(1.0f),
      select((float16)(0.0f), (float16)(1.0f), odd != 0), select((float16)(1.0f), (float16)(0.0f), odd != 0),
      (float16)(1.0f), convert_uint16(face), out, slot_counts, &clipped, &early_culled);
#undef SETUP_X0
#undef SETUP_Y0
#undef SETUP_Z0
#undef SETUP_X1
#undef SETUP_Y1
#undef SETUP_Z1
#undef SETUP_X2
#undef SETUP_Y2
#undef SETUP_Z2
  /* Triangles that cross a plane (few): clipped one by one, only the fan's slots written. */
  for (int i = 0; i < SEAMCL_SETUP_LANES; ++i) {
    if (clipped[i]) visible_slots += setup_input_triangle(frame, positions, faces, out, slot_counts, t[i]);
  }
  group_visible[get_local_id(0)] = visible_slots;
  group_early_culled[get_local_id(0)] = lanes_set(early_culled);
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0) {
    uint sum = 0, culled_sum = 0;
    for (int i = 0; i < SEAMCL_SETUP_GROUP; ++i) {
      sum += group_visible[i];
      culled_sum += group_early_culled[i];
    }
    if (sum > 0) atomic_add(&stats->visible_triangles, sum);
    if (culled_sum > 0) atomic_add(&stats->early_culled, culled_sum);
  }
}
