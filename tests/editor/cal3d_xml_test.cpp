// Cal3D's XML formats (.xsf, .xaf, .xmf) get the structural checks of the
// binary ones before Cal3D reads them: ids in range, no cycles, bounded
// nesting, counts that match and numbers that parse and are finite. The
// files are Cally's, written as XML by Cal3D itself, then broken one field
// at a time; the unbroken files still import.
#include <gtest/gtest.h>

#include <cal3d/cal3d.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "editor/import/cal3d_importer.h"
#include "tests/support/cal3d_support.h"
#include "tests/support/temp_dir.h"

namespace sinew::editor {
namespace {

std::string cally_file(const std::string& file) {
  return std::string(SINEW_SHARED_DIR) + "/content/cal3d/cally/" + file;
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The first `from` in `text` replaced by `to`.
std::string with(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

struct Case {
  std::string file;   // which of c.xsf, c.xmf, c.xaf is broken
  std::string bytes;  // its broken text
  ErrorCode code;
  std::string field;  // the field the error must name
};

class Cal3dXml : public ::testing::Test {
 protected:
  void SetUp() override {
    // Cal3D's saver picks XML by extension.
    CalCoreModel core("cally");
    ASSERT_TRUE(core.loadCoreSkeleton(cally_file("cally.csf")));
    const int mesh = core.loadCoreMesh(cally_file("cally_neck.cmf"));
    const int clip = core.loadCoreAnimation(cally_file("cally_wave.caf"));
    ASSERT_GE(mesh, 0);
    ASSERT_GE(clip, 0);
    ASSERT_TRUE(CalSaver::saveCoreSkeleton(dir_.file("c.xsf"), core.getCoreSkeleton()));
    ASSERT_TRUE(CalSaver::saveCoreMesh(dir_.file("c.xmf"), core.getCoreMesh(mesh)));
    ASSERT_TRUE(CalSaver::saveCoreAnimation(dir_.file("c.xaf"), core.getCoreAnimation(clip)));
    testing_support::free_cal3d_animation_tracks(core);
    xsf_ = read(dir_.file("c.xsf"));
    xmf_ = read(dir_.file("c.xmf"));
    xaf_ = read(dir_.file("c.xaf"));
  }

  // Imports a model of skeleton, mesh and animation with `file` replaced by
  // `bytes` (written to a copy named like it), the others as Cal3D wrote them.
  Expected<character::Model> import_with(const std::string& file, const std::string& bytes) {
    auto path = [&](const std::string& name) {
      if (name != file) return dir_.file("c" + name.substr(name.find('.')));
      std::ofstream(dir_.file("bad" + name.substr(name.find('.'))), std::ios::binary) << bytes;
      return dir_.file("bad" + name.substr(name.find('.')));
    };
    std::ofstream(dir_.file("m.cfg")) << "skeleton=" << path("c.xsf") << "\nmesh=" << path("c.xmf")
                                      << "\nanimation=" << path("c.xaf") << "\n";
    return import_cal3d(dir_.file("m.cfg"));
  }

  void expect_refused(const Case& c) {
    SCOPED_TRACE(c.file + " " + c.field);
    auto m = import_with(c.file, c.bytes);
    ASSERT_FALSE(m.ok());
    EXPECT_EQ(m.status().code(), c.code) << m.status().message();
    EXPECT_NE(m.status().file().find("bad."), std::string_view::npos) << m.status().message();
    EXPECT_EQ(m.status().field(), c.field) << m.status().message();
    EXPECT_LE(m.status().message().size(), 300u) << m.status().message();
  }

  testing_support::TempDir dir_;
  std::string xsf_, xmf_, xaf_;
};

TEST_F(Cal3dXml, FilesCal3dWritesImport) {
  auto m = import_with("", "");
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->skeleton.joint_count(), 37u);
  EXPECT_EQ(m->clips.size(), 1u);
}

// Found by a hostile-input probe: Cal3D follows these links unchecked and
// died with SIGSEGV; the binary skeleton's checks now hold for XML.
TEST_F(Cal3dXml, SkeletonLinksOutOfRangeOrCyclicAreRefused) {
  const std::vector<Case> cases = {
      {"c.xsf", with(xsf_, "<PARENTID>-1</PARENTID>", "<PARENTID>999</PARENTID>"), ErrorCode::kOutOfBounds,
       "bone[0].parentId"},
      {"c.xsf", with(xsf_, "<PARENTID>0</PARENTID>", "<PARENTID>-7</PARENTID>"), ErrorCode::kOutOfBounds,
       "BONE[1].PARENTID"},
      {"c.xsf", with(xsf_, "<CHILDID>1</CHILDID>", "<CHILDID>99</CHILDID>"), ErrorCode::kInvalidData,
       "bone[0].children[0]"},
      {"c.xsf", with(xsf_, "<CHILDID>1</CHILDID>", "<CHILDID>100000</CHILDID>"), ErrorCode::kOutOfBounds,
       "BONE[0].CHILDID[0]"},
      // Bone 0 made the child of its own child: the parents form a cycle.
      {"c.xsf", with(xsf_, "<PARENTID>-1</PARENTID>", "<PARENTID>1</PARENTID>"), ErrorCode::kInvalidData,
       "bone[0].parentId"},
      {"c.xsf", with(xsf_, "NUMBONES=\"37\"", "NUMBONES=\"38\""), ErrorCode::kInvalidData, "SKELETON.NUMBONES"},
      {"c.xsf", with(xsf_, "<BONE ID=\"1\"", "<BONE ID=\"2\""), ErrorCode::kInvalidData, "BONE[1].ID"},
      {"c.xsf", with(xsf_, "NAME=\"Cally\" ", ""), ErrorCode::kInvalidData, "BONE[0].NAME"},
      {"c.xsf", with(xsf_, "NUMCHILDS=\"1\"", "NUMCHILDS=\"2\""), ErrorCode::kInvalidData, "BONE[0].NUMCHILDS"},
  };
  for (const Case& c : cases) expect_refused(c);
}

// Cal3D reads numbers with atoi/atof and streams: `abc` became 0 and `nan`
// a NaN joint, and the model came out distorted with exit 0.
TEST_F(Cal3dXml, MalformedNumbersAndCountsAreRefused) {
  const std::string rotation = "<ROTATION>-0 0 0.707106 0.707107</ROTATION>";
  const std::vector<Case> cases = {
      {"c.xsf", with(xsf_, rotation, "<ROTATION>nan 0 0.707106 0.707107</ROTATION>"), ErrorCode::kInvalidData,
       "BONE[0].ROTATION"},
      {"c.xsf", with(xsf_, rotation, "<ROTATION>-0 inf 0.707106 0.707107</ROTATION>"), ErrorCode::kInvalidData,
       "BONE[0].ROTATION"},
      {"c.xsf", with(xsf_, rotation, "<ROTATION>-0 0 0.707106</ROTATION>"), ErrorCode::kInvalidData,
       "BONE[0].ROTATION"},
      {"c.xsf", with(xsf_, rotation, "<ROTATION>-0 0 0.707106 1e39</ROTATION>"), ErrorCode::kInvalidData,
       "BONE[0].ROTATION"},
      {"c.xsf", with(xsf_, "<PARENTID>0</PARENTID>", "<PARENTID>abc</PARENTID>"), ErrorCode::kInvalidData,
       "BONE[1].PARENTID"},
      {"c.xaf", with(xaf_, "TIME=\"0\"", "TIME=\"abc\""), ErrorCode::kInvalidData, "TRACK[0].KEYFRAME[0].TIME"},
      {"c.xaf", with(xaf_, "DURATION=\"3.36667\"", "DURATION=\"inf\""), ErrorCode::kInvalidData,
       "ANIMATION.DURATION"},
      {"c.xaf", with(xaf_, "NUMTRACKS=\"14\"", "NUMTRACKS=\"15\""), ErrorCode::kInvalidData, "ANIMATION.NUMTRACKS"},
      {"c.xaf", with(xaf_, "BONEID=\"5\"", "BONEID=\"-1\""), ErrorCode::kOutOfBounds, "TRACK[0].BONEID"},
      {"c.xaf", with(xaf_, "NUMKEYFRAMES=\"101\"", "NUMKEYFRAMES=\"x\""), ErrorCode::kInvalidData,
       "TRACK[0].NUMKEYFRAMES"},
      {"c.xaf", with(xaf_, "<ROTATION>0 0 0 1</ROTATION>", "<ROTATION>0 0 nan 1</ROTATION>"),
       ErrorCode::kInvalidData, "TRACK[0].KEYFRAME[0].ROTATION"},
      {"c.xmf", with(xmf_, "<FACE VERTEXID=\"0 1 34\" />", "<FACE VERTEXID=\"0 1 999\" />"),
       ErrorCode::kOutOfBounds, "SUBMESH[0].FACE[0].VERTEXID"},
      {"c.xmf", with(xmf_, "<FACE VERTEXID=\"0 1 34\" />", "<FACE VERTEXID=\"0 1\" />"), ErrorCode::kInvalidData,
       "SUBMESH[0].FACE[0].VERTEXID"},
      {"c.xmf", with(xmf_, "NUMVERTICES=\"36\"", "NUMVERTICES=\"37\""), ErrorCode::kInvalidData,
       "SUBMESH[0].NUMVERTICES"},
      {"c.xmf", with(xmf_, "NUMFACES=\"44\"", "NUMFACES=\"-1\""), ErrorCode::kOutOfBounds, "SUBMESH[0].NUMFACES"},
      {"c.xmf", with(xmf_, "<INFLUENCE ID=\"6\">1</INFLUENCE>", "<INFLUENCE ID=\"6\">nan</INFLUENCE>"),
       ErrorCode::kInvalidData, "SUBMESH[0].VERTEX[0].INFLUENCE[0]"},
      {"c.xmf", with(xmf_, "NUMINFLUENCES=\"1\"", "NUMINFLUENCES=\"2\""), ErrorCode::kInvalidData,
       "SUBMESH[0].VERTEX[0].NUMINFLUENCES"},
      {"c.xmf", with(xmf_, "<POS>-1.13624 7.72225 162.52</POS>", "<POS>-1.13624 7.72225 abc</POS>"),
       ErrorCode::kInvalidData, "SUBMESH[0].VERTEX[0].POS"},
  };
  for (const Case& c : cases) expect_refused(c);
}

// Cal3D's XML parser recurses per level and overflowed the stack at about
// 40,000 levels; nesting is refused before it parses, whatever the depth.
TEST_F(Cal3dXml, DeepNestingIsRefusedBeforeCal3dParses) {
  for (const std::size_t depth : {std::size_t{17}, std::size_t{40000}, std::size_t{200000}}) {
    std::string deep = "<SKELETON NUMBONES=\"0\">";
    for (std::size_t i = 0; i < depth; ++i) deep += "<BONE>";
    for (std::size_t i = 0; i < depth; ++i) deep += "</BONE>";
    deep += "</SKELETON>";
    expect_refused({"c.xsf", deep, ErrorCode::kLimitExceeded, "BONE"});
  }
  const std::vector<Case> cases = {
      {"c.xsf", xsf_.substr(0, xsf_.find("</BONE>")), ErrorCode::kTruncated, "BONE"},
      {"c.xsf", with(xsf_, "</SKELETON>", "</SKELETONX>"), ErrorCode::kInvalidData, "SKELETONX"},
      {"c.xsf", "<!DOCTYPE x>" + xsf_, ErrorCode::kInvalidData, "xml"},
      {"c.xsf", xsf_ + "<SKELETON NUMBONES=\"0\"/>", ErrorCode::kInvalidData, "SKELETON"},
      {"c.xsf", "<!-- no element -->", ErrorCode::kInvalidData, "SKELETON"},
      // XML allows it; Cal3D's parser does not, and said only "invalid file format".
      {"c.xsf", "\xEF\xBB\xBF" + xsf_, ErrorCode::kInvalidData, "xml"},
  };
  for (const Case& c : cases) expect_refused(c);
}

}  // namespace
}  // namespace sinew::editor
