// How a host runs Sinew's work on its own threads. A pass splits a frame
// into independent tasks (skinning chunks, bone boxes, image tiles) and
// hands each batch to the scheduler: one callback, fork-join. Without a
// scheduler, the pass uses its own TBB task arena (PassDesc::threads).
#pragma once

#include <cstdint>

namespace sinew::api {

// One batch: call task(context, i) once for every i in [0, count), on any
// threads in any order, possibly concurrently, and return when every call
// has returned. Tasks never throw and never block on each other. A task may
// itself submit a batch (nested parallelism): the scheduler may then run
// the inner batch on the calling thread.
using TaskFunction = void (*)(void* context, std::uint32_t index);

struct TaskScheduler {
  // How many tasks the host will run at once: sets how finely work is
  // split (the image and skinning are cut into about 4x this many pieces).
  int concurrency = 1;
  void* user = nullptr;  // passed back to run_batch
  void (*run_batch)(void* user, std::uint32_t count, TaskFunction task, void* context) = nullptr;
};

}  // namespace sinew::api
