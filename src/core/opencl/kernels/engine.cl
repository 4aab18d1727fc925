// amytiss OpenCL engine: MDP construction (stored transitions), synthesis sweep (stored and
// on-the-fly). One algorithm for every device; the host prepends a generated prelude that
// defines the problem as compile-time constants, the contraction functions and the system's
// amytiss_dynamics() (see opencl/source.cpp), and appends nothing.
//
// Prelude contract (all numbers printed by the host so that they read back exactly):
//   STATE_DIMS, INPUT_DIMS, DIST_DIMS         dimensions (INPUT/DIST may be 0)
//   N_STATES, N_INPUTS, N_DISTS               grid sizes (1 for a zero-dimensional grid)
//   MASS_RECORD                               sum_i WIDTH[i]: floats of one transition record
//                                             (WIDTH[i] = n_i for a whole-grid dimension, else
//                                             2 min(h_i, n_i - 1) + 1; Layout in opencl/layout.hpp)
//   BOUNDS_CAPACITY                           (max_i WIDTH[i] + 1) rounded up to a multiple of 8
//   MULTIPLICATIVE (0/1), UNIFORM (0/1: 0 = normal), TRUNCATION_NONE (0/1), ON_THE_FLY (0/1)
//   GROUP_SIZE                                work-items per group of synthesize_group
//   ROLE_FREE, ROLE_FIXED_ZERO, ROLE_FIXED_ONE the cell-role codes of the roles buffer (CellRole)
//   __constant arrays (length max(1, dims)): STATE_LB, STATE_ETA (double), STATE_COUNT,
//   HALF_CELLS, WHOLE_DIM, WIDTH, MASS_OFFSET, PADDED_STRIDE (int); KEEP_HALF (long: NoiseModel's h);
//   INPUT_LB, INPUT_ETA, INPUT_COUNT;
//   DIST_LB, DIST_ETA, DIST_COUNT; NOISE_SCALE (double, the additive scale per dimension).
//   Only for a state grid with faces, FACED_STATES defined and: STATE_FACED, FACE_START,
//   POINT_START (int per dimension), STATE_FACES, STATE_POINTS (double, the faced dimensions'
//   count + 1 faces and count points one after the other), KEEP_RADIUS (double per dimension:
//   NoiseModel::window_radius). A faced dimension keeps the cells meeting [mean -+ KEEP_RADIUS];
//   then kernels/faced_states.cl (state_face, state_point, place_faced_window) precedes this file.
//   double contract_global(__global const double* v, __global const float* m) and
//   double contract_private(__global const double* v, const float* m): the separable contraction
//     sum_a0 m[a0] * (sum_a1 m[MASS_OFFSET[1] + a1] * (... v[a0*PADDED_STRIDE[0] + ...])),
//     generated with the window widths as literal trip counts (same text, two address spaces:
//     stored records are read in place, on-the-fly records from private memory).
//
// Value layout: V (double) lives in a padded array, each dimension extended by HALF_CELLS[i] zero
// cells on both sides (plus 4 zero cells at the end for the contraction's vector over-read), so a window
// never needs clipping in the sweep: a transition record is the padded flat
// offset of its window's first cell plus its per-dimension masses (zero where the window leaves
// the grid or the truncation region).

// Floats after a record in private mass arrays: normal_masses() writes masses eight at a time.
#define MASS_SLACK 8

// Point of a flat (row-major, last dimension fastest) grid index.
void grid_point(ulong flat, int dims, __constant double* lb, __constant double* eta,
                __constant int* count, double* out) {
  for (int dim = dims - 1; dim >= 0; --dim) {
    ulong k = flat % (ulong)count[dim];
    flat /= (ulong)count[dim];
    out[dim] = lb[dim] + (double)k * eta[dim];
  }
}

// Padded flat offset of the state cell with the given flat index.
uint padded_offset(uint state) {
  uint offset = 0;
  for (int dim = STATE_DIMS - 1; dim >= 0; --dim) {
    uint k = state % (uint)STATE_COUNT[dim];
    state /= (uint)STATE_COUNT[dim];
    offset += (k + (uint)HALF_CELLS[dim]) * (uint)PADDED_STRIDE[dim];
  }
  return offset;
}

// erfc(z) for z >= 0: Chebyshev expansion of Numerical Recipes 3rd ed. (Erf::erfccheb).
// Measured against glibc erfc on [0, 27] in steps of 1e-4: absolute error <= 5e-16, far below
// the float the masses are stored in; several times faster than the OpenCL library erfc on pocl.
__constant double ERFC_COEFFICIENTS[28] = {
    -1.3026537197817094, 6.4196979235649026e-1, 1.9476473204185836e-2, -9.561514786808631e-3,
    -9.46595344482036e-4, 3.66839497852761e-4, 4.2523324806907e-5, -2.0278578112534e-5,
    -1.624290004647e-6, 1.303655835580e-6, 1.5626441722e-8, -8.5238095915e-8,
    6.529054439e-9, 5.059343495e-9, -9.91364156e-10, -2.27365122e-10,
    9.6467911e-11, 2.394038e-12, -6.886027e-12, 8.94487e-13,
    3.13092e-13, -1.12708e-13, 3.81e-16, 7.106e-15,
    -1.523e-15, -9.4e-17, 1.21e-16, -2.8e-17};
// Eight at a time: the recurrence is a serial dependency chain, so lanes are what makes it fast.
double8 erfc_nonnegative8(double8 z) {
  const double8 t = 2.0 / (2.0 + z), ty = 4.0 * t - 2.0;
  double8 d = 0.0, dd = 0.0;
  for (int j = 27; j > 0; --j) {
    const double8 previous = d;
    // One fma on the dependency chain; the subtraction uses the value of an earlier iteration.
    d = fma(ty, d, ERFC_COEFFICIENTS[j] - dd);
    dd = previous;
  }
  return t * exp(-z * z + 0.5 * (ERFC_COEFFICIENTS[0] + ty * d) - dd);
}

// Two independent groups of eight, their recurrences interleaved (four AVX2 chains in flight);
// lane for lane the same arithmetic as erfc_nonnegative8. Measured on pocl: faster than two
// erfc_nonnegative8 calls and than one double16 evaluation (whose code pocl compiles poorly:
// robot safety construction 0.78 s vs 0.44 s with this one).
double8 erfc_nonnegative8x2(double8 z, double8 z2, double8* result2) {
  const double8 t = 2.0 / (2.0 + z), ty = 4.0 * t - 2.0;
  const double8 t2 = 2.0 / (2.0 + z2), ty2 = 4.0 * t2 - 2.0;
  double8 d = 0.0, dd = 0.0, d2 = 0.0, dd2 = 0.0;
  for (int j = 27; j > 0; --j) {
    const double8 previous = d, previous2 = d2;
    d = fma(ty, d, ERFC_COEFFICIENTS[j] - dd);
    d2 = fma(ty2, d2, ERFC_COEFFICIENTS[j] - dd2);
    dd = previous;
    dd2 = previous2;
  }
  *result2 = t2 * exp(-z2 * z2 + 0.5 * (ERFC_COEFFICIENTS[0] + ty2 * d2) - dd2);
  return t * exp(-z * z + 0.5 * (ERFC_COEFFICIENTS[0] + ty * d) - dd);
}

#if UNIFORM
// Mass of [lo, hi] under the uniform law with the given mean and half-width `scale` (normal
// masses come from the shared cell-bound tails in normal_masses). Scale 0 is a point mass, 1
// when lo <= mean < hi (as NoiseModel).
double interval_mass(double lo, double hi, double mean, double scale) {
  if (scale <= 0.0) return (lo <= mean && mean < hi) ? 1.0 : 0.0;
  double overlap = fmin(hi, mean + scale) - fmax(lo, mean - scale);
  return overlap > 0.0 ? fmin(1.0, overlap / (2.0 * scale)) : 0.0;
}
#endif

// Window of dimension dim for the post mean `mean`, placed in double exactly as Grid::nearest:
// writes window_first[dim] and the kept range keep_first[dim]..keep_last[dim] of grid indices;
// returns the padded offset along dim of the window's first cell.
uint place_window(int dim, double mean, int* window_first, int* keep_first, int* keep_last) {
#ifdef FACED_STATES
  if (STATE_FACED[dim]) return place_faced_window(dim, mean, window_first, keep_first, keep_last);
#endif
  const int count = STATE_COUNT[dim];
  const double eta = STATE_ETA[dim];
  // A non-finite post state has no cell: all its mass leaves the grid.
  const bool finite = isfinite(mean);
  // Truncation keeps nearest +- KEEP_HALF (NoiseModel's h, which may exceed the grid; the
  // layout's half_cells is capped at count - 1). Clamp before converting so that far-away
  // means cannot overflow the integer: beyond this range nothing is kept either way.
  const long keep_half = KEEP_HALF[dim];
  double nearest_real = floor((mean - STATE_LB[dim]) / eta + 0.5);
  nearest_real = fmax(fmin(nearest_real, (double)(count + keep_half + 1)), (double)(-keep_half - 2));
  const long nearest = finite ? (long)nearest_real : -keep_half - 2;
  // A whole-grid dimension's window is the grid itself, from index 0 (HALF_CELLS is 0 there).
  const int start = WHOLE_DIM[dim] ? 0 : (int)clamp(nearest, 0L, (long)(count - 1));
#if TRUNCATION_NONE
  keep_first[dim] = 0;
  keep_last[dim] = finite ? count - 1 : -1;
#else
  keep_first[dim] = (int)max(nearest - keep_half, 0L);
  keep_last[dim] = (int)min(nearest + keep_half, (long)(count - 1));
#endif
  window_first[dim] = start - HALF_CELLS[dim];
  // Padded index of grid cell start - half is start.
  return (uint)start * (uint)PADDED_STRIDE[dim];
}

#if UNIFORM
// Masses of dimension dim's window under the uniform law, zero outside the kept range.
void uniform_masses(int dim, double mean, double scale, int window_first, int keep_first, int keep_last,
                    float* m) {
  for (int j = 0; j < WIDTH[dim]; ++j) {
    const int k = window_first + j;
    // The bounds as NoiseModel::cell_mass writes them: neighbours share a bound exactly.
#ifdef FACED_STATES
    const double mass = interval_mass(state_face(dim, k), state_face(dim, k + 1), mean, scale);
#else
    const double mass = interval_mass(STATE_LB[dim] + ((double)k - 0.5) * STATE_ETA[dim],
                                      STATE_LB[dim] + ((double)k + 0.5) * STATE_ETA[dim], mean, scale);
#endif
    m[MASS_OFFSET[dim] + j] = (k >= keep_first && k <= keep_last) ? (float)mass : 0.0f;
  }
}
#else
// Dimension dim's cell bounds and the arguments of their erfc evaluations, |b - mean| / (scale
// sqrt 2), in slots dim * BOUNDS_CAPACITY onwards of bound and tail.
void bound_arguments(int dim, double mean, double scale, int window_first, double* bound, double* tail) {
  const double eta = STATE_ETA[dim];
  const double inverse = scale > 0.0 ? 1.0 / (scale * 1.4142135623730951) : 0.0;
  for (int b = 0; b < BOUNDS_CAPACITY; ++b) {
    const int slot = dim * BOUNDS_CAPACITY + b;
#ifdef FACED_STATES
    bound[slot] = state_face(dim, window_first + b);
#else
    bound[slot] = STATE_LB[dim] + ((double)(window_first + b) - 0.5) * eta;
#endif
    tail[slot] = fabs(bound[slot] - mean) * inverse;
  }
}

// tail(b) = erfc(|b - mean| / (scale sqrt 2)) / 2, the mass beyond b on the far side, in place of
// every dimension's arguments at once, so that the erfc runs with the most lanes in flight.
void bound_tails(double* tail) {
  int b = 0;
  for (; b + 16 <= STATE_DIMS * BOUNDS_CAPACITY; b += 16) {
    double8 second;
    const double8 first = erfc_nonnegative8x2(vload8(0, tail + b), vload8(1, tail + b), &second);
    vstore8(0.5 * first, 0, tail + b);
    vstore8(0.5 * second, 1, tail + b);
  }
  if (b < STATE_DIMS * BOUNDS_CAPACITY)
    vstore8(0.5 * erfc_nonnegative8(vload8(0, tail + b)), 0, tail + b);
}

// Masses of dimension dim's window under the normal law from its bounds' tails, zero outside the
// kept range, eight cells at a time: a vector may run past the dimension's window into the next
// one's masses (rewritten right after) or into the MASS_SLACK floats after the record, which
// every caller's array has.
void normal_masses(int dim, double mean, double scale, int window_first, int keep_first, int keep_last,
                   const double* bound, const double* tail, float* m) {
  // One erfc per cell bound (not two per cell); every difference subtracts tails on one side
  // of the mean, accurate to ~1e-16 in absolute terms, far below the float the mass is stored
  // in. Lane for lane the rule lo >= mean: tail(lo) - tail(hi); hi <= mean: tail(hi) - tail(lo);
  // otherwise 1 - tail(lo) - tail(hi). Scale 0 is a point mass in [lo, hi).
  const double8 mean8 = (double8)(mean);
  for (int j = 0; j < WIDTH[dim]; j += 8) {
    const int slot = dim * BOUNDS_CAPACITY + j;
    const double8 lo = vload8(0, bound + slot), hi = vload8(0, bound + slot + 1);
    const double8 tail_lo = vload8(0, tail + slot), tail_hi = vload8(0, tail + slot + 1);
    double8 mass;
    if (scale <= 0.0) {
      mass = select((double8)(0.0), (double8)(1.0), (lo <= mean8) & (mean8 < hi));
    } else {
      const double8 straddling = select(1.0 - tail_lo - tail_hi, tail_hi - tail_lo, hi <= mean8);
      mass = select(straddling, tail_lo - tail_hi, lo >= mean8);
    }
    const int8 k = (int8)(window_first + j) + (int8)(0, 1, 2, 3, 4, 5, 6, 7);
    const int8 kept = (k >= (int8)(keep_first)) & (k <= (int8)(keep_last));
    vstore8(select((float8)(0.0f), convert_float8(mass), kept), 0, m + MASS_OFFSET[dim] + j);
  }
}
#endif

// Transition record of the triple (state, input, disturbance): post mean computed once, window
// placed in double exactly as Grid::nearest, masses in double rounded to float. Returns the
// padded offset of the window's first cell; writes MASS_RECORD masses to m.
uint compute_record(ulong state, ulong input, ulong disturbance, float* m) {
  double x[STATE_DIMS], post[STATE_DIMS];
  double u[INPUT_DIMS > 0 ? INPUT_DIMS : 1];
  double w[DIST_DIMS > 0 ? DIST_DIMS : 1];
  u[0] = 0.0;
  w[0] = 0.0;
#ifdef FACED_STATES
  state_point(state, x);
#else
  grid_point(state, STATE_DIMS, STATE_LB, STATE_ETA, STATE_COUNT, x);
#endif
  grid_point(input, INPUT_DIMS, INPUT_LB, INPUT_ETA, INPUT_COUNT, u);
  grid_point(disturbance, DIST_DIMS, DIST_LB, DIST_ETA, DIST_COUNT, w);
  amytiss_dynamics(x, u, w, post);

  // Pass 1: window placement per dimension; for normal noise, the arguments of every dimension's
  // erfc evaluations go into one array so that pass 2 runs them with the most lanes in flight.
  uint offset = 0;
  int window_first[STATE_DIMS], keep_first[STATE_DIMS], keep_last[STATE_DIMS];
  double mean[STATE_DIMS], scale[STATE_DIMS];
#if !UNIFORM
  // + 8: the last dimension's hi vector reads past its bounds (lanes never kept).
  double bound[STATE_DIMS * BOUNDS_CAPACITY + 8], tail[STATE_DIMS * BOUNDS_CAPACITY + 8];
#endif
  for (int dim = 0; dim < STATE_DIMS; ++dim) {
    mean[dim] = post[dim];
#if MULTIPLICATIVE
    scale[dim] = NOISE_SCALE[dim] * fabs(x[dim]);
#else
    scale[dim] = NOISE_SCALE[dim];
#endif
    offset += place_window(dim, mean[dim], window_first, keep_first, keep_last);
#if !UNIFORM
    bound_arguments(dim, mean[dim], scale[dim], window_first[dim], bound, tail);
#endif
  }
  // Pass 2 (normal law): the tails of every cell bound.
#if !UNIFORM
  bound_tails(tail);
#endif
  // Pass 3: the masses, zero outside the kept range.
  for (int dim = 0; dim < STATE_DIMS; ++dim) {
#if UNIFORM
    uniform_masses(dim, mean[dim], scale[dim], window_first[dim], keep_first[dim], keep_last[dim], m);
#else
    normal_masses(dim, mean[dim], scale[dim], window_first[dim], keep_first[dim], keep_last[dim], bound, tail, m);
#endif
  }
  return offset;
}

// Algorithm 2: one record per (state, input, disturbance) triple of a chunk of states.
__kernel void construct(ulong triple_begin, ulong triple_count, __global uint* starts,
                        __global float* masses) {
  const ulong local_triple = get_global_id(0);
  if (local_triple >= triple_count) return;
  const ulong triple = triple_begin + local_triple;
  const ulong disturbance = triple % N_DISTS;
  const ulong pair = triple / N_DISTS;
  float m[MASS_RECORD + MASS_SLACK];
  starts[local_triple] = compute_record(pair / N_INPUTS, pair % N_INPUTS, disturbance, m);
  __global float* out = masses + local_triple * MASS_RECORD;
  for (int j = 0; j < MASS_RECORD; ++j) out[j] = m[j];
}

// min over disturbances of the expected next value for (state, input); stops as soon as the
// minimum cannot beat `bar` (the best value of a lower input), which cannot change the argmax.
double input_value(__global const double* v, uint state, uint local_state, uint input, double bar,
                   __global const uint* starts, __global const float* masses) {
  double worst = INFINITY;
  for (uint disturbance = 0; disturbance < N_DISTS; ++disturbance) {
#if ON_THE_FLY
    float m[MASS_RECORD + MASS_SLACK];
    const uint start = compute_record(state, input, disturbance, m);
    worst = fmin(worst, contract_private(v + start, m));
#else
    const ulong record = ((ulong)local_state * N_INPUTS + input) * N_DISTS + disturbance;
    worst = fmin(worst, contract_global(v + starts[record], masses + record * MASS_RECORD));
#endif
    if (worst <= bar) break;
  }
  return worst;
}

// max over the inputs first, first + step, ... of input_value(), and in *best_index the lowest
// input attaining it (left as given when no input beats -1). Pruning against the best of lower
// inputs keeps the argmax exact.
double best_over_inputs(__global const double* v, uint state, uint local_state, uint first, uint step,
                        uint* best_index, __global const uint* starts, __global const float* masses) {
  double best = -1.0;
  for (uint input = first; input < N_INPUTS; input += step) {
    const double value = input_value(v, state, local_state, input, best, starts, masses);
    if (value > best) {
      best = value;
      *best_index = input;
    }
  }
  return best;
}

// Fixed cells keep their value; returns true when the state is Free.
// Masses are stored as float: a row's rounded masses may sum to 1 + a few 1e-8 where the exact
// row sums to at most 1, and so may a value. The exact value is a probability, so the excess is
// pure rounding (inside the error bound of docs/engine.md) and is removed here, after the argmax.
double probability_from_sum(double value) { return fmin(value, 1.0); }

bool handle_fixed(uint state, uint offset, __global const uchar* roles, __global double* v_next,
                  __global uint* best_input) {
  const uchar role = roles[state];
  if (role == ROLE_FREE) return true;
  v_next[offset] = role == ROLE_FIXED_ONE ? 1.0 : 0.0;
  best_input[state] = 0;
  return false;
}

// Algorithm 4, one work-item per state (CPU: each work-item streams its own records).
// Chunk: states state_begin .. state_begin + state_count; starts/masses hold that chunk's records.
__kernel void synthesize_item(__global const double* v, __global double* v_next,
                              __global uint* best_input, __global const uchar* roles,
                              uint state_begin, uint state_count, __global const uint* starts,
                              __global const float* masses) {
  const uint local_state = get_global_id(0);
  if (local_state >= state_count) return;
  const uint state = state_begin + local_state;
  const uint offset = padded_offset(state);
  if (!handle_fixed(state, offset, roles, v_next, best_input)) return;
  uint best_index = 0;
  v_next[offset] = probability_from_sum(best_over_inputs(v, state, local_state, 0, 1, &best_index, starts, masses));
  best_input[state] = best_index;
}

// Algorithm 4, one work-group per state, its work-items over inputs, argmax in local memory
// (GPU: many inputs in flight per state). Same input_value(), same tie rule (lowest index), so
// the result is bit-identical to synthesize_item.
__kernel __attribute__((reqd_work_group_size(GROUP_SIZE, 1, 1)))
void synthesize_group(__global const double* v, __global double* v_next,
                      __global uint* best_input, __global const uchar* roles, uint state_begin,
                      uint state_count, __global const uint* starts,
                      __global const float* masses) {
  __local double group_value[GROUP_SIZE];
  __local uint group_index[GROUP_SIZE];
  const uint local_state = get_group_id(0);
  const uint lane = get_local_id(0);
  if (local_state >= state_count) return;  // uniform over the group
  const uint state = state_begin + local_state;
  const uint offset = padded_offset(state);
  if (roles[state] != ROLE_FREE) {
    if (lane == 0) handle_fixed(state, offset, roles, v_next, best_input);
    return;  // uniform over the group
  }
  uint best_index = 0xffffffffu;
  group_value[lane] = best_over_inputs(v, state, local_state, lane, GROUP_SIZE, &best_index, starts, masses);
  group_index[lane] = best_index;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = GROUP_SIZE / 2; stride > 0; stride /= 2) {
    if (lane < stride) {
      const double other = group_value[lane + stride];
      const uint other_index = group_index[lane + stride];
      if (other > group_value[lane] ||
          (other == group_value[lane] && other_index < group_index[lane])) {
        group_value[lane] = other;
        group_index[lane] = other_index;
      }
    }
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (lane == 0) {
    v_next[offset] = probability_from_sum(group_value[0]);
    best_input[state] = group_index[0];
  }
}
