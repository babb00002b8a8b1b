#include "gyrocal/reduce/reducer.hpp"

// Read-ahead: the record's reader on a thread of its own, a few batches of rows ahead of the reducer
// (reduce_record).
#include <condition_variable>
#include <exception>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "gyrocal/core/error.hpp"
#include "gyrocal/reduce/record_summary.hpp"

namespace gyrocal {

namespace {

/// Rows read ahead by the reader's thread: kReadAheadBatches batches of kReadAheadRows rows (5.2 MB).
constexpr std::size_t kReadAheadRows = 8192;
constexpr std::size_t kReadAheadBatches = 4;

/// The reader on a thread of its own, a few batches of rows ahead of the caller's thread (docs/
/// performance.md): parsing and reducing overlap. Rows arrive in the record's order; an error of the reader
/// (gyrocal::Error naming the file and line) is rethrown by next() where its row would have been. The
/// thread parses only: with the accumulation on a third thread, parsing is the longest of the three, so the
/// record's summary and the caller's observer run on the caller's thread (docs/performance.md).
class ReadAhead {
 public:
  explicit ReadAhead(RecordReader& reader) : reader_(reader), batches_(kReadAheadBatches) {
    for (auto& b : batches_) b.rows.resize(kReadAheadRows);
    thread_ = std::thread([this] { produce(); });
  }
  ~ReadAhead() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  /// The next batch of rows (empty at the end of the record); valid until the next call.
  std::span<const RecordSample> next() {
    std::unique_lock<std::mutex> lock(mutex_);
    if (holding_) {  // the caller is done with the batch it held: its slot is free again
      holding_ = false;
      // The rows read before an error went first; the error comes where the next row would have been.
      if (batches_[head_].error) std::rethrow_exception(batches_[head_].error);
      head_ = (head_ + 1) % batches_.size();
      --filled_;
      changed_.notify_all();
    }
    changed_.wait(lock, [&] { return filled_ > 0; });
    Batch& b = batches_[head_];
    if (b.error && b.count == 0) std::rethrow_exception(b.error);
    holding_ = true;
    return {b.rows.data(), b.count};
  }

 private:
  struct Batch {
    std::vector<RecordSample> rows;
    std::size_t count = 0;
    std::exception_ptr error;
  };
  void produce() {
    std::size_t tail = 0;
    bool ended = false;
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [&] { return stop_ || filled_ < batches_.size(); });
        if (stop_) return;
      }
      Batch& b = batches_[tail];
      b.count = 0;
      try {
        while (!ended && b.count < b.rows.size()) {
          if (reader_.next(b.rows[b.count]))
            ++b.count;
          else
            ended = true;
        }
      } catch (...) {
        b.error = std::current_exception();
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++filled_;
      }
      changed_.notify_all();
      // The end of the record is an empty batch (or an error): the consumer stops there.
      if (b.count == 0 || b.error) return;
      tail = (tail + 1) % batches_.size();
    }
  }

  RecordReader& reader_;
  std::vector<Batch> batches_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t head_ = 0, filled_ = 0;
  bool holding_ = false, stop_ = false;
};

/// The one pass of reduce_record and reduce_record_channels: the rows read ahead, summarised, observed and
/// pushed into `reducer`.
void push_record(Reducer& reducer, RecordReader& reader,
                 const std::function<void(std::span<const RecordSample>)>& observe) {
  reducer.set_record_layout(reader.layout());
  if (reader.layout())
    for (const OutputColumn& o : reader.layout()->output_columns())
      if (o.form == OutputForm::kIncrement) reducer.set_increments(true);
  RecordSummary summary;  // of every row read
  ReadAhead ahead(reader);
  for (auto rows = ahead.next(); !rows.empty(); rows = ahead.next()) {
    for (const RecordSample& s : rows) summary.add(s);
    if (observe) observe(rows);
    for (const RecordSample& s : rows) reducer.push_unsummarised(s);
  }
  reducer.set_summary(summary);
}

}  // namespace

Reduction reduce_record(RecordReader& reader, const TestSpec& plan, const ReduceOptions& options,
                        double reference_rate_rad_s,
                        const std::function<void(std::span<const RecordSample>)>& observe) {
  if (reader.output_count() != 1)
    throw Error(fmt::format("{}: it is read with {} output columns; reduce_record_channels reduces them.",
                            reader.name(), reader.output_count()));
  Reducer reducer(PlannedTest{plan, reference_rate_rad_s}, options, reader.name());
  push_record(reducer, reader, observe);
  return reducer.finish();
}

std::vector<Reduction> reduce_record_channels(
    RecordReader& reader, const TestSpec& plan, const ReduceOptions& options, double reference_rate_rad_s,
    const std::function<void(std::span<const RecordSample>)>& observe) {
  Reducer reducer(PlannedTest{plan, reference_rate_rad_s}, options, reader.name());
  std::vector<std::string> names;
  if (reader.layout()) {
    for (const OutputColumn& o : reader.layout()->output_columns()) names.push_back(o.column);
  } else {
    names.push_back(reader.output_column());
  }
  reducer.set_output_columns(names);
  push_record(reducer, reader, observe);
  return reducer.finish_channels();
}

}  // namespace gyrocal
