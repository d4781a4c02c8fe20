/* The tessellator's slot grid, shared by the geometry program (tessellate.cl) and the shading
 * program (shade_resolve.cl, which lights a displaced render with the vertices' normals).
 * Patch p's slot (i, j) is vertex p * (T+1)^2 + j * (T+1) + i. Micro-triangle t lies in patch
 * t / (2 T^2), cell c = (t / 2) % T^2 at (c % T, c / T), split (00, 10, 11) for even t and
 * (00, 11, 01) for odd t; adaptive (T >= 2), the cells (T-1, 0) and (0, T-1) split the other way,
 * (00, 10, 01) and (10, 11, 01). tessellated_setup computes the same indices on 16 lanes. */

SEAMCL_INLINE int tess_vertex_index(int patch, int i, int j, int t) { return (patch * (t + 1) + j) * (t + 1) + i; }

/* Whether cell (ci, cj) splits on its 10-01 diagonal. */
SEAMCL_INLINE int tess_cell_flipped(int ci, int cj, int t, int adaptive) {
  return adaptive && t >= 2 && ((ci == t - 1 && cj == 0) || (ci == 0 && cj == t - 1));
}

/* Corner k (0..2) of triangle `odd` (0: even, 1: odd) of a cell, as (di, dj) offsets from its
 * 00 corner. */
SEAMCL_INLINE void tess_cell_corner(int odd, int k, int flipped, int* di, int* dj) {
  /* plain: (00, 10, 11), (00, 11, 01); flipped: (00, 10, 01), (10, 11, 01) */
  const int plain_i[6] = {0, 1, 1, 0, 1, 0}, plain_j[6] = {0, 0, 1, 0, 1, 1};
  const int flip_i[6] = {0, 1, 0, 1, 1, 0}, flip_j[6] = {0, 0, 1, 0, 1, 1};
  *di = flipped ? flip_i[3 * odd + k] : plain_i[3 * odd + k];
  *dj = flipped ? flip_j[3 * odd + k] : plain_j[3 * odd + k];
}

/* The three vertices of micro-triangle `tri`, in the setup's order. */
SEAMCL_INLINE void tess_triangle_vertices(int tri, int t, int adaptive, int* v) {
  const int patch = tri / (2 * t * t);
  const int cell = (tri / 2) % (t * t);
  const int ci = cell % t, cj = cell / t;
  const int flipped = tess_cell_flipped(ci, cj, t, adaptive);
  for (int k = 0; k < 3; ++k) {
    int di = 0, dj = 0;
    tess_cell_corner(tri & 1, k, flipped, &di, &dj);
    v[k] = tess_vertex_index(patch, ci + di, cj + dj, t);
  }
}
