// sinew-editor: the offline tool. `sinew-editor <command> [args]`; each
// command is a function taking its arguments and two streams and returning
// the exit code (0 success, 1 user error, 2 usage error), so tests run them
// in-process.
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "editor/cli/pack_commands.h"
#include "editor/cli/render_command.h"
#include "runtime/cli/command_line.h"
#include "runtime/core/status.h"
#ifdef SINEW_HAVE_GUI
#include "editor/gui/editor_app.h"
#endif

namespace {

// The command line, dispatched to the command.
int run(const std::vector<std::string>& args);

}  // namespace

// Library code returns errors; what is left to catch here is memory running
// out (an input that needs more than the machine has) and bugs. Either is
// one line and exit 1, never an abort.
int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  const std::string command = args.empty() ? "" : args.front();
  try {
    return run(args);
  } catch (const std::bad_alloc&) {
    std::cerr << "sinew-editor " << command
              << ": out of memory: the input needs more than this machine has (the glTF import limits "
                 "--max-triangles, --max-clips, --max-keys, --max-nodes and --max-bytes, and bake's --max-memory-mib, "
                 "bound it lower)\n";
  } catch (const std::exception& e) {
    std::cerr << "sinew-editor " << command << ": internal error: " << sinew::printable(e.what()) << "\n";
  }
  return 1;
}

namespace {

int run(const std::vector<std::string>& args) {
  sinew::cli::CommandLine line("sinew-editor", "The offline tool: content packs, renders and the editor window.\n");
  line.command("bake", "bake a model's fuzzy kd-trees into a content pack");
  line.command("inspect", "sizes, counts, pose space, fuzzy area, tree depths, provenance of a pack");
  line.command("validate", "check a pack completely (exit 0 when valid)");
  line.command("subdivide", "split every triangle into four, L times (the paper's larger Cally variants)");
  line.command("render", "pose with one clip and ray trace a model or a pack");
  line.command("gui", "the editor window: clips, bake, joint limits, overlays, stats");
  line.footer("Run `sinew-editor COMMAND --help` for a command's options.\n");
  if (const auto done = sinew::cli::help_or_usage_error(line, line.parse(args), std::cout, std::cerr)) return *done;
  const std::string& command = line.chosen_command();
  const std::vector<std::string>& rest = line.command_arguments();
  if (command.empty()) {
    return sinew::cli::usage_error("sinew-editor", sinew::invalid_argument("COMMAND", "", "missing (see --help)"),
                                   std::cerr);
  }
  if (command == "bake") return sinew::editor::run_bake(rest, std::cout, std::cerr);
  if (command == "subdivide") return sinew::editor::run_subdivide(rest, std::cout, std::cerr);
  if (command == "inspect") return sinew::editor::run_inspect(rest, std::cout, std::cerr);
  if (command == "validate") return sinew::editor::run_validate(rest, std::cout, std::cerr);
  if (command == "render") return sinew::editor::run_render(rest, std::cout, std::cerr);
#ifdef SINEW_HAVE_GUI
  return sinew::editor::run_gui(rest, std::cout, std::cerr);
#else
  std::cerr << "sinew-editor: this build has no window (configured with SINEW_BUILD_DISPLAY=OFF)\n";
  return 1;
#endif
}

}  // namespace
