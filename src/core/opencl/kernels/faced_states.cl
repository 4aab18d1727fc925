// State grids with a dimension given by its cell faces: the host adds this file, after the
// prelude's FACED_STATES constants and before engine.cl, only for such a grid (opencl/source.cpp),
// so that a uniform grid's program text is the one it always was.

// Face k of state dimension dim (uniform: lb + (k - 1/2) eta); beyond a faced dimension's grid the
// faces continue with its outermost cells' widths, as Grid::face.
double state_face(int dim, int k) {
  if (!STATE_FACED[dim]) return STATE_LB[dim] + ((double)k - 0.5) * STATE_ETA[dim];
  const int count = STATE_COUNT[dim];
  __constant double* f = STATE_FACES + FACE_START[dim];
  if (k < 0) return f[0] + (double)k * (f[1] - f[0]);
  if (k > count) return f[count] + (double)(k - count) * (f[count] - f[count - 1]);
  return f[k];
}

// The cell of a faced dimension containing v, clamped to 0..count-1 (Grid::clamped_cell).
int faced_cell(int dim, double v) {
  __constant double* f = STATE_FACES + FACE_START[dim];
  int lo = 0, hi = STATE_COUNT[dim] - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (f[mid] <= v) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

// Point of a flat state index: a faced dimension's midpoints, as Grid::point.
void state_point(ulong flat, double* out) {
  for (int dim = STATE_DIMS - 1; dim >= 0; --dim) {
    ulong k = flat % (ulong)STATE_COUNT[dim];
    flat /= (ulong)STATE_COUNT[dim];
    out[dim] = STATE_FACED[dim] ? STATE_POINTS[POINT_START[dim] + (int)k] : STATE_LB[dim] + (double)k * STATE_ETA[dim];
  }
}

// place_window() of a faced dimension (NoiseModel::dimension_window): the window starts HALF_CELLS
// before the cell containing the mean (clamped), the kept cells meet [mean -+ KEEP_RADIUS].
uint place_faced_window(int dim, double mean, int* window_first, int* keep_first, int* keep_last) {
  const int count = STATE_COUNT[dim];
  const bool finite = isfinite(mean);
  __constant double* f = STATE_FACES + FACE_START[dim];
  const int start = WHOLE_DIM[dim] || !finite ? 0 : faced_cell(dim, mean);
#if TRUNCATION_NONE
  keep_first[dim] = 0;
  keep_last[dim] = finite ? count - 1 : -1;
#else
  const double lo = mean - KEEP_RADIUS[dim], hi = mean + KEEP_RADIUS[dim];
  const bool meets = finite && !(hi < f[0] || lo > f[count]);
  keep_first[dim] = meets ? faced_cell(dim, lo) : 0;
  keep_last[dim] = meets ? faced_cell(dim, hi) : -1;
#endif
  window_first[dim] = start - HALF_CELLS[dim];
  return (uint)start * (uint)PADDED_STRIDE[dim];
}
