// The replay's three threads (app/replay.hpp): a reader parses rows into batches of samples, the
// calling thread runs the estimator, a writer formats and writes the estimates. Batches are
// allocated once and recycled (memory does not grow with the log); hand-offs are per batch, not
// per row. Or, when a replay has one core (`--jobs`), the same interface on the calling thread
// alone: a row read, estimated and written after the other. Private to the app library.
#pragma once

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "extwrench/core/error.hpp"
#include "extwrench/core/sample.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/io/log.hpp"

namespace extwrench::detail {

inline constexpr std::size_t kBatches = 4;       // per ring: enough slack for the stages' jitter
inline constexpr std::size_t kBatchRows = 1024;  // rows per hand-off
// The estimating thread is the critical path: when the threads outnumber the free cores, the
// reader and the writer give way to it. Linux keeps a nice value per thread; theirs is raised
// by kHelperNice over the process's (never lowered; a failure only costs speed).
inline constexpr int kHelperNice = 5;

inline void give_way_to_the_estimator() {
  const auto tid = static_cast<id_t>(::gettid());
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, tid);
  if (errno == 0) (void)::setpriority(PRIO_PROCESS, tid, std::min(nice + kHelperNice, 19));
}

/// A bounded ring of batches from one producer thread to one consumer thread, in order.
template <class Item>
class BatchRing {
 public:
  struct Batch {
    std::vector<Item> items;   // kBatchRows slots, reused: their vectors keep their capacity
    std::size_t count = 0;     // items in use
    bool last = false;         // no batch follows (end of input, or the error below)
    std::exception_ptr error;  // the producer's failure, to rethrow after the items
  };

  explicit BatchRing(const Item& prototype) : ring_(kBatches) {
    for (Batch& b : ring_) b.items.assign(kBatchRows, prototype);
  }

  /// Producer: the next batch to fill (emptied), waiting for the consumer to free one;
  /// nullptr once cancelled.
  Batch* acquire_free() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return cancelled_ || produced_ - consumed_ < kBatches; });
    if (cancelled_) return nullptr;
    Batch& b = ring_[produced_ % kBatches];
    b.count = 0;
    b.last = false;
    b.error = nullptr;
    return &b;
  }
  /// Producer: hands the batch acquired last to the consumer.
  void publish() {
    {
      const std::lock_guard lock(mutex_);
      ++produced_;
    }
    changed_.notify_all();
  }
  /// Consumer: the oldest published batch, waiting for one; nullptr once cancelled.
  Batch* acquire_full() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return cancelled_ || consumed_ < produced_; });
    if (cancelled_) return nullptr;
    return &ring_[consumed_ % kBatches];
  }
  /// Consumer: gives the batch acquired last back to the producer.
  void release() {
    {
      const std::lock_guard lock(mutex_);
      ++consumed_;
    }
    changed_.notify_all();
  }
  /// Either side: wakes and stops the other one (it sees nullptr).
  void cancel() {
    {
      const std::lock_guard lock(mutex_);
      cancelled_ = true;
    }
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;  // produced_, consumed_ or cancelled_ changed
  std::vector<Batch> ring_;
  std::size_t produced_ = 0;
  std::size_t consumed_ = 0;
  bool cancelled_ = false;
};

/// A sample as the pipeline hands it out, with what the row hook computed from it (on the reader's
/// thread when threaded: work there is off the estimating thread's critical path).
struct PipelineRow {
  Sample sample;
  double derived = std::numeric_limits<double>::quiet_NaN();  // NaN without a hook
};
using RowHook = std::function<double(const Sample&)>;

/// The reader and writer threads around the estimator loop (`threaded`), or the plain loop
/// without them. Rows come out of next() in log order; a malformed row's error comes out after
/// every row before it, as it would from a plain loop. Estimates go in through push(). The
/// destructor (also on an exception) writes every estimate pushed so far, then stops and joins
/// both threads.
class Pipeline {
 public:
  /// row_hook (may be empty: derived NaN) runs once per row read, on the reader's thread.
  Pipeline(LogReader& reader, EstimatesWriter& writer, const Sample& sample_prototype,
           const ContactEstimate& estimate_prototype, bool threaded, RowHook row_hook = {})
      : row_hook_(std::move(row_hook)) {
    if (!threaded) {
      reader_ = &reader;
      writer_ = &writer;
      row_.sample = sample_prototype;
      return;
    }
    in_.emplace(PipelineRow{sample_prototype});
    out_.emplace(estimate_prototype);
    reader_thread_ = std::thread([this, &reader] { read_rows(reader); });
    try {
      writer_thread_ = std::thread([this, &writer] { write_rows(writer); });
    } catch (...) {
      stop_reader();
      throw;
    }
  }
  ~Pipeline() {
    finish_output();
    stop_reader();
  }
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// The next sample, valid until the following call; nullptr at the end of the log. Rethrows
  /// the reader's error (a malformed row) at its place in the sequence.
  const PipelineRow* next() {
    if (reader_ != nullptr) return read_row(*reader_, row_) ? &row_ : nullptr;
    for (;;) {
      if (in_batch_ == nullptr) {
        in_batch_ = in_->acquire_full();  // the reader is only cancelled by our destructor
        in_index_ = 0;
        if (in_batch_ == nullptr) return nullptr;
      }
      if (in_index_ < in_batch_->count) return &in_batch_->items[in_index_++];
      const bool last = in_batch_->last;
      const std::exception_ptr error = in_batch_->error;
      in_->release();
      in_batch_ = nullptr;
      if (error) fail(error);
      if (last) return nullptr;
    }
  }

  /// Queues an estimate for writing (copied: the estimator overwrites its result).
  void push(const ContactEstimate& e) {
    if (writer_ != nullptr) return writer_->write(e);
    if (out_batch_ == nullptr) {
      out_batch_ = out_->acquire_free();
      if (out_batch_ == nullptr) fail(nullptr);  // the writer failed
    }
    out_batch_->items[out_batch_->count++] = e;
    if (out_batch_->count == kBatchRows) {
      out_->publish();
      out_batch_ = nullptr;
    }
  }

  /// Writes every estimate pushed, then joins the writer; rethrows its error (disk full...).
  void finish() {
    finish_output();
    if (write_error_) std::rethrow_exception(write_error_);
  }

 private:
  bool read_row(LogReader& reader, PipelineRow& row) const {
    if (!reader.next(row.sample)) return false;
    row.derived = row_hook_ ? row_hook_(row.sample) : std::numeric_limits<double>::quiet_NaN();
    return true;
  }

  void read_rows(LogReader& reader) {
    give_way_to_the_estimator();
    for (;;) {
      auto* b = in_->acquire_free();
      if (b == nullptr) return;  // cancelled: the consumer has stopped
      try {
        while (b->count < kBatchRows) {
          if (!read_row(reader, b->items[b->count])) {
            b->last = true;
            break;
          }
          ++b->count;
        }
      } catch (...) {
        b->error = std::current_exception();
        b->last = true;
      }
      const bool last = b->last;
      in_->publish();
      if (last) return;
    }
  }

  void write_rows(EstimatesWriter& writer) {
    give_way_to_the_estimator();
    try {
      for (;;) {
        auto* b = out_->acquire_full();
        if (b == nullptr) return;
        for (std::size_t k = 0; k < b->count; ++k) writer.write(b->items[k]);
        const bool last = b->last;
        out_->release();
        if (last) return;
      }
    } catch (...) {
      write_error_ = std::current_exception();  // read by the main thread after join()
      out_->cancel();
    }
  }

  // A failure while estimates are still queued: those rows are written first, and an earlier
  // write failure takes precedence (in a plain loop it would have been thrown first).
  [[noreturn]] void fail(const std::exception_ptr& error) {
    finish_output();
    if (write_error_) std::rethrow_exception(write_error_);
    if (error) std::rethrow_exception(error);
    throw Error("replay: internal error: the writer stopped without an error");
  }

  void finish_output() {
    if (!writer_thread_.joinable()) return;
    if (out_batch_ == nullptr) out_batch_ = out_->acquire_free();  // nullptr if the writer failed
    if (out_batch_ != nullptr) {
      out_batch_->last = true;
      out_->publish();
      out_batch_ = nullptr;
    }
    writer_thread_.join();
  }

  void stop_reader() {
    if (!reader_thread_.joinable()) return;
    in_->cancel();
    reader_thread_.join();
  }

  RowHook row_hook_;
  std::optional<BatchRing<PipelineRow>> in_;  // threaded only
  std::optional<BatchRing<ContactEstimate>> out_;
  typename BatchRing<PipelineRow>::Batch* in_batch_ = nullptr;
  std::size_t in_index_ = 0;
  typename BatchRing<ContactEstimate>::Batch* out_batch_ = nullptr;
  std::exception_ptr write_error_;
  std::thread reader_thread_;
  std::thread writer_thread_;
  // The plain loop (not threaded): reads into row_, writes directly.
  LogReader* reader_ = nullptr;
  EstimatesWriter* writer_ = nullptr;
  PipelineRow row_;
};

}  // namespace extwrench::detail
