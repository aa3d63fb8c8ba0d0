#include "extwrench/app/jobs.hpp"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace extwrench {

int default_jobs() {
  const unsigned cores = std::thread::hardware_concurrency();
  return cores == 0 ? 1 : static_cast<int>(std::min(cores, 1024u));
}

bool replays_pipelined(int jobs, std::size_t replays) {
  if (jobs < 2 || replays == 0) return false;
  const auto cores = static_cast<std::size_t>(jobs);
  return cores >= 2 * std::min(cores, replays);
}

std::size_t JobOutcomes::first_failure() const {
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (errors[i]) return i;
  return errors.size();
}

namespace {

// The shared state of one run_jobs call: the next index to hand out and which jobs have ended.
struct JobBoard {
  std::mutex mutex;
  std::condition_variable ended;  // a job ended
  std::size_t next = 0;
  std::size_t stop_at;  // no index >= stop_at is handed out (a failure, stop_after_failure)
  std::vector<bool> started;
  std::vector<bool> done;
};

void work(JobBoard& board, JobOutcomes& out, const std::function<void(std::size_t)>& job,
          bool stop_after_failure) {
  for (;;) {
    std::size_t i = 0;
    {
      const std::lock_guard lock(board.mutex);
      if (board.next >= board.stop_at) return;
      i = board.next++;
      board.started[i] = true;
    }
    std::exception_ptr error;
    try {
      job(i);
    } catch (...) {
      error = std::current_exception();
    }
    {
      const std::lock_guard lock(board.mutex);
      out.errors[i] = error;
      board.done[i] = true;
      if (error && stop_after_failure) board.stop_at = std::min(board.stop_at, i + 1);
    }
    board.ended.notify_all();
  }
}

}  // namespace

JobOutcomes run_jobs(std::size_t count, const std::function<void(std::size_t)>& job,
                     const JobsOptions& options, const std::function<void(std::size_t)>& finished) {
  if (options.jobs < 1) throw std::invalid_argument("run_jobs: jobs must be at least 1");
  JobOutcomes out;
  out.errors.assign(count, nullptr);
  out.skipped.assign(count, false);
  JobBoard board;
  board.stop_at = count;
  board.started.assign(count, false);
  board.done.assign(count, false);
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(options.jobs), count);
  if (threads <= 1) {  // in the calling thread: a serial run is exactly a plain loop
    work(board, out, job, options.stop_after_failure);
  }
  std::vector<std::jthread> pool;
  pool.reserve(threads > 1 ? threads : 0);
  for (std::size_t t = 0; threads > 1 && t < threads; ++t)
    pool.emplace_back([&] { work(board, out, job, options.stop_after_failure); });
  std::exception_ptr finished_error;
  for (std::size_t i = 0; i < count; ++i) {
    {
      std::unique_lock lock(board.mutex);
      // Not started and past stop_at: it never will be (indices below stop_at only are handed out).
      const auto never = [&] { return !board.started[i] && i >= board.stop_at; };
      board.ended.wait(lock, [&] { return board.done[i] || never(); });
      if (!board.done[i]) out.skipped[i] = true;
    }
    if (finished && !finished_error) {
      try {
        finished(i);
      } catch (...) {
        finished_error = std::current_exception();
      }
    }
  }
  pool.clear();  // joins
  if (finished_error) std::rethrow_exception(finished_error);
  return out;
}

}  // namespace extwrench
