#include "formats/input_file.hpp"

#include <fcntl.h>
#include <linux/magic.h>
#include <sys/stat.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>

#include "formats/output_file.hpp"  // fileTypeName

namespace gyrod::formats {
namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& cause, bool unreadable) {
  throw InputFileError(path + ": " + cause, unreadable);
}

[[noreturn]] void refuseType(const std::string& path, std::string_view what, const InputKind& kind,
                             std::string_view instead_of = "a file") {
  std::ostringstream s;
  s << "cannot read: it is " << what << ", not " << instead_of << " (a " << kind.name << " must be a regular file)";
  refuse(path, s.str(), true);
}

std::string sizeText(std::uint64_t bytes) {
  std::ostringstream s;
  s.precision(3);
  if (bytes >= kGiB)
    s << static_cast<double>(bytes) / static_cast<double>(kGiB) << " GiB";
  else if (bytes >= kMiB)
    s << static_cast<double>(bytes) / static_cast<double>(kMiB) << " MiB";
  else
    s << bytes << " bytes";
  return s.str();
}

[[noreturn]] void refuseSize(const std::string& path, std::uint64_t bytes, const InputKind& kind, bool at_least) {
  refuse(path,
         "cannot read: " + std::string(at_least ? "more than " : "") + sizeText(bytes) + ", over the " +
             sizeText(kind.max_bytes) + " a " + std::string(kind.name) + " may hold",
         false);
}

// Files of /proc and /sys say they are regular and have no size (or a page), but read
// without end (/proc/self/mem faults, /proc/kcore is the memory), or have side effects.
std::string_view pseudoFilesystem(int fd) {
  struct statfs fs {};
  if (::fstatfs(fd, &fs) != 0) return {};
  if (fs.f_type == PROC_SUPER_MAGIC) return "a file of /proc";
  if (fs.f_type == SYSFS_MAGIC) return "a file of /sys";
  return {};
}

}  // namespace

InputFile openInputFile(const std::string& path, const InputKind& kind) {
  // stat() first: a device is refused without being opened (opening some has effects).
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) refuse(path, std::string("cannot open: ") + std::strerror(errno), true);
  if (!S_ISREG(st.st_mode)) refuseType(path, fileTypeName(st.st_mode), kind);
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) refuse(path, std::string("cannot open: ") + std::strerror(errno), true);
  InputFile file(::fdopen(fd, "rb"));
  if (!file) {
    const int error = errno;
    ::close(fd);
    refuse(path, std::string("cannot open: ") + std::strerror(error), true);
  }
  // The path may name another file by now: what counts is what was opened.
  if (::fstat(fd, &st) != 0) refuse(path, std::string("cannot read: ") + std::strerror(errno), true);
  if (!S_ISREG(st.st_mode)) refuseType(path, fileTypeName(st.st_mode), kind);
  if (const std::string_view pseudo = pseudoFilesystem(fd); !pseudo.empty())
    refuseType(path, pseudo, kind, "a regular file");
  if (static_cast<std::uint64_t>(st.st_size) > kind.max_bytes)
    refuseSize(path, static_cast<std::uint64_t>(st.st_size), kind, false);
  return file;
}

std::string readInputFile(const std::string& path, const InputKind& kind) {
  const InputFile file = openInputFile(path, kind);
  std::string text;
  char buffer[65536];
  while (true) {
    const std::size_t n = std::fread(buffer, 1, sizeof buffer, file.get());
    if (n == 0) break;
    if (text.size() + n > kind.max_bytes) refuseSize(path, kind.max_bytes, kind, true);
    text.append(buffer, n);
  }
  if (std::ferror(file.get())) refuse(path, std::string("read error: ") + std::strerror(errno), true);
  return text;
}

}  // namespace gyrod::formats
