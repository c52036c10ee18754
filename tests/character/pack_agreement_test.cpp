// One validation for every consumer: each pack of the corruption suites
// (tests/support/damaged_packs.h, and re-sealed packs with values past the
// magnitude bound or no triangles) is either refused by all four consumers
// or rendered by all four, each reached through the library entry point
// its program calls:
//
//   sinew-editor validate   editor::run_validate
//   sinew-editor render     editor::render_model
//   sinew-demo              demo::DemoSession::create, then one frame
//   libsinew                api::Character::load, World, RayTracePass
//
// A pack at the bound's edge (the mannequin scaled up until it just passes)
// must render in all four: the bound is what they can frame and trace.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "character/bake.h"
#include "character/pack.h"
#include "character/renderable.h"
#include "content/mannequin/mannequin.h"
#include "editor/cli/pack_commands.h"
#include "editor/cli/render_command.h"
#include "game_demo/demo_session.h"
#include "runtime/jobs/job_system.h"
#include "sinew/sinew.h"
#include "tests/support/damaged_packs.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

constexpr int kSize = 24;

// Each consumer's verdict: accepted and rendered (empty), or its message.
struct Verdicts {
  std::array<std::string, 4> errors;  // validate, render, demo, libsinew
  std::array<bool, 4> rendered{};
  bool agree() const { return std::all_of(rendered.begin(), rendered.end(), [&](bool r) { return r == rendered[0]; }); }
  std::string describe() const {
    static constexpr const char* kNames[4] = {"validate", "render", "demo", "libsinew"};
    std::string s;
    for (int i = 0; i < 4; ++i) {
      s += std::string("\n  ") + kNames[i] + ": " + (rendered[i] ? "rendered" : "refused: " + errors[i]);
    }
    return s;
  }
};

std::string validate(const std::string& path) {
  std::ostringstream out, err;
  return editor::run_validate({path}, out, err) == 0 ? "" : err.str() + " ";
}

std::string render(const std::string& path) {
  editor::RenderOptions options;
  options.model_path = path;
  options.width = options.height = kSize;
  options.threads = 1;
  auto rendered = editor::render_model(options);
  return rendered.ok() ? "" : rendered.status().message() + " ";
}

std::string demo_frame(const std::string& path, JobSystem& jobs) {
  demo::SessionOptions options;
  options.model_path = path;
  options.characters = 2;
  options.width = options.height = kSize;
  auto session = demo::DemoSession::create(options, jobs);
  if (!session.ok()) return session.status().message() + " ";
  auto frame = (*session)->frame(1.0f / 30.0f, demo::PlayerInput{}, demo::FollowCamera{}, jobs);
  return frame.ok() ? "" : frame.status().message() + " ";
}

// As a host would: the character at the origin, posed by its first clip,
// a camera backed off from its bind bounds.
std::string libsinew_frame(const std::string& path) {
  auto character = api::Character::load(path);
  if (!character.ok()) return character.error().message + " ";
  auto world = api::World::create();
  if (!world.ok()) return world.error().message + " ";
  auto instance = world.value().add_instance(character.value());
  if (!instance.ok()) return instance.error().message + " ";
  if (character.value().clip_count() > 0) {
    const api::Status posed = world.value().pose_at(instance.value(), character.value().clip_name(0), 0.37);
    if (!posed.ok()) return posed.error().message + " ";
  }
  const api::Character::Bounds b = character.value().bind_bounds();
  const api::Float3 centre{0.5f * (b.min.x + b.max.x), 0.5f * (b.min.y + b.max.y), 0.5f * (b.min.z + b.max.z)};
  const float radius = std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z, 1e-3f});
  api::PassDesc desc;
  desc.width = desc.height = kSize;
  desc.threads = 1;
  auto pass = api::RayTracePass::create(desc);
  if (!pass.ok()) return pass.error().message + " ";
  const api::Light light{api::Light::Kind::kPoint, {centre.x, centre.y + 2 * radius, centre.z + 2 * radius}};
  api::PassInputs inputs;
  inputs.camera.eye = {centre.x, centre.y, centre.z + 3 * radius};
  inputs.camera.target = centre;
  inputs.lights = std::span<const api::Light>(&light, 1);
  std::vector<std::uint8_t> rgba(4 * kSize * kSize);
  api::PassOutputs outputs;
  outputs.color_rgba8 = {rgba.data(), 0};
  auto stats = pass.value().execute(world.value(), inputs, outputs);
  return stats.ok() ? "" : stats.error().message + " ";
}

Verdicts consume(const std::vector<std::byte>& bytes, const std::string& path, JobSystem& jobs) {
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  Verdicts v;
  v.errors = {validate(path), render(path), demo_frame(path, jobs), libsinew_frame(path)};
  for (int i = 0; i < 4; ++i) v.rendered[i] = v.errors[i].empty();
  return v;
}

struct Mannequin {
  character::Model model;
  rt::FuzzyCharacterData fuzzy;
};

const Mannequin& mannequin() {
  static const Mannequin m = [] {
    Mannequin out;
    out.model = content::make_mannequin().value();
    character::BakeRequest request;
    request.pose_space.mode = anim::PoseSpaceMode::kClip;
    request.pose_space.clips = {"idle"};
    request.pose_space.every_frame_30hz = false;
    JobSystem jobs(2);
    out.fuzzy = character::bake_in_memory(out.model, request, jobs).value().fuzzy;
    return out;
  }();
  return m;
}

std::vector<std::byte> pack_of(const character::Model& model, const rt::FuzzyCharacterData* fuzzy) {
  character::PackContents contents;
  contents.model = &model;
  contents.fuzzy = fuzzy;
  contents.provenance.source_name = "agreement";
  return character::serialize_pack(contents).value();
}

// The model's lengths (positions, translations, inverse binds' and clip
// keys' translations) times `factor`: the same character, larger.
character::Model scaled(const character::Model& model, float factor) {
  character::Model out = model;
  for (Vec3& p : out.mesh.positions) p *= factor;
  anim::RawSkeleton raw;
  const auto parents = model.skeleton.parents();
  for (std::size_t j = 0; j < model.skeleton.joint_count(); ++j) {
    anim::RawJoint joint;
    joint.name = model.skeleton.names()[j];
    joint.parent = parents[j];
    joint.rest = model.skeleton.rest_pose()[j];
    joint.rest.translation *= factor;
    joint.inverse_bind = model.skeleton.inverse_bind()[j];
    for (Vec4& row : joint.inverse_bind.rows) row.w *= factor;
    raw.joints.push_back(joint);
  }
  out.skeleton = anim::Skeleton::build(raw, "scaled").value();
  out.clips.clear();
  for (const anim::Clip& clip : model.clips) {
    anim::RawClip rc;
    rc.name = clip.name();
    rc.tracks.assign(clip.tracks().begin(), clip.tracks().end());
    for (anim::JointTracks& t : rc.tracks) {
      for (Vec3& v : t.translation.values) v *= factor;
    }
    out.clips.push_back(anim::Clip::build(std::move(rc), out.skeleton, "scaled").value());
  }
  return out;
}

// The fuzzy bake alone (character::bake_in_memory checks the model first).
rt::FuzzyCharacterData bake_without_the_check(const character::Model& model, JobSystem& jobs) {
  const std::vector<Affine3> samples =
      character::pose_space_skinning(model, character::default_pose_space(), {}).value();
  rt::FuzzyBakeInput input;
  input.mesh = &model.mesh;
  input.bone_count = static_cast<std::uint32_t>(model.skeleton.joint_count());
  input.bone_parents = model.skeleton.parents();
  input.samples = samples;
  return rt::bake_fuzzy_character(input, rt::FuzzyBakeOptions{}, jobs).value();
}

TEST(PackAgreement, EveryDamagedPackIsRefusedByAllOrRenderedByAll) {
  testing_support::TempDir dir;
  JobSystem jobs(1);
  const Mannequin& m = mannequin();
  const auto pristine = pack_of(m.model, &m.fuzzy);
  int refused = 0, rendered = 0;
  for (const testing_support::DamagedPack& damaged : testing_support::randomly_damaged_packs(pristine, 8, 50)) {
    const Verdicts v = consume(damaged.bytes, dir.file("damaged.pack"), jobs);
    EXPECT_TRUE(v.agree()) << damaged.what << v.describe();
    (v.rendered[0] ? rendered : refused) += 1;
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(rendered, 0);
  RecordProperty("refused", refused);
  RecordProperty("rendered", rendered);
}

// Values a re-sealed pack can hold that no consumer can frame: every
// consumer refuses them, and the message names the file, the field, the
// value and the limit.
TEST(PackAgreement, MagnitudesPastTheBoundAndNoTrianglesAreRefusedByAll) {
  testing_support::TempDir dir;
  JobSystem jobs(1);
  const Mannequin& m = mannequin();
  struct Case {
    const char* what;
    std::function<void(character::Model&)> damage;
    std::string field;
    std::string value;
  };
  auto with_joint = [](character::Model& model, const std::function<void(anim::RawJoint&)>& change) {
    anim::RawSkeleton raw;
    for (std::size_t j = 0; j < model.skeleton.joint_count(); ++j) {
      anim::RawJoint joint{model.skeleton.names()[j], model.skeleton.parents()[j], model.skeleton.rest_pose()[j],
                           model.skeleton.inverse_bind()[j]};
      if (j == 3) change(joint);
      raw.joints.push_back(joint);
    }
    model.skeleton = anim::Skeleton::build(raw, "test").value();
  };
  const Case cases[] = {
      {"a vertex at 1e30", [](character::Model& model) { model.mesh.positions[5].y = 1e30f; },
       "MESH.positions[5]", "1e+30"},
      {"a joint scale of 1e30", [&](character::Model& model) { with_joint(model, [](anim::RawJoint& j) { j.rest.scale.x = 1e30f; }); },
       "SKEL.joints[3].scale", "1e+30"},
      {"a joint translation of 3e38",
       [&](character::Model& model) { with_joint(model, [](anim::RawJoint& j) { j.rest.translation.z = 3e38f; }); },
       "SKEL.joints[3].translation", "3e+38"},
      {"every length times 1e25", [](character::Model& model) { model = scaled(model, 1e25f); },
       "SKEL.joints[", "e+2"},
      {"a joint scale of 1e5 on every joint",
       [&](character::Model& model) {
         anim::RawSkeleton raw;
         for (std::size_t j = 0; j < model.skeleton.joint_count(); ++j) {
           raw.joints.push_back({model.skeleton.names()[j], model.skeleton.parents()[j],
                                 model.skeleton.rest_pose()[j], model.skeleton.inverse_bind()[j]});
           raw.joints.back().rest.scale = Vec3(1e5f);
         }
         model.skeleton = anim::Skeleton::build(raw, "test").value();
       },
       "SKEL.joints[", "reach"},
      {"no triangles",
       [](character::Model& model) {
         model.mesh.triangles.clear();
         model.mesh.triangle_material.clear();
       },
       "MESH.triangle_count", "0"},
  };
  for (const Case& c : cases) {
    character::Model model = m.model;
    c.damage(model);
    // Re-sealed with the pristine bake's trees, as a hostile file would be;
    // without triangles, with the trees the fuzzy bake gives such a mesh
    // (what baking a .cfg without meshes used to write).
    rt::FuzzyCharacterData fuzzy = m.fuzzy;
    if (model.mesh.triangle_count() == 0) fuzzy = bake_without_the_check(model, jobs);
    const std::string path = dir.file("extreme.pack");
    const Verdicts v = consume(pack_of(model, &fuzzy), path, jobs);
    for (int i = 0; i < 4; ++i) EXPECT_FALSE(v.rendered[i]) << c.what << v.describe();
    const std::string& message = v.errors[0];
    EXPECT_NE(message.find(path + ": " + c.field), std::string::npos) << c.what << ": " << message;
    EXPECT_NE(message.find(c.value), std::string::npos) << c.what << ": " << message;
    if (c.field != "MESH.triangle_count") {
      EXPECT_NE(message.find("limit 1e+09"), std::string::npos) << c.what << ": " << message;
    }
  }
}

// The bound is what the consumers can handle: the mannequin grown until the
// next doubling would pass it renders everywhere, and that doubling is
// refused everywhere.
TEST(PackAgreement, APackAtTheBoundRendersInEveryConsumer) {
  testing_support::TempDir dir;
  JobSystem jobs(1);
  const Mannequin& m = mannequin();
  float factor = 1.0f;
  while (character::check_renderable(scaled(m.model, 2.0f * factor), "x").ok()) factor *= 2.0f;
  ASSERT_GT(factor, 1e7f);  // the mannequin is about 2 units tall
  RecordProperty("factor", std::to_string(factor));
  character::Model large = scaled(m.model, factor);
  character::BakeRequest request;
  request.pose_space.mode = anim::PoseSpaceMode::kClip;
  request.pose_space.clips = {"idle"};
  request.pose_space.every_frame_30hz = false;
  auto baked = character::bake_in_memory(large, request, jobs);
  ASSERT_TRUE(baked.ok()) << baked.status().message();
  const Verdicts at_bound = consume(pack_of(large, &baked->fuzzy), dir.file("large.pack"), jobs);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(at_bound.rendered[i]) << at_bound.describe();
  const Verdicts past = consume(pack_of(scaled(m.model, 2.0f * factor), nullptr), dir.file("larger.pack"), jobs);
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(past.rendered[i]) << past.describe();
}

}  // namespace
}  // namespace sinew
