/* Stage 2: binning into SEAMCL_TILE_SIZE x SEAMCL_TILE_SIZE pixel tiles, so that the raster cost
 * of a tile follows the triangles that touch it. The input triangles are cut into `chunks`
 * contiguous runs of chunk_triangles (the last one shorter), one work-item each, which keeps its
 * own count per tile (chunk_counts[chunk * tiles + tile]): no two work-items touch one counter,
 * so there are no atomics (a locked add per list entry, and the counters' cache lines moving
 * between cores, were most of this stage at 99,037 faces). Three kernels, queued back to back:
 *   bin_count  per chunk: zeroes its counts, then +1 on every tile a written slot's (slot_counts,
 *              from setup) triangle may cover;
 *   bin_scan   one work-item: per tile, exclusive prefix sums over tiles and, within a tile, over
 *              chunks -> tile_offsets, tile_counts, and each chunk's cursor in its place in
 *              chunk_counts;
 *   bin_fill   per chunk, the same walk as bin_count: appends the slot index (k * input_triangles
 *              + t, the record's index) to each tile's list at its cursor, and at the
 *              same entry of tile_entry_rows the rows and columns of the tile that the slot's
 *              box covers (tile-relative, 4 bits each: row_lo | row_hi << 4 | col_lo << 8 |
 *              col_hi << 12), so raster skips the entry on its other rows without reading the
 *              slot's record.
 * A tile's list is in input order (chunk, then triangle, then fan slot); raster does not depend
 * on it (ties in depth are broken by input order, raster_slot_precedes).
 * Most input triangles write one slot or none (culled), so walking triangles rather than all
 * SEAMCL_CLIP_SLOTS slots reads a few bytes for each culled one instead of six records.
 * A tile is skipped when one edge function is negative over all of its sample positions (the
 * standard corner test), so long thin triangles do not fill their whole bounding box.
 * If the lists need more than bin_capacity entries, bin_fill drops the rest and the host, seeing
 * stats.bin_entries > capacity, grows the buffer and renders again.
 * Host guarantees: slot_counts written for this frame; chunk_counts holds chunks * tiles entries;
 * chunks * chunk_triangles >= input_triangles (chunks 0 when there are none: bin_count and
 * bin_fill are not run). Twin: host/pipeline/stages/binning_twin.cpp. */

#if SEAMCL_TILE_SIZE != 16
#error "tile_entry_rows packs tile-relative rows and columns in 4 bits each"
#endif

SEAMCL_INLINE int tile_may_be_covered(__global const TriangleSetup* s, int tile_x, int tile_y) {
  /* Fixed-point extent of every sample position inside the tile. */
  const long x_lo = (long)tile_x * SEAMCL_TILE_SIZE * SEAMCL_SUBPIXEL_ONE;
  const long y_lo = (long)tile_y * SEAMCL_TILE_SIZE * SEAMCL_SUBPIXEL_ONE;
  const long x_hi = x_lo + SEAMCL_TILE_SIZE * SEAMCL_SUBPIXEL_ONE - 16;
  const long y_hi = y_lo + SEAMCL_TILE_SIZE * SEAMCL_SUBPIXEL_ONE - 16;
  for (int i = 0; i < 3; ++i) {
    const long a = s->edge_a[i];
    const long b = s->edge_b[i];
    const long best = a * (a > 0 ? x_hi : x_lo) + b * (b > 0 ? y_hi : y_lo) + s->edge_c[i];
    if (best < 0) return 0;
  }
  return 1;
}

/* Triangle t's written slots over the tiles each may cover: with `fill` 0, +1 on the tile's
 * counter (counts, its chunk's, one per tile); with `fill` 1, the slot appended to the tile's list
 * at its counter (the chunk's cursor), which moves on. */
SEAMCL_INLINE void bin_triangle(__constant FrameParams* frame, __global const TriangleSetup* setups,
                                __global const uint* slot_counts, int t, __global uint* counters, int fill,
                                __global uint* tile_lists, __global ushort* tile_entry_rows) {
  const uint written = min(slot_counts[t], (uint)SEAMCL_CLIP_SLOTS);
  for (uint k = 0; k < written; ++k) {
    const uint slot = k * (uint)frame->input_triangles + (uint)t;
    __global const TriangleSetup* s = setups + slot;
    if (s->bbox_max_x < s->bbox_min_x || s->bbox_max_y < s->bbox_min_y) continue;
    for (int ty = s->bbox_min_y / SEAMCL_TILE_SIZE; ty <= s->bbox_max_y / SEAMCL_TILE_SIZE; ++ty) {
      for (int tx = s->bbox_min_x / SEAMCL_TILE_SIZE; tx <= s->bbox_max_x / SEAMCL_TILE_SIZE; ++tx) {
        if (!tile_may_be_covered(s, tx, ty)) continue;
        const uint entry = counters[ty * frame->tiles_x + tx]++;
        if (!fill || entry >= frame->bin_capacity) continue;
        tile_lists[entry] = slot;
        const int x0 = tx * SEAMCL_TILE_SIZE, y0 = ty * SEAMCL_TILE_SIZE;
        const int row_lo = max(s->bbox_min_y - y0, 0), row_hi = min(s->bbox_max_y - y0, SEAMCL_TILE_SIZE - 1);
        const int col_lo = max(s->bbox_min_x - x0, 0), col_hi = min(s->bbox_max_x - x0, SEAMCL_TILE_SIZE - 1);
        tile_entry_rows[entry] = (ushort)(row_lo | row_hi << 4 | col_lo << 8 | col_hi << 12);
      }
    }
  }
}

__kernel void bin_count(__constant FrameParams* frame, __global const TriangleSetup* setups,
                        __global const uint* slot_counts, __global uint* chunk_counts, int chunk_triangles) {
  const int chunk = (int)get_global_id(0);
  const int tiles = frame->tiles_x * frame->tiles_y;
  __global uint* counts = chunk_counts + (size_t)chunk * (size_t)tiles;
  for (int tile = 0; tile < tiles; ++tile) counts[tile] = 0;
  const int first = chunk * chunk_triangles;
  const int end = min(first + chunk_triangles, frame->input_triangles);
  for (int t = first; t < end; ++t) {
    if (t + 16 < end) SEAMCL_PREFETCH(setups + t + 16);
    bin_triangle(frame, setups, slot_counts, t, counts, 0, 0, 0);
  }
}

__kernel void bin_scan(__constant FrameParams* frame, __global uint* chunk_counts, int chunks,
                       __global uint* tile_counts, __global uint* tile_offsets, __global FrameStats* stats) {
  if (get_global_id(0) != 0) return;
  const int tiles = frame->tiles_x * frame->tiles_y;
  uint running = 0;
  for (int tile = 0; tile < tiles; ++tile) {
    tile_offsets[tile] = running;
    for (int chunk = 0; chunk < chunks; ++chunk) {
      __global uint* count = chunk_counts + (size_t)chunk * (size_t)tiles + tile;
      const uint n = *count;
      *count = running; /* from here on the chunk's cursor in this tile's list */
      running += n;
    }
    tile_counts[tile] = running - tile_offsets[tile];
  }
  stats->bin_entries = running;
}

__kernel void bin_fill(__constant FrameParams* frame, __global const TriangleSetup* setups,
                       __global const uint* slot_counts, __global uint* chunk_cursors, int chunk_triangles,
                       __global uint* tile_lists, __global ushort* tile_entry_rows) {
  const int chunk = (int)get_global_id(0);
  __global uint* cursors = chunk_cursors + (size_t)chunk * (size_t)(frame->tiles_x * frame->tiles_y);
  const int first = chunk * chunk_triangles;
  const int end = min(first + chunk_triangles, frame->input_triangles);
  for (int t = first; t < end; ++t) {
    if (t + 16 < end) SEAMCL_PREFETCH(setups + t + 16);
    bin_triangle(frame, setups, slot_counts, t, cursors, 1, tile_lists, tile_entry_rows);
  }
}
