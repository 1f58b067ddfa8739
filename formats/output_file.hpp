#pragma once
// The one owner of every file gyroctl writes (README "Output files"): the target is checked,
// the bytes go to a temporary file beside it, and only a complete file is renamed into place.
//
// Rules:
// - The target must be a regular file or not exist. A device, FIFO, socket or directory is
//   refused, naming what it is; nothing is written and it is left as it was.
// - A symbolic link to a regular file is written through: the file it points to is replaced,
//   the link stays. A link to anything else, or to nothing, is refused.
// - The target may not be one of the command's inputs (same st_dev/st_ino, so through
//   symbolic and hard links too): refused, naming both paths.
// - An existing file keeps its permission bits (and, where permitted, its owner and group);
//   a new file is created with 0644 less the umask.
// - The temporary file is `<target>.tmp-gyroctl-<pid>`. It is removed on every way out: an
//   exception (the destructor), and SIGINT, SIGTERM or SIGHUP (a handler unlinks every live
//   temporary file, then re-raises the signal so the exit status still tells the signal).
#include <sys/types.h>

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace gyrod::formats {

// A target that must not be written (not a regular file, or one of the inputs). The
// command exits with its usage status: the user named the wrong path.
class OutputTargetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "a directory", "a FIFO", "a character device", ... for the st_mode of a file.
std::string fileTypeName(mode_t mode);

// Checks `target` against the rules above without writing anything; returns the path that
// will be replaced (the target, or the regular file its symbolic link points to). Throws
// OutputTargetError, or std::runtime_error when the folder cannot be examined.
std::string checkOutputTarget(const std::string& target, const std::vector<std::string>& inputs);

// Where AtomicOutputFile's stream writes (fopencookie): the reason of the first failed write
// (ENOSPC, EIO, ...) is kept for the message, where errno would have lost it.
struct OutputSink {
  int fd = -1;
  int first_error = 0;
};

class AtomicOutputFile {
 public:
  // Checks the target (checkOutputTarget) and creates the temporary file beside it.
  AtomicOutputFile(const std::string& target, const std::vector<std::string>& inputs);
  ~AtomicOutputFile();  // removes the temporary file unless commit() succeeded
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;
  AtomicOutputFile(AtomicOutputFile&&) = delete;  // the stream points at sink_
  AtomicOutputFile& operator=(AtomicOutputFile&&) = delete;

  std::FILE* stream() { return file_; }
  void write(std::string_view bytes);
  bool failed() const;  // a write has failed (e.g. the disk is full); commit() will throw
  // Bytes free for an unprivileged writer on the target's filesystem (statvfs f_bavail).
  std::uint64_t availableBytes() const;
  const std::string& target() const { return target_; }
  const std::string& tempPath() const { return temp_; }

  // Flushes, fsyncs and renames the temporary file onto the target. Throws
  // std::runtime_error (and removes the temporary file) when any step fails.
  void commit();

 private:
  void discard() noexcept;

  std::string target_;    // as the user gave it, for messages
  std::string replaced_;  // the path renamed onto (the link's target for a symbolic link)
  std::string temp_;
  OutputSink sink_;
  std::FILE* file_ = nullptr;
  int registry_slot_ = -1;
};

// The whole of `text` into `target` through an AtomicOutputFile.
void writeFileAtomically(const std::string& target, std::string_view text, const std::vector<std::string>& inputs);

}  // namespace gyrod::formats
