// The editor window used the way a person uses it: under Xvfb, the real X
// pointer (XTest) moves onto a panel widget and clicks, and the window reads
// that input through GLFW and Dear ImGui as it would a mouse's. Nothing here
// calls start_bake() or any other action directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "character/bake.h"
#include "character/pack.h"
#include "content/mannequin/mannequin.h"
#include "editor/gui/editor_app.h"
#include "runtime/display/window.h"
#include "runtime/jobs/job_system.h"
#include "tests/support/temp_dir.h"
#include "tests/support/x_pointer.h"

namespace sinew::editor::gui {
namespace {

using testing_support::TempDir;
using testing_support::XPointer;

constexpr std::uint32_t kPackSamples = 20;

class EditorInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // ctest runs this under xvfb-run: no display is a broken set-up, not a skip.
    ASSERT_TRUE(Window::display_available()) << "run this test under xvfb-run";
    ASSERT_TRUE(pointer_.ok()) << "the X server has no XTest extension";
    // A pack with a small pose space, so the panel offers "Save as pack"
    // only after a bake made in the window.
    auto mannequin = content::make_mannequin();
    ASSERT_TRUE(mannequin.ok()) << mannequin.status().message();
    JobSystem jobs(2);
    character::BakeRequest request;
    request.pose_space.mode = anim::PoseSpaceMode::kClips;
    request.pose_space.samples = kPackSamples;
    request.pose_space.every_frame_30hz = false;
    auto baked = character::bake_in_memory(*mannequin, request, jobs);
    ASSERT_TRUE(baked.ok()) << baked.status().message();
    ASSERT_EQ(baked->fuzzy.stats.sample_count, kPackSamples);
    character::PackContents contents;
    contents.model = &*mannequin;
    contents.fuzzy = &baked->fuzzy;
    ASSERT_TRUE(character::write_pack(dir_.file("start.pack"), contents).ok());

    GuiOptions options;
    options.model_path = dir_.file("start.pack");
    options.width = 980;
    options.height = 900;  // every default-open panel fits the column
    options.threads = 2;
    options.pack_path = dir_.file("clicked.pack");
    options.limits_path = dir_.file("limits.json");
    auto app = EditorApp::create(options);
    ASSERT_TRUE(app.ok()) << app.status().message();
    app_ = std::move(*app);
    app_->set_playing(false);
    step(2);
  }

  // Frames, each recording which widget labels reported a press.
  void step(int frames) {
    for (int i = 0; i < frames; ++i) {
      auto stepped = app_->step();
      ASSERT_TRUE(stepped.ok() && *stepped) << (stepped.ok() ? "window closed" : stepped.status().message());
      for (const PanelWidget& w : app_->widgets()) {
        if (w.pressed) pressed_.push_back(w.label);
      }
    }
  }

  // The widget of that kind showing `text` (its label before any "##"),
  // as a person finds it.
  const PanelWidget* find(WidgetKind kind, const std::string& text) const {
    for (const PanelWidget& w : app_->widgets()) {
      if (w.kind == kind && w.label.substr(0, w.label.find("##")) == text) return &w;
    }
    return nullptr;
  }

  // Moves the real pointer onto the widget, presses and releases the left
  // button with frames in between (a person's click spans frames too).
  // True when the widget reported the press in one of those frames.
  bool click(WidgetKind kind, const std::string& text) {
    const PanelWidget* w = find(kind, text);
    EXPECT_NE(w, nullptr) << "no widget \"" << text << "\" in the last frame";
    if (w == nullptr) return false;
    const std::string label = w->label;
    int wx = 0, wy = 0;
    app_->window_position(&wx, &wy);
    const int x = wx + static_cast<int>((w->min_x + w->max_x) * 0.5f);
    const int y = wy + static_cast<int>((w->min_y + w->max_y) * 0.5f);
    pressed_.clear();
    pointer_.move_to(x, y);
    step(2);
    pointer_.left_button(true);
    step(2);
    pointer_.left_button(false);
    step(2);
    return std::find(pressed_.begin(), pressed_.end(), label) != pressed_.end();
  }

  void wait_for_bake() {
    for (int i = 0; i < 6000 && app_->bake_running(); ++i) {
      step(1);
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_FALSE(app_->bake_running());
  }

  TempDir dir_;
  XPointer pointer_;
  std::unique_ptr<EditorApp> app_;
  std::vector<std::string> pressed_;
};

TEST_F(EditorInputTest, ClickingBakeThenSaveWritesAPackOfTheNewBake) {
  ASSERT_EQ(find(WidgetKind::kButton, "Save as pack"), nullptr) << "a loaded pack has no trees of this session to save";
  EXPECT_TRUE(click(WidgetKind::kButton, "Bake"));
  EXPECT_TRUE(app_->bake_running()) << "the click started no bake: " << app_->message();
  wait_for_bake();
  ASSERT_NE(app_->message().find("bake done"), std::string::npos) << app_->message();
  step(1);
  const std::uint32_t baked_samples = app_->stats().pose_samples;
  EXPECT_GT(baked_samples, kPackSamples);  // the panel's default: every key time and 30 Hz of every clip

  const std::string written = dir_.file("clicked.pack");
  ASSERT_FALSE(std::filesystem::exists(written));
  EXPECT_TRUE(click(WidgetKind::kButton, "Save as pack"));
  ASSERT_TRUE(std::filesystem::exists(written)) << app_->message();
  auto pack = character::Pack::open(written);
  ASSERT_TRUE(pack.ok()) << pack.status().message();
  ASSERT_TRUE(pack->has_fuzzy());
  EXPECT_EQ(pack->fuzzy_stats().sample_count, baked_samples);
  EXPECT_EQ(pack->model().mesh.triangle_count(), app_->model()->mesh.triangle_count());
}

TEST_F(EditorInputTest, EveryPanelWidgetHasItsOwnId) {
  // A panel closed by default, opened by a click on its header.
  EXPECT_TRUE(click(WidgetKind::kHeader, "Joint limits"));
  ASSERT_NE(find(WidgetKind::kButton, "Save limits"), nullptr);
  // The Lights panel, above it, closed by default too: its soft-lighting
  // fields join the check.
  EXPECT_TRUE(click(WidgetKind::kHeader, "Lights"));
  for (const char* label : {"radius", "shadow samples", "AO rays", "AO radius"}) {
    EXPECT_NE(find(WidgetKind::kField, label), nullptr) << label;
  }
  std::map<std::uint32_t, std::vector<std::string>> by_id;
  for (const PanelWidget& w : app_->widgets()) by_id[w.id].push_back(w.label);
  EXPECT_GT(by_id.size(), 20u);
  for (const auto& [id, labels] : by_id) {
    std::string names;
    for (const std::string& l : labels) names += " \"" + l + "\"";
    EXPECT_EQ(labels.size(), 1u) << "one ImGui ID " << id << " for" << names;
  }
}

TEST_F(EditorInputTest, EveryButtonAnswersARealClick) {
  std::vector<std::string> buttons;
  for (const PanelWidget& w : app_->widgets()) {
    if (w.kind == WidgetKind::kButton) buttons.push_back(w.label.substr(0, w.label.find("##")));
  }
  ASSERT_GT(buttons.size(), 5u);  // Load, Play, the clips' actions, Reframe camera, Bake
  for (const std::string& label : buttons) {
    EXPECT_TRUE(click(WidgetKind::kButton, label)) << "\"" << label << "\" did not answer a click; " << app_->message();
    wait_for_bake();
  }
  EXPECT_TRUE(click(WidgetKind::kHeader, "Joint limits"));
  EXPECT_TRUE(click(WidgetKind::kButton, "Save limits"));
  EXPECT_TRUE(std::filesystem::exists(dir_.file("limits.json"))) << app_->message();
}

}  // namespace
}  // namespace sinew::editor::gui
