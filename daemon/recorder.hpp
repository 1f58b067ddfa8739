#pragma once
// Recording of samples to CSV files that `gyroctl analyze` reads. The lines are
// formats/recording_format.hpp's (docs/recording-format.md): the column line first,
// "t,gx,gy,gz,temp" (s, °/s, °/s, °/s, °C) then the optional columns the options and the
// samples ask for (time; ax,ay,az; the rate stream), one line per sample with every value in
// its shortest round-trip form (reads back bit-exact), and '#' comment lines for the rest:
//   # GAP seq=123 t=2.46 count=4 reason=fifo_overflow     samples the device lost
//   # DROPPED count=7 reason=ring_full                     samples the recorder lost:
//                                                          ring_full (the writer fell behind),
//                                                          disk_full (ENOSPC, EDQUOT) or
//                                                          write_error (any other failed write)
// A loss to a failed write is announced by a DROPPED line at the next write that succeeds
// (in the same file, or the next one after a rotation); while the disk stays full no line
// can say so, and the counts (stats(), STATUS "recorder", the shutdown line) do.
//
// Whether a file has ax,ay,az is decided by the first sample pushed (accel or not: the
// device's FIFO either carries it or not), so the column line, and with it the header, is
// written with the first lines of the file, not when the file is created. Until a first
// sample comes, GAP and DROPPED lines wait in memory.
// This file owns the ring, the writer thread, the files and their rotation.
//
// The event loop pushes fixed-size records into a preallocated single-producer /
// single-consumer ring: no allocation, no lock, no system call; a full ring drops the
// record and counts it. A writer thread wakes every flush interval, formats what is in
// the ring and write()s it.
//
// Durability policy:
//  - write(2) at every flush interval: what was written survives a crash of gyrod (even
//    kill -9), since it is in the kernel's page cache. So a crash loses at most the
//    records pushed since the last completed flush.
//  - fdatasync(2) when a file is closed (rotation, stop), and at every flush when
//    fsync_each_flush is set; otherwise a power cut may also lose what the kernel had not
//    yet written back (typically up to 30 s).
//  - Files end with whole lines after a kill -9: a line never crosses a page boundary of
//    the file (padding lines "#   ...   " fill the rest of a page when the next line does
//    not fit), and each write() covers at most one page. Linux checks for a fatal signal
//    only between the pages of a write, so each write() lands whole or not at all. The
//    padding is an ordinary '#' comment (a lone '\n' when one byte is left), which numpy's
//    genfromtxt(comments='#') and pandas' read_csv(comment='#') skip.
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "daemon/config.hpp"
#include "daemon/spsc_ring.hpp"
#include "formats/recording_format.hpp"

namespace gyrod::daemon {

class RecorderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The base name used inside a folder given as the recording path.
inline constexpr const char* kDefaultRecordingName = "gyro.csv";

struct RecorderOptions {
  // Base name dir/stem.ext. Files are dir/stem-YYYYmmddTHHMMSSZ-NNNNNN.ext (UTC time of
  // opening, then an index that makes the name unique), so name order is creation order.
  // An existing folder records into it: folder/gyro-YYYYmmddTHHMMSSZ-NNNNNN.csv.
  std::string path;
  std::size_t ring_capacity = 4096;  // records; rounded up to a power of two
  std::uint64_t rotate_bytes = 0;    // new file before one would exceed this size; 0 = never
  double rotate_after_s = 0.0;       // new file at the first flush this long after opening; 0 = never
  double flush_interval_s = 1.0;     // > 0
  bool fsync_each_flush = false;
  std::size_t keep = 0;                      // files of this base name to keep (oldest deleted); 0 = all
  std::vector<std::string> header_comments;  // written as "# ..." lines after the column line of each file
  // The `time`, rate-stream and attitude columns (formats/recording_format.hpp); `accel` is
  // ignored: ax,ay,az are there when the first sample has accel; the attitude columns, when
  // `attitude` is set and the first sample has an orientation.
  recording::SampleColumns columns;
};

// Options for [record]: sizes converted, ring sized for 4 flush intervals at rate_hz
// (at least 1024 records, at most 2^18).
RecorderOptions recorderOptions(const RecordConfig& config, double rate_hz);

struct RecorderStats {
  std::uint64_t pushed = 0;          // records accepted into the ring
  std::uint64_t dropped = 0;         // records refused because the ring was full
  std::uint64_t written = 0;         // records whose lines write() has accepted
  std::uint64_t lost_to_errors = 0;  // records whose lines could not be written (disk full, I/O error)
  std::uint64_t lost_announced = 0;  // of those, announced by a DROPPED line now in a file
  std::uint64_t write_errors = 0;    // failed write()/open() calls
  std::uint64_t flushes = 0;         // completed flushes
  std::uint64_t files_opened = 0;
};

// One ring slot. Plain data, fixed size.
struct RecorderRecord {
  enum class Kind : std::uint8_t { Sample, Gap };
  Kind kind = Kind::Sample;
  std::uint32_t gap_count = 0;       // Gap: samples missing
  std::uint64_t dropped_before = 0;  // records dropped (ring full) just before this one
  std::uint64_t gap_seq = 0;         // Gap: sequence number of the first missing sample
  recording::SampleValues sample;    // Sample: its values; Gap: sample.t_s is the first missing sample's time
  char gap_reason[24] = {};          // Gap: NUL-terminated (truncated) reason token
};

class Recorder {
 public:
  // Opens the first file (header written) and starts the writer thread.
  // Throws RecorderError naming the path when the file cannot be created, and
  // std::invalid_argument for bad options.
  explicit Recorder(RecorderOptions options);
  ~Recorder();  // stop()
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Producer side: call from one thread only (the event loop). Wait-free: no allocation,
  // no lock, no system call. False when the ring is full (counted in stats().dropped).
  bool pushSample(const recording::SampleValues& sample) noexcept;
  // A sample of t,gx,gy,gz,temp alone (no time, accel or rate values).
  bool pushSample(double t_s, double gx_dps, double gy_dps, double gz_dps, double temp_c) noexcept;
  // A gap of `count` samples starting at sequence number `seq` (time t_s of the first
  // missing sample); `reason` is a short token such as "fifo_overflow" (characters other
  // than [A-Za-z0-9_.-] become '_', longer than 23 characters is truncated).
  bool pushGap(std::uint64_t seq, double t_s, std::uint32_t count, std::string_view reason) noexcept;

  // Blocks until the writer has written everything pushed before the call (GAP lines before
  // the first sample excepted: they wait for it, see above). Not for the event loop (it waits
  // for disk I/O); for shutdown paths and tests.
  void flush();
  // Writes what is left (and a final DROPPED line if records were dropped since the
  // last pushed record), fdatasyncs and closes the file, joins the writer. Idempotent.
  // Call it from the producer thread, or after the producer has stopped pushing.
  void stop();

  RecorderStats stats() const noexcept;  // any thread
  std::string currentFile() const;       // any thread
  // The last failed write, open or sync: "write to FILE: No space left on device"; empty if
  // none failed. Any thread.
  std::string lastError() const;
  // Recording files of this base name in its directory, oldest first.
  std::vector<std::string> files() const;

 private:
  // Producer side: into the ring, or counted as dropped.
  bool pushRecord(const RecorderRecord& r) noexcept;
  void writerLoop();
  void flushOnce(bool final_flush);
  // `announces_lost` / `announces_drops`: records lost to write errors / dropped from a full
  // ring that this DROPPED line announces, counted as announced once the line is written.
  void appendLine(std::string_view line, bool is_record, std::uint64_t announces_lost = 0,
                  std::uint64_t announces_drops = 0);
  void announceLosses(recording::RecordingLine& line);
  std::string headerText() const;
  void writePending();
  void emitPage();
  void clearPage();
  bool openNextFile(const std::string& previous_name);
  void closeFile();
  void pruneOldFiles();
  void reportError(const std::string& what, int error_number);

  RecorderOptions options_;
  std::string directory_, stem_, extension_;
  std::size_t page_size_ = 4096;
  SpscRing<RecorderRecord> ring_;

  // Producer-side state.
  std::uint64_t pending_drops_ = 0;
  std::atomic<std::uint64_t> pushed_{0}, dropped_{0};

  // Writer-side state (writer thread, and the constructor/stop() before/after it runs).
  int fd_ = -1;
  std::uint64_t file_bytes_ = 0;     // bytes in the current file (written)
  std::uint64_t file_records_ = 0;   // sample/gap lines in the current file
  std::int64_t file_opened_ns_ = 0;  // steady clock
  std::uint64_t next_index_ = 0;
  std::int64_t file_opened_unix_s_ = 0;  // for the header's "opened" comment
  std::string previous_file_;            // for the header's "continues" comment
  // The file's columns: `accel` and `attitude` from the first sample; until then none is written.
  recording::SampleColumns columns_;
  bool columns_known_ = false;
  std::uint64_t drops_reported_ = 0;         // dropped records announced (or in lines on their way to a file)
  std::uint64_t drops_unwritten_ = 0;        // of those, announced in a page whose write failed: to announce again
  const char* loss_reason_ = "write_error";  // the cause of the last failed write (a DROPPED reason)
  // Lines formatted but not yet written; padding and rotation are decided when they are
  // written, since both depend on the position in the file.
  std::string pending_;
  struct PendingLine {
    std::size_t end;  // offset in pending_ just past the line's '\n'
    bool record;      // a sample or gap (counted), not a comment
    std::uint64_t announces_lost;
    std::uint64_t announces_drops;
  };
  std::vector<PendingLine> pending_lines_;
  std::string page_;                // bytes for the current page of the file, not yet written
  std::uint64_t page_records_ = 0;  // records in page_
  std::uint64_t page_announces_lost_ = 0, page_announces_drops_ = 0;  // DROPPED counts in page_
  bool in_error_ = false;                                             // last write failed (log once per episode)
  std::atomic<std::uint64_t> written_{0}, lost_{0}, write_errors_{0}, flushes_{0}, files_opened_{0};
  std::atomic<std::uint64_t> lost_announced_count_{0};

  mutable std::mutex file_mutex_;  // guards current_file_ and last_error_
  std::string current_file_;
  std::string last_error_;

  std::mutex wake_mutex_;
  std::condition_variable wake_;
  std::condition_variable flushed_;
  bool stopping_ = false;
  std::uint64_t flush_requests_ = 0, flushes_done_ = 0;
  bool stopped_ = false;
  std::thread writer_;
};

// "gyro-20250101T120000Z-000000.csv" for stem "gyro", extension ".csv".
std::string recordingFileName(std::string_view stem, std::string_view extension, std::int64_t unix_seconds,
                              std::uint64_t index);
// True when `name` has the form recordingFileName(stem, extension, ...) gives.
bool isRecordingFileName(std::string_view name, std::string_view stem, std::string_view extension);

}  // namespace gyrod::daemon
