#include "daemon/recorder.hpp"

#include <pthread.h>
#include <sched.h>

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <new>
#include <tuple>

#include "formats/recording_format.hpp"

namespace gyrod::daemon {
namespace {

namespace fs = std::filesystem;

// Header and a first line (a RecordingLine) fit in one page of any size (≥ 4096): written in one write().
// A calibration state the rate stream started from takes about 1.2 KiB of it.
constexpr std::size_t kMaxHeaderBytes = 4096 - std::tuple_size_v<decltype(recording::RecordingLine::bytes)>;

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string utcStamp(std::int64_t unix_seconds, const char* format) {
  const std::tm tm = recording::utcCalendarTime(unix_seconds);
  char buf[32];
  const auto n = std::strftime(buf, sizeof buf, format, &tm);
  return std::string(buf, n);
}

std::int64_t unixNow() {
  return std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool allDigits(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

std::string recordingFileName(std::string_view stem, std::string_view extension, std::int64_t unix_seconds,
                              std::uint64_t index) {
  char idx[32];
  std::snprintf(idx, sizeof idx, "%06llu", static_cast<unsigned long long>(index));
  return std::string(stem) + "-" + utcStamp(unix_seconds, "%Y%m%dT%H%M%SZ") + "-" + idx + std::string(extension);
}

bool isRecordingFileName(std::string_view name, std::string_view stem, std::string_view extension) {
  // stem "-" YYYYmmdd "T" HHMMSS "Z-" index(≥ 6 digits) extension
  if (name.size() < stem.size() + 1 + 16 + 1 + 6 + extension.size()) return false;
  if (name.substr(0, stem.size()) != stem || name[stem.size()] != '-') return false;
  if (name.substr(name.size() - extension.size()) != extension) return false;
  const auto middle = name.substr(stem.size() + 1, name.size() - stem.size() - 1 - extension.size());
  return allDigits(middle.substr(0, 8)) && middle[8] == 'T' && allDigits(middle.substr(9, 6)) &&
         middle.substr(15, 2) == "Z-" && middle.size() >= 17 + 6 && allDigits(middle.substr(17));
}

RecorderOptions recorderOptions(const RecordConfig& c, double rate_hz) {
  RecorderOptions o;
  o.path = c.path;
  o.rotate_bytes = static_cast<std::uint64_t>(std::llround(c.rotate_mb * 1e6));
  o.rotate_after_s = c.rotate_minutes * 60.0;
  o.flush_interval_s = c.flush_interval_s;
  o.fsync_each_flush = c.fsync_each_flush;
  o.keep = c.keep;
  const double wanted = 4.0 * rate_hz * c.flush_interval_s;
  o.ring_capacity = static_cast<std::size_t>(std::clamp(wanted, 1024.0, static_cast<double>(1u << 18)));
  return o;
}

Recorder::Recorder(RecorderOptions options) : options_(std::move(options)), ring_(options_.ring_capacity) {
  if (options_.path.empty()) throw std::invalid_argument("Recorder: path is empty");
  if (!(options_.flush_interval_s > 0.0) || !std::isfinite(options_.flush_interval_s))
    throw std::invalid_argument("Recorder: flush_interval_s must be > 0 (got " +
                                std::to_string(options_.flush_interval_s) + ")");
  if (!(options_.rotate_after_s >= 0.0)) throw std::invalid_argument("Recorder: rotate_after_s must be ≥ 0");
  recording::SampleColumns all_columns = options_.columns;
  all_columns.accel = true;
  all_columns.attitude = true;
  std::size_t header_bytes = recording::columnsLine(all_columns).size() + 128;
  for (const auto& c : options_.header_comments) {
    if (c.find('\n') != std::string::npos) throw std::invalid_argument("Recorder: a header comment contains a newline");
    header_bytes += c.size() + 3;
  }
  if (header_bytes > kMaxHeaderBytes)
    throw std::invalid_argument("Recorder: header comments too long (" + std::to_string(header_bytes) +
                                " bytes, at most " + std::to_string(kMaxHeaderBytes) + ")");

  std::error_code ec;
  const fs::path p =
      fs::is_directory(options_.path, ec) ? fs::path(options_.path) / kDefaultRecordingName : fs::path(options_.path);
  directory_ = p.has_parent_path() ? p.parent_path().string() : ".";
  stem_ = p.stem().string();
  extension_ = p.extension().string();
  if (stem_.empty() || stem_ == "." || stem_ == "..")
    throw std::invalid_argument("Recorder: path '" + options_.path + "' does not name a file");
  const long page = sysconf(_SC_PAGESIZE);
  page_size_ = page > 0 ? static_cast<std::size_t>(page) : 4096;
  pending_.reserve(1 << 16);
  page_.reserve(page_size_);

  if (!openNextFile({})) {
    throw RecorderError(options_.path + ": cannot create recording file in " + directory_ + ": " +
                        std::strerror(errno));
  }
  columns_ = options_.columns;
  columns_.accel = false;
  columns_.attitude = false;
  in_error_ = false;
  writer_ = std::thread([this] { writerLoop(); });
}

Recorder::~Recorder() { stop(); }

bool Recorder::pushSample(const recording::SampleValues& sample) noexcept {
  RecorderRecord r;
  r.kind = RecorderRecord::Kind::Sample;
  r.dropped_before = pending_drops_;
  r.sample = sample;
  return pushRecord(r);
}

bool Recorder::pushSample(double t_s, double gx_dps, double gy_dps, double gz_dps, double temp_c) noexcept {
  recording::SampleValues v;
  v.t_s = t_s;
  v.gx_dps = gx_dps;
  v.gy_dps = gy_dps;
  v.gz_dps = gz_dps;
  v.temp_c = temp_c;
  return pushSample(v);
}

bool Recorder::pushRecord(const RecorderRecord& r) noexcept {
  if (!ring_.tryPush(r)) {
    ++pending_drops_;
    dropped_.store(dropped_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    return false;
  }
  pending_drops_ = 0;
  pushed_.store(pushed_.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  return true;
}

bool Recorder::pushGap(std::uint64_t seq, double t_s, std::uint32_t count, std::string_view reason) noexcept {
  RecorderRecord r;
  r.kind = RecorderRecord::Kind::Gap;
  r.dropped_before = pending_drops_;
  r.gap_seq = seq;
  r.gap_count = count;
  r.sample.t_s = t_s;
  const std::size_t n = std::min(reason.size(), sizeof r.gap_reason - 1);
  for (std::size_t i = 0; i < n; ++i) r.gap_reason[i] = recording::reasonCharacter(reason[i]);
  r.gap_reason[n] = '\0';
  return pushRecord(r);
}

void Recorder::flush() {
  std::unique_lock lock(wake_mutex_);
  if (stopping_) return;
  const auto ticket = ++flush_requests_;
  wake_.notify_all();
  flushed_.wait(lock, [&] { return flushes_done_ >= ticket || stopping_; });
}

void Recorder::stop() {
  {
    std::lock_guard lock(wake_mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  flushed_.notify_all();
  if (writer_.joinable()) writer_.join();
  // The writer has exited: this thread owns the writer-side state now.
  flushOnce(true);
  closeFile();
}

RecorderStats Recorder::stats() const noexcept {
  RecorderStats s;
  s.pushed = pushed_.load(std::memory_order_relaxed);
  s.dropped = dropped_.load(std::memory_order_relaxed);
  s.written = written_.load(std::memory_order_acquire);
  s.lost_to_errors = lost_.load(std::memory_order_relaxed);
  s.lost_announced = lost_announced_count_.load(std::memory_order_relaxed);
  s.write_errors = write_errors_.load(std::memory_order_relaxed);
  s.flushes = flushes_.load(std::memory_order_acquire);
  s.files_opened = files_opened_.load(std::memory_order_relaxed);
  return s;
}

std::string Recorder::currentFile() const {
  std::lock_guard lock(file_mutex_);
  return current_file_;
}

std::string Recorder::lastError() const {
  std::lock_guard lock(file_mutex_);
  return last_error_;
}

std::vector<std::string> Recorder::files() const {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(directory_, ec)) {
    const auto name = entry.path().filename().string();
    if (isRecordingFileName(name, stem_, extension_)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::vector<std::string> paths;
  paths.reserve(names.size());
  for (const auto& n : names) paths.push_back((fs::path(directory_) / n).string());
  return paths;
}

void Recorder::writerLoop() {
  // gyrod's event loop may run SCHED_FIFO (systemd/gyrod.service.in); this thread inherits
  // the policy, and formatting and writing lines must never compete with the loop for a CPU.
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  const auto interval = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(options_.flush_interval_s));
  auto next = std::chrono::steady_clock::now() + interval;
  std::unique_lock lock(wake_mutex_);
  while (true) {
    wake_.wait_until(lock, next, [&] { return stopping_ || flush_requests_ != flushes_done_; });
    if (stopping_) break;
    const auto requested = flush_requests_;
    lock.unlock();
    try {
      flushOnce(false);
    } catch (const std::bad_alloc&) {  // formatting grows pending_: those lines are lost, counted
      for (const auto& l : pending_lines_) lost_.fetch_add(l.record ? 1 : 0, std::memory_order_relaxed);
      pending_.clear();
      pending_lines_.clear();
      reportError("format lines", ENOMEM);
    }
    lock.lock();
    flushes_done_ = requested;
    flushed_.notify_all();
    const auto now = std::chrono::steady_clock::now();
    if (now >= next) next = now + interval;
  }
}

void Recorder::flushOnce(bool final_flush) {
  if (!final_flush && options_.rotate_after_s > 0.0 && fd_ >= 0 && file_records_ > 0 &&
      static_cast<double>(steadyNowNs() - file_opened_ns_) >= options_.rotate_after_s * 1e9) {
    const auto previous = fs::path(currentFile()).filename().string();
    closeFile();
    openNextFile(previous);
  }

  recording::RecordingLine line;
  announceLosses(line);
  RecorderRecord r;
  const auto dropLine = [&](std::uint64_t count) {
    appendLine(recording::formatDroppedLine(line, count, "ring_full"), false, 0, count);
    drops_reported_ += count;
  };
  while (ring_.tryPop(r)) {
    if (r.dropped_before > 0) dropLine(r.dropped_before);
    if (r.kind == RecorderRecord::Kind::Gap) {
      appendLine(recording::formatGapLine(line, r.gap_seq, r.sample.t_s, r.gap_count, std::string_view(r.gap_reason)),
                 true);
      continue;
    }
    if (!columns_known_) {  // the first sample: does the device give accel, the stream an orientation?
      const auto& a = r.sample.accel_g;
      columns_.accel = std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
      columns_.attitude = options_.columns.attitude && std::isfinite(r.sample.attitude[0]);
      columns_known_ = true;
    }
    appendLine(recording::formatSampleLine(line, columns_, r.sample), true);
  }
  if (final_flush) {
    const auto unreported = dropped_.load(std::memory_order_relaxed) - drops_reported_;
    if (unreported > 0) dropLine(unreported);
    columns_known_ = true;  // no sample came: the file says so with the columns it would have had
  }
  if (!columns_known_) {  // GAP/DROPPED lines before the first sample wait for the column line
    flushes_.fetch_add(1, std::memory_order_release);
    return;
  }
  writePending();
  if (final_flush && fd_ >= 0 && file_bytes_ == 0) {  // a file without a sample still says what it is
    page_ = headerText();
    emitPage();
  }
  if (options_.fsync_each_flush && fd_ >= 0 && ::fdatasync(fd_) != 0) reportError("fdatasync", errno);
  flushes_.fetch_add(1, std::memory_order_release);
}

void Recorder::appendLine(std::string_view line, bool is_record, std::uint64_t announces_lost,
                          std::uint64_t announces_drops) {
  pending_.append(line);
  pending_lines_.push_back({pending_.size(), is_record, announces_lost, announces_drops});
}

// Losses whose DROPPED line is not in a file yet: records a failed write lost, and ring drops
// announced in a page whose write failed. First in the flush, so the line sits where the
// hole in t begins to show (or just after, when the file changed).
void Recorder::announceLosses(recording::RecordingLine& line) {
  const auto lost = lost_.load(std::memory_order_relaxed) - lost_announced_count_.load(std::memory_order_relaxed);
  if (lost > 0) appendLine(recording::formatDroppedLine(line, lost, loss_reason_), false, lost, 0);
  if (drops_unwritten_ > 0) {
    appendLine(recording::formatDroppedLine(line, drops_unwritten_, "ring_full"), false, 0, drops_unwritten_);
    drops_unwritten_ = 0;
  }
}

void Recorder::writePending() {
  std::size_t begin = 0;
  for (std::size_t i = 0; i < pending_lines_.size(); ++i) {
    const auto [line_end, record, announces_lost, announces_drops] = pending_lines_[i];
    const std::string_view line(pending_.data() + begin, line_end - begin);
    begin = line_end;
    if (fd_ < 0 && !openNextFile({})) {
      // No file to write to (e.g. the directory was removed): these lines are lost.
      for (std::size_t j = i; j < pending_lines_.size(); ++j) {
        if (pending_lines_[j].record) lost_.fetch_add(1, std::memory_order_relaxed);
        drops_unwritten_ += pending_lines_[j].announces_drops;
      }
      break;
    }
    if (options_.rotate_bytes > 0 && file_records_ + page_records_ > 0 &&
        file_bytes_ + page_.size() + line.size() > options_.rotate_bytes) {
      emitPage();
      const auto previous = fs::path(currentFile()).filename().string();
      closeFile();
      if (!openNextFile(previous)) {
        --i;  // retried (and counted as lost) at the top of the loop
        begin -= line.size();
        continue;
      }
    }
    // The header goes with the first lines of a file, in the same write (it is shorter than
    // kMaxHeaderBytes, far less than a page, so header and line fit in page 0).
    if (file_bytes_ == 0 && page_.empty()) page_ = headerText();
    // Keep every line inside one page of the file: pad the rest of the page if it does
    // not fit. Padding is a comment line ("#" and spaces) or, for one byte, an empty line.
    const std::size_t room = page_size_ - static_cast<std::size_t>((file_bytes_ + page_.size()) % page_size_);
    if (line.size() > room) {
      if (room == 1) {
        page_.push_back('\n');
      } else {
        page_.push_back('#');
        page_.append(room - 2, ' ');
        page_.push_back('\n');
      }
      emitPage();
    }
    page_.append(line);
    if (record) ++page_records_;
    page_announces_lost_ += announces_lost;
    page_announces_drops_ += announces_drops;
    if ((file_bytes_ + page_.size()) % page_size_ == 0) emitPage();
  }
  emitPage();
  pending_.clear();
  pending_lines_.clear();
}

// Writes page_, which lies within one page of the file, in one write() where possible.
void Recorder::emitPage() {
  if (page_.empty()) return;
  if (fd_ < 0) {
    lost_.fetch_add(page_records_, std::memory_order_relaxed);
    drops_unwritten_ += page_announces_drops_;
  } else {
    std::size_t done = 0;
    while (done < page_.size()) {
      const ssize_t n = ::write(fd_, page_.data() + done, page_.size() - done);
      if (n > 0) {
        done += static_cast<std::size_t>(n);
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      const int error_number = n < 0 ? errno : EIO;
      // Take back a partial page so the file still ends with a whole line.
      if (done > 0 && ::ftruncate(fd_, static_cast<off_t>(file_bytes_)) == 0)
        ::lseek(fd_, static_cast<off_t>(file_bytes_), SEEK_SET);
      reportError("write to " + currentFile(), error_number);
      lost_.fetch_add(page_records_, std::memory_order_relaxed);
      drops_unwritten_ += page_announces_drops_;
      clearPage();
      return;
    }
    file_bytes_ += page_.size();
    file_records_ += page_records_;
    lost_announced_count_.fetch_add(page_announces_lost_, std::memory_order_relaxed);
    written_.fetch_add(page_records_, std::memory_order_release);
    if (in_error_) {
      spdlog::info("recorder: writing to {} again", currentFile());
      in_error_ = false;
    }
  }
  clearPage();
}

void Recorder::clearPage() {
  page_.clear();
  page_records_ = 0;
  page_announces_lost_ = 0;
  page_announces_drops_ = 0;
}

bool Recorder::openNextFile(const std::string& previous_name) {
  const auto now = unixNow();
  int fd = -1;
  std::string path;
  for (int attempt = 0; attempt < 1000; ++attempt) {
    path = (fs::path(directory_) / recordingFileName(stem_, extension_, now, next_index_++)).string();
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0640);
    if (fd >= 0 || errno != EEXIST) break;
  }
  if (fd < 0) {
    const int e = errno;
    reportError("create " + path, e);
    errno = e;
    return false;
  }
  // The header is written with the file's first lines (writePending), when the columns are known.
  fd_ = fd;
  file_bytes_ = 0;
  file_opened_unix_s_ = now;
  previous_file_ = previous_name;
  file_records_ = 0;
  file_opened_ns_ = steadyNowNs();
  {
    std::lock_guard lock(file_mutex_);
    current_file_ = path;
  }
  files_opened_.fetch_add(1, std::memory_order_relaxed);
  spdlog::info("recorder: writing {}", path);
  pruneOldFiles();
  return true;
}

// The column line first (genfromtxt's names=True reads the first line), then the comments.
std::string Recorder::headerText() const {
  return recording::columnsLine(columns_) +
         recording::recordingHeaderComments(file_opened_unix_s_, previous_file_, options_.header_comments);
}

void Recorder::closeFile() {
  if (fd_ < 0) return;
  emitPage();
  // Durable at close: a finished file survives a power cut.
  if (::fdatasync(fd_) != 0) reportError("fdatasync " + currentFile(), errno);
  if (::close(fd_) != 0) reportError("close " + currentFile(), errno);
  fd_ = -1;
}

void Recorder::pruneOldFiles() {
  if (options_.keep == 0) return;
  const auto all = files();
  const auto current = currentFile();
  std::size_t count = all.size();
  for (const auto& f : all) {
    if (count <= options_.keep) break;
    if (f == current) continue;
    std::error_code ec;
    if (fs::remove(f, ec)) {
      --count;
      spdlog::debug("recorder: removed old recording {}", f);
    } else if (ec) {
      spdlog::warn("recorder: cannot remove old recording {}: {}", f, ec.message());
    }
  }
}

void Recorder::reportError(const std::string& what, int error_number) {
  write_errors_.fetch_add(1, std::memory_order_relaxed);
  loss_reason_ = error_number == ENOSPC || error_number == EDQUOT ? "disk_full" : "write_error";
  {
    std::lock_guard lock(file_mutex_);
    last_error_ = what + ": " + std::strerror(error_number);
  }
  // One message per episode: a full disk would otherwise log every flush.
  if (!in_error_) spdlog::error("recorder: {}: {}", what, std::strerror(error_number));
  in_error_ = true;
}

}  // namespace gyrod::daemon
