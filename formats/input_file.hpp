#pragma once
// The one way gyrod and gyroctl open a file they read (the configuration, a model, a motion
// CSV, a recording, a mock replay file, a foreign recording to import). A path names any kind
// of file, and reading the wrong kind does harm: /dev/zero or /dev/urandom never end (the
// reader grows until the memory is gone), a FIFO blocks open() until a writer comes, a
// directory or /proc/self/mem reads as an empty file. So only a regular file outside /proc
// and /sys is read: it is checked with stat() before it is opened (a device is never opened),
// opened O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY (a FIFO swapped in meanwhile cannot
// block), checked again with fstat() on what was opened, and refused when it is larger than
// the limit of its kind. Every refusal is one line naming the path and what it is.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "formats/recording_csv.hpp"

namespace gyrod::formats {

// What a file is read as, and the most bytes a file of that kind may hold.
struct InputKind {
  std::string_view name;  // "configuration file", as the messages say it
  std::uint64_t max_bytes;
};

inline constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;
inline constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;
// gyrod's configuration: a few KiB in practice.
inline constexpr InputKind kConfigurationInput{"configuration file", 1 * kMiB};
// A sensor model (`gyroctl analyze --write-model`): a few KiB, more with narrowband lines.
inline constexpr InputKind kModelInput{"model file", 16 * kMiB};
// A motion CSV (t,wx,wy,wz): read whole into memory by the simulator and the mock.
inline constexpr InputKind kMotionInput{"motion CSV", 256 * kMiB};
// A recording the mock replays: held in gyrod's memory, each sample repeated up to the chip's
// internal rate, so much smaller than what gyroctl reads.
inline constexpr InputKind kReplayInput{"replay file", 256 * kMiB};
// A recording gyroctl reads (analyze, filter, model-check, ...): a day at 8 kHz with the rate
// columns stays below this.
inline constexpr InputKind kRecordingInput{"recording", 256 * kGiB};
// A password (gyrod's mqtt.password_file; systemd's LoadCredential=): one line.
inline constexpr InputKind kCredentialInput{"credential file", 64 * 1024};
// A TLS certificate or private key in PEM (gyrod's mqtt.ca_file, cert_file, key_file): a CA
// bundle such as Debian's ca-certificates.crt is about 200 KiB.
inline constexpr InputKind kTlsFileInput{"TLS file", 4 * kMiB};
// A foreign recording `gyroctl import` converts (read whole into memory).
inline constexpr InputKind kImportInput{"recording to import", 4 * kGiB};

// A file that cannot be read as `kind`. unreadable(): it is missing, not readable, or not a
// regular file (gyroctl's "no input", 66); otherwise it is too large (an unusable input, 65).
// A RecordingError, as every other problem of an input file is.
class InputFileError : public recording::RecordingError {
 public:
  InputFileError(const std::string& what, bool unreadable) : RecordingError(what), unreadable_(unreadable) {}
  bool unreadable() const noexcept { return unreadable_; }

 private:
  bool unreadable_;
};

struct InputFileCloser {
  void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using InputFile = std::unique_ptr<std::FILE, InputFileCloser>;

// The file opened for reading as described above, or InputFileError "PATH: cause". The
// size limit is checked here on the size fstat() reports; a reader that reads the whole file
// checks it again on what it reads (readInputFile).
InputFile openInputFile(const std::string& path, const InputKind& kind);
// The whole file (at most kind.max_bytes: a file that grows past it while read is refused).
std::string readInputFile(const std::string& path, const InputKind& kind);

}  // namespace gyrod::formats
