#include "editor/gui/editor_app.h"

#include <GLFW/glfw3.h>
#include <GL/gl.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>

#include "animation/joint_limits.h"
#include "character/pack.h"
#include "editor/gui/bake_job.h"
#include "editor/gui/panels.h"
#include "editor/gui/pose_player.h"
#include "editor/import/model_loader.h"
#include "runtime/display/imgui_layer.h"
#include "runtime/display/pixel_display.h"
#include "runtime/display/window.h"
#include "runtime/jobs/job_system.h"
#include "runtime/timing/phase_timers.h"

namespace sinew::editor::gui {
namespace {

constexpr int kPanelWidth = 340;

// The model and the trees in use. Heap-allocated so that the spans the
// scene and the bake worker hold stay valid while it lives.
struct Loaded {
  std::optional<character::Pack> pack;
  character::Model imported;
  std::unique_ptr<rt::FuzzyCharacterData> baked;  // null: the pack's trees

  const character::Model& model() const { return pack ? pack->model() : imported; }
  rt::FuzzyCharacterView view() const { return baked ? baked->view() : pack->fuzzy(); }
  const rt::FuzzyBakeStats& stats() const { return baked ? baked->stats : pack->fuzzy_stats(); }
};

int first_bone_with_triangles(const rt::FuzzyCharacterView& fuzzy) {
  // The bone with the most triangles: the most telling boxes to show first.
  std::uint32_t best = 0;
  for (std::uint32_t b = 0; b < fuzzy.bone_trees.size(); ++b) {
    if (fuzzy.bone_trees[b].triangle_count > fuzzy.bone_trees[best].triangle_count) best = b;
  }
  return static_cast<int>(best);
}

anim::PoseSpaceDesc pose_space_of(const BakeSettings& s) {
  anim::PoseSpaceDesc desc;
  desc.mode = s.mode;
  const bool random = s.mode == anim::PoseSpaceMode::kArbitrary || s.mode == anim::PoseSpaceMode::kLimits;
  desc.samples = random && s.samples <= 0 ? 1000 : s.samples;
  desc.every_frame_30hz = !random && s.every_frame_30hz;
  if (s.mode == anim::PoseSpaceMode::kClip) desc.clips = {s.clip};
  return desc;
}

}  // namespace

struct EditorApp::Impl {
  GuiOptions options;
  std::unique_ptr<Window> window;
  std::unique_ptr<ImGuiLayer> imgui;
  std::unique_ptr<PixelDisplay> display;
  std::unique_ptr<JobSystem> jobs;
  PhaseTimers timers;

  std::unique_ptr<Loaded> loaded;
  std::unique_ptr<PosePlayer> player;
  std::unique_ptr<BakeJob> bake;
  Viewport viewport;
  PanelState panels;
  WidgetLog widgets;  // the last frame's
  std::vector<Affine3> skinning;

  bool playing = true;
  bool capture = false;
  Screenshot shown;
  std::string message;
  EditorStats stats;
  double smoothed_ms = 0.0;
  std::chrono::steady_clock::time_point last_frame = std::chrono::steady_clock::now();
  bool dragging = false;
  double drag_x = 0.0;
  double drag_y = 0.0;

  Status use_loaded(std::unique_ptr<Loaded> next);
  Status load_path(const std::string& path);
  void poll_bake();
  void handle_mouse(int viewport_width);
  Status draw_panels(int x, int height);
  Status start_bake(const BakeSettings& settings);
  Status save_pack(const std::string& path);
};

EditorApp::EditorApp(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

EditorApp::~EditorApp() {
  // The bake worker reads the model: stop it before the model goes.
  if (impl_) impl_->bake.reset();
}

Expected<std::unique_ptr<EditorApp>> EditorApp::create(const GuiOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  WindowOptions window_options;
  window_options.width = options.width;
  window_options.height = options.height;
  window_options.title = "Sinew editor";
  window_options.visible = options.visible;
  SINEW_ASSIGN_OR_RETURN(impl->window, Window::create(window_options));
  SINEW_ASSIGN_OR_RETURN(impl->imgui, ImGuiLayer::create(*impl->window));
  impl->display = std::make_unique<PixelDisplay>();
  impl->jobs = std::make_unique<JobSystem>(options.threads);
  impl->viewport.overlay = options.overlay;
  copy_text(impl->panels.pack_path, options.pack_path);
  copy_text(impl->panels.limits_path, options.limits_path);
  std::unique_ptr<EditorApp> app(new EditorApp(std::move(impl)));
  if (!options.model_path.empty()) SINEW_RETURN_IF_ERROR(app->load(options.model_path));
  return app;
}

Status EditorApp::Impl::use_loaded(std::unique_ptr<Loaded> next) {
  bake.reset();  // cancels and joins: it may read the old model
  if (!next->pack || !next->pack->has_fuzzy()) {
    character::BakeRequest request;  // the default pose space: every clip
    SINEW_ASSIGN_OR_RETURN(character::InMemoryBake baked, character::bake_in_memory(next->model(), request, *jobs));
    next->baked = std::make_unique<rt::FuzzyCharacterData>(std::move(baked.fuzzy));
  }
  const character::Model& model = next->model();
  if (model.mesh.triangle_count() == 0) {
    return make_error(ErrorCode::kInvalidData, model.source, "triangles", "0", "the model has no triangles");
  }
  SINEW_RETURN_IF_ERROR(viewport.reset(model, next->view(), true));
  player = std::make_unique<PosePlayer>(model);
  loaded = std::move(next);
  panels.reset_for(loaded->model(), loaded->pack ? loaded->pack->limits() : std::span<const anim::JointLimit>{});
  viewport.bone = static_cast<std::uint32_t>(first_bone_with_triangles(loaded->view()));
  panels.bone = static_cast<int>(viewport.bone);
  message = "loaded " + (model.source.empty() ? std::string("model") : model.source);
  return Status{};
}

Status EditorApp::Impl::load_path(const std::string& path) {
  auto next = std::make_unique<Loaded>();
  if (character::is_pack_path(path)) {
    SINEW_ASSIGN_OR_RETURN(character::Pack pack, character::Pack::open(path));
    next->pack.emplace(std::move(pack));
  } else {
    SINEW_ASSIGN_OR_RETURN(next->imported, load_model(path));
  }
  return use_loaded(std::move(next));
}

Status EditorApp::load(const std::string& path) {
  SINEW_RETURN_IF_ERROR(impl_->load_path(path));
  const GuiOptions& o = impl_->options;
  if (!o.clip.empty()) SINEW_RETURN_IF_ERROR(set_clip(o.clip));
  if (!o.bone.empty()) SINEW_RETURN_IF_ERROR(set_bone(o.bone));
  if (o.time) {
    SINEW_RETURN_IF_ERROR(set_time(*o.time));
    set_playing(false);
  }
  return Status{};
}

Status EditorApp::load(character::Model model) {
  auto next = std::make_unique<Loaded>();
  next->imported = std::move(model);
  return impl_->use_loaded(std::move(next));
}

void EditorApp::Impl::poll_bake() {
  if (!bake || !bake->done()) return;
  Expected<character::InMemoryBake> result = bake->take();
  bake.reset();
  if (!result.ok()) {
    // A cancelled or failed bake leaves the trees in use untouched.
    message = result.status().code() == ErrorCode::kCancelled ? "bake cancelled; the previous trees stay in use"
                                                               : "bake failed: " + result.status().message();
    return;
  }
  auto fuzzy = std::make_unique<rt::FuzzyCharacterData>(std::move(result->fuzzy));
  const Status reset = viewport.reset(loaded->model(), fuzzy->view(), false);
  if (!reset.ok()) {
    message = "bake result rejected: " + reset.message();
    (void)viewport.reset(loaded->model(), loaded->view(), false);
    return;
  }
  loaded->baked = std::move(fuzzy);  // the old trees go only after the scene let go of them
  message = "bake done: " + std::to_string(loaded->baked->stats.sample_count) + " pose samples";
}

Status EditorApp::Impl::start_bake(const BakeSettings& settings) {
  if (!loaded) return invalid_argument("bake", "no model", "load a model first");
  if (bake) return invalid_argument("bake", "running", "a bake is already running");
  character::BakeRequest request;
  request.pose_space = pose_space_of(settings);
  if (settings.mode == anim::PoseSpaceMode::kLimits) request.limits = panels.limits;
  request.fuzzy.padding = settings.padding;
  // The worker gets its own pool so the viewport keeps rendering.
  bake = std::make_unique<BakeJob>(loaded->model(), std::move(request), 0);
  message = "baking...";
  return Status{};
}

Status EditorApp::Impl::save_pack(const std::string& path) {
  if (!loaded || !loaded->baked) {
    return invalid_argument("save", path, "only trees baked in this session can be saved");
  }
  character::PackContents contents;
  contents.model = &loaded->model();
  contents.limits = panels.limits;
  contents.fuzzy = loaded->baked.get();
  contents.provenance.tool_version = "sinew-editor gui";
  return character::write_pack(path, contents);
}

void EditorApp::Impl::handle_mouse(int viewport_width) {
  double x = 0.0, y = 0.0;
  window->cursor_position(&x, &y);
  const bool down = window->mouse_button_down(GLFW_MOUSE_BUTTON_LEFT);
  if (!down) {
    dragging = false;
    return;
  }
  if (!dragging) {
    // A drag starts only inside the viewport and outside any panel.
    dragging = !imgui->wants_mouse() && x < viewport_width;
  } else {
    constexpr float kRadiansPerPixel = 0.008f;
    viewport.orbit(static_cast<float>(x - drag_x) * kRadiansPerPixel, static_cast<float>(y - drag_y) * kRadiansPerPixel);
  }
  drag_x = x;
  drag_y = y;
}

Expected<bool> EditorApp::step() {
  Impl& m = *impl_;
  m.window->poll_events();
  if (m.window->should_close()) return false;
  const auto now = std::chrono::steady_clock::now();
  const double wall_ms = std::chrono::duration<double, std::milli>(now - m.last_frame).count();
  m.last_frame = now;
  m.smoothed_ms = m.smoothed_ms == 0.0 ? wall_ms : m.smoothed_ms + 0.05 * (wall_ms - m.smoothed_ms);

  int fb_w = 0, fb_h = 0;
  m.window->framebuffer_size(&fb_w, &fb_h);
  const int panel_w = std::min(kPanelWidth, fb_w / 2);
  const int view_w = std::max(1, fb_w - panel_w);
  const int view_h = std::max(1, fb_h);
  m.handle_mouse(view_w);
  m.poll_bake();

  ViewportFrame frame;
  if (m.loaded) {
    if (m.playing) m.player->advance(std::min(0.1, wall_ms * 1e-3));
    {
      ScopedPhase phase(m.timers, "animation");
      m.skinning = m.player->skinning();
    }
    m.viewport.resize(view_w, view_h);
    SINEW_ASSIGN_OR_RETURN(frame, m.viewport.render(m.skinning, *m.jobs, &m.timers));
  }

  {
    ScopedPhase phase(m.timers, "display");
    glViewport(0, 0, fb_w, fb_h);
    glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    if (m.loaded) {
      SINEW_RETURN_IF_ERROR(m.display->present(m.viewport.width(), m.viewport.height(), m.viewport.image(),
                                               m.viewport.width(), m.viewport.height()));
    }
    // Stats first so the panel shows this frame's numbers.
    EditorStats& s = m.stats;
    s.fps = m.smoothed_ms > 0.0 ? 1000.0 / m.smoothed_ms : 0.0;
    s.phases_ms = m.timers.latest();
    s.escaped_triangles = frame.scene.escaped_triangles;
    s.escaped_pixels = frame.escaped_pixels;
    s.shadow_rays = frame.render.shadow_rays;
    s.ao_rays = frame.render.ao_rays;
    s.trace_shadow_ms = frame.render.trace_shadow_ms;
    s.trace_ao_ms = frame.render.trace_ao_ms;
    if (m.loaded) {
      const rt::FuzzyBakeStats& b = m.loaded->stats();
      s.triangles = m.loaded->model().mesh.triangle_count();
      s.bones = m.loaded->model().skeleton.joint_count();
      s.pose_samples = b.sample_count;
      s.fuzzy_area_ratio = b.rest_area > 0.0 ? b.fuzzy_area / b.rest_area : 0.0;
      s.from_pack = !m.loaded->baked;
    }
    m.imgui->begin_frame();
    const Status panels = m.draw_panels(view_w, fb_h);
    m.imgui->end_frame();
    if (!panels.ok()) m.message = panels.message();
    if (m.capture) m.shown.rgba = m.window->read_back_buffer(&m.shown.width, &m.shown.height);
    m.window->swap_buffers();
  }
  return true;
}

Status EditorApp::Impl::draw_panels(int x, int height) {
  PanelContext ctx;
  ctx.model = loaded ? &loaded->model() : nullptr;
  ctx.fuzzy = loaded ? loaded->view() : rt::FuzzyCharacterView{};
  ctx.player = player.get();
  ctx.viewport = &viewport;
  ctx.stats = &stats;
  ctx.playing = &playing;
  ctx.bake_running = bake != nullptr;
  ctx.bake_progress = bake ? bake->progress() : 0.0;
  ctx.bake_phase = bake ? bake->phase() : std::string();
  ctx.can_save_pack = loaded && loaded->baked;
  ctx.message = message;
  widgets.clear();
  ctx.widgets = &widgets;
  const PanelActions actions = draw_editor_panels(panels, ctx, static_cast<float>(x), static_cast<float>(height));
  if (actions.load) return load_path(panels.load_path_text());
  if (actions.bake) return start_bake(panels.bake);
  if (actions.cancel_bake && bake) bake->cancel();
  if (actions.save_pack) {
    SINEW_RETURN_IF_ERROR(save_pack(panels.pack_path_text()));
    message = "saved " + panels.pack_path_text();
  }
  if (actions.save_limits && loaded) {
    SINEW_RETURN_IF_ERROR(anim::save_joint_limits(panels.limits_path_text(), panels.limits, loaded->model().skeleton));
    message = "saved " + panels.limits_path_text();
  }
  if (actions.action_clip >= 0 && player) SINEW_RETURN_IF_ERROR(player->trigger_action(actions.action_clip));
  return Status{};
}

void EditorApp::set_overlay(Overlay overlay) { impl_->viewport.overlay = overlay; }

Status EditorApp::set_bone(const std::string& name_or_index) {
  if (!impl_->loaded) return invalid_argument("--bone", name_or_index, "no model loaded");
  const anim::Skeleton& skeleton = impl_->loaded->model().skeleton;
  int bone = -1;
  if (auto found = skeleton.find(name_or_index)) {
    bone = *found;
  } else {
    int index = 0;
    const auto [end, ec] = std::from_chars(name_or_index.data(), name_or_index.data() + name_or_index.size(), index);
    if (ec == std::errc{} && end == name_or_index.data() + name_or_index.size()) bone = index;
  }
  if (bone < 0 || static_cast<std::size_t>(bone) >= skeleton.joint_count()) {
    return make_error(ErrorCode::kNotFound, impl_->loaded->model().source, "--bone", name_or_index,
                      "no such bone (" + std::to_string(skeleton.joint_count()) + " bones)");
  }
  impl_->viewport.bone = static_cast<std::uint32_t>(bone);
  impl_->panels.bone = bone;
  return Status{};
}

Status EditorApp::set_clip(const std::string& name) {
  if (!impl_->loaded) return invalid_argument("--clip", name, "no model loaded");
  const character::Model& model = impl_->loaded->model();
  const anim::Clip* clip = model.find_clip(name);
  if (clip == nullptr) return make_error(ErrorCode::kNotFound, model.source, "--clip", name, "no such clip");
  return set_cycles(static_cast<int>(clip - model.clips.data()), -1, 0.0f);
}

Status EditorApp::set_cycles(int clip_a, int clip_b, float blend) {
  if (!impl_->player) return invalid_argument("clip", std::to_string(clip_a), "no model loaded");
  SINEW_RETURN_IF_ERROR(impl_->player->set_cycles(clip_a, clip_b, blend));
  impl_->panels.clip_a = clip_a;
  impl_->panels.clip_b = clip_b;
  impl_->panels.blend = blend;
  return Status{};
}

Status EditorApp::set_time(double seconds) {
  if (!impl_->player) return invalid_argument("--time", std::to_string(seconds), "no model loaded");
  return impl_->player->seek(seconds);
}

void EditorApp::set_playing(bool playing) { impl_->playing = playing; }

Status EditorApp::trigger_action(int clip) {
  if (!impl_->player) return invalid_argument("clip", std::to_string(clip), "no model loaded");
  return impl_->player->trigger_action(clip);
}

void EditorApp::orbit(float yaw_radians, float pitch_radians) { impl_->viewport.orbit(yaw_radians, pitch_radians); }

Status EditorApp::start_bake(const BakeSettings& settings) { return impl_->start_bake(settings); }
bool EditorApp::bake_running() const { return impl_->bake != nullptr; }
double EditorApp::bake_progress() const { return impl_->bake ? impl_->bake->progress() : 0.0; }
void EditorApp::cancel_bake() {
  if (impl_->bake) impl_->bake->cancel();
}
const std::string& EditorApp::message() const { return impl_->message; }

void EditorApp::set_capture(bool on) { impl_->capture = on; }
const Screenshot& EditorApp::last_shown() const { return impl_->shown; }

const WidgetLog& EditorApp::widgets() const { return impl_->widgets; }
void EditorApp::window_position(int* x, int* y) const { impl_->window->position(x, y); }

const character::Model* EditorApp::model() const { return impl_->loaded ? &impl_->loaded->model() : nullptr; }
rt::FuzzyCharacterView EditorApp::fuzzy() const {
  return impl_->loaded ? impl_->loaded->view() : rt::FuzzyCharacterView{};
}
std::span<const Affine3> EditorApp::skinning() const { return impl_->skinning; }
const Viewport& EditorApp::viewport() const { return impl_->viewport; }
Viewport& EditorApp::viewport() { return impl_->viewport; }
EditorStats EditorApp::stats() const { return impl_->stats; }

}  // namespace sinew::editor::gui
