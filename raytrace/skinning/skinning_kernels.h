// Private to raytrace/skinning: the per-range kernels behind skin_vertices().
//
// The AVX2 kernel lives in a translation unit compiled with -mavx2 -mfma even
// in the portable build. Any inline function it instantiates from a shared
// header (std::span, glm, Affine3) could be emitted there with AVX2
// instructions and then picked by the linker for callers on a CPU without
// AVX2 (an ODR trap). So the kernels exchange raw float pointers only and use
// nothing but intrinsics inside.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::rt::detail {

// One frame's skinning inputs and outputs as flat arrays. Vertices are
// 3 floats (x, y, z), bones 12 floats (three rows [r0 r1 r2 t]), influences
// as PackedInfluences lays them out (packed_influences.h): per group of
// kAvx2Lanes vertices its slots [group_slot_begin[g], group_slot_begin[g+1]),
// each slot kAvx2Lanes weights and joints.
struct SkinningArrays {
  const float* rest_positions = nullptr;
  const float* rest_normals = nullptr;  // null: no normals are written
  const std::uint32_t* group_slot_begin = nullptr;
  const std::uint16_t* slot_joints = nullptr;
  const float* slot_weights = nullptr;
  const std::uint16_t* group_bone = nullptr;  // per group, or 0xFFFF (PackedInfluences::group_bone)
  const float* bones = nullptr;
  float* positions = nullptr;
  float* normals = nullptr;             // null: no normals are written
};

inline constexpr std::size_t kFloatsPerBone = 12;
inline constexpr std::size_t kAvx2Lanes = 8;

// Skins vertices [begin, end); begin and end must be multiples of kAvx2Lanes.
// Call only when avx2_kernel_compiled() and the CPU has AVX2 and FMA.
void skin_range_avx2(const SkinningArrays& arrays, std::size_t begin, std::size_t end);

// The escape check (skinning.h, EscapeCheckInput) of 8 consecutive vertices
// that have one check each, all against the same bone: `positions` their 24
// floats, `bone_from_world` that bone's 12, `boxes[i]` lane i's box as 6
// floats (lower x y z, upper x y z). Returns the lanes that escaped as bits
// 0-7, each lane's answer bit for bit the scalar check's (the same products
// and sums in the same order, no FMA), and bit 8 set when all 24 position
// floats are finite; then `lower` and `upper` get the box of the 8 points.
// Call only when avx2_kernel_compiled() and the CPU has AVX2 and FMA.
std::uint32_t escape_block_avx2(const float* positions, const float* bone_from_world, float tolerance,
                                const float* const boxes[kAvx2Lanes], float lower[3], float upper[3]);
inline constexpr std::uint32_t kEscapeBlockFinite = 1u << 8;

// Whether the 24 floats of 8 consecutive positions are all finite; if so
// `lower` and `upper` get the box of the 8 points (escape_block_avx2's).
// Call only when avx2_kernel_compiled() and the CPU has AVX2 and FMA.
bool finite_block_box_avx2(const float* positions, float lower[3], float upper[3]);

// Whether skinning_avx2.cpp was compiled with AVX2 and FMA enabled.
bool avx2_kernel_compiled();

}  // namespace sinew::rt::detail
