#include "editor/gui/bake_job.h"

#include "runtime/jobs/job_system.h"

namespace sinew::editor::gui {

BakeJob::BakeJob(const character::Model& model, character::BakeRequest request, int threads) {
  worker_ = std::thread([this, &model, request = std::move(request), threads]() mutable {
    run(model, std::move(request), threads);
  });
}

BakeJob::~BakeJob() {
  cancel();
  if (worker_.joinable()) worker_.join();
}

void BakeJob::run(const character::Model& model, character::BakeRequest request, int threads) {
  request.fuzzy.progress = [this](std::string_view phase, double fraction) {
    progress_.store(fraction);
    {
      std::lock_guard<std::mutex> lock(phase_mutex_);
      phase_ = std::string(phase);
    }
    return !cancel_.load();
  };
  JobSystem jobs(threads);  // its own pool: the viewport's keeps rendering meanwhile
  Expected<character::InMemoryBake> baked = character::bake_in_memory(model, request, jobs);
  // Pose sampling runs before the fuzzy bake reports progress, so a cancel
  // that arrives then is honoured here.
  if (baked.ok() && cancel_.load()) {
    baked = make_error(ErrorCode::kCancelled, "", "bake", "cancelled", "cancelled by the user");
  }
  result_.emplace(std::move(baked));
  done_.store(true);
}

std::string BakeJob::phase() const {
  std::lock_guard<std::mutex> lock(phase_mutex_);
  return phase_;
}

Expected<character::InMemoryBake> BakeJob::take() {
  if (worker_.joinable()) worker_.join();
  if (!result_) return make_error(ErrorCode::kInternal, "", "bake", "none", "the bake result was already taken");
  Expected<character::InMemoryBake> out = std::move(*result_);
  result_.reset();
  return out;
}

}  // namespace sinew::editor::gui
