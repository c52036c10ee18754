// Field-by-field equality of two imported models (skeleton, mesh, clips,
// materials), bit for bit, as GoogleTest expectations.
#pragma once

#include <gtest/gtest.h>

#include <cstring>

#include "character/model.h"

namespace sinew::testing_support {

inline void expect_same_model(const character::Model& a, const character::Model& b) {
  ASSERT_EQ(a.skeleton.joint_count(), b.skeleton.joint_count());
  for (std::size_t j = 0; j < a.skeleton.joint_count(); ++j) {
    EXPECT_EQ(a.skeleton.names()[j], b.skeleton.names()[j]);
    EXPECT_EQ(a.skeleton.parents()[j], b.skeleton.parents()[j]);
    EXPECT_EQ(0, std::memcmp(&a.skeleton.inverse_bind()[j], &b.skeleton.inverse_bind()[j], sizeof(Affine3)));
  }
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.normals, b.mesh.normals);
  EXPECT_EQ(a.mesh.uvs, b.mesh.uvs);
  EXPECT_EQ(a.mesh.joints, b.mesh.joints);
  EXPECT_EQ(a.mesh.weights, b.mesh.weights);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  EXPECT_EQ(a.mesh.triangle_material, b.mesh.triangle_material);
  EXPECT_EQ(a.mesh.material_colors, b.mesh.material_colors);
  EXPECT_EQ(a.material_names, b.material_names);
  ASSERT_EQ(a.clips.size(), b.clips.size());
  for (std::size_t c = 0; c < a.clips.size(); ++c) {
    EXPECT_EQ(a.clips[c].name(), b.clips[c].name());
    EXPECT_EQ(a.clips[c].duration(), b.clips[c].duration());
    ASSERT_EQ(a.clips[c].tracks().size(), b.clips[c].tracks().size());
    for (std::size_t t = 0; t < a.clips[c].tracks().size(); ++t) {
      const anim::JointTracks& x = a.clips[c].tracks()[t];
      const anim::JointTracks& y = b.clips[c].tracks()[t];
      EXPECT_EQ(x.joint, y.joint);
      EXPECT_EQ(x.rotation.times, y.rotation.times);
      EXPECT_EQ(x.rotation.values, y.rotation.values);
      EXPECT_EQ(x.translation.values, y.translation.values);
      EXPECT_EQ(x.scale.values, y.scale.values);
    }
  }
}

}  // namespace sinew::testing_support
