/* Stage 2: binning into SEAMCL_TILE_SIZE x SEAMCL_TILE_SIZE pixel tiles, so that the raster cost
 * of a tile follows the triangles that touch it. Three kernels, queued back to back:
 *   bin_count  one work-item per input triangle, over its written slots (slot_counts, from
 *              setup): +1 on every tile a slot's triangle may cover;
 *   bin_scan   one work-item: exclusive prefix sum of the counts -> list offsets (and cursors);
 *   bin_fill   the same walk as bin_count: appends the slot index (k * input_triangles + t, the
 *              record's index) to each tile's list, and at the
 *              same entry of tile_entry_rows the rows and columns of the tile that the slot's
 *              box covers (tile-relative, 4 bits each: row_lo | row_hi << 4 | col_lo << 8 |
 *              col_hi << 12), so raster skips the entry on its other rows without reading the
 *              slot's record.
 * Most input triangles write one slot or none (culled), so walking triangles rather than all
 * SEAMCL_CLIP_SLOTS slots reads a few bytes for each culled one instead of six records.
 * A tile is skipped when one edge function is negative over all of its sample positions (the
 * standard corner test), so long thin triangles do not fill their whole bounding box.
 * List order inside a tile depends on atomics; raster does not depend on it (ties in depth are
 * broken by input order, raster_slot_precedes). If the lists need more than bin_capacity entries, bin_fill drops the
 * rest and the host, seeing stats.bin_entries > capacity, grows the buffer and renders again.
 * Host guarantees: tile_counts zeroed before bin_count; slot_counts written for this frame. Twin: host/binning.cpp. */

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

__kernel void bin_count(__constant FrameParams* frame, __global const TriangleSetup* setups,
                        __global const uint* slot_counts, __global uint* tile_counts) {
  const int t = (int)get_global_id(0);
  if (t >= frame->input_triangles) return;
  const uint written = min(slot_counts[t], (uint)SEAMCL_CLIP_SLOTS);
  for (uint k = 0; k < written; ++k) {
    __global const TriangleSetup* s = setups + (size_t)k * (size_t)frame->input_triangles + t;
    if (s->bbox_max_x < s->bbox_min_x || s->bbox_max_y < s->bbox_min_y) continue;
    for (int ty = s->bbox_min_y / SEAMCL_TILE_SIZE; ty <= s->bbox_max_y / SEAMCL_TILE_SIZE; ++ty) {
      for (int tx = s->bbox_min_x / SEAMCL_TILE_SIZE; tx <= s->bbox_max_x / SEAMCL_TILE_SIZE; ++tx) {
        if (tile_may_be_covered(s, tx, ty)) atomic_inc(&tile_counts[ty * frame->tiles_x + tx]);
      }
    }
  }
}

__kernel void bin_scan(__constant FrameParams* frame, __global const uint* tile_counts,
                       __global uint* tile_offsets, __global uint* tile_cursors, __global FrameStats* stats) {
  if (get_global_id(0) != 0) return;
  const int tiles = frame->tiles_x * frame->tiles_y;
  uint running = 0;
  for (int t = 0; t < tiles; ++t) {
    tile_offsets[t] = running;
    tile_cursors[t] = running;
    running += tile_counts[t];
  }
  stats->bin_entries = running;
}

__kernel void bin_fill(__constant FrameParams* frame, __global const TriangleSetup* setups,
                       __global const uint* slot_counts, __global uint* tile_cursors, __global uint* tile_lists,
                       __global ushort* tile_entry_rows) {
  const int t = (int)get_global_id(0);
  if (t >= frame->input_triangles) return;
  const uint written = min(slot_counts[t], (uint)SEAMCL_CLIP_SLOTS);
  for (uint k = 0; k < written; ++k) {
    const uint slot = k * (uint)frame->input_triangles + (uint)t;
    __global const TriangleSetup* s = setups + slot;
    if (s->bbox_max_x < s->bbox_min_x || s->bbox_max_y < s->bbox_min_y) continue;
    for (int ty = s->bbox_min_y / SEAMCL_TILE_SIZE; ty <= s->bbox_max_y / SEAMCL_TILE_SIZE; ++ty) {
      for (int tx = s->bbox_min_x / SEAMCL_TILE_SIZE; tx <= s->bbox_max_x / SEAMCL_TILE_SIZE; ++tx) {
        if (!tile_may_be_covered(s, tx, ty)) continue;
        const uint entry = atomic_inc(&tile_cursors[ty * frame->tiles_x + tx]);
        if (entry >= frame->bin_capacity) continue;
        tile_lists[entry] = slot;
        const int x0 = tx * SEAMCL_TILE_SIZE, y0 = ty * SEAMCL_TILE_SIZE;
        const int row_lo = max(s->bbox_min_y - y0, 0), row_hi = min(s->bbox_max_y - y0, SEAMCL_TILE_SIZE - 1);
        const int col_lo = max(s->bbox_min_x - x0, 0), col_hi = min(s->bbox_max_x - x0, SEAMCL_TILE_SIZE - 1);
        tile_entry_rows[entry] = (ushort)(row_lo | row_hi << 4 | col_lo << 8 | col_hi << 12);
      }
    }
  }
}
