// Cal3D importer: counts against content/README.md, an oracle against the
// Cal3D library's own posing and skinning, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cal3d/cal3d.h>
#include <cal3d/coretrack.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "animation/clip.h"
#include "animation/pose.h"
#include "animation/reference_skinning.h"
#include "character/bake.h"
#include "editor/import/cal3d_importer.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/cal3d_support.h"

namespace sinew::editor {
namespace {

namespace fs = std::filesystem;

std::string model_cfg(const std::string& model) {
  return std::string(SINEW_SHARED_DIR) + "/content/cal3d/" + model + "/" + model + ".cfg";
}
std::string model_file(const std::string& model, const std::string& file) {
  return std::string(SINEW_SHARED_DIR) + "/content/cal3d/" + model + "/" + file;
}

// ---------------------------------------------------------------- counts

TEST(Cal3dImport, CallyCountsMatchReadme) {
  auto m = import_cal3d(model_cfg("cally"));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->mesh.triangle_count(), 3342u);
  EXPECT_EQ(m->mesh.vertex_count(), 1844u);
  EXPECT_EQ(m->skeleton.joint_count(), 37u);
  ASSERT_EQ(m->clips.size(), 7u);
  // The .cfg lists only walk: it comes first, the others follow by file name.
  EXPECT_EQ(m->clips[0].name(), "walk");
  for (const char* name : {"idle", "jog", "walk", "strut", "wave", "tornado_kick", "shoot_arrow"}) {
    EXPECT_NE(m->find_clip(name), nullptr) << name;
  }
  // Durations are Cal3D's header durations (README), not the last key
  // times (one frame earlier): see the importer's header.
  EXPECT_NEAR(m->find_clip("wave")->duration(), 3.367f, 1e-3f);
  EXPECT_NEAR(m->find_clip("walk")->duration(), 1.0333f, 1e-3f);
  EXPECT_NEAR(m->find_clip("jog")->duration(), 0.8f, 1e-3f);
  EXPECT_EQ(m->find_clip("wave")->tracks().size(), 14u);
  EXPECT_EQ(m->mesh.normals.size(), m->mesh.vertex_count());
  // Cally's meshes carry no texture coordinates (no maps in its .cmf files).
  EXPECT_TRUE(m->mesh.uvs.empty());
  EXPECT_EQ(m->mesh.triangle_material.size(), m->mesh.triangle_count());
  EXPECT_EQ(m->mesh.material_colors.size(), m->material_names.size());
  for (std::uint32_t mat : m->mesh.triangle_material) ASSERT_LT(mat, m->mesh.material_colors.size());
  // Max 4 influences per vertex (README), rows sum to 1.
  int max_infl = 0;
  for (std::size_t v = 0; v < m->mesh.vertex_count(); ++v) {
    float sum = 0.0f;
    int n = 0;
    for (float w : m->mesh.weights[v]) {
      sum += w;
      n += w > 0.0f ? 1 : 0;
    }
    max_infl = std::max(max_infl, n);
    ASSERT_NEAR(sum, 1.0f, 1e-5f);
  }
  EXPECT_EQ(max_infl, 4);
}

TEST(Cal3dImport, PaladinCountsMatchReadme) {
  auto m = import_cal3d(model_cfg("paladin"));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->mesh.triangle_count(), 3422u);
  EXPECT_EQ(m->mesh.vertex_count(), 2235u);
  EXPECT_EQ(m->skeleton.joint_count(), 58u);
  EXPECT_EQ(m->clips.size(), 7u);
  EXPECT_NE(m->find_clip("sneak"), nullptr);
  EXPECT_EQ(m->mesh.uvs.size(), m->mesh.vertex_count());
  EXPECT_EQ(m->material_names.size(), 19u);
}

TEST(Cal3dImport, SkeletonAndHeroLoad) {
  auto s = import_cal3d(model_cfg("skeleton"));
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->mesh.triangle_count(), 4604u);
  EXPECT_EQ(s->mesh.vertex_count(), 2527u);
  EXPECT_EQ(s->skeleton.joint_count(), 23u);
  EXPECT_EQ(s->clips.size(), 7u);
  auto h = import_cal3d(model_cfg("hero"));
  ASSERT_TRUE(h.ok()) << h.status().message();
  EXPECT_EQ(h->mesh.triangle_count(), 5188u);
  EXPECT_EQ(h->mesh.vertex_count(), 3575u);
  EXPECT_EQ(h->skeleton.joint_count(), 58u);
  ASSERT_EQ(h->clips.size(), 1u);
  EXPECT_EQ(h->clips[0].name(), "idle");
}

// ---------------------------------------------------------------- oracle

// The Cal3D side, loaded independently of the importer: its own
// CalCoreModel, the same files, the same scale.
struct CalSide {
  CalCoreModel core{"oracle"};
  std::vector<int> mesh_ids;
  float scale = 1.0f;

  CalSide() = default;
  CalSide(const CalSide&) = delete;
  CalSide& operator=(const CalSide&) = delete;
  ~CalSide() { testing_support::free_cal3d_animation_tracks(core); }
};

bool load_cal_side(const std::string& model, CalSide& side) {
  std::ifstream in(model_cfg(model));
  std::stringstream text;
  text << in.rdbuf();
  auto cfg = parse_cal3d_config(text.str(), model_cfg(model));
  if (!cfg.ok()) return false;
  side.scale = cfg->scale;
  if (!side.core.loadCoreSkeleton(model_file(model, cfg->skeleton))) return false;
  for (const std::string& mesh : cfg->meshes) {
    const int id = side.core.loadCoreMesh(model_file(model, mesh));
    if (id < 0) return false;
    side.mesh_ids.push_back(id);
  }
  return true;
}

struct OracleErrors {
  double joint_translation = 0.0;  // relative to the bounding-box diagonal
  double joint_rotation = 0.0;     // max |R e_k - R_cal e_k|
  double vertex = 0.0;             // relative to the bounding-box diagonal
  int samples = 0;
};

// Poses both sides with one clip as a weight-1 cycle (no fade: delay 0) at
// 2 * sample_count times and compares every bone and every skinned vertex.
void run_oracle(const std::string& model, const character::Model& ours, CalSide& side,
                const std::string& clip_name, int sample_count, OracleErrors& err) {
  const anim::Clip* clip = ours.find_clip(clip_name);
  ASSERT_NE(clip, nullptr) << clip_name;
  const int anim_id = side.core.loadCoreAnimation(model_file(model, model + "_" + clip_name + ".caf"));
  ASSERT_GE(anim_id, 0);
  CalCoreAnimation* core_anim = side.core.getCoreAnimation(anim_id);
  // CalCoreModel::scale scales what is loaded so far: scale this clip alone.
  if (side.scale != 1.0f) core_anim->scale(side.scale);
  const float duration = core_anim->getDuration();
  // The importer extends each track to Cal3D's header duration, so both
  // sides loop at the same time.
  EXPECT_NEAR(clip->duration(), duration, 1e-5f) << model << " " << clip_name;

  CalModel cal(&side.core);
  for (int id : side.mesh_ids) ASSERT_TRUE(cal.attachMesh(id));
  // Without internal data the physique skins every vertex (spring vertices
  // included) instead of leaving spring vertices to the spring system,
  // whose state would depend on history (content/README.md).
  cal.disableInternalData();
  CalMixer* mixer = cal.getMixer();
  ASSERT_TRUE(mixer->blendCycle(anim_id, 1.0f, 0.0f));
  // A zero step applies the cycle's weight (delay 0) and sets the mixer's
  // duration, with no fading; the spring system is never updated.
  mixer->updateAnimation(0.0f);

  const anim::Skeleton& skel = ours.skeleton;
  std::vector<anim::JointTransform> local(skel.joint_count());
  std::vector<Affine3> model_m(skel.joint_count()), skin(skel.joint_count());
  std::vector<Vec3> positions(ours.mesh.vertex_count());
  anim::SamplingCache cache;
  const double diag = testing_support::bbox_diagonal(ours.mesh);
  std::vector<CalBone*>& bones = cal.getSkeleton()->getVectorBone();
  ASSERT_EQ(bones.size(), skel.joint_count());

  // First `sample_count` times set directly, spread over [0, duration)
  // including 0, off the key times; then as many played by stepping the
  // mixer past the end several times, against Sinew's looping clip time.
  double playback = 0.0;
  const float step = duration * 0.29f;
  for (int i = 0; i < 2 * sample_count; ++i) {
    float t = 0.0f;
    if (i < sample_count) {
      t = duration * (static_cast<float>(i) + (i == 0 ? 0.0f : 0.37f)) / static_cast<float>(sample_count);
      mixer->setAnimationTime(t);
    } else {
      if (i == sample_count) mixer->setAnimationTime(0.0f);
      mixer->updateAnimation(step);  // never CalModel::update: no springs
      playback += static_cast<double>(step);
      t = anim::clip_time(*clip, playback, /*loop=*/true);
    }
    mixer->updateSkeleton();

    ASSERT_TRUE(anim::rest_pose(skel, local).ok());
    anim::sample_clip(*clip, t, cache, local);
    ASSERT_TRUE(anim::local_to_model(skel, local, model_m).ok());
    ASSERT_TRUE(anim::skinning_matrices(skel, model_m, Affine3::identity(), skin).ok());
    ASSERT_TRUE(anim::skin_reference(ours.mesh, skin, positions, {}).ok());

    for (CalBone* bone : bones) {
      const auto j = skel.find(bone->getCoreBone()->getName());
      ASSERT_TRUE(j.has_value());
      const Affine3& m = model_m[static_cast<std::size_t>(*j)];
      const CalVector& ct = bone->getTranslationAbsolute();
      const Vec3 d = m.translation_part() - Vec3(ct.x, ct.y, ct.z);
      err.joint_translation = std::max(err.joint_translation, static_cast<double>(glm::length(d)) / diag);
      // Rotation compared by what it does to vectors, with Cal3D's own
      // vector-by-quaternion product: this is what pins the conjugate mapping.
      for (int k = 0; k < 3; ++k) {
        CalVector e(k == 0 ? 1.0f : 0.0f, k == 1 ? 1.0f : 0.0f, k == 2 ? 1.0f : 0.0f);
        e *= bone->getRotationAbsolute();
        Vec3 ours_e = m.transform_vector(Vec3(k == 0 ? 1.0f : 0.0f, k == 1 ? 1.0f : 0.0f,
                                              k == 2 ? 1.0f : 0.0f));
        err.joint_rotation = std::max(
            err.joint_rotation, static_cast<double>(glm::length(ours_e - Vec3(e.x, e.y, e.z))));
      }
    }

    const auto vertex_error =
        testing_support::max_vertex_error_vs_cal3d(cal, side.mesh_ids, positions, diag);
    ASSERT_TRUE(vertex_error.has_value()) << "vertex counts differ from Cal3D's";
    err.vertex = std::max(err.vertex, *vertex_error);
    ++err.samples;
  }
}

void oracle_model(const std::string& model, const std::vector<std::string>& clips) {
  auto ours = import_cal3d(model_cfg(model));
  ASSERT_TRUE(ours.ok()) << ours.status().message();
  CalSide side;
  ASSERT_TRUE(load_cal_side(model, side)) << CalError::getLastErrorText();
  if (side.scale != 1.0f) side.core.scale(side.scale);  // skeleton + meshes
  constexpr double kTolerance = 1e-4;
  for (const std::string& clip : clips) {
    OracleErrors err;
    run_oracle(model, *ours, side, clip, 24, err);
    std::printf("[oracle] %s %-6s samples %d: joint translation %.3g, joint rotation %.3g, vertex %.3g"
                " (relative to bbox diagonal)\n",
                model.c_str(), clip.c_str(), err.samples, err.joint_translation, err.joint_rotation,
                err.vertex);
    EXPECT_EQ(err.samples, 48);
    EXPECT_LT(err.joint_translation, kTolerance) << model << " " << clip;
    EXPECT_LT(err.joint_rotation, kTolerance) << model << " " << clip;
    EXPECT_LT(err.vertex, kTolerance) << model << " " << clip;
  }
}

TEST(Cal3dOracle, CallyMatchesCal3dLibrary) { oracle_model("cally", {"walk", "jog", "strut", "wave"}); }

TEST(Cal3dOracle, PaladinMatchesCal3dLibraryAtHalfScale) {
  oracle_model("paladin", {"walk", "jog", "strut", "wave"});
}

// The rest pose (no clip) must reproduce the bind mesh on both sides.
TEST(Cal3dOracle, RestPoseSkinsToBindMesh) {
  auto ours = import_cal3d(model_cfg("cally"));
  ASSERT_TRUE(ours.ok()) << ours.status().message();
  const anim::Skeleton& skel = ours->skeleton;
  std::vector<anim::JointTransform> local(skel.joint_count());
  std::vector<Affine3> model_m(skel.joint_count()), skin(skel.joint_count());
  std::vector<Vec3> positions(ours->mesh.vertex_count());
  ASSERT_TRUE(anim::rest_pose(skel, local).ok());
  ASSERT_TRUE(anim::local_to_model(skel, local, model_m).ok());
  ASSERT_TRUE(anim::skinning_matrices(skel, model_m, Affine3::identity(), skin).ok());
  ASSERT_TRUE(anim::skin_reference(ours->mesh, skin, positions, {}).ok());
  const double diag = testing_support::bbox_diagonal(ours->mesh);
  double max_err = 0.0;
  for (std::size_t v = 0; v < positions.size(); ++v) {
    max_err = std::max(max_err, static_cast<double>(glm::length(positions[v] - ours->mesh.positions[v])) / diag);
  }
  EXPECT_LT(max_err, 1e-5);
}

// ---------------------------------------------------------------- bad input

class Cal3dBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sinew_cal3d_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  // One Cally file of each binary kind, and the name its copies get.
  struct BinaryKind {
    std::string source;
    std::string name;
  };
  static std::vector<BinaryKind> binary_kinds() {
    return {{model_file("cally", "cally.csf"), "t.csf"},
            {model_file("cally", "cally_chest.cmf"), "t.cmf"},
            {model_file("cally", "cally_wave.caf"), "t.caf"}};
  }
  // A .cfg using `file` as the kind its name says (t.csf, t.cmf or t.caf),
  // with the skeleton `csf` otherwise, and the mesh `mesh` when given.
  static std::string cfg_using(const std::string& name, const std::string& file, const std::string& csf,
                               const std::string& mesh = "") {
    std::string cfg = "skeleton=" + (name == "t.csf" ? file : csf) + "\n";
    if (name == "t.cmf") {
      cfg += "mesh=" + file + "\n";
    } else if (!mesh.empty()) {
      cfg += "mesh=" + mesh + "\n";
    }
    if (name == "t.caf") cfg += "animation=" + file + "\n";
    return cfg;
  }
  static std::string read(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }
  fs::path dir_;
};

TEST_F(Cal3dBadInput, MissingCfg) {
  const std::string path = (dir_ / "nope.cfg").string();
  auto m = import_cal3d(path);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(m.status().file(), path);
}

TEST_F(Cal3dBadInput, CfgNamingMissingFiles) {
  const std::string csf = model_file("cally", "cally.csf");
  const std::string cmf = model_file("cally", "cally_chest.cmf");
  struct Case {
    std::string cfg;
    std::string missing;
  };
  const std::vector<Case> cases = {
      {"skeleton=missing.csf\nmesh=" + cmf + "\n", "missing.csf"},
      {"skeleton=" + csf + "\nmesh=missing.cmf\n", "missing.cmf"},
      {"skeleton=" + csf + "\nmesh=" + cmf + "\nanimation=missing.caf\n", "missing.caf"},
      {"skeleton=" + csf + "\nmaterial=missing.xrf\n", "missing.xrf"},
  };
  for (const Case& c : cases) {
    auto m = import_cal3d(write("m.cfg", c.cfg));
    ASSERT_FALSE(m.ok()) << c.missing;
    EXPECT_EQ(m.status().code(), ErrorCode::kNotFound) << m.status().message();
    EXPECT_EQ(m.status().file(), (dir_ / c.missing).string()) << m.status().message();
  }
}

TEST_F(Cal3dBadInput, GarbageCfgLines) {
  const std::string csf = model_file("cally", "cally.csf");
  const std::vector<std::string> bad = {
      "skeleton=" + csf + "\nthis line is garbage\n",
      "skeleton=" + csf + "\nscale=abc\n",
      "skeleton=" + csf + "\nscale=-1\n",
      "skeleton=" + csf + "\nscale=nan\n",
      "skeleton=" + csf + "\nmesh=\n",
      "skeleton=" + csf + "\nskeleton=" + csf + "\n",
      "mesh=foo.cmf\n",
      std::string("skeleton=") + csf + "\n\x01\x02\xff\xfe\n",
  };
  for (const std::string& text : bad) {
    const std::string path = write("g.cfg", text);
    auto m = import_cal3d(path);
    ASSERT_FALSE(m.ok()) << text;
    EXPECT_EQ(m.status().file(), path) << m.status().message();
    EXPECT_FALSE(m.status().detail().empty());
  }
  // Unknown keys, comments, blanks and CRLF are fine.
  auto ok = import_cal3d(write(
      "u.cfg", "# comment\r\n\r\n  path = whatever \r\nfoo=bar\r\nskeleton = " + csf + "\r\n"));
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->skeleton.joint_count(), 37u);
  EXPECT_EQ(ok->mesh.triangle_count(), 0u);
}

// A UTF-8 byte-order mark before `scale=` made the key unknown, so it was
// skipped and the model came out 100 times too large. The mark is dropped;
// a UTF-16 mark (the file is not UTF-8) is refused, naming the file.
TEST(Cal3dConfig, ByteOrderMarkIsStripped) {
  const std::string bom = "\xEF\xBB\xBF";
  for (const char* first : {"scale=0.01\n", "  scale = 0.01\r\n"}) {
    auto cfg = parse_cal3d_config(bom + first + "skeleton=a.csf\n", "m.cfg");
    ASSERT_TRUE(cfg.ok()) << cfg.status().message();
    EXPECT_FLOAT_EQ(cfg->scale, 0.01f) << first;
  }
  auto skeleton_first = parse_cal3d_config(bom + "skeleton=a.csf\n", "m.cfg");
  ASSERT_TRUE(skeleton_first.ok()) << skeleton_first.status().message();
  EXPECT_EQ(skeleton_first->skeleton, "a.csf");
  for (const std::string& utf16 : {std::string("\xFF\xFEs\0k\0", 6), std::string("\xFE\xFF\0s\0k", 6)}) {
    auto refused = parse_cal3d_config(utf16, "w.cfg");
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.status().file(), "w.cfg");
    EXPECT_EQ(refused.status().field(), "encoding") << refused.status().message();
  }
}

// Bytes after the end of the data: Cal3D's loaders stop reading there and
// would ignore them; the import refuses them, naming the file.
TEST_F(Cal3dBadInput, TrailingBytesAreRefused) {
  const std::string csf = model_file("cally", "cally.csf");
  const std::string cmf = model_file("cally", "cally_chest.cmf");
  for (const BinaryKind& kind : binary_kinds()) {
    const std::string bytes = read(kind.source);
    for (const std::string& tail : {std::string(1, '\0'), std::string("garbage"), bytes.substr(0, 64)}) {
      const std::string file = write(kind.name, bytes + tail);
      auto m = import_cal3d(write("t.cfg", cfg_using(kind.name, file, csf)));
      ASSERT_FALSE(m.ok()) << kind.name << " with " << tail.size() << " trailing bytes";
      EXPECT_EQ(m.status().file(), file) << m.status().message();
      EXPECT_NE(m.status().message().find(std::to_string(tail.size()) + " bytes follow the end of the data"),
                std::string::npos)
          << m.status().message();
    }
    // The file as it is still loads.
    const std::string file = write(kind.name, bytes);
    auto ok = import_cal3d(write("t.cfg", cfg_using(kind.name, file, csf, cmf)));
    EXPECT_TRUE(ok.ok()) << ok.status().message();
  }
}

// Truncated copies of each binary file type at several lengths: an error
// naming the truncated file, never a crash (run under ASan too).
TEST_F(Cal3dBadInput, TruncatedFiles) {
  const std::string csf = model_file("cally", "cally.csf");
  for (const BinaryKind& kind : binary_kinds()) {
    const std::string bytes = read(kind.source);
    ASSERT_GT(bytes.size(), 100u);
    const std::vector<std::size_t> lengths = {0,  1,  3,  4,  7,  8,  12, 16, 20, 33, 64,
                                              bytes.size() / 3, bytes.size() / 2, bytes.size() - 4,
                                              bytes.size() - 1};
    for (std::size_t len : lengths) {
      const std::string file = write(kind.name, bytes.substr(0, len));
      auto m = import_cal3d(write("t.cfg", cfg_using(kind.name, file, csf)));
      ASSERT_FALSE(m.ok()) << kind.name << " truncated to " << len;
      EXPECT_EQ(m.status().file(), file) << m.status().message();
    }
  }
}

// Bytes patched inside otherwise valid files: what Cal3D itself does not
// check (counts against the file size, face ids, track bone ids, NaNs).
TEST_F(Cal3dBadInput, CorruptFields) {
  const std::string csf = model_file("cally", "cally.csf");
  auto patch_i32 = [](std::string bytes, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xff);
    return bytes;
  };
  struct Case {
    std::string name;
    std::string bytes;
    ErrorCode code;
  };
  const std::string cmf = read(model_file("cally", "cally_chest.cmf"));
  const std::string caf = read(model_file("cally", "cally_wave.caf"));
  auto i32_at = [](const std::string& bytes, std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
    return static_cast<std::size_t>(v);
  };
  const std::vector<Case> cases = {
      // .cmf: magic, version, submeshCount, then material, vertexCount (16), ...
      {"c.cmf", patch_i32(cmf, 16, 0x7fffffffu), ErrorCode::kTruncated},
      {"c.cmf", patch_i32(cmf, 16, 0x80000000u), ErrorCode::kInvalidData},
      // The last face's last vertex id.
      {"c.cmf", patch_i32(cmf, cmf.size() - 4, 99999u), ErrorCode::kOutOfBounds},
      // .caf: magic, version, duration, trackCount (12), track[0].bone (16),
      // keyframeCount (20), key[0].time (24).
      {"c.caf", patch_i32(caf, 12, 0x10000000u), ErrorCode::kTruncated},
      {"c.caf", patch_i32(caf, 16, 999u), ErrorCode::kOutOfBounds},
      {"c.caf", patch_i32(caf, 24, 0x7fc00000u), ErrorCode::kInvalidData},
      // A negative bone id in a later track: Cal3D leaked the tracks before
      // it (found by fuzzing). track[0] has 4-byte bone, keyframeCount and
      // 32-byte keys, so track[1].bone follows them.
      {"c.caf", patch_i32(caf, 24 + 32 * i32_at(caf, 20), 0xffffffefu), ErrorCode::kOutOfBounds},
  };
  for (const Case& c : cases) {
    const std::string file = write(c.name, c.bytes);
    std::string cfg = "skeleton=" + csf + "\n";
    cfg += (c.name == "c.cmf" ? "mesh=" : "animation=") + file + "\n";
    auto m = import_cal3d(write("c.cfg", cfg));
    ASSERT_FALSE(m.ok()) << c.name;
    EXPECT_EQ(m.status().code(), c.code) << m.status().message();
    EXPECT_EQ(m.status().file(), file) << m.status().message();
  }
}

// Skeleton files that crashed inside Cal3D when fuzzed (a bone name without
// its NUL: strlen past the buffer; a parent id past the bone count: a null
// bone in CalCoreBone::calculateState), plus a child list that contradicts
// the parents and an absurd bone count: refused by the pre-check, naming
// the field.
TEST_F(Cal3dBadInput, CorruptSkeletonLinksAndNames) {
  const std::string csf = read(model_file("cally", "cally.csf"));
  auto i32_at = [&csf](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(csf[at + static_cast<std::size_t>(i)]);
    return v;
  };
  auto patch_i32 = [](std::string bytes, std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xff);
    return bytes;
  };
  // magic, version, boneCount, then bone[0]: name length (12), name, 14 floats, parent.
  const std::size_t name_length = i32_at(12);
  const std::size_t parent_at = 16 + name_length + 14 * 4;
  const std::size_t child_count_at = parent_at + 4;
  ASSERT_EQ(i32_at(parent_at), 0xffffffffu) << "bone[0] of cally.csf is a root";
  ASSERT_GT(i32_at(child_count_at), 0u);

  std::string no_nul = csf;
  no_nul[16 + name_length - 1] = 'X';
  std::string huge("CSF\0", 4);
  huge += std::string("\xbc\x02\x00\x00", 4) + std::string("\x88\x13\x00\x00", 4);  // version 700, 5000 bones
  huge += std::string(5000 * 72, '\0');
  struct Case {
    std::string bytes;
    ErrorCode code;
    std::string field;
  };
  const std::vector<Case> cases = {
      {no_nul, ErrorCode::kInvalidData, "bone[0].name"},
      {patch_i32(csf, parent_at, 999u), ErrorCode::kOutOfBounds, "bone[0].parentId"},
      {patch_i32(csf, child_count_at + 4, 0u), ErrorCode::kInvalidData, "bone[0].children[0]"},
      {huge, ErrorCode::kLimitExceeded, "boneCount"},
  };
  for (const Case& c : cases) {
    const std::string file = write("s.csf", c.bytes);
    auto m = import_cal3d(write("s.cfg", "skeleton=" + file + "\n"));
    ASSERT_FALSE(m.ok()) << c.field;
    EXPECT_EQ(m.status().code(), c.code) << m.status().message();
    EXPECT_EQ(m.status().file(), file) << m.status().message();
    EXPECT_EQ(m.status().field(), c.field) << m.status().message();
  }
  // The unpatched file still loads.
  auto m = import_cal3d(write("s.cfg", "skeleton=" + write("s.csf", csf) + "\n"));
  ASSERT_TRUE(m.ok()) << m.status().message();
}

// A .cfg without meshes imports (a skeleton and clips are a model), but
// such a model has nothing to trace: the bake refuses it in one line naming
// the .cfg, where it used to write a pack that validate accepted and
// render refused.
TEST_F(Cal3dBadInput, ACfgWithoutMeshesIsNotBaked) {
  const std::string cfg = write("s.cfg", "skeleton=" + model_file("cally", "cally.csf") + "\n");
  auto m = import_cal3d(cfg);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->mesh.triangle_count(), 0u);
  JobSystem jobs(1);
  auto bake = character::bake_in_memory(*m, character::BakeRequest{}, jobs);
  ASSERT_FALSE(bake.ok());
  EXPECT_EQ(bake.status().message(),
            cfg + ": mesh.triangle_count = 0: the model has no triangles: nothing to frame or trace");
}

// A symbolic link to a .cfg looked for the model's files beside the link;
// they are found beside the .cfg it links to, as if it were opened there.
TEST_F(Cal3dBadInput, ASymlinkedCfgReadsTheFilesBesideItsTarget) {
  const fs::path link = dir_ / "linked.cfg";
  fs::create_symlink(model_file("cally", "cally.cfg"), link);
  auto linked = import_cal3d(link.string());
  ASSERT_TRUE(linked.ok()) << linked.status().message();
  auto direct = import_cal3d(model_file("cally", "cally.cfg"));
  ASSERT_TRUE(direct.ok()) << direct.status().message();
  EXPECT_EQ(linked->mesh.triangle_count(), direct->mesh.triangle_count());
  ASSERT_EQ(linked->clips.size(), direct->clips.size());
  for (std::size_t c = 0; c < direct->clips.size(); ++c) EXPECT_EQ(linked->clips[c].name(), direct->clips[c].name());
}

// XML materials go to Cal3D's XML loader, which dereferences missing
// attributes and element texts (found by fuzzing: a HEADER without MAGIC
// crashed in strcasecmp(nullptr)); the importer refuses them first. The
// same file with the canonical header still loads, so the check is not
// simply refusing every material.
TEST_F(Cal3dBadInput, MalformedXmlMaterialsAreRefusedBeforeCal3d) {
  const std::string csf = model_file("cally", "cally.csf");
  const std::string cmf = model_file("cally", "cally_neck.cmf");
  const std::string good = read(model_file("cally", "cally_skin.xrf"));
  auto with = [&good](const std::string& from, const std::string& to) {
    std::string text = good;
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
  };
  struct Case {
    std::string bytes;
    std::string element;  // the field the error must name
  };
  const std::vector<Case> cases = {
      {with("MAGIC=", "M2AGIC="), "HEADER"},  // the fuzzer's input, in essence
      {with(" VERSION=\"900\"", ""), "HEADER"},
      {with("<MATERIAL NUMMAPS=\"0\">", "<MATERIAL>"), "MATERIAL"},
      {with("<AMBIENT>128 98 98 0</AMBIENT>", "<AMBIENT></AMBIENT>"), "AMBIENT"},
      {with("<AMBIENT>128 98 98 0</AMBIENT>", "<AMBIENT/>"), "AMBIENT"},
      {with("<DIFFUSE>240 184 184 0</DIFFUSE>", "<DIFFUSE>240 x 184 0</DIFFUSE>"), "DIFFUSE"},
      {with("<SHININESS>0.05</SHININESS>", ""), "SHININESS"},
      {with("</MATERIAL>", "<MAP/></MATERIAL>"), "MATERIAL"},
      {with("</MATERIAL>", "<MAP>  </MAP></MATERIAL>"), "MAP"},
      {good.substr(0, good.find("<MATERIAL")), "MATERIAL"},
      {"", "magic"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.bytes);
    const std::string xrf = write("m.xrf", c.bytes);
    auto m = import_cal3d(write("m.cfg", "skeleton=" + csf + "\nmesh=" + cmf + "\nmaterial=" + xrf + "\n"));
    ASSERT_FALSE(m.ok());
    EXPECT_EQ(m.status().file(), xrf) << m.status().message();
    EXPECT_EQ(m.status().field(), c.element) << m.status().message();
  }
  const std::string xrf = write("m.xrf", with("</MATERIAL>", "<MAP>skin.tga</MAP>\n</MATERIAL>"));
  auto m = import_cal3d(write("m.cfg", "skeleton=" + csf + "\nmesh=" + cmf + "\nmaterial=" + xrf + "\n"));
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_FALSE(m->mesh.material_colors.empty());
  EXPECT_FLOAT_EQ(m->mesh.material_colors[0].x, 240.0f / 255.0f);
}

TEST_F(Cal3dBadInput, TwoListedAnimationsWithOneClipName) {
  const std::string csf = model_file("cally", "cally.csf");
  const std::string walk = model_file("cally", "cally_walk.caf");
  const std::string copy = write("cally_walk.caf", read(walk));
  const std::string cfg = write("d.cfg", "skeleton=" + csf + "\nanimation=" + walk +
                                             "\nanimation=" + walk + "\nanimation=" + copy + "\n");
  auto m = import_cal3d(cfg);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), ErrorCode::kDuplicate) << m.status().message();
  EXPECT_EQ(m.status().file(), cfg);
  // Listed twice is one clip.
  auto once = import_cal3d(write("e.cfg", "skeleton=" + csf + "\nanimation=" + walk +
                                              "\nanimation=" + walk + "\n"));
  ASSERT_TRUE(once.ok()) << once.status().message();
  EXPECT_EQ(once->clips.size(), 1u);
  EXPECT_EQ(once->clips[0].name(), "cally_walk");  // no "e_" prefix to strip
}

// Not bad input, but needs the fixture's folder: paladin.cfg's scale=0.5
// halves positions, bone and keyframe translations relative to scale=1.
TEST_F(Cal3dBadInput, PaladinCfgScaleIsApplied) {
  auto half = import_cal3d(model_cfg("paladin"));
  ASSERT_TRUE(half.ok()) << half.status().message();
  const std::string cfg = "scale=1.0\nskeleton=" + model_file("paladin", "paladin.csf") +
                          "\nmesh=" + model_file("paladin", "paladin_body.cmf") +
                          "\nanimation=" + model_file("paladin", "paladin_walk.caf") + "\n";
  auto full = import_cal3d(write("p.cfg", cfg));
  ASSERT_TRUE(full.ok()) << full.status().message();
  ASSERT_LE(full->mesh.vertex_count(), half->mesh.vertex_count());
  for (std::size_t v = 0; v < full->mesh.vertex_count(); ++v) {
    ASSERT_NEAR(glm::length(full->mesh.positions[v] * 0.5f - half->mesh.positions[v]), 0.0f, 1e-4f);
  }
  for (std::size_t j = 0; j < full->skeleton.joint_count(); ++j) {
    ASSERT_NEAR(glm::length(full->skeleton.rest_pose()[j].translation * 0.5f -
                            half->skeleton.rest_pose()[j].translation),
                0.0f, 1e-4f);
  }
  // Clip name "paladin_walk" here: the .cfg is p.cfg, no "p_" prefix.
  const anim::JointTracks& a = full->clips.at(0).tracks()[0];
  const anim::JointTracks& b = half->find_clip("walk")->tracks()[0];
  ASSERT_EQ(a.translation.values.size(), b.translation.values.size());
  EXPECT_NEAR(glm::length(a.translation.values[3] * 0.5f - b.translation.values[3]), 0.0f, 1e-4f);
}

}  // namespace
}  // namespace sinew::editor
