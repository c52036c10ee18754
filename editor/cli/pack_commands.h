// `sinew-editor bake`, `inspect` and `validate`: content packs from the
// command line. Each takes its arguments and two streams and returns the
// exit code (0 success, 1 a user error with one clear message, 2 a usage
// error), so the tests run them in-process.
//
//   bake MODEL -o OUT.pack [--pose-space arbitrary|limits|clips|clip:NAME]
//        [--clips a,b,c] [--samples N] [--seed S] [--limits FILE.json]
//        [--pad FRACTION] [--candidates all|influencing] [--rigid-bones merge|keep] [--threads N]
//   subdivide MODEL --levels L -o OUT.pack
//   inspect PACK [--json]
//   validate PACK
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace sinew::editor {

int run_bake(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int run_subdivide(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int run_inspect(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
int run_validate(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace sinew::editor
