#include "runtime/display/imgui_layer.h"

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl2.h>

namespace sinew {

Expected<std::unique_ptr<ImGuiLayer>> ImGuiLayer::create(Window& window) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini littering the working folder
  ImGui::StyleColorsDark();
  // Callbacks are installed (and chained to any the window had) so ImGui
  // sees clicks and typing; the game polls key state and is unaffected.
  if (!ImGui_ImplGlfw_InitForOpenGL(window.handle(), true)) {
    ImGui::DestroyContext();
    return make_error(ErrorCode::kInternal, "", "imgui", "glfw", "cannot initialise the GLFW backend");
  }
  if (!ImGui_ImplOpenGL2_Init()) {
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    return make_error(ErrorCode::kInternal, "", "imgui", "opengl2", "cannot initialise the OpenGL 2 backend");
  }
  return std::unique_ptr<ImGuiLayer>(new ImGuiLayer());
}

ImGuiLayer::~ImGuiLayer() {
  ImGui_ImplOpenGL2_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void ImGuiLayer::begin_frame() {
  ImGui_ImplOpenGL2_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
}

void ImGuiLayer::end_frame() {
  ImGui::Render();
  ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
}

bool ImGuiLayer::wants_mouse() const { return ImGui::GetIO().WantCaptureMouse; }
bool ImGuiLayer::wants_keyboard() const { return ImGui::GetIO().WantCaptureKeyboard; }

}  // namespace sinew
