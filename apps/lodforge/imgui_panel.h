// Dear ImGui over a GLFW window, for the panels of `lodforge view` (packages and point
// packages): set up when made, shut down when it goes out of scope.
#pragma once

struct GLFWwindow;

namespace lodforge::cli {

class ImGuiPanel {
 public:
  explicit ImGuiPanel(GLFWwindow* window);
  ~ImGuiPanel();
  ImGuiPanel(const ImGuiPanel&) = delete;
  ImGuiPanel& operator=(const ImGuiPanel&) = delete;
};

}  // namespace lodforge::cli
