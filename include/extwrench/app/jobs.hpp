// Independent jobs (one log's replay, one seed's simulation, one scheme's replay) run on
// several threads: the engine of `--jobs N` in `extwrench estimate` and `simulate`. Each job
// writes only its own files and results, so the outcome does not depend on the number of
// threads; what a job prints is buffered by its caller and printed in `finished`, which comes in
// index order whatever the scheduling.
#pragma once

#include <cstddef>
#include <exception>
#include <functional>
#include <vector>

namespace extwrench {

/// The default number of jobs at once: the number of cores (std::thread::hardware_concurrency),
/// 1 when unknown.
[[nodiscard]] int default_jobs();

/// Whether replays run on `jobs` cores get their own reader and writer threads
/// (ReplayOptions::pipelined): when min(jobs, replays) of them run at once and each has at least
/// two cores. A pipelined replay keeps about 1.8 cores busy; `--jobs N` means N cores, so with
/// fewer than two cores per replay (--jobs 1, or more than jobs / 2 replays) each runs on its
/// own thread alone.
[[nodiscard]] bool replays_pipelined(int jobs, std::size_t replays);

struct JobsOptions {
  int jobs = 1;  ///< threads running jobs at once (≥ 1; 1: in the calling thread, in order)
  /// After a failure, start no job of a higher index (the jobs of lower indices have already
  /// started and finish): the lowest failing index is then the same as in a serial run.
  bool stop_after_failure = false;
};

/// The outcome of each job, by index: null on success, the exception it threw otherwise; a job
/// never started (stop_after_failure) has skipped set.
struct JobOutcomes {
  std::vector<std::exception_ptr> errors;
  std::vector<bool> skipped;
  /// The lowest index that failed, or errors.size() when none did.
  [[nodiscard]] std::size_t first_failure() const;
};

/// Runs job(0) … job(count - 1) on min(jobs, count) threads, handing out indices in increasing
/// order. `finished(i)` (optional) runs in the calling thread once job i and every job before it
/// have ended (or were skipped), in index order. Exceptions of a job are caught and returned;
/// an exception of `finished` is rethrown after every running job has ended. Throws
/// std::invalid_argument for jobs < 1.
JobOutcomes run_jobs(std::size_t count, const std::function<void(std::size_t)>& job,
                     const JobsOptions& options,
                     const std::function<void(std::size_t)>& finished = {});

}  // namespace extwrench
