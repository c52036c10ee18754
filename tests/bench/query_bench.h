// sinew-bench queries: gameplay queries in a crowd. Every tick poses every
// instance of a grid of characters and traces a batch of seeded random
// rays through the public API (World::intersect over a span: lazy
// skinning, only the instances the rays reach are skinned), and the same
// rays through an Embree peer that skins every instance and refits or
// rebuilds its BVH (embree_crowd.h). Both answer every checked ray as
// brute force does, or the run fails.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// `args` are the arguments after "queries"; returns 0, 1 (a failure, or an
// answer that differs from brute force) or 2 (usage error).
int run_query_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench
