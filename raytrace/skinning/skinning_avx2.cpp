// AVX2+FMA linear blend skinning, 8 vertices per iteration.
//
// Each lane is one vertex of a group of the packed influences
// (packed_influences.h), whose slots hold the group's weights a register at
// a time. Per slot each lane's bone rows are loaded (two rows per 256-bit
// register) and transposed into 12 column registers, and the blended matrix
// sum_k w_k B_k is accumulated with FMAs, then applied to the rest position
// (and its 3x3 part to the rest normal). A lane past its own influences
// adds 0 * B (exactly 0, skinning matrices are finite), so the result matches
// the scalar path, which skips zero weights, up to rounding.
//
// Loads + transposes instead of _mm256_i32gather_ps for the bones: 12
// gathers per slot made this kernel slower than the scalar path, 24 row
// loads and 24 shuffles per slot are not.
//
// See skinning_kernels.h for why this file uses raw pointers and intrinsics
// only.
#include "raytrace/skinning/skinning_kernels.h"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

namespace sinew::rt::detail {

#if defined(__AVX2__) && defined(__FMA__)

namespace {

struct Vec3x8 {
  __m256 x;
  __m256 y;
  __m256 z;
};

// 8 consecutive xyz triples <-> one register per coordinate: three
// 256-bit loads or stores, each coordinate's eight values spread over the
// three registers at distinct lanes, so two blends and one permute apiece.
Vec3x8 load_xyz8(const float* p) {
  const __m256 a = _mm256_loadu_ps(p);       // x0 y0 z0 x1 y1 z1 x2 y2
  const __m256 b = _mm256_loadu_ps(p + 8);   // z2 x3 y3 z3 x4 y4 z4 x5
  const __m256 c = _mm256_loadu_ps(p + 16);  // y5 z5 x6 y6 z6 x7 y7 z7
  const __m256 x = _mm256_blend_ps(_mm256_blend_ps(a, b, 0x92), c, 0x24);
  const __m256 y = _mm256_blend_ps(_mm256_blend_ps(a, b, 0x24), c, 0x49);
  const __m256 z = _mm256_blend_ps(_mm256_blend_ps(a, b, 0x49), c, 0x92);
  return {_mm256_permutevar8x32_ps(x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)),
          _mm256_permutevar8x32_ps(y, _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)),
          _mm256_permutevar8x32_ps(z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7))};
}

void store_xyz8(float* out, const Vec3x8& v) {
  const __m256 x = _mm256_permutevar8x32_ps(v.x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
  const __m256 y = _mm256_permutevar8x32_ps(v.y, _mm256_setr_epi32(5, 0, 3, 6, 1, 4, 7, 2));
  const __m256 z = _mm256_permutevar8x32_ps(v.z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
  _mm256_storeu_ps(out, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x92), z, 0x24));
  _mm256_storeu_ps(out + 8, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x24), z, 0x49));
  _mm256_storeu_ps(out + 16, _mm256_blend_ps(_mm256_blend_ps(x, y, 0x49), z, 0x92));
}

// The blended matrix of 8 vertices: m[r * 4 + c] is row r, column c per lane.
struct Matrix3x4x8 {
  __m256 m[12];
};

// Eight rows of four floats as four registers of eight: the rows side by
// side in each half (row i in lane i), then a 4x4 transpose per half.
void transpose8x4(const __m128 rows[8], __m256 cols[4]) {
  __m256 x[4];
  for (int i = 0; i < 4; ++i) x[i] = _mm256_insertf128_ps(_mm256_castps128_ps256(rows[i]), rows[i + 4], 1);
  const __m256 t0 = _mm256_unpacklo_ps(x[0], x[1]);
  const __m256 t1 = _mm256_unpackhi_ps(x[0], x[1]);
  const __m256 t2 = _mm256_unpacklo_ps(x[2], x[3]);
  const __m256 t3 = _mm256_unpackhi_ps(x[2], x[3]);
  cols[0] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
  cols[1] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
  cols[2] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
  cols[3] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

// Row r of the 8 lanes' bones as 4 column registers (cols[c] = B_lane[r][c]).
void load_bone_row8(const float* const lane_bones[8], int r, __m256 cols[4]) {
  __m128 rows[8];
  for (int i = 0; i < 8; ++i) rows[i] = _mm_loadu_ps(lane_bones[i] + 4 * r);
  transpose8x4(rows, cols);
}

// Group g's slots are whole registers: one load of the slot's weights, and
// its joints straight from the slot (no transpose).
//
// A group rigid on one bone (PackedInfluences::group_bone: every rigid
// block of the escape check is one, and so are many groups of a fine
// mesh) takes that bone's entries broadcast, plus zero:
// fma(1, b, 0) to the bit (-0 + 0 is +0), without the row loads and
// transposes.
Matrix3x4x8 blend_bones(const SkinningArrays& a, std::size_t group) {
  Matrix3x4x8 out;
  for (__m256& e : out.m) e = _mm256_setzero_ps();
  const std::size_t first = a.group_slot_begin[group];
  const std::size_t last = a.group_slot_begin[group + 1];
  if (a.group_bone != nullptr && a.group_bone[group] != 0xFFFF) {
    const float* bone = a.bones + kFloatsPerBone * a.group_bone[group];
    for (std::size_t e = 0; e < kFloatsPerBone; ++e) out.m[e] = _mm256_add_ps(_mm256_set1_ps(bone[e]), out.m[e]);
    return out;
  }
  for (std::size_t slot = first; slot < last; ++slot) {
    const __m256 w = _mm256_loadu_ps(a.slot_weights + slot * kAvx2Lanes);
    const std::uint16_t* joints = a.slot_joints + slot * kAvx2Lanes;
    const float* lane_bones[8];
    for (std::size_t lane = 0; lane < 8; ++lane) lane_bones[lane] = a.bones + kFloatsPerBone * joints[lane];
    for (int r = 0; r < 3; ++r) {
      __m256 cols[4];
      load_bone_row8(lane_bones, r, cols);
      for (int c = 0; c < 4; ++c) out.m[4 * r + c] = _mm256_fmadd_ps(w, cols[c], out.m[4 * r + c]);
    }
  }
  return out;
}

// b's rows times (x, y, z) added to `start` (per row: start[r]), each
// product fused: x first, then y, then z.
Vec3x8 transform8(const Matrix3x4x8& b, const Vec3x8& p, const __m256 (&start)[3]) {
  Vec3x8 out;
  __m256* dst[3] = {&out.x, &out.y, &out.z};
  for (int r = 0; r < 3; ++r) {
    const __m256* row = b.m + 4 * r;
    __m256 acc = _mm256_fmadd_ps(row[0], p.x, start[r]);
    acc = _mm256_fmadd_ps(row[1], p.y, acc);
    *dst[r] = _mm256_fmadd_ps(row[2], p.z, acc);
  }
  return out;
}

// A point: the rows' translations start the sums.
Vec3x8 transform_point8(const Matrix3x4x8& b, const Vec3x8& p) {
  const __m256 start[3] = {b.m[3], b.m[7], b.m[11]};
  return transform8(b, p, start);
}

// A vector: the sums start at -0, which x * y + (-0) leaves exactly x * y
// (its sign too), as the product alone would be.
Vec3x8 transform_vector8(const Matrix3x4x8& b, const Vec3x8& n) {
  const __m256 minus_zero = _mm256_set1_ps(-0.0f);
  const __m256 start[3] = {minus_zero, minus_zero, minus_zero};
  return transform8(b, n, start);
}

}  // namespace

void skin_range_avx2(const SkinningArrays& a, std::size_t begin, std::size_t end) {
  const bool with_normals = a.rest_normals != nullptr && a.normals != nullptr;
  for (std::size_t v = begin; v + kAvx2Lanes <= end; v += kAvx2Lanes) {
    const Matrix3x4x8 blended = blend_bones(a, v / kAvx2Lanes);
    store_xyz8(a.positions + 3 * v, transform_point8(blended, load_xyz8(a.rest_positions + 3 * v)));
    if (with_normals) {
      store_xyz8(a.normals + 3 * v, transform_vector8(blended, load_xyz8(a.rest_normals + 3 * v)));
    }
  }
}

namespace {

float min_of(__m256 v) {
  __m128 m = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_min_ps(m, _mm_movehl_ps(m, m));
  m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}

float max_of(__m256 v) {
  __m128 m = _mm_max_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  m = _mm_max_ps(m, _mm_movehl_ps(m, m));
  m = _mm_max_ss(m, _mm_shuffle_ps(m, m, 1));
  return _mm_cvtss_f32(m);
}

// Whether all 24 coordinates are finite; then the box of the 8 points.
bool finite_box(const Vec3x8& p, float lower[3], float upper[3]) {
  const __m256 zero = _mm256_setzero_ps();
  const __m256 finite =
      _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(p.x, p.x), zero, _CMP_EQ_OQ),
                                  _mm256_cmp_ps(_mm256_sub_ps(p.y, p.y), zero, _CMP_EQ_OQ)),
                    _mm256_cmp_ps(_mm256_sub_ps(p.z, p.z), zero, _CMP_EQ_OQ));
  if (_mm256_movemask_ps(finite) != 0xFF) return false;
  lower[0] = min_of(p.x);
  lower[1] = min_of(p.y);
  lower[2] = min_of(p.z);
  upper[0] = max_of(p.x);
  upper[1] = max_of(p.y);
  upper[2] = max_of(p.z);
  return true;
}

}  // namespace

std::uint32_t escape_block_avx2(const float* positions, const float* bone_from_world, float tolerance,
                                const float* const boxes[kAvx2Lanes], float lower[3], float upper[3]) {
  const Vec3x8 p = load_xyz8(positions);
  // Lane by lane the scalar check's ((m0 x + m1 y) + m2 z) + m3 per row,
  // with separate products and sums: the same bits.
  __m256 q[3];
  for (int r = 0; r < 3; ++r) {
    const float* row = bone_from_world + 4 * r;
    q[r] = _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(row[0]), p.x),
                                                     _mm256_mul_ps(_mm256_set1_ps(row[1]), p.y)),
                                       _mm256_mul_ps(_mm256_set1_ps(row[2]), p.z)),
                         _mm256_set1_ps(row[3]));
  }
  // Each box as (lower x y z, upper x) and, from lower z on, (lower z,
  // upper x y z): both loads inside its six floats.
  __m128 low_rows[8];
  __m128 high_rows[8];
  for (std::size_t i = 0; i < kAvx2Lanes; ++i) {
    low_rows[i] = _mm_loadu_ps(boxes[i]);
    high_rows[i] = _mm_loadu_ps(boxes[i] + 2);
  }
  __m256 low[4];
  __m256 high[4];
  transpose8x4(low_rows, low);
  transpose8x4(high_rows, high);
  const __m256 tol = _mm256_set1_ps(tolerance);
  const __m256 zero = _mm256_setzero_ps();
  __m256 in = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  for (int axis = 0; axis < 3; ++axis) {
    const __m256 inside = _mm256_and_ps(_mm256_cmp_ps(q[axis], _mm256_sub_ps(low[axis], tol), _CMP_GE_OQ),
                                        _mm256_cmp_ps(q[axis], _mm256_add_ps(high[axis + 1], tol), _CMP_LE_OQ));
    const __m256 finite = _mm256_cmp_ps(_mm256_sub_ps(q[axis], q[axis]), zero, _CMP_EQ_OQ);
    in = _mm256_and_ps(in, _mm256_and_ps(inside, finite));
  }
  std::uint32_t result = static_cast<std::uint32_t>(~_mm256_movemask_ps(in)) & 0xFFu;
  if (finite_box(p, lower, upper)) result |= kEscapeBlockFinite;
  return result;
}

bool finite_block_box_avx2(const float* positions, float lower[3], float upper[3]) {
  return finite_box(load_xyz8(positions), lower, upper);
}

bool avx2_kernel_compiled() { return true; }

#else  // not compiled for AVX2: the dispatcher never calls the kernel

void skin_range_avx2(const SkinningArrays&, std::size_t, std::size_t) {}

std::uint32_t escape_block_avx2(const float*, const float*, float, const float* const[kAvx2Lanes], float[3],
                                float[3]) {
  return 0;
}

bool finite_block_box_avx2(const float*, float[3], float[3]) { return false; }

bool avx2_kernel_compiled() { return false; }

#endif

}  // namespace sinew::rt::detail
