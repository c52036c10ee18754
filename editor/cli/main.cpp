// sinew-editor: the offline tool. `sinew-editor <command> [args]`; each
// command is a function taking its arguments and two streams and returning
// the exit code (0 success, 1 user error, 2 usage error), so tests run them
// in-process.
#include <iostream>
#include <string>
#include <vector>

#include "editor/cli/render_command.h"

namespace {

const char* const kUsage =
    "usage: sinew-editor <command> [args]   (sinew-editor <command> --help for its options)\n";

void print_help(std::ostream& out) {
  out << kUsage
      << "\ncommands:\n"
         "  render   import, bake in memory, pose with one clip and ray trace a model\n";
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    std::cerr << "sinew-editor: missing command\n" << kUsage;
    return 2;
  }
  const std::string& command = args.front();
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (command == "--help" || command == "-h" || command == "help") {
    print_help(std::cout);
    return 0;
  }
  if (command == "render") return sinew::editor::run_render(rest, std::cout, std::cerr);
  std::cerr << "sinew-editor: unknown command '" << command << "'\n" << kUsage;
  return 2;
}
