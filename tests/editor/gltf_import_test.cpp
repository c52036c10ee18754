// glTF importer tests: conformance on real skinned models, an independent
// straight-from-the-spec skinning oracle, bind-pose round trip, and a
// bad-input suite (Debian's assimp test models plus synthetic corruptions).
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "animation/pose.h"
#include "animation/reference_skinning.h"
#include "editor/import/gltf_container.h"
#include "editor/import/gltf_importer.h"

namespace sinew::editor {
namespace {

namespace fs = std::filesystem;

const std::string kShared = SINEW_SHARED_DIR;
const std::string kCesiumMan = kShared + "/content/gltf/CesiumMan/CesiumMan.glb";
const std::string kBrainStem = kShared + "/content/gltf/BrainStem/BrainStem.glb";
const std::string kAssimp = "/usr/share/assimp/models/glTF2";
const std::string kSimpleSkin = kAssimp + "/simple_skin/simple_skin.gltf";

struct Known {
  std::string path;
  std::size_t triangles, vertices, joints;
};

const std::vector<Known>& known_models() {
  static const std::vector<Known> k = {
      {kCesiumMan, 4672, 3273, 19},
      {kBrainStem, 61666, 34159, 18},
      {kSimpleSkin, 8, 10, 2},
  };
  return k;
}

float model_size(const SkinnedMesh& m) {
  Vec3 lo(1e30f), hi(-1e30f);
  for (const Vec3& p : m.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return glm::length(hi - lo);
}

// Our pipeline: clip (or rest pose when clip is null) -> skinned positions.
std::vector<Vec3> pose_and_skin(const character::Model& m, const anim::Clip* clip, float t) {
  const std::size_t n = m.skeleton.joint_count();
  std::vector<anim::JointTransform> local(n);
  EXPECT_TRUE(anim::rest_pose(m.skeleton, local).ok());
  if (clip != nullptr) {
    anim::SamplingCache cache;
    anim::sample_clip(*clip, t, cache, local);
  }
  std::vector<Affine3> model(n), skin(n);
  EXPECT_TRUE(anim::local_to_model(m.skeleton, local, model).ok());
  EXPECT_TRUE(anim::skinning_matrices(m.skeleton, model, Affine3::identity(), skin).ok());
  std::vector<Vec3> out(m.mesh.vertex_count());
  EXPECT_TRUE(anim::skin_reference(m.mesh, skin, out, {}).ok());
  return out;
}

// ---------------------------------------------------------------------------
// (1) Conformance

TEST(GltfImport, KnownModelsImportWithExpectedCounts) {
  for (const Known& k : known_models()) {
    SCOPED_TRACE(k.path);
    const auto m = import_gltf(k.path);
    ASSERT_TRUE(m.ok()) << m.status().message();
    EXPECT_EQ(m->mesh.triangle_count(), k.triangles);
    EXPECT_EQ(m->mesh.vertex_count(), k.vertices);
    EXPECT_EQ(m->skeleton.joint_count(), k.joints);
    EXPECT_EQ(m->mesh.normals.size(), k.vertices);
    EXPECT_EQ(m->mesh.joints.size(), k.vertices);
    EXPECT_EQ(m->mesh.weights.size(), k.vertices);
    EXPECT_EQ(m->mesh.triangle_material.size(), k.triangles);
    EXPECT_EQ(m->material_names.size(), m->mesh.material_colors.size());
    ASSERT_FALSE(m->clips.empty());
    for (const auto& w : m->mesh.weights) {
      float sum = 0;
      for (float x : w) sum += x;
      ASSERT_NEAR(sum, 1.0f, 1e-5f);
    }
    for (const auto& j : m->mesh.joints) {
      for (auto x : j) ASSERT_LT(x, m->skeleton.joint_count());
    }
    for (const auto& t : m->mesh.triangles) {
      for (auto v : t) ASSERT_LT(v, m->mesh.vertex_count());
    }
    for (std::size_t i = 0; i < m->clips.size(); ++i) {
      EXPECT_EQ(m->clips[i].name().empty(), false);
      EXPECT_EQ(m->find_clip("#" + std::to_string(i)), &m->clips[i]);
    }
    // Animates: poses at two times differ and stay finite.
    const anim::Clip& clip = m->clips[0];
    const auto a = pose_and_skin(*m, &clip, 0.0f);
    const auto b = pose_and_skin(*m, &clip, clip.duration() * 0.3f);
    float moved = 0;
    for (std::size_t v = 0; v < a.size(); ++v) {
      ASSERT_TRUE(std::isfinite(a[v].x) && std::isfinite(b[v].y));
      moved = std::max(moved, glm::length(a[v] - b[v]));
    }
    EXPECT_GT(moved, 1e-3f * model_size(m->mesh));
  }
}

TEST(GltfImport, ClipNamesFollowDesign) {
  const auto m = import_gltf(kSimpleSkin);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->clips.size(), 1u);
  EXPECT_EQ(m->clips[0].name(), "animation_0");  // the file's animation has no name
}

// ---------------------------------------------------------------------------
// (2) Independent oracle: tinygltf + glm, straight from the glTF 2.0 spec.

struct Oracle {
  tinygltf::Model model;

  bool load(const std::string& path) {
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const bool glb = path.size() > 4 && path.substr(path.size() - 4) == ".glb";
    return glb ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
               : loader.LoadASCIIFromFile(&model, &err, &warn, path);
  }

  // Element `i` of accessor `a` as up to 16 doubles (float / normalised
  // unsigned, or raw integers when `raw`).
  std::vector<double> element(int a, std::size_t i, bool raw = false) const {
    const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(a)];
    const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(acc.bufferView)];
    const tinygltf::Buffer& buf = model.buffers[static_cast<std::size_t>(bv.buffer)];
    const int n = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(acc.type));
    const int cs = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(acc.componentType));
    const std::size_t stride = bv.byteStride ? bv.byteStride : static_cast<std::size_t>(n * cs);
    const unsigned char* p = buf.data.data() + bv.byteOffset + acc.byteOffset + i * stride;
    std::vector<double> out(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      const unsigned char* q = p + k * cs;
      double v = 0;
      if (acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        float f;
        std::memcpy(&f, q, 4);
        v = static_cast<double>(f);
      } else if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) {
        v = raw ? q[0] : q[0] / 255.0;
      } else if (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        std::uint16_t s;
        std::memcpy(&s, q, 2);
        v = raw ? s : s / 65535.0;
      }
      out[static_cast<std::size_t>(k)] = v;
    }
    return out;
  }

  struct Trs {
    glm::dvec3 t{0.0};
    glm::dquat r{1, 0, 0, 0};
    glm::dvec3 s{1.0};
  };

  // Node locals, with animation 0's channels sampled at `time` (linear,
  // step and cubic spline as the spec's appendix describes).
  // A negative `time` gives the nodes' own (rest) transforms.
  std::vector<glm::dmat4> locals(double time) const {
    std::vector<Trs> trs(model.nodes.size());
    std::vector<bool> has_matrix(model.nodes.size(), false);
    std::vector<glm::dmat4> mats(model.nodes.size(), glm::dmat4(1.0));
    for (std::size_t i = 0; i < model.nodes.size(); ++i) {
      const tinygltf::Node& n = model.nodes[i];
      if (n.matrix.size() == 16) {
        has_matrix[i] = true;
        for (int k = 0; k < 16; ++k) mats[i][k / 4][k % 4] = n.matrix[static_cast<std::size_t>(k)];
      }
      if (n.translation.size() == 3) trs[i].t = {n.translation[0], n.translation[1], n.translation[2]};
      if (n.rotation.size() == 4) trs[i].r = glm::dquat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
      if (n.scale.size() == 3) trs[i].s = {n.scale[0], n.scale[1], n.scale[2]};
    }
    if (time >= 0 && !model.animations.empty()) {
      const tinygltf::Animation& an = model.animations[0];
      for (const auto& ch : an.channels) {
        if (ch.target_path == "weights") continue;
        const auto& smp = an.samplers[static_cast<std::size_t>(ch.sampler)];
        const std::size_t keys = model.accessors[static_cast<std::size_t>(smp.input)].count;
        if (keys == 0) continue;
        std::vector<double> times(keys);
        for (std::size_t k = 0; k < keys; ++k) times[k] = element(smp.input, k)[0];
        const bool cubic = smp.interpolation == "CUBICSPLINE";
        auto value = [&](std::size_t k, int slot) {
          return element(smp.output, cubic ? 3 * k + static_cast<std::size_t>(slot) : k);
        };
        std::vector<double> v;
        if (time <= times[0]) {
          v = value(0, 1);
        } else if (time >= times[keys - 1]) {
          v = value(keys - 1, 1);
        } else {
          std::size_t k = 0;
          while (times[k + 1] <= time) ++k;
          const double td = times[k + 1] - times[k];
          const double u = (time - times[k]) / td;
          const auto a = value(k, 1), b = value(k + 1, 1);
          v = a;  // sized like a value; overwritten below
          if (smp.interpolation == "STEP") {
            v = a;
          } else if (cubic) {
            const auto ao = value(k, 2), bi = value(k + 1, 0);
            const double u2 = u * u, u3 = u2 * u;
            for (std::size_t c = 0; c < a.size(); ++c) {
              v[c] = (2 * u3 - 3 * u2 + 1) * a[c] + td * (u3 - 2 * u2 + u) * ao[c] +
                     (-2 * u3 + 3 * u2) * b[c] + td * (u3 - u2) * bi[c];
            }
          } else if (ch.target_path == "rotation") {
            glm::dquat qa(a[3], a[0], a[1], a[2]), qb(b[3], b[0], b[1], b[2]);
            const glm::dquat q = glm::slerp(qa, qb, u);  // shortest path per glm
            v = {q.x, q.y, q.z, q.w};
          } else {
            for (std::size_t c = 0; c < a.size(); ++c) v[c] = a[c] + u * (b[c] - a[c]);
          }
        }
        Trs& t = trs[static_cast<std::size_t>(ch.target_node)];
        if (ch.target_path == "translation") t.t = {v[0], v[1], v[2]};
        if (ch.target_path == "rotation") t.r = glm::normalize(glm::dquat(v[3], v[0], v[1], v[2]));
        if (ch.target_path == "scale") t.s = {v[0], v[1], v[2]};
      }
    }
    for (std::size_t i = 0; i < model.nodes.size(); ++i) {
      if (has_matrix[i]) continue;
      mats[i] = glm::translate(glm::dmat4(1.0), trs[i].t) * glm::mat4_cast(trs[i].r) *
                glm::scale(glm::dmat4(1.0), trs[i].s);
    }
    return mats;
  }

  std::vector<glm::dmat4> globals(double time) const {
    const auto local = locals(time);
    std::vector<glm::dmat4> g(model.nodes.size(), glm::dmat4(1.0));
    std::vector<int> parent(model.nodes.size(), -1);
    for (std::size_t i = 0; i < model.nodes.size(); ++i) {
      for (int c : model.nodes[i].children) parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
    }
    for (std::size_t i = 0; i < model.nodes.size(); ++i) {
      glm::dmat4 m = local[i];
      for (int p = parent[i]; p != -1; p = parent[static_cast<std::size_t>(p)]) {
        m = local[static_cast<std::size_t>(p)] * m;
      }
      g[i] = m;
    }
    return g;
  }
};

// Compares our pipeline with the oracle on sampled vertices of every skinned
// mesh instance, at rest and at six times of clip 0. Returns the worst error
// relative to the model size; `checked` receives the number of samples.
void compare_with_oracle(const std::string& path, double& worst, int& checked) {
  {
    Oracle o;
    ASSERT_TRUE(o.load(path));
    const auto m = import_gltf(path);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const float size = model_size(m->mesh);
    const anim::Clip& clip = m->clips[0];
    worst = 0;
    checked = 0;
    // The rest pose (ti = -1), then six times across the clip.
    for (int ti = -1; ti < 6; ++ti) {
      const double t = ti < 0 ? -1.0 : static_cast<double>(clip.duration()) * ti / 5.0 * 0.999 + 0.01 * ti;
      const auto g = o.globals(t);
      const auto ours = pose_and_skin(*m, ti < 0 ? nullptr : &clip, static_cast<float>(t));
      // Our vertex order: meshes in order, their nodes in order, primitives.
      std::size_t base = 0;
      for (std::size_t mi = 0; mi < o.model.meshes.size(); ++mi) {
        for (std::size_t ni = 0; ni < o.model.nodes.size(); ++ni) {
          const auto& node = o.model.nodes[ni];
          if (node.mesh != static_cast<int>(mi)) continue;
          for (const auto& prim : o.model.meshes[mi].primitives) {
            const int pos = prim.attributes.at("POSITION");
            const std::size_t count = o.model.accessors[static_cast<std::size_t>(pos)].count;
            if (node.skin >= 0) {
              const auto& skin = o.model.skins[static_cast<std::size_t>(node.skin)];
              for (std::size_t v = 0; v < count; v += std::max<std::size_t>(1, count / 7)) {
                const auto p = o.element(pos, v);
                glm::dvec4 acc(0.0);
                double wsum = 0;
                for (int set = 0; set < 2; ++set) {
                  const auto ja = prim.attributes.find("JOINTS_" + std::to_string(set));
                  const auto wa = prim.attributes.find("WEIGHTS_" + std::to_string(set));
                  if (ja == prim.attributes.end()) continue;
                  const auto js = o.element(ja->second, v, true);
                  const auto ws = o.element(wa->second, v);
                  for (int c = 0; c < 4; ++c) {
                    if (ws[static_cast<std::size_t>(c)] == 0) continue;
                    const int jn = skin.joints[static_cast<std::size_t>(js[static_cast<std::size_t>(c)])];
                    glm::dmat4 ibm(1.0);
                    if (skin.inverseBindMatrices >= 0) {
                      const auto e = o.element(skin.inverseBindMatrices,
                                               static_cast<std::size_t>(js[static_cast<std::size_t>(c)]));
                      for (int q = 0; q < 16; ++q) ibm[q / 4][q % 4] = e[static_cast<std::size_t>(q)];
                    }
                    const glm::dmat4 joint_matrix = g[static_cast<std::size_t>(jn)] * ibm;
                    acc += ws[static_cast<std::size_t>(c)] * (joint_matrix * glm::dvec4(p[0], p[1], p[2], 1.0));
                    wsum += ws[static_cast<std::size_t>(c)];
                  }
                }
                const glm::dvec3 expect = glm::dvec3(acc) / wsum;
                const double err = glm::length(expect - glm::dvec3(ours[base + v]));
                worst = std::max(worst, err / static_cast<double>(size));
                ++checked;
              }
            }
            base += count;
          }
        }
      }
    }
  }
}

TEST(GltfImport, MatchesIndependentSpecSkinning) {
  for (const Known& k : known_models()) {
    SCOPED_TRACE(k.path);
    double worst = 1;
    int checked = 0;
    compare_with_oracle(k.path, worst, checked);
    EXPECT_GT(checked, 30);
    EXPECT_LT(worst, 1e-4) << "max relative error " << worst;
    std::printf("[ oracle ] %s: %d vertex samples, max error %.3g x model size\n",
                fs::path(k.path).filename().c_str(), checked, worst);
  }
}

// ---------------------------------------------------------------------------
// (3) Bind pose reproduces the rest mesh. The bind pose is the one whose
// model-space joint transforms are the inverses of the inverse bind
// matrices. Note: it is NOT the nodes' rest pose in these files (CesiumMan,
// BrainStem and simple_skin all have rest globals != IBM^-1; the oracle
// test above covers the rest pose), so the pose is built from the IBMs.

TEST(GltfImport, BindPoseSkinningReproducesRestMesh) {
  for (const Known& k : known_models()) {
    SCOPED_TRACE(k.path);
    const auto m = import_gltf(k.path);
    ASSERT_TRUE(m.ok()) << m.status().message();
    const float size = model_size(m->mesh);
    const std::size_t n = m->skeleton.joint_count();
    std::vector<Affine3> model(n), skin(n);
    for (std::size_t j = 0; j < n; ++j) model[j] = inverse(m->skeleton.inverse_bind()[j]);
    ASSERT_TRUE(anim::skinning_matrices(m->skeleton, model, Affine3::identity(), skin).ok());
    std::vector<Vec3> skinned(m->mesh.vertex_count());
    ASSERT_TRUE(anim::skin_reference(m->mesh, skin, skinned, {}).ok());
    float worst = 0;
    for (std::size_t v = 0; v < skinned.size(); ++v) {
      worst = std::max(worst, glm::length(skinned[v] - m->mesh.positions[v]) / size);
    }
    EXPECT_LT(worst, 1e-4f);
    // How far the file's rest pose is from its bind pose, for the record.
    const auto rest = pose_and_skin(*m, nullptr, 0.0f);
    float rest_dev = 0;
    for (std::size_t v = 0; v < rest.size(); ++v) {
      rest_dev = std::max(rest_dev, glm::length(rest[v] - m->mesh.positions[v]) / size);
    }
    std::printf("[ bind   ] %s: bind-pose max error %.3g x model size (rest pose deviates %.3g)\n",
                fs::path(k.path).filename().c_str(), static_cast<double>(worst),
                static_cast<double>(rest_dev));
  }
}

// ---------------------------------------------------------------------------
// Static (skinless) models import as one root joint.

TEST(GltfImport, StaticModelImportsWithOneRootJoint) {
  const auto m = import_gltf(kAssimp + "/BoxTextured-glTF-Binary/BoxTextured.glb");
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->skeleton.joint_count(), 1u);
  EXPECT_EQ(m->skeleton.names()[0], "<static>");
  EXPECT_EQ(m->mesh.triangle_count(), 12u);
  // Never silently: one line says it is static, naming the file.
  ASSERT_EQ(m->warnings.size(), 1u);
  EXPECT_NE(m->warnings[0].find("BoxTextured.glb: skins: none: a static model"), std::string::npos) << m->warnings[0];
  EXPECT_EQ(m->warnings[0].find('\n'), std::string::npos);
  EXPECT_EQ(m->mesh.uvs.size(), m->mesh.vertex_count());
  const auto skinned = pose_and_skin(*m, nullptr, 0.0f);
  for (std::size_t v = 0; v < skinned.size(); ++v) {
    EXPECT_LT(glm::length(skinned[v] - m->mesh.positions[v]), 1e-5f);
  }
}

// ---------------------------------------------------------------------------
// (4) Bad input. Debian's assimp test models first.

TEST(GltfImport, AssimpBrokenFilesGiveErrors) {
  const std::vector<std::string> must_fail = {
      "IndexOutOfRange/IndexOutOfRange.gltf",
      "IndexOutOfRange/AllIndicesOutOfRange.gltf",
      "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
      "MissingBin/BoxTextured.gltf",
      "RecursiveNodes/RecursiveNodes.gltf",
      "SchemaFailures/sceneWrongType.gltf",
      "TestNoRootNode/SceneWithoutNodes.gltf",
  };
  for (const std::string& f : must_fail) {
    const std::string path = kAssimp + "/" + f;
    SCOPED_TRACE(path);
    const auto m = import_gltf(path);
    ASSERT_FALSE(m.ok());
    EXPECT_EQ(m.status().file(), path);
    EXPECT_FALSE(m.status().detail().empty());
    std::printf("[ broken ] %s -> %s\n", f.c_str(), m.status().message().c_str());
  }
}

TEST(GltfImport, AssimpOddFilesNeverCrash) {
  // Whatever these give, it is a value: an import or a Status with a message.
  for (const auto& entry : fs::recursive_directory_iterator(kAssimp)) {
    const std::string ext = entry.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    const auto m = import_gltf(entry.path().string());
    const std::string rel = fs::relative(entry.path(), kAssimp).string();
    if (!m.ok()) {
      EXPECT_FALSE(m.status().message().empty());
      std::printf("[ assimp ] %s: error: %s\n", rel.c_str(), std::string(m.status().detail()).c_str());
    } else {
      EXPECT_GT(m->mesh.triangle_count(), 0u);
      std::printf("[ assimp ] %s: %zu triangles, %zu joints, %zu clips\n", rel.c_str(),
                  m->mesh.triangle_count(), m->skeleton.joint_count(), m->clips.size());
    }
  }
}

// The glTF Asset Generator's primitive modes: points and lines (0-3) are
// refused naming the mode; triangles, strips and fans (4-6) import, strips
// and fans as the spec's triangles (glTF 2.0, 3.7.2.1): strip triangle i is
// (v_i, v_{i+1+i%2}, v_{i+2-i%2}), fan triangle i is (v_{i+1}, v_{i+2}, v_0),
// checked against the file's own vertex sequence read through tinygltf.
TEST(GltfImport, PrimitiveModesFollowTheSpec) {
  const std::string dir = kAssimp + "/glTF-Asset-Generator/Mesh_PrimitiveMode/";
  ASSERT_TRUE(fs::exists(dir)) << dir << " not found (the setup installs assimp-testmodels)";
  int refused = 0, strips = 0, fans = 0;
  for (int i = 0; i < 16; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "Mesh_PrimitiveMode_%02d.gltf", i);
    const std::string path = dir + name;
    tinygltf::Model raw;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    ASSERT_TRUE(loader.LoadASCIIFromFile(&raw, &err, &warn, path)) << err;
    const tinygltf::Primitive& prim = raw.meshes[0].primitives[0];
    const int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    const auto m = import_gltf(path);
    if (mode < TINYGLTF_MODE_TRIANGLES) {
      ASSERT_FALSE(m.ok()) << name;
      EXPECT_NE(m.status().field().find(".mode"), std::string_view::npos) << m.status().message();
      ++refused;
      continue;
    }
    ASSERT_TRUE(m.ok()) << name << ": " << m.status().message();
    // The file's positions and vertex sequence, straight from its buffers.
    const auto element = [&](int accessor, std::size_t k, int component) {
      const tinygltf::Accessor& a = raw.accessors[static_cast<std::size_t>(accessor)];
      const tinygltf::BufferView& v = raw.bufferViews[static_cast<std::size_t>(a.bufferView)];
      const std::size_t size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
      const std::size_t stride = v.byteStride != 0 ? v.byteStride
                                                   : size * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(
                                                                static_cast<std::uint32_t>(a.type)));
      const unsigned char* at = raw.buffers[static_cast<std::size_t>(v.buffer)].data.data() + v.byteOffset +
                                a.byteOffset + k * stride + static_cast<std::size_t>(component) * size;
      double value = 0.0;
      if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) value = *reinterpret_cast<const float*>(at);
      if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) value = *at;
      if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) value = *reinterpret_cast<const std::uint16_t*>(at);
      if (a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) value = *reinterpret_cast<const std::uint32_t*>(at);
      return value;
    };
    const int pos = prim.attributes.at("POSITION");
    const std::size_t vcount = raw.accessors[static_cast<std::size_t>(pos)].count;
    std::vector<std::size_t> seq;
    if (prim.indices >= 0) {
      for (std::size_t k = 0; k < raw.accessors[static_cast<std::size_t>(prim.indices)].count; ++k) {
        seq.push_back(static_cast<std::size_t>(element(prim.indices, k, 0)));
      }
    } else {
      for (std::size_t k = 0; k < vcount; ++k) seq.push_back(k);
    }
    std::vector<std::array<std::size_t, 3>> expected;
    for (std::size_t k = 0; mode == TINYGLTF_MODE_TRIANGLES && k + 2 < seq.size(); k += 3) {
      expected.push_back({seq[k], seq[k + 1], seq[k + 2]});
    }
    for (std::size_t k = 0; mode == TINYGLTF_MODE_TRIANGLE_STRIP && k + 2 < seq.size(); ++k) {
      expected.push_back({seq[k], seq[k + 1 + k % 2], seq[k + 2 - k % 2]});
    }
    for (std::size_t k = 0; mode == TINYGLTF_MODE_TRIANGLE_FAN && k + 2 < seq.size(); ++k) {
      expected.push_back({seq[k + 1], seq[k + 2], seq[0]});
    }
    strips += mode == TINYGLTF_MODE_TRIANGLE_STRIP ? 1 : 0;
    fans += mode == TINYGLTF_MODE_TRIANGLE_FAN ? 1 : 0;
    ASSERT_EQ(m->mesh.triangles.size(), expected.size()) << name;
    for (std::size_t t = 0; t < expected.size(); ++t) {
      for (int corner = 0; corner < 3; ++corner) {
        const Vec3& got = m->mesh.positions[m->mesh.triangles[t][static_cast<std::size_t>(corner)]];
        for (int axis = 0; axis < 3; ++axis) {
          EXPECT_FLOAT_EQ(got[axis], static_cast<float>(element(pos, expected[t][static_cast<std::size_t>(corner)], axis)))
              << name << " triangle " << t << " corner " << corner;
        }
      }
    }
  }
  EXPECT_EQ(refused, 8);
  EXPECT_EQ(strips, 2);
  EXPECT_EQ(fans, 2);
}

// Synthetic corruptions of a tiny valid skinned model: one triangle, two
// joints listed out of hierarchy order, an animation.
struct Synthetic {
  std::string json;
  std::vector<unsigned char> bin;
};

template <typename T>
void put(std::vector<unsigned char>& b, std::size_t off, T v) {
  std::memcpy(b.data() + off, &v, sizeof v);
}

Synthetic synthetic() {
  Synthetic s;
  s.bin.assign(472, 0);
  const float pos[9] = {0, 0, 0, 1, 2, 0, 0, 1, 0};
  for (int i = 0; i < 9; ++i) put(s.bin, static_cast<std::size_t>(4 * i), pos[i]);
  // JOINTS_0 (u8) at 36: v0 -> skin joint 1 (hip), v1 -> 0 (knee), v2 -> both.
  const unsigned char joints[12] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0};
  std::memcpy(s.bin.data() + 36, joints, 12);
  const float weights[12] = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0};
  for (int i = 0; i < 12; ++i) put(s.bin, static_cast<std::size_t>(48 + 4 * i), weights[i]);
  const std::uint16_t idx[3] = {0, 1, 2};
  for (int i = 0; i < 3; ++i) put(s.bin, static_cast<std::size_t>(96 + 2 * i), idx[i]);
  // IBMs at 104: knee (global T(0,1,0)) -> T(0,-1,0); hip identity.
  for (int j = 0; j < 2; ++j) {
    for (int d = 0; d < 4; ++d) put(s.bin, static_cast<std::size_t>(104 + 64 * j + 20 * d), 1.0f);
  }
  put(s.bin, 104 + 13 * 4, -1.0f);
  // Animation at 232: times 0, 1; rotations identity and 90 degrees about z.
  put(s.bin, 232, 0.0f);
  put(s.bin, 236, 1.0f);
  const float rot[8] = {0, 0, 0, 1, 0, 0, 0.70710678f, 0.70710678f};
  for (int i = 0; i < 8; ++i) put(s.bin, static_cast<std::size_t>(240 + 4 * i), rot[i]);
  // Alternative encodings of the same data, for the variants below.
  // 272: WEIGHTS as normalised u8; 284: JOINTS as u16.
  const unsigned char w8[12] = {255, 0, 0, 0, 255, 0, 0, 0, 128, 127, 0, 0};
  std::memcpy(s.bin.data() + 272, w8, 12);
  for (int i = 0; i < 12; ++i) {
    put(s.bin, static_cast<std::size_t>(284 + 2 * i), static_cast<std::uint16_t>(joints[i]));
  }
  // 308: sparse index (vertex 1), 312: its replacement position.
  put(s.bin, 308, std::uint16_t{1});
  put(s.bin, 312, 2.0f);
  put(s.bin, 316, 2.0f);
  // 324: positions interleaved with stride 16 (bufferViews[1]).
  for (int v = 0; v < 3; ++v) {
    for (int k = 0; k < 3; ++k) put(s.bin, static_cast<std::size_t>(324 + 16 * v + 4 * k), pos[3 * v + k]);
  }
  // 372: knee translation keys (0,1,0), (0,1.5,0).
  put(s.bin, 376, 1.0f);
  put(s.bin, 388, 1.5f);
  // 400: the same keys as a cubic spline (in-tangent, value, out-tangent).
  const float spline[18] = {0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 0, 2, 0, 1.5f, 0, 0, 0, 0};
  for (int i = 0; i < 18; ++i) put(s.bin, static_cast<std::size_t>(400 + 4 * i), spline[i]);
  s.json = R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1]}],
  "nodes": [
    {"name": "body", "mesh": 0, "skin": 0},
    {"name": "hip", "children": [2]},
    {"name": "knee", "translation": [0, 1, 0]}
  ],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2},
                              "indices": 3, "mode": 4}]}],
  "skins": [{"joints": [2, 1], "inverseBindMatrices": 4, "skeleton": 1}],
  "animations": [{"channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}],
                  "samplers": [{"input": 5, "output": 6, "interpolation": "LINEAR"}]}],
  "buffers": [{"uri": "synthetic.bin", "byteLength": 472}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 472},
                  {"buffer": 0, "byteOffset": 324, "byteLength": 48, "byteStride": 16}],
  "accessors": [
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
    {"bufferView": 0, "byteOffset": 36, "componentType": 5121, "count": 3, "type": "VEC4"},
    {"bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 3, "type": "VEC4"},
    {"bufferView": 0, "byteOffset": 96, "componentType": 5123, "count": 3, "type": "SCALAR"},
    {"bufferView": 0, "byteOffset": 104, "componentType": 5126, "count": 2, "type": "MAT4"},
    {"bufferView": 0, "byteOffset": 232, "componentType": 5126, "count": 2, "type": "SCALAR"},
    {"bufferView": 0, "byteOffset": 240, "componentType": 5126, "count": 2, "type": "VEC4"},
    {"bufferView": 0, "byteOffset": 272, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"},
    {"bufferView": 0, "byteOffset": 284, "componentType": 5123, "count": 3, "type": "VEC4"},
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3",
     "sparse": {"count": 1, "indices": {"bufferView": 0, "byteOffset": 308, "componentType": 5123},
                "values": {"bufferView": 0, "byteOffset": 312}}},
    {"bufferView": 1, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
    {"bufferView": 0, "byteOffset": 372, "componentType": 5126, "count": 2, "type": "VEC3"},
    {"bufferView": 0, "byteOffset": 400, "componentType": 5126, "count": 6, "type": "VEC3"}
  ]
})";
  return s;
}

class GltfSynthetic : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("sinew_gltf_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::string write(const Synthetic& s, std::size_t bin_bytes = SIZE_MAX) {
    const std::string path = (dir_ / "synthetic.gltf").string();
    std::ofstream(path, std::ios::binary) << s.json;
    std::ofstream bin(dir_ / "synthetic.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(s.bin.data()),
              static_cast<std::streamsize>(std::min(bin_bytes, s.bin.size())));
    return path;
  }

  static void replace(std::string& s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    s.replace(at, from.size(), to);
  }

  // Imports and expects an error whose field mentions `field_part`.
  void expect_error(const Synthetic& s, const std::string& field_part, std::size_t bin_bytes = SIZE_MAX) {
    const std::string path = write(s, bin_bytes);
    const auto m = import_gltf(path);
    ASSERT_FALSE(m.ok()) << "expected an error about " << field_part;
    EXPECT_EQ(m.status().file(), path);
    const std::string msg = m.status().message();
    EXPECT_NE(msg.find(field_part), std::string::npos) << msg;
    std::printf("[ synth  ] %s\n", msg.c_str());
  }

  fs::path dir_;
};

TEST_F(GltfSynthetic, ValidModelImportsRemapsJointsAndAnimates) {
  const auto m = import_gltf(write(synthetic()));
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->skeleton.joint_count(), 2u);
  const int hip = *m->skeleton.find("hip");
  const int knee = *m->skeleton.find("knee");
  EXPECT_EQ(hip, 0);  // sorted: the parent first although the skin lists it second
  EXPECT_EQ(m->mesh.joints[0][0], hip);
  EXPECT_EQ(m->mesh.joints[1][0], knee);
  ASSERT_EQ(m->clips.size(), 1u);
  EXPECT_EQ(m->clips[0].name(), "animation_0");
  // At t = 1 the hip turned 90 degrees about z: vertex 1 (1,2,0) on the
  // knee -> (-2, 1, 0).
  const auto p = pose_and_skin(*m, &m->clips[0], 1.0f);
  EXPECT_NEAR(p[1].x, -2.0f, 1e-5f);
  EXPECT_NEAR(p[1].y, 1.0f, 1e-5f);
  EXPECT_EQ(m->mesh.material_colors.size(), 1u);  // the default material
  EXPECT_TRUE(m->warnings.empty()) << m->warnings.front();  // skinned, no morph targets
}

// Morph targets are not Sinew's (it deforms by bones): the import goes on
// in the base shape, and says so in one line naming the first primitive.
TEST_F(GltfSynthetic, MorphTargetsAreWarnedAboutInOneLine) {
  Synthetic s = synthetic();
  replace(s.json, "\"attributes\": {\"POSITION\": 0, \"JOINTS_0\": 1, \"WEIGHTS_0\": 2}",
          "\"attributes\": {\"POSITION\": 0, \"JOINTS_0\": 1, \"WEIGHTS_0\": 2}, "
          "\"targets\": [{\"POSITION\": 0}, {\"POSITION\": 0}]");
  const std::string path = write(s);
  const auto m = import_gltf(path);
  ASSERT_TRUE(m.ok()) << m.status().message();
  ASSERT_EQ(m->warnings.size(), 1u);
  EXPECT_EQ(m->warnings[0], path + ": meshes[0].primitives[0].targets: 2 morph targets (all meshes), ignored with "
                                   "their weights' animation: Sinew deforms by bones only, so the meshes bake and "
                                   "render in their base shape");
  // The base shape: the positions as stored.
  EXPECT_EQ(m->mesh.positions[1], Vec3(1.0f, 2.0f, 0.0f));
}

TEST_F(GltfSynthetic, EightInfluencesSmallComponentsAndStride) {
  // Same mesh through u16 joints, normalised u8 weights, a strided position
  // view and a second influence set duplicating the first.
  Synthetic s = synthetic();
  replace(s.json, "\"POSITION\": 0, \"JOINTS_0\": 1, \"WEIGHTS_0\": 2",
          "\"POSITION\": 10, \"JOINTS_0\": 8, \"WEIGHTS_0\": 7, \"JOINTS_1\": 1, \"WEIGHTS_1\": 2");
  const auto m = import_gltf(write(s));
  ASSERT_TRUE(m.ok()) << m.status().message();
  const auto ref = import_gltf(write(synthetic()));
  ASSERT_TRUE(ref.ok());
  EXPECT_EQ(m->mesh.positions, ref->mesh.positions);
  // Vertex 2: (128/255, 127/255) then (0.5, 0.5), renormalised over 4 slots.
  const auto& w = m->mesh.weights[2];
  EXPECT_NEAR(w[0] + w[1] + w[4] + w[5], 1.0f, 1e-6f);
  EXPECT_NEAR(w[4], 0.25f, 1e-3f);
  EXPECT_EQ(m->mesh.joints[2][4], m->mesh.joints[2][0]);
  const auto a = pose_and_skin(*m, &m->clips[0], 0.7f);
  const auto b = pose_and_skin(*ref, &ref->clips[0], 0.7f);
  for (int v = 0; v < 2; ++v) EXPECT_LT(glm::length(a[static_cast<std::size_t>(v)] - b[static_cast<std::size_t>(v)]), 1e-6f);
  EXPECT_LT(glm::length(a[2] - b[2]), 1e-2f);
}

TEST_F(GltfSynthetic, SparsePositions) {
  Synthetic s = synthetic();
  replace(s.json, "\"POSITION\": 0", "\"POSITION\": 9");
  const auto m = import_gltf(write(s));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->mesh.positions[0], Vec3(0, 0, 0));
  EXPECT_EQ(m->mesh.positions[1], Vec3(2, 2, 0));
  EXPECT_EQ(m->mesh.positions[2], Vec3(0, 1, 0));
}

class GltfFolding : public GltfSynthetic, public ::testing::WithParamInterface<const char*> {};

TEST_P(GltfFolding, NonJointNodesAreFoldedIntoJoints) {
  // An "outer" node (translation, rotation, uniform scale) above the root
  // joint and a "mid" node between hip and knee; the knee's translation and
  // the hip's rotation are animated. Model-space joints must equal the glTF
  // global transforms: checked against the oracle.
  Synthetic s = synthetic();
  replace(s.json, "\"scenes\": [{\"nodes\": [0, 1]}]", "\"scenes\": [{\"nodes\": [0, 3]}]");
  replace(s.json, "{\"name\": \"hip\", \"children\": [2]}", "{\"name\": \"hip\", \"children\": [4]}");
  replace(s.json, "{\"name\": \"knee\", \"translation\": [0, 1, 0]}",
          "{\"name\": \"knee\", \"translation\": [0, 1, 0]},"
          "{\"name\": \"outer\", \"children\": [1], \"translation\": [1, 2, 3],"
          " \"rotation\": [0.70710678, 0, 0, 0.70710678], \"scale\": [2, 2, 2]},"
          "{\"name\": \"mid\", \"children\": [2], \"translation\": [0.5, 0, 0],"
          " \"rotation\": [0, 0.5, 0, 0.8660254]}");
  replace(s.json, "{\"sampler\": 0, \"target\": {\"node\": 1, \"path\": \"rotation\"}}",
          "{\"sampler\": 0, \"target\": {\"node\": 1, \"path\": \"rotation\"}},"
          "{\"sampler\": 1, \"target\": {\"node\": 2, \"path\": \"translation\"}}");
  replace(s.json, "\"samplers\": [{\"input\": 5, \"output\": 6, \"interpolation\": \"LINEAR\"}]",
          "\"samplers\": [{\"input\": 5, \"output\": 6, \"interpolation\": \"LINEAR\"}," +
          std::string("{\"input\": 5, \"output\": ") +
              (std::string(GetParam()) == "CUBICSPLINE" ? "12" : "11") +
              ", \"interpolation\": \"" + GetParam() + "\"}]");
  const std::string path = write(s);
  const auto m = import_gltf(path);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->skeleton.joint_count(), 2u);
  double worst = 1;
  int checked = 0;
  compare_with_oracle(path, worst, checked);
  EXPECT_GT(checked, 10);
  EXPECT_LT(worst, 1e-5);
  std::printf("[ fold   ] %s: max error %.3g x model size over %d samples\n", GetParam(), worst,
              checked);
}

// The knee's translation channel uses each interpolation in turn (the
// oracle implements the spec's formulas for all three).
INSTANTIATE_TEST_SUITE_P(Interpolations, GltfFolding,
                         ::testing::Values("LINEAR", "STEP", "CUBICSPLINE"));

TEST_F(GltfSynthetic, MatrixTransformsAreDecomposed) {
  // The knee and a non-joint parent above the hip given as matrices.
  Synthetic s = synthetic();
  replace(s.json, "\"scenes\": [{\"nodes\": [0, 1]}]", "\"scenes\": [{\"nodes\": [0, 3]}]");
  replace(s.json, "{\"name\": \"knee\", \"translation\": [0, 1, 0]}",
          "{\"name\": \"knee\", \"matrix\": [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1]},"
          "{\"name\": \"outer\", \"children\": [1],"
          " \"matrix\": [0, 0, -3, 0, 0, 3, 0, 0, 3, 0, 0, 0, 4, 5, 6, 1]}");
  const std::string path = write(s);
  double worst = 1;
  int checked = 0;
  compare_with_oracle(path, worst, checked);
  EXPECT_GT(checked, 10);
  EXPECT_LT(worst, 1e-5);
}

TEST_F(GltfSynthetic, NonUniformScaleAboveAnimatedJointIsAnError) {
  Synthetic s = synthetic();
  replace(s.json, "\"scenes\": [{\"nodes\": [0, 1]}]", "\"scenes\": [{\"nodes\": [0, 3]}]");
  replace(s.json, "{\"name\": \"knee\", \"translation\": [0, 1, 0]}",
          "{\"name\": \"knee\", \"translation\": [0, 1, 0]},"
          "{\"name\": \"outer\", \"children\": [1], \"scale\": [1, 2, 3]}");
  expect_error(s, "nodes[1]");
}

TEST_F(GltfSynthetic, RandomCorruptionsNeverCrash) {
  // Deterministic mutations of the synthetic model: digits in the JSON
  // (indices, offsets, counts, component types) and bytes in the buffer.
  // Each import must return a value or a Status; ASan/UBSan runs catch the rest.
  std::uint32_t rng = 12345;
  auto next = [&rng] {
    rng = rng * 1664525u + 1013904223u;
    return rng >> 8;
  };
  const Synthetic base = synthetic();
  std::vector<std::size_t> digits;
  for (std::size_t i = 0; i < base.json.size(); ++i) {
    if (base.json[i] >= '0' && base.json[i] <= '9') digits.push_back(i);
  }
  int errors = 0;
  for (int iter = 0; iter < 300; ++iter) {
    Synthetic s = base;
    const int edits = 1 + static_cast<int>(next() % 3);
    for (int e = 0; e < edits; ++e) {
      if (next() % 2 == 0) {
        s.json[digits[next() % digits.size()]] = static_cast<char>('0' + next() % 10);
      } else {
        s.bin[next() % s.bin.size()] = static_cast<unsigned char>(next());
      }
    }
    const auto m = import_gltf(write(s));
    if (!m.ok()) {
      ++errors;
      EXPECT_FALSE(m.status().detail().empty());
    }
  }
  std::printf("[ fuzz   ] 300 mutations, %d rejected\n", errors);
}

// A second mesh node with its own skin over the same joints.
Synthetic two_skins(const std::string& second_joints) {
  Synthetic s = synthetic();
  const std::string knee = "{\"name\": \"knee\", \"translation\": [0, 1, 0]}";
  s.json.replace(s.json.find(knee), knee.size(),
                 knee + ", {\"name\": \"body2\", \"mesh\": 0, \"skin\": 1}");
  const std::string skin = "\"skeleton\": 1}";
  s.json.replace(s.json.find(skin), skin.size(),
                 skin + ", {\"joints\": " + second_joints + ", \"inverseBindMatrices\": 4}");
  return s;
}

TEST_F(GltfSynthetic, TwoSkinsOverTheSameJointsMerge) {
  const auto m = import_gltf(write(two_skins("[2, 1]")));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->skeleton.joint_count(), 2u);
  EXPECT_EQ(m->mesh.vertex_count(), 6u);
  EXPECT_EQ(m->mesh.triangle_count(), 2u);
  EXPECT_EQ(m->mesh.joints[4][0], m->mesh.joints[1][0]);
}

TEST_F(GltfSynthetic, TwoSkinsWithConflictingBindsAreAnError) {
  expect_error(two_skins("[1, 2]"), "skins[1].inverseBindMatrices[0]");
}

// The synthetic model as a .glb: its buffer in the BIN chunk, `trailing`
// bytes after the declared end.
std::string write_glb(const fs::path& path, Synthetic s, const std::string& trailing = "") {
  const auto at = s.json.find("\"uri\": \"synthetic.bin\", ");
  EXPECT_NE(at, std::string::npos);
  s.json.erase(at, std::string("\"uri\": \"synthetic.bin\", ").size());
  std::string json = s.json;
  while (json.size() % 4 != 0) json += ' ';
  std::string bin(s.bin.begin(), s.bin.end());
  while (bin.size() % 4 != 0) bin += '\0';
  const auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::uint32_t length = static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size());
  const std::string bytes = "glTF" + u32(2) + u32(length) + u32(static_cast<std::uint32_t>(json.size())) +
                            u32(0x4E4F534Au) + json + u32(static_cast<std::uint32_t>(bin.size())) +
                            u32(0x004E4942u) + bin + trailing;
  std::ofstream(path, std::ios::binary) << bytes;
  return path.string();
}

// JSON nested thousands of levels deep overflowed the stack of tinygltf's
// recursive parser (a crash); nesting is now bounded by a scan first, in
// .gltf and .glb alike. The limit is exact, and brackets inside strings do
// not count.
TEST_F(GltfSynthetic, DeepNestingIsRefusedBeforeParsing) {
  const auto with_extras = [](const std::string& extras) {
    Synthetic s = synthetic();
    replace(s.json, "\"scene\": 0,", "\"scene\": 0, \"extras\": " + extras + ",");
    return s;
  };
  const auto arrays = [](std::size_t n) { return std::string(n, '[') + std::string(n, ']'); };
  const auto objects = [](std::size_t n) {
    std::string j;
    for (std::size_t i = 0; i < n; ++i) j += "{\"a\": ";
    return j + "1" + std::string(n, '}');
  };
  // The document's own object is the first level.
  const std::size_t limit = kMaxJsonNesting;
  for (const bool glb : {false, true}) {
    for (const std::string& extras : {arrays(15000), objects(15000), arrays(limit), objects(limit)}) {
      const Synthetic s = with_extras(extras);
      const std::string path = glb ? write_glb(dir_ / "deep.glb", s) : write(s);
      const auto m = import_gltf(path);
      ASSERT_FALSE(m.ok());
      EXPECT_EQ(m.status().code(), ErrorCode::kLimitExceeded);
      EXPECT_EQ(m.status().file(), path);
      EXPECT_NE(m.status().message().find("nested deeper than 256 levels"), std::string::npos)
          << m.status().message();
    }
    for (const std::string& extras :
         {arrays(limit - 1), objects(limit - 1), "\"" + std::string(20000, '[') + "\\\"{{\""}) {
      const Synthetic s = with_extras(extras);
      const std::string path = glb ? write_glb(dir_ / "deep.glb", s) : write(s);
      const auto m = import_gltf(path);
      EXPECT_TRUE(m.ok()) << m.status().message();
    }
  }
}

// Bytes past a .glb's declared length were ignored; the header must
// describe the whole file.
TEST_F(GltfSynthetic, GlbLengthMustBeTheFileSize) {
  ASSERT_TRUE(import_gltf(write_glb(dir_ / "ok.glb", synthetic())).ok());
  for (const std::string& trailing : {std::string("x"), std::string(4, '\0'), std::string(1000, 'g')}) {
    const std::string path = write_glb(dir_ / "long.glb", synthetic(), trailing);
    const auto m = import_gltf(path);
    ASSERT_FALSE(m.ok());
    EXPECT_EQ(m.status().file(), path);
    EXPECT_NE(m.status().message().find("glb.header.length"), std::string::npos) << m.status().message();
    EXPECT_NE(m.status().message().find("data past the declared end"), std::string::npos) << m.status().message();
  }
}

// A .glb whose BIN chunk and buffer claimed 8 bytes more than the file
// holds was accepted, and tinygltf read past the end of its input (valgrind:
// invalid reads). Every chunk's header and length, and the BIN buffer's
// byteLength, are now checked against the bytes present before tinygltf
// sees the file.
TEST_F(GltfSynthetic, GlbChunkAndBufferLengthsMustFitTheBytesPresent) {
  const auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  // The synthetic model as a .glb whose BIN chunk header says `bin_claim`
  // bytes (its true size when 0) and whose buffer says `buffer_claim`, with
  // `bin_chunk` false leaving the chunk out; the header's length is always
  // the file's size.
  const auto glb = [&](const std::string& name, std::uint32_t bin_claim, std::uint32_t buffer_claim,
                       bool bin_chunk = true, const std::string& after = "") {
    Synthetic s = synthetic();
    replace(s.json, "\"uri\": \"synthetic.bin\", \"byteLength\": 472",
            "\"byteLength\": " + std::to_string(buffer_claim));
    std::string json = s.json;
    while (json.size() % 4 != 0) json += ' ';
    std::string bin(s.bin.begin(), s.bin.end());
    while (bin.size() % 4 != 0) bin += '\0';
    std::string chunks = u32(static_cast<std::uint32_t>(json.size())) + u32(0x4E4F534Au) + json;
    if (bin_chunk) chunks += u32(bin_claim != 0 ? bin_claim : static_cast<std::uint32_t>(bin.size())) + u32(0x004E4942u) + bin;
    chunks += after;
    const std::string bytes = "glTF" + u32(2) + u32(static_cast<std::uint32_t>(12 + chunks.size())) + chunks;
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  };
  ASSERT_EQ(synthetic().bin.size(), 472u);
  const auto ok = import_gltf(glb("ok.glb", 0, 472));
  ASSERT_TRUE(ok.ok()) << ok.status().message();

  struct Case {
    std::string path;
    ErrorCode code;
    std::string field;
  };
  const std::vector<Case> cases = {
      // The probe's file: chunk and buffer both 8 bytes past the end.
      {glb("both.glb", 480, 480), ErrorCode::kTruncated, "glb.chunks[1].length"},
      {glb("chunk.glb", 0xfffffff0u, 472), ErrorCode::kTruncated, "glb.chunks[1].length"},
      {glb("buffer.glb", 0, 480), ErrorCode::kTruncated, "buffers[0].byteLength"},
      {glb("nobin.glb", 0, 472, /*bin_chunk=*/false), ErrorCode::kInvalidData, "buffers[0].uri"},
      {glb("header.glb", 0, 472, true, std::string(5, '\0')), ErrorCode::kTruncated, "glb.chunks[2]"},
      {glb("second.glb", 0, 472, true, u32(4) + u32(0x004E4942u) + std::string(4, '\0')), ErrorCode::kInvalidData,
       "glb.chunks[2].type"},
  };
  for (const Case& c : cases) {
    const auto m = import_gltf(c.path);
    ASSERT_FALSE(m.ok()) << c.field;
    EXPECT_EQ(m.status().code(), c.code) << m.status().message();
    EXPECT_EQ(m.status().file(), c.path);
    EXPECT_EQ(m.status().field(), c.field) << m.status().message();
  }
  // Chunks of other types are skipped, as the spec asks.
  const auto extra = import_gltf(glb("extra.glb", 0, 472, true, u32(4) + u32(0x12345678u) + std::string(4, 'x')));
  EXPECT_TRUE(extra.ok()) << extra.status().message();
}

// asset.version is major.minor: 2.x is glTF 2.0; 1.0 and 3.0 are other formats.
TEST_F(GltfSynthetic, AssetVersionMustBeTwo) {
  struct Case {
    std::string version;
    bool ok;
    std::string message;
  };
  for (const Case& c : {Case{"2.1", true, ""}, Case{"3.0", false, "asset.version = 3.0: only glTF 2.x"},
                        Case{"1.0", false, "asset.version = 1.0: glTF 1.0 is not supported"},
                        Case{"20.0", false, "only glTF 2.x"}}) {
    Synthetic s = synthetic();
    replace(s.json, "\"version\": \"2.0\"", "\"version\": \"" + c.version + "\"");
    for (const bool glb : {false, true}) {
      const std::string path = glb ? write_glb(dir_ / "v.glb", s) : write(s);
      const auto m = import_gltf(path);
      ASSERT_EQ(m.ok(), c.ok) << c.version << ": " << (m.ok() ? "" : m.status().message());
      if (!c.ok) {
        EXPECT_NE(m.status().message().find(c.message), std::string::npos) << m.status().message();
      }
    }
  }
}

// A chain of 250,000 nodes beside the model: the cycle check walked every
// node up to its root, quadratic in the chain (100,000 nodes took 9.5 s,
// 400,000 over a minute); it is linear now. Closing the chain into a loop
// names a node on the loop.
TEST_F(GltfSynthetic, LongNodeChainsImportInLinearTime) {
  constexpr std::size_t kChain = 250000;
  const auto with_chain = [&](bool loop) {
    Synthetic s = synthetic();
    std::string chain;
    chain.reserve(kChain * 24);
    for (std::size_t i = 0; i < kChain; ++i) {
      const std::size_t node = 3 + i;
      const std::size_t child = i + 1 < kChain ? node + 1 : (loop ? 3 : 0);
      chain += ",\n    {\"name\": \"n" + std::to_string(i) + "\"";
      if (child != 0) chain += ", \"children\": [" + std::to_string(child) + "]";
      chain += "}";
    }
    replace(s.json, "{\"name\": \"knee\", \"translation\": [0, 1, 0]}",
            "{\"name\": \"knee\", \"translation\": [0, 1, 0]}" + chain);
    return s;
  };
  const auto m = import_gltf(write(with_chain(false)));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->skeleton.joint_count(), 2u) << "the chain holds no joint";
  const std::string path = write(with_chain(true));
  const auto looped = import_gltf(path);
  ASSERT_FALSE(looped.ok());
  const std::string msg = looped.status().message();
  EXPECT_NE(msg.find("cycle through this node"), std::string::npos) << msg;
  const auto at = msg.find("nodes[");
  ASSERT_NE(at, std::string::npos) << msg;
  const std::size_t node = std::stoul(msg.substr(at + 6));
  EXPECT_GE(node, 3u) << msg;
  EXPECT_LT(node, 3 + kChain) << msg;
}

// External files come only from the asset's folder (and below) unless more
// folders are allowed: ".." escapes (plain or percent-encoded), absolute
// paths, other schemes and links out of the folder are refused before any
// read, naming the field; tinygltf's own fallback to the current directory
// is refused too. data: URIs and subfolders still work.
// A bad data URI of a few KB was echoed whole into one line of the error.
// Messages are one line of at most 300 bytes, whatever the input.
TEST_F(GltfSynthetic, ABadDataUriIsNotEchoed) {
  Synthetic s = synthetic();
  replace(s.json, "\"uri\": \"synthetic.bin\"",
          "\"uri\": \"data:application/octet-stream;base64," + std::string(5000, '!') + "\"");
  const auto m = import_gltf(write(s));
  ASSERT_FALSE(m.ok());
  const std::string message = m.status().message();
  EXPECT_LE(message.size(), 300u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(message.rfind((dir_ / "synthetic.gltf").string() + ": ", 0), 0u) << message;
}

TEST_F(GltfSynthetic, ExternalFilesStayInsideTheAssetFolder) {
  const fs::path outside = dir_ / "outside";
  const fs::path asset = dir_ / "asset";
  fs::create_directories(outside);
  fs::create_directories(asset / "sub");
  const Synthetic base = synthetic();
  const auto write_bin = [&](const fs::path& p) {
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(base.bin.data()), static_cast<std::streamsize>(base.bin.size()));
  };
  write_bin(outside / "synthetic.bin");
  write_bin(asset / "sub" / "synthetic.bin");
  fs::create_symlink(outside / "synthetic.bin", asset / "link.bin");
  const auto with_uri = [&](const std::string& uri, const std::string& extra = "") {
    Synthetic s = base;
    replace(s.json, "\"uri\": \"synthetic.bin\"", "\"uri\": \"" + uri + "\"");
    if (!extra.empty()) replace(s.json, "\"scene\": 0,", "\"scene\": 0, " + extra + ",");
    const std::string path = (asset / "model.gltf").string();
    std::ofstream(path, std::ios::binary) << s.json;
    return path;
  };
  struct Refused {
    std::string uri, extra, field, message;
  };
  const std::string secret = (outside / "synthetic.bin").string();
  for (const Refused& r : {
           Refused{"../outside/synthetic.bin", "", "buffers[0].uri", "outside the asset's folder"},
           Refused{"%2e%2e/outside/synthetic.bin", "", "buffers[0].uri", "outside the asset's folder"},
           Refused{"sub/../../outside/synthetic.bin", "", "buffers[0].uri", "outside the asset's folder"},
           Refused{secret, "", "buffers[0].uri", "absolute paths are not allowed"},
           Refused{"file://" + secret, "", "buffers[0].uri", "only relative file names and data: URIs"},
           Refused{"link.bin", "", "buffers[0].uri", "outside the asset's folder"},
           Refused{"%zz.bin", "", "buffers[0].uri", "malformed percent escape"},
           Refused{"sub/synthetic.bin", "\"images\": [{\"uri\": \"../../../../etc/passwd\"}]", "images[0].uri",
                   "outside the asset's folder"},
       }) {
    const std::string path = with_uri(r.uri, r.extra);
    const auto m = import_gltf(path);
    ASSERT_FALSE(m.ok()) << r.uri;
    EXPECT_EQ(m.status().file(), path);
    EXPECT_NE(m.status().message().find(r.field), std::string::npos) << m.status().message();
    EXPECT_NE(m.status().message().find(r.message), std::string::npos) << m.status().message();
  }
  EXPECT_TRUE(import_gltf(with_uri("sub/synthetic.bin")).ok());
  EXPECT_TRUE(import_gltf(with_uri("sub%2Fsynthetic.bin")).ok());
  // Another folder, once allowed.
  GltfImportOptions more_roots;
  more_roots.asset_roots = {outside.string()};
  const auto allowed = import_gltf(with_uri("../outside/synthetic.bin"), more_roots);
  EXPECT_TRUE(allowed.ok()) << allowed.status().message();
  // A data: URI needs no folder at all.
  static const char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < base.bin.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, base.bin.size() - i);  // bytes in this group
    std::uint32_t group = 0;
    for (std::size_t k = 0; k < 3; ++k) group = group << 8 | (k < n ? std::uint32_t{base.bin[i + k]} : 0u);
    for (std::size_t k = 0; k < 4; ++k) b64 += k <= n ? kBase64[(group >> (18 - 6 * k)) & 63] : '=';
  }
  const auto embedded = import_gltf(with_uri("data:application/octet-stream;base64," + b64));
  EXPECT_TRUE(embedded.ok()) << embedded.status().message();
  // A name missing beside the asset but present in the current directory:
  // tinygltf would look there; the read is refused.
  const fs::path cwd = fs::current_path();
  fs::current_path(outside);
  const auto fallback = import_gltf(with_uri("synthetic.bin"));
  fs::current_path(cwd);
  ASSERT_FALSE(fallback.ok());
  EXPECT_NE(fallback.status().message().find("outside the asset's folder"), std::string::npos)
      << fallback.status().message();
}

// Ids are integers in [0, 2^31 - 1] (tinygltf keeps them in int: 4294967297
// read as 1, and -1 as "absent"), wherever they sit; required extensions
// that would change the geometry are refused, material-only ones are fine.
TEST_F(GltfSynthetic, IdsAndRequiredExtensionsFollowTheSpec) {
  struct Case {
    std::string from, to, field, message;
  };
  for (const Case& c : {
           Case{"\"POSITION\": 0", "\"POSITION\": 4294967296", "attributes.POSITION", "past 2^31 - 1"},
           Case{"\"indices\": 3", "\"indices\": 4294967299", "primitives[0].indices", "past 2^31 - 1"},
           Case{"\"indices\": 3", "\"indices\": -1", "primitives[0].indices", "a negative index"},
           Case{"\"children\": [2]", "\"children\": [-2]", "nodes[1].children[0]", "a negative index"},
           Case{"\"joints\": [2, 1]", "\"joints\": [2, 1.5]", "skins[0].joints[1]", "must be an integer"},
           Case{"\"input\": 5", "\"input\": 18446744073709551615", "samplers[0].input", "past 2^31 - 1"},
           Case{"\"scene\": 0,", "\"scene\": 0, \"extensionsRequired\": [\"KHR_draco_mesh_compression\"],",
                "extensionsRequired[0]", "does not support"},
           Case{"\"scene\": 0,", "\"scene\": 0, \"extensionsRequired\": [\"KHR_mesh_quantization\"],",
                "extensionsRequired[0]", "does not support"},
       }) {
    Synthetic s = synthetic();
    replace(s.json, c.from, c.to);
    expect_error(s, c.field);
    const auto m = import_gltf(write(s));
    ASSERT_FALSE(m.ok());
    EXPECT_NE(m.status().message().find(c.message), std::string::npos) << m.status().message();
  }
  Synthetic fine = synthetic();
  replace(fine.json, "\"scene\": 0,",
          "\"scene\": 0, \"extensionsUsed\": [\"KHR_materials_unlit\"], "
          "\"extensionsRequired\": [\"KHR_materials_unlit\"],");
  const auto m = import_gltf(write(fine));
  EXPECT_TRUE(m.ok()) << m.status().message();
}

// Resource limits, generated: 5,000 nodes instancing one mesh (a few KB of
// JSON, a triangle per node here; 23 M triangles in the report that found
// it), an animation repeated 10,000 times, more keys than allowed. Each is
// refused early, naming the limit and the option that raises it; raised,
// the same file imports.
TEST_F(GltfSynthetic, ResourceLimitsAreNamedAndCanBeRaised) {
  Synthetic many = synthetic();
  std::string nodes, scene_nodes;
  for (int i = 0; i < 5000; ++i) {
    nodes += ",\n    {\"mesh\": 0, \"skin\": 0}";
    scene_nodes += ", " + std::to_string(3 + i);
  }
  replace(many.json, "{\"name\": \"knee\", \"translation\": [0, 1, 0]}",
          "{\"name\": \"knee\", \"translation\": [0, 1, 0]}" + nodes);
  replace(many.json, "\"nodes\": [0, 1]}", "\"nodes\": [0, 1" + scene_nodes + "]}");
  GltfImportOptions small;
  small.limits.max_triangles = 1000;
  const auto refused = import_gltf(write(many), small);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_NE(refused.status().message().find("more triangles than the import limit of 1000 (raise it with "
                                            "--max-triangles)"),
            std::string::npos)
      << refused.status().message();
  const auto raised = import_gltf(write(many));  // the default limit
  ASSERT_TRUE(raised.ok()) << raised.status().message();
  EXPECT_EQ(raised->mesh.triangle_count(), 5001u);

  Synthetic repeated = synthetic();
  const std::string animation =
      "{\"channels\": [{\"sampler\": 0, \"target\": {\"node\": 1, \"path\": \"rotation\"}}],\n"
      "                  \"samplers\": [{\"input\": 5, \"output\": 6, \"interpolation\": \"LINEAR\"}]}";
  std::string animations = animation;
  for (int i = 1; i < 10000; ++i) animations += ", " + animation;
  replace(repeated.json, animation, animations);
  const auto clips = import_gltf(write(repeated));
  ASSERT_FALSE(clips.ok());
  EXPECT_NE(clips.status().message().find("animations = 10000: more clips than the import limit of 1024 (raise "
                                          "it with --max-clips)"),
            std::string::npos)
      << clips.status().message();
  GltfImportOptions few_keys;
  few_keys.limits.max_keys = 1;
  const auto keys = import_gltf(write(synthetic()), few_keys);
  ASSERT_FALSE(keys.ok());
  EXPECT_NE(keys.status().message().find("--max-keys"), std::string::npos) << keys.status().message();

  // Nodes: the file above has 5,003.
  GltfImportOptions few_nodes;
  few_nodes.limits.max_nodes = 5002;
  const auto nodes_refused = import_gltf(write(many), few_nodes);
  ASSERT_FALSE(nodes_refused.ok());
  EXPECT_EQ(nodes_refused.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_NE(nodes_refused.status().message().find(
                "nodes = 5003: more nodes than the import limit of 5002 (raise it with --max-nodes)"),
            std::string::npos)
      << nodes_refused.status().message();
  few_nodes.limits.max_nodes = 5003;
  EXPECT_TRUE(import_gltf(write(many), few_nodes).ok());

  // Bytes: the document's own, then those of its external buffer on top
  // (neither file is read past the limit).
  const Synthetic plain = synthetic();
  const std::string path = write(plain);
  const std::size_t document = plain.json.size(), total = document + plain.bin.size();
  GltfImportOptions bytes;
  bytes.limits.max_bytes = document - 1;
  const auto document_refused = import_gltf(path, bytes);
  ASSERT_FALSE(document_refused.ok());
  EXPECT_EQ(document_refused.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_NE(document_refused.status().message().find(std::to_string(document) +
                                                     " bytes: more bytes than the import limit of " +
                                                     std::to_string(document - 1) + " (raise it with --max-bytes)"),
            std::string::npos)
      << document_refused.status().message();
  bytes.limits.max_bytes = total - 1;
  const auto buffer_refused = import_gltf(path, bytes);
  ASSERT_FALSE(buffer_refused.ok());
  EXPECT_EQ(buffer_refused.status().code(), ErrorCode::kLimitExceeded);
  EXPECT_NE(buffer_refused.status().message().find("synthetic.bin"), std::string::npos)
      << buffer_refused.status().message();
  EXPECT_NE(buffer_refused.status().message().find("(raise it with --max-bytes)"), std::string::npos)
      << buffer_refused.status().message();
  bytes.limits.max_bytes = total;
  EXPECT_TRUE(import_gltf(path, bytes).ok());
}

TEST_F(GltfSynthetic, MissingFile) {
  const auto m = import_gltf((dir_ / "nope.gltf").string());
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), ErrorCode::kNotFound);
}

TEST_F(GltfSynthetic, MissingBufferFile) {
  Synthetic s = synthetic();
  replace(s.json, "\"uri\": \"synthetic.bin\"", "\"uri\": \"missing.bin\"");
  expect_error(s, "missing.bin");
}

TEST_F(GltfSynthetic, TruncatedBufferFile) {
  expect_error(synthetic(), "synthetic.bin", 300);
}

TEST_F(GltfSynthetic, TruncatedJson) {
  Synthetic s = synthetic();
  s.json.resize(s.json.size() / 2);
  expect_error(s, "json");
}

TEST_F(GltfSynthetic, AccessorPastBufferEnd) {
  Synthetic s = synthetic();
  replace(s.json, "\"byteOffset\": 240, \"componentType\": 5126, \"count\": 2",
          "\"byteOffset\": 240, \"componentType\": 5126, \"count\": 20");
  expect_error(s, "accessors[6]");
}

TEST_F(GltfSynthetic, AccessorIndexOutOfRange) {
  Synthetic s = synthetic();
  replace(s.json, "\"POSITION\": 0", "\"POSITION\": 70");
  expect_error(s, "attributes.POSITION");
}

TEST_F(GltfSynthetic, JointIndexPastJointCount) {
  Synthetic s = synthetic();
  s.bin[36] = 7;  // vertex 0's first joint, weight 1
  expect_error(s, "JOINTS_0[0]");
}

TEST_F(GltfSynthetic, AllZeroWeights) {
  Synthetic s = synthetic();
  put(s.bin, 48 + 32, 0.0f);
  put(s.bin, 48 + 36, 0.0f);  // vertex 2
  expect_error(s, "WEIGHTS_0[2]");
}

TEST_F(GltfSynthetic, NaNPosition) {
  Synthetic s = synthetic();
  put(s.bin, 16, std::nanf(""));  // vertex 1's y
  expect_error(s, "POSITION -> accessors[0][1]");
}

TEST_F(GltfSynthetic, NodeCycle) {
  Synthetic s = synthetic();
  replace(s.json, "{\"name\": \"knee\", \"translation\": [0, 1, 0]}",
          "{\"name\": \"knee\", \"translation\": [0, 1, 0], \"children\": [1]}");
  expect_error(s, "nodes[");
}

TEST_F(GltfSynthetic, ModeLines) {
  Synthetic s = synthetic();
  replace(s.json, "\"mode\": 4", "\"mode\": 1");
  expect_error(s, "meshes[0].primitives[0].mode");
}

TEST_F(GltfSynthetic, TooFewInverseBindMatrices) {
  Synthetic s = synthetic();
  replace(s.json, "\"componentType\": 5126, \"count\": 2, \"type\": \"MAT4\"",
          "\"componentType\": 5126, \"count\": 1, \"type\": \"MAT4\"");
  expect_error(s, "skins[0].inverseBindMatrices");
}

TEST_F(GltfSynthetic, SamplerOutputCountMismatch) {
  Synthetic s = synthetic();
  replace(s.json, "\"byteOffset\": 240, \"componentType\": 5126, \"count\": 2",
          "\"byteOffset\": 240, \"componentType\": 5126, \"count\": 1");
  expect_error(s, "animations[0].samplers[0].output");
}

TEST_F(GltfSynthetic, SkinJointOutOfRange) {
  Synthetic s = synthetic();
  replace(s.json, "\"joints\": [2, 1]", "\"joints\": [2, 9]");
  expect_error(s, "skins[0].joints[1]");
}

TEST_F(GltfSynthetic, TruncatedGlb) {
  std::ifstream in(kCesiumMan, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 1000u);
  const std::string path = (dir_ / "cut.glb").string();
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  const auto m = import_gltf(path);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().file(), path);
}

// Found by fuzzing (a time-out): accessors without a bufferView are zeros,
// so a 400-byte file could declare 11 million vertices and make the importer
// allocate and process gigabytes. Their count is now limited by the bytes
// of the file's buffers (here: none), before anything is allocated.
TEST_F(GltfSynthetic, UnbackedAccessorCountIsLimitedByTheBuffers) {
  const std::string path = (dir_ / "huge.gltf").string();
  std::ofstream(path, std::ios::binary)
      << R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "accessors": [{"componentType": 5126, "count": 11000000, "type": "VEC3",
                 "min": [0, 0, 0], "max": [0, 0, 0]}]})";
  const auto m = import_gltf(path);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.status().code(), ErrorCode::kLimitExceeded) << m.status().message();
  EXPECT_EQ(m.status().file(), path);
  EXPECT_NE(m.status().field().find("accessors[0].count"), std::string::npos) << m.status().message();
  EXPECT_EQ(m.status().value(), "11000000");
}

TEST_F(GltfSynthetic, WeightsChannelIgnoredAndCubicSplineAccepted) {
  Synthetic s = synthetic();
  // A cubic spline sampler needs 3 values per key: reuse the 2 rotation
  // keys' storage as a 1-key spline (in, value, out) would need 3 VEC4s, so
  // use count 2 keys x 3 = 6 vec4 at 176 (IBM area reads as data; finite).
  replace(s.json, "\"interpolation\": \"LINEAR\"", "\"interpolation\": \"CUBICSPLINE\"");
  replace(s.json, "{\"bufferView\": 0, \"byteOffset\": 240, \"componentType\": 5126, \"count\": 2, \"type\": \"VEC4\"}",
          "{\"bufferView\": 0, \"byteOffset\": 176, \"componentType\": 5126, \"count\": 6, \"type\": \"VEC4\"}");
  replace(s.json, "{\"sampler\": 0, \"target\": {\"node\": 1, \"path\": \"rotation\"}}",
          "{\"sampler\": 0, \"target\": {\"node\": 1, \"path\": \"rotation\"}},"
          "{\"sampler\": 0, \"target\": {\"node\": 0, \"path\": \"weights\"}}");
  // Value slots (1 and 4) must be non-zero quaternions: write them.
  const float q[4] = {0, 0, 0, 1};
  for (int i = 0; i < 4; ++i) {
    put(s.bin, static_cast<std::size_t>(176 + 16 + 4 * i), q[i]);
    put(s.bin, static_cast<std::size_t>(176 + 64 + 4 * i), q[i]);
  }
  const auto m = import_gltf(write(s));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->clips[0].tracks()[0].rotation.interpolation, anim::Interpolation::kCubicSpline);
}

}  // namespace
}  // namespace sinew::editor
