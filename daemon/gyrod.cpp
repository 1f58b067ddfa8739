#include "daemon/gyrod.hpp"

#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <systemd/sd-daemon.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "daemon/command_line.hpp"
#include "daemon/network_sandbox.hpp"
#include "daemon/watchdog.hpp"
#include "driver/counter_names.hpp"
#include "driver/fifo_frame.hpp"
#include "driver/mpu6050_config.hpp"
#include "formats/calibration.hpp"
#include "formats/calibration_state.hpp"
#include "formats/input_file.hpp"
#include "formats/model_toml.hpp"
#include "formats/recording_header.hpp"
#include "formats/toml_document.hpp"
#include "processing/simulation/sensor_model.hpp"
#include "protocol/effect_line.hpp"

namespace gyrod::daemon {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The accelerated mock's virtual clock is pumped from this real-time timer, in steps of at
// most kMaxVirtualStepNs, and at most half of what the FIFO holds at the device's rate
// (maxVirtualStepNs), so that the FIFO never overflows in a step.
constexpr auto kPumpPeriod = std::chrono::milliseconds(10);
constexpr std::int64_t kMaxVirtualStepNs = 200'000'000;
// Real time one pump may spend before returning to the loop.
constexpr std::int64_t kMaxPumpWorkNs = 20'000'000;
// What all clients' requests may take of one CPU (daemon/unix_socket_server.hpp): the RATE lines
// go on however many requests come.
constexpr double kRequestCpuShare = 0.5;
std::string hostName() {
  std::array<char, 256> name{};
  if (::gethostname(name.data(), name.size() - 1) != 0 || name[0] == '\0') return "localhost";
  std::string host(name.data());
  std::replace_if(
      host.begin(), host.end(), [](char c) { return c == '/' || c == '+' || c == '#'; }, '_');
  return host;
}

MqttSettings mqttSettings(const GyrodConfig& c, const std::string& device) {
  const MqttEndpoint endpoint = parseMqttUrl(c.mqtt.url);
  MqttSettings s;
  s.host = endpoint.host;
  s.port = endpoint.port;
  s.tls = endpoint.tls;
  s.ca_file = c.mqtt.ca_file;
  s.cert_file = c.mqtt.cert_file;
  s.key_file = c.mqtt.key_file;
  s.buffer_messages = c.mqtt.buffer_messages;
  s.prefix = c.mqtt.prefix.empty() ? "gyrod/" + hostName() : c.mqtt.prefix;
  s.client_id = c.mqtt.client_id.empty() ? "gyrod-" + hostName() : c.mqtt.client_id;
  s.qos = c.mqtt.qos;
  s.rate_every = c.mqtt.rate_every;
  s.username = c.mqtt.username;
  if (!c.mqtt.password_file.empty()) {
    try {
      s.password = formats::readInputFile(c.mqtt.password_file, formats::kCredentialInput);
    } catch (const std::exception& e) {
      throw ConfigError(std::string(e.what()) + " (mqtt.password_file)");
    }
    while (!s.password.empty() && (s.password.back() == '\n' || s.password.back() == '\r')) s.password.pop_back();
  }
  s.device = device;
  s.rate_hz = c.device.rate_hz;
  s.queue_lines = clientQueueLines(recordedSamplesPerSecond(c));
  s.home_assistant = c.mqtt.home_assistant;
  s.home_assistant_prefix = c.mqtt.home_assistant_prefix;
  s.orientation = !c.filter.model.empty() && c.device.accel;
  return s;
}

LineForClients gapLine(std::uint64_t first_seq, std::uint64_t count, std::string_view reason) {
  LineForClients line;
  line.kind = LineForClients::Kind::Gap;
  line.gap_first_seq = first_seq;
  line.gap_count = count;
  const std::size_t n = std::min(reason.size(), protocol::kMaxGapReasonBytes);
  std::memcpy(line.gap_reason.data(), reason.data(), n);
  line.gap_reason[n] = '\0';
  return line;
}

std::int64_t monotonicNowNs() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

spdlog::level::level_enum spdlogLevel(driver::LogLevel level) {
  switch (level) {
    case driver::LogLevel::Debug: return spdlog::level::debug;
    case driver::LogLevel::Info: return spdlog::level::info;
    case driver::LogLevel::Warning: return spdlog::level::warn;
    case driver::LogLevel::Error: return spdlog::level::err;
  }
  return spdlog::level::info;
}

// How soon a data-ready wake-up runs on a busy CPU depends on the loop's policy: SCHED_OTHER
// lets the running task finish its slice, often until the next scheduler tick (4 ms at
// HZ=250); SCHED_FIFO preempts it at once (docs/driver.md "Latency").
std::string loopSchedulingNote() {
  const int policy = ::sched_getscheduler(0);
  if (policy == SCHED_FIFO || policy == SCHED_RR) {
    sched_param param{};
    ::sched_getparam(0, &param);
    return std::string(policy == SCHED_FIFO ? "SCHED_FIFO" : "SCHED_RR") + " priority " +
           std::to_string(param.sched_priority);
  }
  return "SCHED_OTHER: when the CPUs are busy a sample can reach clients a scheduler tick late (1-10 ms); "
         "run gyrod SCHED_FIFO for sub-millisecond delivery (the systemd unit does; by hand: chrt -f 10 gyrod ...)";
}

// Half the time the FIFO takes to fill, or the host's queue of data-ready edges (16, as the
// kernel's GPIO line-event FIFO) when that is shorter: 73 frames of 14 bytes are 73 ms at 1 kHz,
// so a fixed step (200 ms, 2.5 s of FIFO at 50 Hz) overflowed the FIFO at every step, and an edge
// queue that overflows leaves the driver without the edge that dates a new segment.
std::int64_t maxVirtualStepNs(const driver::Mpu6050Config& chip) {
  const auto fifo_frames = driver::mpu6050::fifo::kSize / driver::frameBytesFor(chip.accel);
  const auto queued_edges = driver::MockMpu6050Config{}.data_ready_queue_depth;
  const double samples = 0.5 * static_cast<double>(std::min(fifo_frames, queued_edges));
  const double step_ns = samples / chip.sample_rate_hz * 1e9;
  return std::max<std::int64_t>(1, std::min(kMaxVirtualStepNs, static_cast<std::int64_t>(step_ns)));
}

Vec3 modelBias(const std::string& path) {
  const processing::SimulationModel model = recording::readModelToml(path);
  return {model.axes[0].bias_dps, model.axes[1].bias_dps, model.axes[2].bias_dps};
}

// A published sample as the recording holds it: the same values, so the file is the stream.
recording::SampleValues recordedSample(const RateSample& r, std::int64_t wall_ns) {
  recording::SampleValues v;
  v.t_s = r.t_s;
  v.gx_dps = r.raw_dps[0];
  v.gy_dps = r.raw_dps[1];
  v.gz_dps = r.raw_dps[2];
  v.temp_c = r.temp_c;
  v.wall_ns = wall_ns;
  v.accel_g = r.accel_g;
  v.rate_dps = r.rate_dps;
  v.bias_dps = r.bias_dps;
  v.still = r.still ? static_cast<std::int8_t>(*r.still) : std::int8_t{-1};
  v.attitude = {r.quat[0],
                r.quat[1],
                r.quat[2],
                r.quat[3],
                r.roll_pitch_heading_deg[0],
                r.roll_pitch_heading_deg[1],
                r.roll_pitch_heading_deg[2],
                r.inclination_std_deg,
                r.heading_std_deg};
  return v;
}

}  // namespace

namespace {

// The state the rate stream started from, in the recording's header (empty: none).
void appendCalibrationStateHeader(std::vector<std::string>& comments, const std::string& started_from) {
  if (started_from.empty()) return;
  comments.push_back(
      "the rate stream started from this calibration state (docs/calibration-state.md; gyroctl filter reads it):");
  for (std::string& line : recording::calibrationStateHeaderComments(started_from)) comments.push_back(std::move(line));
}

}  // namespace

// With a state directory: the keeper, and the rate stream started from what it restores. Returns
// that state as the recording's header carries it (with the time since it was written already in
// its variances, so that `gyroctl filter --model` starts from the same bits), or "".
std::string Gyrod::startCalibrationKeeper() {
  const std::string dir = calibrationStateDirectory(config_.state.directory);
  if (dir.empty()) return {};
  calibration_ = std::make_unique<CalibrationKeeper>(loop_, dir, rate_model_.fingerprint, config_.device.rate_hz,
                                                     config_.state.save_interval_s);
  if (pipeline_.rateModel() != RateModel::SensorModel) return {};
  std::optional<RestoredCalibration> restored = calibration_->restore();
  if (!restored || !pipeline_.startRateFrom(restored->residual, restored->elapsed_s)) return {};
  restored->state.residual = pipeline_.rateEstimator()->learned();
  return formats::calibrationStateToToml(restored->state);
}

// [check] enabled: the live check on the still samples, when filter.model gives the still
// detector (without it a moving board would be compared with its still baseline).
void Gyrod::startLiveCheck() {
  if (!config_.check.enabled) {
    live_check_off_ = "[check] enabled = false";
    return;
  }
  if (pipeline_.rateModel() != RateModel::SensorModel) {
    live_check_off_ = "it runs on still samples, and the still detector needs filter.model";
    spdlog::info("live check: off ({})", live_check_off_);
    return;
  }
  // The coupling the model gives each axis: the check names a bias that follows temperature
  // otherwise.
  std::array<double, 3> coupling{};
  if (rate_model_.params)
    for (std::size_t a = 0; a < coupling.size(); ++a)
      coupling[a] = rate_model_.params->axes[a].temperature_coefficient_dps_per_c;
  live_ = std::make_unique<LiveChecker>(loop_, config_.device.rate_hz, config_.check.interval_s,
                                        config_.check.baseline_s, config_.check.false_alarms_per_week, coupling,
                                        [this](const processing::LiveEffect& e) { queueEffect(e); });
  spdlog::info(
      "live check: every {} s of still data at {} Hz against a baseline of the first {} s "
      "(docs/live-check.md)",
      formats::shortest(config_.check.interval_s), formats::shortest(live_->analysisRateHz()),
      formats::shortest(config_.check.baseline_s));
}

void Gyrod::queueEffect(const processing::LiveEffect& e) {
  std::string line = protocol::effectJson(e).dump() + "\n";
  if (mqtt_) mqtt_->pushEffect(std::string_view(line).substr(0, line.size() - 1));  // a message: no newline
  {
    const std::lock_guard lock(effects_mutex_);
    effect_lines_.push_back(std::move(line));
  }
  effects_queued_.fetch_add(1, std::memory_order_release);
  clients_to_wake_ = true;
  wakeDeliveryThread();
}

// The rate stream's parameters from filter.model, exactly as `gyroctl filter --model` builds
// them (rateEstimatorParameters of readSensorModelToml), at the device's rate, with
// filter.rate_low_pass_hz over the model's low-pass when set.
LoadedRateModel Gyrod::loadRateModel(const GyrodConfig& c) {
  LoadedRateModel loaded;
  const FilterConfig& f = c.filter;
  if (f.model.empty()) return loaded;
  recording::SensorModel model;
  try {
    model = recording::readSensorModelToml(f.model);  // its messages name FILE:LINE
  } catch (const std::exception& e) {                 // unreadable, or not a model file: a misconfiguration
    throw ConfigError(std::string(e.what()) + " (filter.model)");
  }
  try {
    processing::RateEstimatorParameters p = recording::rateEstimatorParameters(model);
    if (std::fabs(p.rate_hz - c.device.rate_hz) > 1e-9 * c.device.rate_hz) {
      std::ostringstream warning;
      warning << f.model << ": model rate " << p.rate_hz << " Hz, device " << c.device.rate_hz
              << " Hz: the rate stream runs at the device's";
      loaded.warning = warning.str();
    }
    p.rate_hz = c.device.rate_hz;
    if (f.rate_low_pass_hz) p.low_pass_hz = *f.rate_low_pass_hz > 0.0 ? f.rate_low_pass_hz : std::nullopt;
    processing::validateRateEstimatorParameters(p);
    loaded.params = p;
  } catch (const std::invalid_argument& e) {
    throw ConfigError(f.model + " (filter.model): cannot run the rate stream on it: " + std::string(e.what()));
  }
  std::ostringstream identity;
  identity << f.model << '\n' << f.rate_low_pass_hz.value_or(-1.0) << '\n' << recording::sensorModelToToml(model);
  loaded.identity = identity.str();
  loaded.fingerprint = formats::biasModelFingerprint(*loaded.params);
  return loaded;
}

PipelineSettings Gyrod::pipelineSettings(const GyrodConfig& c, const LoadedRateModel& rate_model) {
  PipelineSettings s;
  s.rate_hz = c.device.rate_hz;
  switch (c.bias.source) {
    case BiasSource::Config:
      s.bias_origin = BiasOrigin::Config;
      for (std::size_t a = 0; a < kAxes; ++a) s.bias_dps[a] = c.bias.values.at(a);
      break;
    case BiasSource::Model:
      s.bias_origin = BiasOrigin::Model;
      s.bias_dps = modelBias(c.filter.model);
      break;
    case BiasSource::Estimate: s.bias_origin = BiasOrigin::Estimate; break;
  }
  s.still_seconds = c.bias.still_seconds;
  s.low_pass_bandwidth_hz = processing::dlpfSetting(c.device.dlpf).bandwidth_hz;
  s.still_window_off_loop = true;  // tens of ms at 8 kHz: not in one turn of the sample loop
  s.mean_window = c.filter.mean_window;
  s.mean_threshold_dps = c.filter.mean_threshold_dps;
  s.kalman = {c.filter.kalman.a, c.filter.kalman.q, c.filter.kalman.r};
  s.allan_window_samples = static_cast<std::size_t>(std::llround(c.allan.window_s * c.device.rate_hz));
  for (double tau : c.allan.taus_s)
    s.allan_cluster_sizes.push_back(static_cast<std::size_t>(std::llround(tau * c.device.rate_hz)));
  s.rate_model = rate_model.params;
  return s;
}

// The recording, its header comments saying what each column is and how to recompute it.
void Gyrod::startRecorder(const std::string& started_from) {
  // Sized for the samples per second it really receives: the accelerated mock's included.
  RecorderOptions options = recorderOptions(config_.record, recordedSamplesPerSecond(config_));
  options.header_comments.push_back("gyrod " + std::string(GYROD_RELEASE) + " recording of " + device_.description);
  options.header_comments.push_back(
      "gx,gy,gz: raw rates as read from the chip (bias not removed); t: CLOCK_MONOTONIC s of the data-ready edge; "
      "time: the same edge in UTC epoch s; GAP lines mark lost samples");
  const driver::Mpu6050Config& chip = device_.driver_config;  // the chain the model check puts in its base model
  options.header_comments.push_back(recording::acquisitionHeaderComment(chip.dlpf_cfg, chip.fs_sel, chip.sample_rate_hz,
                                                                        driver::sampleRateDivider(chip)));
  options.header_comments.push_back(
      "gx_rate..still: the RATE stream's rate, bias and still as published (docs/recording-format.md)");
  if (rate_model_.params)  // the recording holds what the rate stream was fed, at full precision
    options.header_comments.push_back("recompute them: gyroctl filter FILE --model " + config_.filter.model +
                                      " --rate " + formats::shortest(config_.device.rate_hz) +
                                      "; the orientation (qw..heading_std): gyroctl attitude FILE --model " +
                                      config_.filter.model + " --rate " + formats::shortest(config_.device.rate_hz));
  appendCalibrationStateHeader(options.header_comments, started_from);
  options.columns.time = true;
  options.columns.rate = true;
  options.columns.attitude = true;  // when the first sample has an orientation (a model and accel)
  recorder_ = std::make_unique<Recorder>(options);
}

Gyrod::Gyrod(const GyrodConfig& config, std::string config_file)
    : config_(config),
      config_file_(std::move(config_file)),
      rate_model_(loadRateModel(config)),
      device_(makeDeviceParts(config)),
      pipeline_(pipelineSettings(config, rate_model_)),
      noise_refit_(loop_, pipeline_, config.device.rate_hz,
                   [this] { refit_cycles_.fetch_add(1, std::memory_order_release); }),
      allan_reply_([this] { return allanReport(); }),
      reload_(
          loop_, kReloadTimeLimit,
          [file = config_file_, rate_hz = config.device.rate_hz] { return loadReload(file, rate_hz); },
          [this](ReloadedFilter&& reloaded) { applyReload(std::move(reloaded)); },
          [](const std::string& why) { spdlog::error("SIGHUP: keeping the running filter: {}", why); }),
      still_window_(
          loop_, [this](StillWindowOutcome&& outcome) { finishStillWindow(std::move(outcome)); },
          [this](const std::string& why) {
            StillWindowOutcome failed;  // collected again; the window's memory is gone with the job
            failed.error = "the still period could not be evaluated: " + why;
            finishStillWindow(std::move(failed));
          }),
      to_clients_(clientQueueLines(recordedSamplesPerSecond(config))),
      to_clients_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
      stop_delivery_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)),
      stop_clients_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  if (!to_clients_fd_ || !stop_delivery_fd_ || !stop_clients_fd_)
    throw errnoError("eventfd for the delivery and client threads");
  loop_.guardTurnsWith(&state_mutex_);
  held_.reserve(static_cast<std::size_t>(std::ceil(0.5 * config.device.rate_hz)) + 16);  // as the pipeline's
  if (!rate_model_.warning.empty()) spdlog::warn("{}", rate_model_.warning);
  const std::string started_from = startCalibrationKeeper();
  startLiveCheck();
  start_real_ns_ = monotonicNowNs();
  last_pump_real_ns_ = start_real_ns_;
  max_virtual_step_ns_ = maxVirtualStepNs(device_.driver_config);

  SocketOptions socket_options;
  socket_options.path = config_.socket.path;
  socket_options.mode = static_cast<mode_t>(config_.socket.mode);
  if (!config_.socket.group.empty()) socket_options.group = config_.socket.group;
  ServerOptions server_options;
  server_options.client_buffer_bytes = config_.socket.client_buffer_kib * 1024;
  server_options.max_clients = kMaxSocketClients;  // as the memory budget counts them
  server_options.request_cpu_share = kRequestCpuShare;
  server_options.publish_off_loop = true;  // the delivery thread publishes
  server_ =
      std::make_unique<UnixSocketServer>(client_loop_, openListeningSocket(socket_options), *this, server_options);
  client_loop_.addFd(stop_clients_fd_.get(), EPOLLIN, [this](std::uint32_t) { client_loop_.stop(); });

  if (config_.record.enabled()) startRecorder(started_from);

  if (config_.mqtt.enabled()) startMqtt();

  auto log = [](driver::LogLevel level, std::string_view message) { spdlog::log(spdlogLevel(level), "{}", message); };
  driver_ = std::make_unique<driver::Mpu6050Driver>(*device_.bus, *device_.data_ready, *device_.clock, *this,
                                                    device_.driver_config, log);

  loop_.addSignals({SIGTERM, SIGINT, SIGHUP}, [this](int signal_number) {
    if (signal_number == SIGHUP) {
      if (config_file_.empty())
        spdlog::warn("SIGHUP: no configuration file was loaded, nothing to reload");
      else
        reload_.request();  // read and checked off the loop; applied here when ready
    } else {
      spdlog::info("{} received: stopping", signal_number == SIGTERM ? "SIGTERM" : "SIGINT");
      loop_.stop();
    }
  });

  if (device_.virtual_clock) {
    loop_.addPeriodicTimer(kPumpPeriod, [this](std::uint64_t) {
      pumpVirtualClock();
      wakeDeliveryThread();
    });
  } else {
    loop_.addFd(driver_->pollFd(), EPOLLIN, [this](std::uint32_t) {
      driver_->onDataReady();
      rearmDriverTimer();
      wakeDeliveryThread();
    });
    driver_timer_ = Fd(::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC));
    if (!driver_timer_) throw std::system_error(errno, std::generic_category(), "timerfd_create");
    loop_.addFd(driver_timer_.get(), EPOLLIN, [this](std::uint32_t) {
      std::uint64_t expirations = 0;
      [[maybe_unused]] const ssize_t n = ::read(driver_timer_.get(), &expirations, sizeof expirations);
      driver_->onTimer(monotonicNowNs());
      rearmDriverTimer();
      wakeDeliveryThread();
    });
  }

  const auto refit = std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double>(config_.allan.refit_interval_s));
  // The refit runs off the loop (daemon/noise_refit_worker.hpp); the ALLAN reply is cached
  // between refits (daemon/allan_reply_cache.hpp), so no client request waits on either.
  loop_.addPeriodicTimer(refit, [this](std::uint64_t) { noise_refit_.startCycle(); });

  if (::sd_watchdog_enabled(0, &watchdog_usec_) > 0 && watchdog_usec_ > 0) {
    loop_.addPeriodicTimer(watchdogPingPeriod(watchdog_usec_), [this](std::uint64_t) { petWatchdog(); });
  } else {
    watchdog_usec_ = 0;
  }

  spdlog::info("gyrod {}: {} at {} Hz, DLPF_CFG {}, +-{} deg/s; socket {}{}", GYROD_RELEASE, device_.description,
               config_.device.rate_hz, config_.device.dlpf, config_.device.full_scale_dps,
               server_->socketPath().empty() ? std::string("(socket activation)") : server_->socketPath(),
               recorder_ ? ", recording to " + recorder_->currentFile() : std::string());
  if (config_file_.empty())
    spdlog::info("configuration: no file (no --config, and no {}): running on the defaults", kDefaultConfigPath);
  else
    spdlog::info("configuration: loaded from {}", config_file_);
  if (!device_.virtual_clock)
    spdlog::info(
        "event loop scheduling: {}; the clients' requests are served beside it at normal priority, at "
        "most {:.0f} % of a CPU",
        loopSchedulingNote(), kRequestCpuShare * 100.0);
  spdlog::info("rate stream: {}", pipeline_.rateModel() == RateModel::SensorModel
                                      ? "raw - the bias of the sensor model " + config_.filter.model
                                      : std::string("raw - the bias of [bias] (no filter.model: no temperature term)"));
  if (pipeline_.phase() == PipelinePhase::Estimating)
    spdlog::info("keep the sensor still: estimating {} over the first {:.1f} s",
                 config_.bias.source == BiasSource::Estimate ? "the bias and the filter" : "the filter",
                 pipeline_.stillSecondsNeeded());
  driver_->start();
  if (!device_.virtual_clock) rearmDriverTimer();
}

Gyrod::~Gyrod() {
  stopDeliveryThread();  // first: it publishes through the client thread's server
  stopClientThread();
}

int Gyrod::run() {
  running_.store(true, std::memory_order_release);
  client_thread_ = std::thread([this] { clientThreadMain(); });
  int sample_policy = SCHED_OTHER;
  sched_param sample_param{};
  ::pthread_getschedparam(::pthread_self(), &sample_policy, &sample_param);
  delivery_thread_ = std::thread(
      [this, sample_policy, priority = sample_param.sched_priority] { deliveryThreadMain(sample_policy, priority); });
  loop_.run();
  stopDeliveryThread();
  stopClientThread();
  ::sd_notify(0, "STOPPING=1");
  if (calibration_)
    if (const processing::RateEstimator* estimator = pipeline_.rateEstimator()) calibration_->writeAtStop(*estimator);
  std::string recording;
  if (recorder_) {
    // The last writes and the fdatasync of the file: the step of the exit that waits for the
    // disk, so the line says how long it took (a slow exit then names or clears it).
    const std::int64_t stop_start_ns = monotonicNowNs();
    recorder_->stop();
    const std::int64_t stop_ms = (monotonicNowNs() - stop_start_ns) / 1'000'000;
    const RecorderStats s = recorder_->stats();
    const std::string last_error = recorder_->lastError();
    recording = fmt::format(
        "; recording: {} written, {} dropped (ring full), {} lost to write errors ({} failed calls{}), closed in {} ms",
        s.written, s.dropped, s.lost_to_errors, s.write_errors,
        last_error.empty() ? std::string() : ", last: " + last_error, stop_ms);
  }
  std::string mqtt;
  if (mqtt_) {
    mqtt_->stop();  // publishes "offline" (retained) and disconnects
    const MqttStats s = mqtt_->stats();
    mqtt = fmt::format("; MQTT: {} messages published, {} dropped, {} still kept for the broker at the stop",
                       s.published, s.dropped, s.buffered);
  }
  const std::string behind = behind_total_ == 0
                                 ? std::string()
                                 : fmt::format("; {} lines not delivered to clients (delivery_behind)", behind_total_);
  spdlog::info(
      "stopped after {} samples, {} gaps ({} samples lost by the device){}{}{}; longest loop turn {} us (clients' "
      "loop: {} us)",
      samples_published_, gaps_, missing_samples_, behind, recording, mqtt,
      std::chrono::duration_cast<std::chrono::microseconds>(loop_.longestTurn()).count(),
      std::chrono::duration_cast<std::chrono::microseconds>(client_loop_.longestTurn()).count());
  return 0;
}

void Gyrod::rearmDriverTimer() {
  itimerspec spec{};
  if (const auto deadline = driver_->nextDeadlineNs()) {
    const std::int64_t at = std::max<std::int64_t>(*deadline, 1);  // 0 would disarm
    spec.it_value.tv_sec = at / 1'000'000'000;
    spec.it_value.tv_nsec = at % 1'000'000'000;
  }
  ::timerfd_settime(driver_timer_.get(), TFD_TIMER_ABSTIME, &spec, nullptr);
}

void Gyrod::pumpVirtualClock() {
  const std::int64_t now = monotonicNowNs();
  const double speed = config_.mock.speed;
  auto budget = static_cast<std::int64_t>(static_cast<double>(now - last_pump_real_ns_) * speed);
  last_pump_real_ns_ = now;
  // When the machine cannot simulate the chip this fast, run slower rather than let the
  // backlog grow: the loop must keep serving clients and signals between pump steps.
  const auto max_budget = static_cast<std::int64_t>(speed * 2.0 * static_cast<double>(kPumpPeriod.count()) * 1e6);
  if (budget > max_budget) {
    budget = max_budget;
    if (!pump_lagging_warned_) {
      pump_lagging_warned_ = true;
      spdlog::warn("this machine cannot run the mock at {}x real time; it runs as fast as it can", speed);
    }
  }
  while (budget > 0) {
    if (monotonicNowNs() - now > kMaxPumpWorkNs) break;  // the rest of this slice is dropped
    // Sensor time can wait for the clients, a real chip's FIFO cannot: the mock runs no further
    // ahead of the delivery thread than half of the hand-over holds.
    if (to_clients_.sizeSeenByProducer() > to_clients_.capacity() / 2) break;
    const std::int64_t step = std::min(budget, max_virtual_step_ns_);
    device_.virtual_clock->advanceNs(step);
    budget -= step;
    device_.mock->sync();
    driver_->onDataReady();
    // The driver's timers are on sensor time: run every one that is due.
    for (int guard = 0; guard < 64; ++guard) {
      const auto deadline = driver_->nextDeadlineNs();
      if (!deadline || *deadline > device_.virtual_clock->nowNs()) break;
      driver_->onTimer(device_.virtual_clock->nowNs());
    }
  }
}

void Gyrod::onSample(const driver::GyroSample& s) {
  last_sample_real_ns_ = monotonicNowNs();
  ProcessedSample out;
  try {
    out = pipeline_.process(s.seq, static_cast<double>(s.t_ns) * 1e-9, s.rate_dps, s.temp_c, s.accel_g);
  } catch (const std::exception& e) {  // a sample the statistics refuse (non-finite): skip it, say why
    spdlog::error("sample {} skipped: {}", s.seq, e.what());
    return;
  }
  if (out.held) {  // a still window is evaluated off the loop: published when it is done
    held_.push_back({false, s, {}});
    return;
  }
  publish(s, out);
  startStillWindowIfWaiting();  // this sample filled the window
}

void Gyrod::startStillWindowIfWaiting() {
  if (!pipeline_.stillWindowWaiting()) return;
  try {
    still_window_.start(
        [window = pipeline_.takeStillWindow()]() mutable { return evaluateStillWindow(std::move(window)); });
  } catch (const std::exception& e) {  // no thread: evaluate here, once, rather than hold the samples for ever
    spdlog::warn("the still period is evaluated on the sample loop ({})", e.what());
    StillWindowOutcome failed;
    failed.error = std::string("the still period could not be evaluated: ") + e.what();
    finishStillWindow(std::move(failed));
  }
}

void Gyrod::finishStillWindow(StillWindowOutcome&& outcome) {
  const std::span<const ProcessedSample> released = pipeline_.finishStillWindow(std::move(outcome));
  if (!pipeline_.lastStillWindowError().empty()) spdlog::error("{}", pipeline_.lastStillWindowError());
  if (pipeline_.stillPeriod().verdicts != still_verdicts_logged_) logStillPeriodVerdict();
  std::size_t next = 0, done = 0;
  for (; done < held_.size(); ++done) {
    const HeldEvent& e = held_[done];
    if (e.is_gap) {
      publishGap(e.gap);
    } else if (next < released.size()) {
      publish(e.sample, released[next++]);
    } else {
      break;  // held again: a new window filled from the held samples
    }
  }
  held_.erase(held_.begin(), held_.begin() + static_cast<std::ptrdiff_t>(done));
  startStillWindowIfWaiting();
}

void Gyrod::publish(const driver::GyroSample& s, const ProcessedSample& out) {
  if (pipeline_.stillPeriod().verdicts != still_verdicts_logged_) logStillPeriodVerdict();
  RateSample r;
  r.seq = out.seq;
  r.t_s = out.t_s;
  r.temp_c = out.temp_c;
  r.raw_dps = out.raw;
  if (out.filtered) {
    r.mean_dps = out.mean;
    r.kalman_dps = out.kalman;
  } else {  // still period: non-finite values are omitted from the line
    r.mean_dps = {kNaN, kNaN, kNaN};
    r.kalman_dps = {kNaN, kNaN, kNaN};
  }
  if (out.has_rate) {
    r.rate_dps = out.rate;
    r.bias_dps = out.rate_bias;
  } else {  // a start-up bias still being estimated
    r.rate_dps = {kNaN, kNaN, kNaN};
    r.bias_dps = {kNaN, kNaN, kNaN};
  }
  r.still = out.still;
  r.time_s = s.wall_ns != 0 ? static_cast<double>(s.wall_ns) * 1e-9 : kNaN;
  r.accel_g = s.accel_g;
  if (out.attitude) {
    const processing::attitude::AttitudeSample& a = *out.attitude;
    r.quat = a.q;
    r.roll_pitch_heading_deg = {a.roll_deg, a.pitch_deg, a.heading_deg};
    r.inclination_std_deg = a.inclination_std_deg;
    r.heading_std_deg = a.heading_std_deg;
  }
  LineForClients line;
  line.rate = r;
  queueForClients(line);
  if (recorder_) recorder_->pushSample(recordedSample(r, s.wall_ns));
  if (calibration_)
    if (const processing::RateEstimator* estimator = pipeline_.rateEstimator())
      calibration_->onSample(out.t_s, *estimator);
  if (live_) live_->onSample(out.t_s, out.raw, s.temp_c, out.still.value_or(false));
  ++samples_published_;
  last_temp_c_ = r.temp_c;
  last_t_s_ = r.t_s;
}

void Gyrod::onGap(const driver::SampleGap& gap) {
  pipeline_.discontinuity();
  if (!held_.empty()) {  // after samples that are held: in its place
    held_.push_back({true, {}, gap});
    return;
  }
  publishGap(gap);
}

void Gyrod::publishGap(const driver::SampleGap& gap) {
  ++gaps_;
  if (live_) live_->breakRun();
  missing_samples_ += gap.count;
  const std::string_view reason = driver::gapCauseName(gap.cause);  // a [a-z0-9_] token (docs/protocol.md)
  queueForClients(gapLine(gap.first_seq, gap.count, reason));
  if (recorder_) {
    const double t = last_t_s_ ? *last_t_s_ + 1.0 / config_.device.rate_hz : 0.0;
    recorder_->pushGap(gap.first_seq, t, static_cast<std::uint32_t>(std::min<std::uint64_t>(gap.count, UINT32_MAX)),
                       reason);
  }
}

void Gyrod::queueForClients(const LineForClients& line) {
  if (mqtt_) mqtt_->push(line);  // its own ring: never waits
  clients_to_wake_ = true;
  if (behind_count_ > 0) {  // lines the ring could not take before: one GAP for them first
    if (!to_clients_.tryPush(gapLine(behind_first_seq_, behind_count_, protocol::kDeliveryBehindGapReason))) {
      behind_count_ += line.kind == LineForClients::Kind::Rate ? 1 : line.gap_count;
      behind_total_ += line.kind == LineForClients::Kind::Rate ? 1 : 0;
      return;
    }
    behind_count_ = 0;
  }
  if (to_clients_.tryPush(line)) return;
  const bool rate = line.kind == LineForClients::Kind::Rate;
  behind_first_seq_ = rate ? line.rate.seq : line.gap_first_seq;
  behind_count_ = rate ? 1 : line.gap_count;
  if (rate) ++behind_total_;
  spdlog::warn("the delivery thread is {} lines behind the samples: the next lines are sent as a GAP delivery_behind",
               to_clients_.capacity());
}

void Gyrod::wakeDeliveryThread() {
  if (!clients_to_wake_) return;
  clients_to_wake_ = false;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(to_clients_fd_.get(), &one, sizeof one);
  if (mqtt_) mqtt_->wake();  // the same lines are in its ring
}

void Gyrod::publishQueuedLines() {
  std::uint64_t count = 0;
  [[maybe_unused]] const ssize_t n = ::read(to_clients_fd_.get(), &count, sizeof count);
  LineForClients line;
  while (to_clients_.tryPop(line)) {
    if (line.kind == LineForClients::Kind::Rate)
      server_->publishRate(line.rate);
    else
      server_->publishGap({line.gap_first_seq, line.gap_count, std::string_view(line.gap_reason.data())});
  }
  if (effects_queued_.load(std::memory_order_acquire) == 0) return;  // no lock on the per-sample path
  std::vector<std::string> effects;
  {
    const std::lock_guard lock(effects_mutex_);
    effects.swap(effect_lines_);
  }
  effects_queued_.fetch_sub(effects.size(), std::memory_order_relaxed);
  for (const std::string& e : effects) server_->publishEffect(e);
}

void Gyrod::deliveryThreadMain(int sample_policy, int sample_priority) {
  // Real-time one step below a real-time sample thread: a line waits neither for the machine's
  // other tasks nor for the flooded client thread, and never outranks the samples. The thread
  // only copies lines and sends them (a few microseconds per watcher), so it stays far from the
  // kernel's real-time limit, which a thread serving requests reaches.
  std::string note = "SCHED_OTHER, as the sample thread is not real-time above priority 1";
  bool real_time = false;
  if ((sample_policy == SCHED_FIFO || sample_policy == SCHED_RR) && sample_priority > 1) {
    sched_param fifo{};
    fifo.sched_priority = sample_priority - 1;
    const int rc = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &fifo);
    real_time = rc == 0;
    note = real_time ? fmt::format("SCHED_FIFO priority {}, one below the sample thread", fifo.sched_priority)
                     : fmt::format("SCHED_OTHER (SCHED_FIFO priority {} refused: {})", fifo.sched_priority,
                                   std::strerror(rc));
  }
  if (!real_time) {  // a thread starts with its creator's policy: the sample thread's
    const sched_param normal{};
    ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  }
  spdlog::info("delivery thread scheduling: {}", note);
  std::array<pollfd, 2> fds{};
  fds[0] = {to_clients_fd_.get(), POLLIN, 0};
  fds[1] = {stop_delivery_fd_.get(), POLLIN, 0};
  try {
    while (true) {
      if (::poll(fds.data(), fds.size(), -1) < 0) {
        if (errno == EINTR) continue;
        throw errnoError("poll on the delivery thread");
      }
      if (fds[1].revents != 0) return;
      publishQueuedLines();
    }
  } catch (const std::exception& e) {
    // As on the client thread: a fault of the daemon. Stop it rather than stream to nobody.
    spdlog::critical("the delivery thread failed: {}; stopping", e.what());
    ::kill(::getpid(), SIGTERM);
  }
}

namespace {
// Signals a thread's stop eventfd and waits for the thread to end (nothing if it never started).
void signalAndJoin(std::thread& thread, const Fd& stop_fd) {
  if (!thread.joinable()) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = ::write(stop_fd.get(), &one, sizeof one);
  thread.join();
}
}  // namespace

void Gyrod::stopDeliveryThread() { signalAndJoin(delivery_thread_, stop_delivery_fd_); }

void Gyrod::clientThreadMain() {
  // Never real-time, whatever gyrod runs as. A flood of requests keeps this thread busy; a busy
  // real-time thread starves the machine's other tasks, and the kernel then stops real-time work
  // on that CPU to let them run (RT throttling; the fair server of Linux 6.12+), the sample
  // thread's included: at 8 kHz, whose FIFO lasts 9 ms, that lost samples.
  const sched_param normal{};
  ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal);
  try {
    client_loop_.run();
  } catch (const std::exception& e) {
    // The server handles every client's errors itself: this is a fault of the daemon. Stop it
    // (SIGTERM's path, so that the recording is closed) rather than stream to nobody.
    spdlog::critical("the client thread failed: {}; stopping", e.what());
    ::kill(::getpid(), SIGTERM);
  }
}

void Gyrod::stopClientThread() { signalAndJoin(client_thread_, stop_clients_fd_); }

void Gyrod::onStatus(const driver::DeviceStatus& status) {
  if (status.state == driver::DeviceState::Streaming) notifyReadyOnce();
  std::string text = std::string("STATUS=") + driver::deviceStateName(status.state);
  if (!status.reason.empty()) text += ": " + status.reason;
  ::sd_notify(0, text.c_str());
}

void Gyrod::notifyReadyOnce() {
  if (ready_sent_) return;
  ready_sent_ = true;
  ::sd_notify(0, "READY=1");
  spdlog::info("device configured and streaming; socket listening: ready");
}

void Gyrod::petWatchdog() {
  // Only while fresh samples arrive (daemon/watchdog.hpp): a timer that pets blindly would hide a dead sensor.
  if (watchdogPingDue(monotonicNowNs(), last_sample_real_ns_, watchdog_usec_)) ::sd_notify(0, "WATCHDOG=1");
}

// On the reload's thread: nothing here touches the running daemon.
ReloadedFilter Gyrod::loadReload(const std::string& config_file, double device_rate_hz) {
  GyrodConfig fresh = loadConfigFile(config_file);
  fresh.device.rate_hz = device_rate_hz;  // [device] applies at restart
  ReloadedFilter reloaded;
  reloaded.rate_model = loadRateModel(fresh);
  reloaded.filter = fresh.filter;
  return reloaded;
}

void Gyrod::applyReload(ReloadedFilter&& reloaded) {
  try {
    const FilterConfig& f = reloaded.filter;
    LoadedRateModel& rate_model = reloaded.rate_model;
    if (!rate_model.warning.empty()) spdlog::warn("{}", rate_model.warning);
    pipeline_.reloadFilter(f.mean_window, f.mean_threshold_dps, {f.kalman.a, f.kalman.q, f.kalman.r});
    const bool new_rate_model = rate_model.identity != rate_model_.identity;
    if (new_rate_model) {
      pipeline_.reloadRateModel(rate_model.params);
      if (calibration_) calibration_->setFingerprint(rate_model.fingerprint);
      rate_model_ = std::move(rate_model);
    }
    config_.filter = f;
    ++reloads_;
    spdlog::info(
        "SIGHUP: filter reloaded from {} (L = {}, r = {} deg/s; rate stream: {}); other sections apply at "
        "restart",
        config_file_, f.mean_window, f.mean_threshold_dps,
        new_rate_model ? "restarted on " + rateModelDescription() : "unchanged");
  } catch (const std::exception& e) {
    spdlog::error("SIGHUP: keeping the running filter: {}", e.what());
  }
}

// Under the state mutex.
std::string Gyrod::biasDescription() const {
  std::ostringstream bias;
  bias << toString(pipeline_.biasOrigin());
  if (pipeline_.phase() != PipelinePhase::Running) {
    bias << " (estimating)";
  } else {
    bias.precision(6);
    bias << " [" << pipeline_.bias()[0] << ", " << pipeline_.bias()[1] << ", " << pipeline_.bias()[2] << "] deg/s";
  }
  return bias.str();
}

std::string Gyrod::rateModelDescription() const {
  if (pipeline_.rateModel() == RateModel::SensorModel) return "model " + config_.filter.model;
  return "bias";
}

namespace {

std::string_view stillCheckToken(StillPeriodState state) {
  switch (state) {
    case StillPeriodState::Collecting: return protocol::stillCheckName(protocol::StillCheck::Pending);
    case StillPeriodState::MovedRetrying: return protocol::stillCheckName(protocol::StillCheck::MovedRetrying);
    case StillPeriodState::Still: return protocol::stillCheckName(protocol::StillCheck::Still);
    case StillPeriodState::MovedKept: return protocol::stillCheckName(protocol::StillCheck::MovedKept);
    case StillPeriodState::None: break;
  }
  return {};
}

// What the last check found, for the log and STATUS still_check_detail.
std::string stillCheckDetail(const StillPeriodReport& r) {
  const auto& v = r.verdict;
  std::ostringstream s;
  s.precision(3);
  s << "window " << r.attempts << " of at most " << kMaxStillAttempts << ": axis "
    << "xyz"[v.axis % 3] << " Allan deviation " << v.adev_dps << " deg/s at tau " << v.tau_s << " s, "
    << (v.moved ? "over" : "within") << " the " << v.allowed_dps << " deg/s its own noise allows at rest";
  return s.str();
}

}  // namespace

void Gyrod::logStillPeriodVerdict() {
  const StillPeriodReport& r = pipeline_.stillPeriod();
  still_verdicts_logged_ = r.verdicts;
  const std::string detail = stillCheckDetail(r);
  switch (r.state) {
    case StillPeriodState::MovedRetrying:
      spdlog::warn("start-up still period: the board moved ({}); discarding it and estimating again over the next {} s",
                   detail, pipeline_.stillSecondsNeeded());
      break;
    case StillPeriodState::MovedKept:
      spdlog::error(
          "start-up still period: the board moved in every window ({}); using the last one: its bias is suspect "
          "(STATUS still_check moved_kept; restart gyrod with the board at rest)",
          detail);
      break;
    default: spdlog::info("start-up still period: at rest ({})", detail); break;
  }
}

std::string Gyrod::allanReplyLine() {
  const std::uint64_t cycles = refit_cycles_.load(std::memory_order_acquire);
  if (cycles != allan_cycle_served_) {  // a refit has completed since the line was built
    allan_reply_.invalidate();
    allan_cycle_served_ = cycles;
  }
  return allan_reply_.line();
}

// On the MQTT publisher's thread: each reads the state under the state mutex, as a client's
// request does.
void Gyrod::startMqtt() {
  mqtt_ = std::make_unique<MqttPublisher>(mqttSettings(config_, device_.description), mqttDerivedSources());
  if (const std::string obstacle = networkSandboxObstacle(parseMqttUrl(config_.mqtt.url).host); !obstacle.empty())
    spdlog::warn(
        "MQTT: {}, so no broker but one on this board can be reached; under systemd the unit's sandbox "
        "does this, and /usr/share/gyrod/gyrod-mqtt.conf is the drop-in that opens it (docs/fleet.md)",
        obstacle);
}

// On the MQTT publisher's thread, which starts while gyrod is still being built: each source
// answers nothing until run() has begun, then reads the state under the state mutex, as a
// client's request does.
MqttDerivedSources Gyrod::mqttDerivedSources() {
  MqttDerivedSources sources;
  sources.refit_cycles = [this] { return refit_cycles_.load(std::memory_order_acquire); };
  sources.allan_json = [this] {
    if (!running_.load(std::memory_order_acquire)) return std::string();
    std::string line = protocol::allanLine(allanReport());
    if (!line.empty() && line.back() == '\n') line.pop_back();
    return line;
  };
  sources.model_json = [this] {
    if (!running_.load(std::memory_order_acquire)) return std::string();
    const std::lock_guard state(state_mutex_);
    return nlohmann::json{
        {"rate_model", rateModelDescription()}, {"bias", biasDescription()}, {"filter_model", config_.filter.model}}
        .dump();
  };
  return sources;
}

AllanReport Gyrod::allanReport() {
  std::unique_lock state(state_mutex_);
  AllanWindowDeviations d = pipeline_.allanWindowDeviations();
  AllanReport report;
  report.tau0_s = d.tau0_s;
  report.window_s = d.window_s;
  // What the statistics are computed from, not what the window could hold: gaps excepted,
  // the time the samples cover.
  report.samples = d.samples;
  report.span_s = static_cast<double>(d.samples) * d.tau0_s;
  report.confidence = processing::AllanOptions{}.confidence;
  report.tau_s = std::move(d.tau_s);
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    for (std::size_t k = 0; k < kStreams; ++k) {
      report.curves[axis][k].adev_dps = std::move(d.oadev[axis][k]);
      report.curves[axis][k].points = std::move(d.points[axis][k]);
    }
    if (const auto& fit = pipeline_.noiseTerms()[axis]) {
      report.curves[axis][0].noise = fit->value;
      report.curves[axis][0].noise_uncertainty = fit->uncertainty;
    }
  }
  return report;
}

StatusReport Gyrod::statusReport() {
  // Before the state lock: the publisher's error string has a lock of its own, and the sample
  // loop waits for the state lock.
  std::optional<MqttStats> mqtt;
  if (mqtt_) mqtt = mqtt_->stats();
  const std::lock_guard state(state_mutex_);
  StatusReport r;
  r.uptime_s = static_cast<double>(monotonicNowNs() - start_real_ns_) * 1e-9;
  r.samples = samples_published_;
  r.gaps = gaps_;
  r.missing_samples = missing_samples_;
  const auto& c = driver_->counters();
  r.bus_errors = c.transfers_failed;
  r.resets = c.device_resets + c.fifo_resets;
  const driver::DeviceStatus& device_status = driver_->status();
  r.device_state = driver::deviceStateName(device_status.state);
  r.device_reason = device_status.reason;
  r.device_retrying = device_status.retrying;
  for (const auto& counter : driver::kDriverCounterNames)
    r.device_counters.push_back({std::string(counter.name), c.*counter.member});
  r.device = device_.description;
  r.nominal_rate_hz = config_.device.rate_hz;
  if (samples_published_ > 0) r.rate_hz = driver_->estimatedSampleRateHz();
  r.temp_c = last_temp_c_;
  r.bias_source = biasDescription();
  const StillPeriodReport& still = pipeline_.stillPeriod();
  if (still.state != StillPeriodState::None) {
    r.still_check = std::string(stillCheckToken(still.state));
    if (still.attempts > 0) r.still_check_detail = stillCheckDetail(still);
  }
  r.rate_model = rateModelDescription();
  if (recorder_) {
    r.recording = recorder_->currentFile();
    const RecorderStats stats = recorder_->stats();
    r.recorder = protocol::RecorderStatus{stats.written, stats.dropped, stats.lost_to_errors, stats.write_errors,
                                          recorder_->lastError()};
  }
  if (mqtt) r.mqtt = protocol::MqttStatus{mqtt->connected, mqtt->buffered, mqtt->dropped, std::move(mqtt->last_error)};
  if (calibration_ && pipeline_.rateModel() == RateModel::SensorModel)
    r.calibration_state = protocol::CalibrationStateStatus{calibration_->path(), calibration_->restored(),
                                                           calibration_->writes(), calibration_->lastError()};
  if (live_) r.live_check = live_->status();
  return r;
}

// The live check's part of STATUS, copied under the same lock.
protocol::EffectsReport Gyrod::effectsReport() {
  std::optional<protocol::LiveCheckStatus> live_check;
  {
    const std::lock_guard state(state_mutex_);
    if (live_) live_check = live_->status();
  }
  return protocol::effectsReportOf(live_check, live_check_off_);
}

}  // namespace gyrod::daemon
