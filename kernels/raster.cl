/* Stage 3: raster. One work-item per tile (SEAMCL_TILE_SIZE x SEAMCL_TILE_SIZE pixels): it walks
 * its tile's list once, each entry over the tile rows its box covers (tile_entry_rows, from
 * binning: no row reads an entry that misses it, and a record is read once, not once per row), and
 * tests a row with 16-wide integer vectors, written vectorised here because PoCL's work-item loop
 * cannot vectorise a loop over a per-pixel list. The tile's winners stay in private memory
 * (16 rows x 16 x SEAMCL_MAX_SAMPLES slots, 16 KiB) until the list is done.
 *
 * For each sample of the pixel (D3D11 standard positions, below), a triangle covers it iff all
 * three edge functions are >= 0 at the sample's fixed-point position (top-left rule folded into
 * edge_c by setup). Depth is 1/w from the plane: nearer is larger. The sample keeps the covering
 * triangle of largest 1/w, ties going to the earlier input triangle (then fan slot), so the
 * result does not depend on the order of the tile list. Output: sample_triangle[(y * width + x) * sample_count + s], the
 * winning slot or SEAMCL_NO_TRIANGLE.
 * Edge functions are affine: E at a sample is E at a pixel centre (64-bit) plus a * dx + b * dy
 * for the sample's small offset. With |offsets| < 2^29 the centre value clamped to +-2^29, plus
 * the offset, has the sign of the exact sum and fits 32 bits, so the common case runs on int16;
 * edges too long for that bound take the same steps on long16.
 * Up to 4 samples a row runs by lanes (the vector over the row's 16 pixels, a loop over samples);
 * from 8 samples by pixels (the vector over a pixel's samples, a loop over the pixels in the
 * triangle's box, where whole pixels inside or outside an edge skip the per-sample test): cost
 * then follows the covered pixels, not pixels x samples.
 * Depths are computed only where a covered sample already has a triangle (overlapping front
 * faces), both from their planes with the twin's float steps: the eager z-buffer's result.
 * Host guarantees: bin lists and tile_entry_rows built for this frame; bin_entries <= bin_capacity
 * (else it re-runs);
 * global size (tiles_x, tiles_y), work-groups of one; image sides <= 16384 (kMaxImageSide), so
 * fixed-point sample positions fit 32 bits and convert to float exactly.
 * Twin: host/pipeline/stages/raster_twin.cpp. The sample pattern is sample_pattern.h's. */

#if SEAMCL_TILE_SIZE != 16
#error "raster keeps one tile row in a 16-wide vector"
#endif
#if SEAMCL_MAX_SAMPLES != 16
#error "raster keeps one pixel's samples in a 16-wide vector"
#endif

/* Edges whose |a| + |b| is below this keep every in-row offset (< 4096 (|a| + |b|)) under 2^29. */
#define SEAMCL_RASTER_NARROW_EDGE (1 << 17)
#define SEAMCL_RASTER_CLAMP (1 << 29)
/* How many list entries ahead raster prefetches a record. */
#define SEAMCL_RASTER_PREFETCH_AHEAD 4
/* Winners kept per tile row: SEAMCL_MAX_SAMPLES vectors of 16. */
#define SEAMCL_TILE_ROW_WINNERS (SEAMCL_MAX_SAMPLES * SEAMCL_TILE_SIZE)
/* A row's winners are SEAMCL_MAX_SAMPLES vectors whether they run over pixels (a vector per
 * pixel's samples) or over samples (a vector per sample's pixels): the two counts must agree. */
#if SEAMCL_MAX_SAMPLES != SEAMCL_TILE_SIZE
#error "raster's tile rows assume SEAMCL_MAX_SAMPLES == SEAMCL_TILE_SIZE"
#endif

/* 1/w of t's plane at the lanes' fixed-point sample positions (px, py): the twin's float steps. */
SEAMCL_INLINE float16 raster_depth(__global const TriangleSetup* t, int16 px, int16 py) {
  const float16 fx = convert_float16(px) * (1.0f / SEAMCL_SUBPIXEL_ONE);
  const float16 fy = convert_float16(py) * (1.0f / SEAMCL_SUBPIXEL_ONE);
  return t->inv_w[0] + t->inv_w[1] * (fx - t->ref_x) + t->inv_w[2] * (fy - t->ref_y);
}

/* Whether some lane of a mask is set (-1): an OR tree, which PoCL's any() is not (it tests the
 * lanes one by one). */
SEAMCL_INLINE int raster_any(int16 mask) {
  const int8 m8 = mask.lo | mask.hi;
  const int4 m4 = m8.lo | m8.hi;
  const int2 m2 = m4.lo | m4.hi;
  return (m2.x | m2.y) < 0;
}

/* The smallest lane of v. */
SEAMCL_INLINE uint raster_min_lane(uint16 v) {
  const uint8 m8 = min(v.lo, v.hi);
  const uint4 m4 = min(m8.lo, m8.hi);
  const uint2 m2 = min(m4.lo, m4.hi);
  return min(m2.x, m2.y);
}

/* Whether t's 1/w plane is finite (never NaN) at every pixel-space point below 2^24: then any
 * depth beats the empty sample's -infinity, and an uncontested sample needs no depth. */
SEAMCL_INLINE int raster_plane_is_tame(__global const TriangleSetup* t) {
  const float reach = 0x1p24f;
  const float bound = fabs(t->inv_w[0]) + fabs(t->inv_w[1]) * (fabs(t->ref_x) + reach) +
                      fabs(t->inv_w[2]) * (fabs(t->ref_y) + reach);
  return bound < 0x1p100f; /* false for NaN and infinite coefficients */
}

/* Whether slot a comes before slot b in the tie order: input triangle, then fan slot (the order
 * of t * SEAMCL_CLIP_SLOTS + k, which the twin compares). Records are slot-major, slot = k *
 * triangles + t (triangles: the frame's input triangles), so the slot numbers themselves are not in
 * that order. Asked for every contested lane; its result counts only where the depths are equal. */
SEAMCL_INLINE int raster_slot_precedes(uint a, uint b, uint triangles) {
  if (triangles == 0) return a < b; /* no input triangles: no slots either (never a zero divisor) */
  const uint ta = a % triangles, tb = b % triangles;
  return ta < tb || (ta == tb && a < b);
}

/* One sample of the row: the lanes in `covered` (-1) take `slot` where they have no triangle yet,
 * or where it is nearer than theirs (or as near and earlier in the tie order, raster_slot_precedes). Depths are computed only for
 * such contests (overlapping front faces: rare, as back faces are culled), both from their planes
 * with the same steps, so the result is the eager z-buffer's (whose empty samples hold -infinity:
 * a plane that is not tame contests them too, and its NaN depths never win).
 * (px, py): the lanes' fixed-point positions. */
SEAMCL_INLINE void raster_take(__global const TriangleSetup* setups, uint triangles, uint slot, int tame, int16 covered,
                               int16 px, int16 py, uint* best_slot) {
  const uint16 old_slot = vload16(0, best_slot);
  const int16 empty = old_slot == (uint16)SEAMCL_NO_TRIANGLE;
  int16 contested = covered & ~empty;
  int16 takes = covered & empty;
  if (!tame || raster_any(contested)) {
    const float16 depth = raster_depth(setups + slot, px, py);
    takes &= ~isnan(depth); /* -infinity ties the empty sample and wins on slot; NaN never wins */
    /* One winner at a time: all lanes held by it are decided with one vector of its depths. */
    while (raster_any(contested)) {
      const uint other = raster_min_lane(select((uint16)SEAMCL_NO_TRIANGLE, old_slot, contested));
      const int16 held = contested & (old_slot == other);
      const float16 other_depth = raster_depth(setups + other, px, py);
      /* a scalar comparison gives 1, not -1 */
      const int16 lower_slot = (int16)(raster_slot_precedes(slot, other, triangles) ? -1 : 0);
      takes |= held & ((depth > other_depth) | ((depth == other_depth) & lower_slot));
      contested &= ~held;
    }
  }
  vstore16(select(old_slot, (uint16)slot, takes), 0, best_slot);
}

/* Rows of one sample (or few): the vector runs over a row's 16 pixels, the loop over samples;
 * winners stored per row r and sample [r * SEAMCL_TILE_ROW_WINNERS + 16 s + lane]. One list entry
 * (slot) over the rows y_first .. y_last of the tile at (x0, y0): its record is read once for all
 * of them. */
SEAMCL_INLINE void raster_entry_by_lanes(__global const TriangleSetup* setups, uint triangles, uint slot, int x0, int y0,
                                         int y_first, int y_last, int samples, int row, uint* best_tile) {
  __global const TriangleSetup* t = setups + slot;
  const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const int16 x = x0 + lane;
  /* Fixed-point x of each lane's pixel centre. */
  const int16 centre_x = x * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2;
  /* The twin visits the pixels of the bounding box only. */
  const int16 in_box = (x >= t->bbox_min_x) & (x <= t->bbox_max_x);
  const int tame = raster_plane_is_tame(t);
  int a[3], b[3];
  long c[3];
  int wide = 0;
  for (int i = 0; i < 3; ++i) {
    a[i] = t->edge_a[i];
    b[i] = t->edge_b[i];
    c[i] = t->edge_c[i];
    wide |= (long)abs(a[i]) + (long)abs(b[i]) >= SEAMCL_RASTER_NARROW_EDGE;
  }
  if (!wide) {
    /* Per edge, its lowest and highest change over a pixel's sample box [-8, 7] / 16. */
    int low[3], high[3];
    for (int i = 0; i < 3; ++i) {
      low[i] = a[i] * (a[i] > 0 ? -128 : 112) + b[i] * (b[i] > 0 ? -128 : 112);
      high[i] = a[i] * (a[i] > 0 ? 112 : -128) + b[i] * (b[i] > 0 ? 112 : -128);
    }
    for (int y = y_first; y <= y_last; ++y) {
      uint* best_slot = best_tile + (y - y0) * SEAMCL_TILE_ROW_WINNERS;
      const int centre_y = y * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2;
      int16 e[3];
      for (int i = 0; i < 3; ++i) {
        const long at_row = (long)a[i] * (x0 * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2) + (long)b[i] * centre_y + c[i];
        const int clamped = (int)clamp(at_row, (long)-SEAMCL_RASTER_CLAMP, (long)SEAMCL_RASTER_CLAMP);
        e[i] = clamped + a[i] * SEAMCL_SUBPIXEL_ONE * lane;
      }
      /* Lanes whose every sample position (all within [-8, 7] / 16 pixel of the centre) is
       * inside all three edges, and lanes outside one edge at all of them: only the others
       * (pixels an edge crosses) need the test per sample. */
      int16 full = in_box, outside = (int16)(0);
      for (int i = 0; i < 3; ++i) {
        full &= e[i] + low[i] >= 0;
        outside |= e[i] + high[i] < 0;
      }
      const int16 partial = in_box & ~full & ~outside;
      const int any_partial = raster_any(partial);
      if (!any_partial && !raster_any(full)) continue;
      for (int s = 0; s < samples; ++s) {
        const int ox = sample_offsets[row][s][0] * (SEAMCL_SUBPIXEL_ONE / 16);
        const int oy = sample_offsets[row][s][1] * (SEAMCL_SUBPIXEL_ONE / 16);
        int16 covered = full;
        if (any_partial) {
          const int16 any_negative = (e[0] + (a[0] * ox + b[0] * oy)) | (e[1] + (a[1] * ox + b[1] * oy)) |
                                     (e[2] + (a[2] * ox + b[2] * oy));
          covered |= partial & (any_negative >= 0);
          if (!raster_any(covered)) continue;
        }
        raster_take(setups, triangles, slot, tame, covered, centre_x + ox, (int16)(centre_y + oy), best_slot + s * SEAMCL_TILE_SIZE);
      }
    }
  } else {
    const long16 lane_x = convert_long16(centre_x);
    for (int y = y_first; y <= y_last; ++y) {
      uint* best_slot = best_tile + (y - y0) * SEAMCL_TILE_ROW_WINNERS;
      const int centre_y = y * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2;
      long16 e[3];
      for (int i = 0; i < 3; ++i) e[i] = (long)a[i] * lane_x + (long)b[i] * centre_y + c[i];
      for (int s = 0; s < samples; ++s) {
        const long ox = sample_offsets[row][s][0] * (SEAMCL_SUBPIXEL_ONE / 16);
        const long oy = sample_offsets[row][s][1] * (SEAMCL_SUBPIXEL_ONE / 16);
        const long16 any_negative = (e[0] + (a[0] * ox + b[0] * oy)) | (e[1] + (a[1] * ox + b[1] * oy)) |
                                    (e[2] + (a[2] * ox + b[2] * oy));
        const int16 covered = in_box & convert_int16(any_negative >= 0);
        if (!raster_any(covered)) continue;
        raster_take(setups, triangles, slot, tame, covered, centre_x + (int)ox, (int16)(centre_y + (int)oy), best_slot + s * SEAMCL_TILE_SIZE);
      }
    }
  }
}

/* Edges whose |a| + |b| is below this keep a pixel's sample offsets (<= 128 (|a| + |b|)) under 2^29. */
#define SEAMCL_RASTER_NARROW_PIXEL_EDGE (1 << 22)

/* Rows of many samples: the vector runs over one pixel's samples (lanes past the count off), the
 * loop over the pixels of a row inside the triangle's box; winners stored per row r and pixel
 * [r * SEAMCL_TILE_ROW_WINNERS + 16 lane + s]. A pixel whose sample box [-8, 7] / 16 lies inside
 * all three edges is covered at every sample, one outside an edge at none: only pixels an edge
 * crosses test their samples. One list entry (slot) over the rows y_first .. y_last of the tile at
 * (x0, y0), its record read once. */
SEAMCL_INLINE void raster_entry_by_pixels(__global const TriangleSetup* setups, uint triangles, uint slot, int x0, int y0,
                                          int y_first, int y_last, int samples, int row, int16 sample_x,
                                          int16 sample_y, uint* best_tile) {
  __global const TriangleSetup* t = setups + slot;
  const int16 valid = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15) < samples;
  const int tame = raster_plane_is_tame(t);
  /* Per edge: its step per pixel, and its lowest and highest change over the sample box. */
  long a[3], b[3], c[3], step[3], low[3], high[3];
  int narrow = 1;
  int16 d[3];
  const int first = max(t->bbox_min_x, x0) - x0, last = min(t->bbox_max_x, x0 + SEAMCL_TILE_SIZE - 1) - x0;
  for (int i = 0; i < 3; ++i) {
    a[i] = t->edge_a[i];
    b[i] = t->edge_b[i];
    c[i] = t->edge_c[i];
    step[i] = a[i] * SEAMCL_SUBPIXEL_ONE;
    low[i] = a[i] * (a[i] > 0 ? -128 : 112) + b[i] * (b[i] > 0 ? -128 : 112);
    high[i] = a[i] * (a[i] > 0 ? 112 : -128) + b[i] * (b[i] > 0 ? 112 : -128);
    narrow &= abs(a[i]) + abs(b[i]) < SEAMCL_RASTER_NARROW_PIXEL_EDGE;
  }
  /* The change at each sample, in 32 bits when the edges are narrow (else unused). */
  for (int i = 0; i < 3; ++i) d[i] = narrow ? (int)a[i] * sample_x + (int)b[i] * sample_y : (int16)(0);
  for (int y = y_first; y <= y_last; ++y) {
    uint* best_slot = best_tile + (y - y0) * SEAMCL_TILE_ROW_WINNERS;
    const int centre_y = y * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2;
    const int16 py = centre_y + sample_y;
    /* Per edge, its value at the first pixel's centre. */
    long e[3];
    for (int i = 0; i < 3; ++i) e[i] = a[i] * ((x0 + first) * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2) + b[i] * centre_y + c[i];
    for (int l = first; l <= last; ++l, e[0] += step[0], e[1] += step[1], e[2] += step[2]) {
      if (e[0] + high[0] < 0 || e[1] + high[1] < 0 || e[2] + high[2] < 0) continue;
      int16 covered = valid;
      if (e[0] + low[0] < 0 || e[1] + low[1] < 0 || e[2] + low[2] < 0) {
        if (narrow) {
          int cl[3];
          for (int i = 0; i < 3; ++i) cl[i] = (int)clamp(e[i], (long)-SEAMCL_RASTER_CLAMP, (long)SEAMCL_RASTER_CLAMP);
          covered &= ((cl[0] + d[0]) | (cl[1] + d[1]) | (cl[2] + d[2])) >= 0;
        } else {
          const long16 wide_x = convert_long16(sample_x), wide_y = convert_long16(sample_y);
          long16 any_negative = (long16)(0);
          for (int i = 0; i < 3; ++i) any_negative |= e[i] + a[i] * wide_x + b[i] * wide_y;
          covered &= convert_int16(any_negative >= 0);
        }
        if (!raster_any(covered)) continue;
      }
      const int centre_x = (x0 + l) * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2;
      raster_take(setups, triangles, slot, tame, covered, centre_x + sample_x, py, best_slot + l * SEAMCL_TILE_SIZE);
    }
  }
}

/* From this many samples on, rows go by pixels (fewer steps per covered pixel) rather than lanes. */
#define SEAMCL_RASTER_BY_PIXELS_FROM 8

__kernel void raster(__constant FrameParams* frame, __global const TriangleSetup* setups,
                     __global const uint* tile_counts, __global const uint* tile_offsets,
                     __global const uint* tile_lists, __global const ushort* tile_entry_rows,
                     __global uint* sample_triangle) {
  const int tile_x = (int)get_global_id(0);
  const int tile_y = (int)get_global_id(1);
  if (tile_x >= frame->tiles_x || tile_y >= frame->tiles_y) return;
  const int x0 = tile_x * SEAMCL_TILE_SIZE, y0 = tile_y * SEAMCL_TILE_SIZE;
  const int samples = frame->sample_count;
  const int row = sample_pattern_row(samples);
  const int tile = tile_y * frame->tiles_x + tile_x;
  const uint begin = tile_offsets[tile];
  const uint end = min(begin + tile_counts[tile], frame->bin_capacity);
  const int lanes = min(SEAMCL_TILE_SIZE, frame->width - x0);
  const int rows = min(SEAMCL_TILE_SIZE, frame->height - y0);
  const int by_pixels = samples >= SEAMCL_RASTER_BY_PIXELS_FROM;
  /* The tile's winners, row by row; by lanes a row uses its first `samples` vectors. */
  uint best_tile[SEAMCL_TILE_SIZE * SEAMCL_TILE_ROW_WINNERS];
  const int vectors_per_row = by_pixels ? SEAMCL_TILE_SIZE : samples;
  for (int r = 0; r < rows; ++r) {
    for (int i = 0; i < vectors_per_row; ++i) vstore16((uint16)(SEAMCL_NO_TRIANGLE), r * SEAMCL_MAX_SAMPLES + i, best_tile);
  }
  int offset_x[SEAMCL_MAX_SAMPLES], offset_y[SEAMCL_MAX_SAMPLES];
  for (int s = 0; s < SEAMCL_MAX_SAMPLES; ++s) {
    offset_x[s] = s < samples ? sample_offsets[row][s][0] * (SEAMCL_SUBPIXEL_ONE / 16) : 0;
    offset_y[s] = s < samples ? sample_offsets[row][s][1] * (SEAMCL_SUBPIXEL_ONE / 16) : 0;
  }
  const int16 sample_x = vload16(0, offset_x), sample_y = vload16(0, offset_y);
  /* The tile's output lines, fetched to write while the list is walked: at 16x the copy below
   * writes 16 KiB per tile, and without the prefetch each of its stores waits for its line to be
   * read first (docs/performance.md, "MSAA" rows). */
  for (int r = 0; r < rows; ++r) {
    __global const uint* out = sample_triangle + ((size_t)(y0 + r) * (size_t)frame->width + (size_t)x0) * (size_t)samples;
    for (int w = 0; w < lanes * samples; w += 16) SEAMCL_PREFETCH_WRITE(out + w);
  }
  for (uint entry = begin; entry < end; ++entry) {
    /* The record a few entries ahead, both lines the walk reads (edges and box; the 1/w plane
     * raster_plane_is_tame tests): its first read misses the cache (records lie in input order,
     * lists in tile order), and the walk's branches depend on it. */
    if (entry + SEAMCL_RASTER_PREFETCH_AHEAD < end) {
      __global const char* ahead = (__global const char*)(setups + tile_lists[entry + SEAMCL_RASTER_PREFETCH_AHEAD]);
      SEAMCL_PREFETCH(ahead);
      SEAMCL_PREFETCH(ahead + 64);
    }
    /* The rows of the tile the entry's box covers (binning), cut to the record's box and the image
     * (a list may hold entries that miss the tile: the box decides). */
    const uint entry_rows = tile_entry_rows[entry];
    const uint slot = tile_lists[entry];
    __global const TriangleSetup* t = setups + slot;
    if (x0 + SEAMCL_TILE_SIZE - 1 < t->bbox_min_x || x0 > t->bbox_max_x) continue;
    const int y_first = max(y0 + (int)(entry_rows & 15u), t->bbox_min_y);
    const int y_last = min(min(y0 + (int)((entry_rows >> 4) & 15u), t->bbox_max_y), y0 + rows - 1);
    if (y_first > y_last) continue;
    if (by_pixels) {
      raster_entry_by_pixels(setups, (uint)frame->input_triangles, slot, x0, y0, y_first, y_last, samples, row, sample_x,
                             sample_y, best_tile);
    } else {
      raster_entry_by_lanes(setups, (uint)frame->input_triangles, slot, x0, y0, y_first, y_last, samples, row, best_tile);
    }
  }
  for (int r = 0; r < rows; ++r) {
    __global uint* out = sample_triangle + ((size_t)(y0 + r) * (size_t)frame->width + (size_t)x0) * (size_t)samples;
    const uint* best_slot = best_tile + r * SEAMCL_TILE_ROW_WINNERS;
    if (by_pixels) {
      for (int l = 0; l < lanes; ++l) {
        for (int s = 0; s < samples; ++s) out[l * samples + s] = best_slot[l * SEAMCL_TILE_SIZE + s];
      }
    } else {
      for (int l = 0; l < lanes; ++l) {
        for (int s = 0; s < samples; ++s) out[l * samples + s] = best_slot[s * SEAMCL_TILE_SIZE + l];
      }
    }
  }
}

/* The sample pattern as the raster stage uses it, for the test against the D3D11 tables. */
__kernel void sample_pattern(int sample_count, __global int* offsets_out) {
  if (get_global_id(0) != 0) return;
  const int row = sample_pattern_row(sample_count);
  for (int s = 0; s < sample_count; ++s) {
    offsets_out[2 * s] = sample_offsets[row][s][0];
    offsets_out[2 * s + 1] = sample_offsets[row][s][1];
  }
}
