// BakeJob: one in-memory fuzzy bake on a worker thread with its own
// JobSystem, so the window keeps drawing (and can cancel) while it runs.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "character/bake.h"
#include "runtime/core/expected.h"

namespace sinew::editor::gui {

class BakeJob {
 public:
  // Starts baking `model` (which must outlive the job) at once.
  BakeJob(const character::Model& model, character::BakeRequest request, int threads);
  ~BakeJob();  // cancels and joins
  BakeJob(const BakeJob&) = delete;
  BakeJob& operator=(const BakeJob&) = delete;

  void cancel() { cancel_.store(true); }
  bool done() const { return done_.load(); }
  double progress() const { return progress_.load(); }
  std::string phase() const;
  // Joins the worker and hands over the result (once; done() must be true).
  Expected<character::InMemoryBake> take();

 private:
  void run(const character::Model& model, character::BakeRequest request, int threads);

  std::atomic<bool> cancel_{false};
  std::atomic<bool> done_{false};
  std::atomic<double> progress_{0.0};
  mutable std::mutex phase_mutex_;
  std::string phase_ = "starting";
  std::optional<Expected<character::InMemoryBake>> result_;
  std::thread worker_;
};

}  // namespace sinew::editor::gui
