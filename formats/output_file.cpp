#include "formats/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdlib>
#include <cstring>

namespace gyrod::formats {
namespace {

// ---- the temporary files a signal must remove -------------------------------------------
// A fixed table the handler can walk without allocating: unlink() and raise() are
// async-signal-safe, std::string and std::remove are not. The table is changed only with
// the handled signals blocked, so the handler never sees a half-written path.

constexpr std::size_t kMaxLiveTempFiles = 8;
constexpr std::array<int, 3> kCleanedUpSignals = {SIGINT, SIGTERM, SIGHUP};
char g_temp_paths[kMaxLiveTempFiles][PATH_MAX];
volatile std::sig_atomic_t g_temp_used[kMaxLiveTempFiles];
bool g_handlers_installed = false;

extern "C" void removeTempFilesAndReraise(int sig) {
  for (std::size_t i = 0; i < kMaxLiveTempFiles; ++i)
    if (g_temp_used[i]) ::unlink(g_temp_paths[i]);
  // SA_RESETHAND restored the default action: the signal, still blocked here, terminates the
  // process as soon as the handler returns, so the exit status still names the signal.
  ::raise(sig);
}

class SignalsBlocked {
 public:
  SignalsBlocked() {
    sigset_t set;
    sigemptyset(&set);
    for (int sig : kCleanedUpSignals) sigaddset(&set, sig);
    ::sigprocmask(SIG_BLOCK, &set, &previous_);
  }
  ~SignalsBlocked() { ::sigprocmask(SIG_SETMASK, &previous_, nullptr); }
  SignalsBlocked(const SignalsBlocked&) = delete;
  SignalsBlocked& operator=(const SignalsBlocked&) = delete;

 private:
  sigset_t previous_;
};

void installHandlersOnce() {
  if (g_handlers_installed) return;
  g_handlers_installed = true;
  for (int sig : kCleanedUpSignals) {
    struct sigaction current {};
    ::sigaction(sig, nullptr, &current);
    if (current.sa_handler == SIG_IGN) continue;  // e.g. SIGHUP under nohup: keep ignoring it
    struct sigaction action {};
    action.sa_handler = removeTempFilesAndReraise;
    sigemptyset(&action.sa_mask);
    for (int other : kCleanedUpSignals) sigaddset(&action.sa_mask, other);
    action.sa_flags = SA_RESETHAND;
    ::sigaction(sig, &action, nullptr);
  }
}

int registerTempFile(const std::string& path) {
  if (path.size() >= PATH_MAX) throw std::runtime_error(path + ": the temporary file's path is too long");
  SignalsBlocked blocked;
  installHandlersOnce();
  for (std::size_t i = 0; i < kMaxLiveTempFiles; ++i) {
    if (g_temp_used[i]) continue;
    std::memcpy(g_temp_paths[i], path.c_str(), path.size() + 1);
    g_temp_used[i] = 1;
    return static_cast<int>(i);
  }
  throw std::runtime_error(path + ": more than " + std::to_string(kMaxLiveTempFiles) + " output files open at once");
}

void unregisterTempFile(int slot) {
  if (slot < 0) return;
  SignalsBlocked blocked;
  g_temp_used[slot] = 0;
}

// ---- the target's checks ----------------------------------------------------------------

std::string errnoText(int e) { return std::strerror(e); }

std::string parentFolder(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

void requireFolderOf(const std::string& target, const std::string& replaced) {
  const std::string folder = parentFolder(replaced);
  struct stat st {};
  if (::stat(folder.c_str(), &st) != 0)
    throw OutputTargetError(target + ": cannot write: its folder " + folder + ": " + errnoText(errno));
  if (!S_ISDIR(st.st_mode))
    throw OutputTargetError(target + ": cannot write: " + folder + " is " + fileTypeName(st.st_mode) +
                            ", not a folder");
}

void refuseInputAsOutput(const std::string& target, const std::string& replaced,
                         const std::vector<std::string>& inputs) {
  struct stat out {};
  if (::stat(replaced.c_str(), &out) != 0) return;  // a new file cannot be an input
  for (const std::string& input : inputs) {
    struct stat in {};
    if (input.empty() || ::stat(input.c_str(), &in) != 0) continue;
    if (in.st_dev == out.st_dev && in.st_ino == out.st_ino)
      throw OutputTargetError(target + ": refusing to write the output over the input " + input +
                              " (they are the same file)");
  }
}

// ---- the stream's sink: write(2) keeping the first error -------------------------------

ssize_t sinkWrite(void* cookie, const char* bytes, std::size_t size) {
  auto* sink = static_cast<OutputSink*>(cookie);
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(sink->fd, bytes + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (sink->first_error == 0) sink->first_error = n < 0 ? errno : EIO;
      return done > 0 ? static_cast<ssize_t>(done) : -1;
    }
    done += static_cast<std::size_t>(n);
  }
  return static_cast<ssize_t>(done);
}

int sinkClose(void* cookie) {
  auto* sink = static_cast<OutputSink*>(cookie);
  const int rc = ::close(sink->fd);
  if (rc != 0 && sink->first_error == 0) sink->first_error = errno;
  sink->fd = -1;
  return rc;
}

}  // namespace

std::string fileTypeName(mode_t mode) {
  if (S_ISREG(mode)) return "a regular file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

std::string checkOutputTarget(const std::string& target, const std::vector<std::string>& inputs) {
  if (target.empty()) throw OutputTargetError("the output path is empty");
  std::string replaced = target;
  struct stat link {};
  if (::lstat(target.c_str(), &link) != 0) {
    if (errno != ENOENT) throw std::runtime_error(target + ": cannot examine: " + errnoText(errno));
  } else if (S_ISLNK(link.st_mode)) {
    struct stat pointed {};
    if (::stat(target.c_str(), &pointed) != 0)
      throw OutputTargetError(target + ": refusing to write: it is a symbolic link to nothing (" + errnoText(errno) +
                              ")");
    if (!S_ISREG(pointed.st_mode))
      throw OutputTargetError(target + ": refusing to write: it is a symbolic link to " +
                              fileTypeName(pointed.st_mode) + " (gyroctl replaces only regular files)");
    char resolved[PATH_MAX];
    if (::realpath(target.c_str(), resolved) == nullptr)
      throw std::runtime_error(target + ": cannot resolve the symbolic link: " + errnoText(errno));
    replaced = resolved;
  } else if (!S_ISREG(link.st_mode)) {
    throw OutputTargetError(target + ": refusing to write: it is " + fileTypeName(link.st_mode) +
                            " (gyroctl replaces only regular files)");
  }
  requireFolderOf(target, replaced);
  refuseInputAsOutput(target, replaced, inputs);
  return replaced;
}

AtomicOutputFile::AtomicOutputFile(const std::string& target, const std::vector<std::string>& inputs)
    : target_(target), replaced_(checkOutputTarget(target, inputs)) {
  temp_ = replaced_ + ".tmp-gyroctl-" + std::to_string(::getpid());
  struct stat existing {};
  const bool replacing = ::stat(replaced_.c_str(), &existing) == 0;
  // Registered before it exists, so that no moment has the file on disk and unknown to the
  // signal handler.
  registry_slot_ = registerTempFile(temp_);
  int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0 && errno == EEXIST) {  // left by a killed process that had our pid
    ::unlink(temp_.c_str());
    fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  }
  if (fd < 0) {
    const int e = errno;
    unregisterTempFile(registry_slot_);
    throw std::runtime_error(target_ + ": cannot create the temporary file " + temp_ + ": " + errnoText(e));
  }
  if (replacing) {
    // The replaced file's permissions; its owner and group only where we may set them.
    ::fchmod(fd, existing.st_mode & 0777);
    if (::fchown(fd, existing.st_uid, existing.st_gid) != 0) {
      [[maybe_unused]] const int ignored = ::fchown(fd, static_cast<uid_t>(-1), existing.st_gid);
    }
  }
  sink_.fd = fd;
  file_ = ::fopencookie(&sink_, "wb", cookie_io_functions_t{nullptr, sinkWrite, nullptr, sinkClose});
  if (!file_) {
    const int e = errno;
    ::close(fd);
    sink_.fd = -1;
    discard();
    throw std::runtime_error(target_ + ": cannot write " + temp_ + ": " + errnoText(e));
  }
  std::setvbuf(file_, nullptr, _IOFBF, std::size_t{1} << 16);  // fewer write(2) calls for long outputs
}

AtomicOutputFile::~AtomicOutputFile() { discard(); }

void AtomicOutputFile::discard() noexcept {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (registry_slot_ >= 0) {
    ::unlink(temp_.c_str());
    unregisterTempFile(registry_slot_);
    registry_slot_ = -1;
  }
}

void AtomicOutputFile::write(std::string_view bytes) {
  if (file_ && !bytes.empty()) std::fwrite(bytes.data(), 1, bytes.size(), file_);
}

bool AtomicOutputFile::failed() const { return file_ == nullptr || std::ferror(file_) != 0; }

std::uint64_t AtomicOutputFile::availableBytes() const {
  struct statvfs fs {};
  if (sink_.fd < 0 || ::fstatvfs(sink_.fd, &fs) != 0)
    throw std::runtime_error(target_ + ": cannot read the free space of its filesystem: " + errnoText(errno));
  return static_cast<std::uint64_t>(fs.f_bavail) * static_cast<std::uint64_t>(fs.f_frsize);
}

void AtomicOutputFile::commit() {
  if (!file_) throw std::runtime_error(target_ + ": already committed or discarded");
  const auto fail = [this](const std::string& what, int e) {
    discard();
    throw std::runtime_error(target_ + ": " + what + ": " + errnoText(e) + " (the target is unchanged)");
  };
  errno = 0;
  if (std::fflush(file_) != 0 || std::ferror(file_))
    fail("write failed", sink_.first_error ? sink_.first_error : errno ? errno : EIO);
  // EINVAL: a filesystem without fsync (e.g. some FUSE mounts); the rename still orders it.
  if (::fsync(sink_.fd) != 0 && errno != EINVAL) fail("fsync failed", errno);
  const int closed = std::fclose(file_);
  file_ = nullptr;
  if (closed != 0) fail("close failed", sink_.first_error ? sink_.first_error : errno);
  if (::rename(temp_.c_str(), replaced_.c_str()) != 0) fail("cannot rename " + temp_ + " onto it", errno);
  unregisterTempFile(registry_slot_);
  registry_slot_ = -1;
  // The rename itself durable: best effort, a folder that cannot be opened changes nothing.
  const int dir = ::open(parentFolder(replaced_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

void writeFileAtomically(const std::string& target, std::string_view text, const std::vector<std::string>& inputs) {
  AtomicOutputFile out(target, inputs);
  out.write(text);
  out.commit();
}

}  // namespace gyrod::formats
