#pragma once
// gyrod wired together: device → driver → pipeline → socket clients and recorder. Data flows
// one way:
//   FIFO bytes → samples (driver/) → filters and statistics (daemon/sample_pipeline) →
//   RATE/GAP lines (daemon/unix_socket_server) and the recording (daemon/recorder).
// Three threads:
//  - the sample thread (the process's main thread, SCHED_FIFO under the systemd unit), with
//    its epoll loop (daemon/event_loop.hpp): the device, the pipeline, the refit and reload
//    results, signals and the watchdog. It hands each sample to the delivery thread through a
//    lock-free ring and never touches a client;
//  - the delivery thread (SCHED_FIFO one step below a real-time sample thread): takes the
//    lines from the ring, formats them and moves them into the watching clients' buffers and
//    sockets (UnixSocketServer::publishRate, publishGap), and nothing else;
//  - the client thread (SCHED_OTHER), with its own epoll loop: the socket, every client's
//    requests and replies, what the delivery thread leaves it (EPOLLOUT, dropping clients).
//    However many clients flood it, it only ever competes with the sample thread for the
//    state mutex, which it holds for the copy of one STATUS or ALLAN report, and with the
//    delivery thread for a client's buffer, held for the copy of one line (priority
//    inheritance: daemon/priority_inheritance_mutex.hpp).
// Nothing on the per-sample path allocates or blocks: the recorder is a lock-free ring
// drained by its own thread, so is the hand-over to the clients, and every client has a
// bounded buffer.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "daemon/allan_reply_cache.hpp"
#include "daemon/calibration_keeper.hpp"
#include "daemon/client_handover.hpp"
#include "daemon/config.hpp"
#include "daemon/device_backend.hpp"
#include "daemon/event_loop.hpp"
#include "daemon/live_checker.hpp"
#include "daemon/memory_budget.hpp"
#include "daemon/mqtt_publisher.hpp"
#include "daemon/noise_refit_worker.hpp"
#include "daemon/off_loop_job.hpp"
#include "daemon/priority_inheritance_mutex.hpp"
#include "daemon/recorder.hpp"
#include "daemon/reload_worker.hpp"
#include "daemon/sample_pipeline.hpp"
#include "daemon/spsc_ring.hpp"
#include "daemon/unix_socket_server.hpp"
#include "driver/mpu6050_driver.hpp"

namespace gyrod::daemon {

// The rate stream's model as read from filter.model; `identity` tells a SIGHUP whether it
// changed (the path, the low-pass and the file's contents).
struct LoadedRateModel {
  std::optional<processing::RateEstimatorParameters> params;
  std::string identity;
  std::string fingerprint;  // formats::biasModelFingerprint: the calibration state's key
  std::string warning;      // for the log, written by the loop thread (the load may run on another)
};

// What a SIGHUP reads and checks off the loop: the [filter] section and its rate model.
struct ReloadedFilter {
  FilterConfig filter;
  LoadedRateModel rate_model;
};

// How long a SIGHUP's reading and checking may take before it is abandoned.
inline constexpr std::chrono::milliseconds kReloadTimeLimit{5000};

class Gyrod final : public driver::SampleSink, public ServerContent {
 public:
  // Builds everything from the configuration; throws with a one-line message when the
  // device, the socket, the recording or a model file cannot be set up.
  Gyrod(const GyrodConfig& config, std::string config_file);
  ~Gyrod() override;
  Gyrod(const Gyrod&) = delete;
  Gyrod& operator=(const Gyrod&) = delete;

  // Runs until SIGTERM or SIGINT; returns the process exit status.
  int run();

  // driver::SampleSink
  void onSample(const driver::GyroSample& sample) override;
  void onGap(const driver::SampleGap& gap) override;
  void onStatus(const driver::DeviceStatus& status) override;
  // ServerContent: called on the client thread; each takes the state mutex for its copy.
  AllanReport allanReport() override;
  std::string allanReplyLine() override;
  StatusReport statusReport() override;
  protocol::EffectsReport effectsReport() override;

 private:
  static LoadedRateModel loadRateModel(const GyrodConfig& config);
  static PipelineSettings pipelineSettings(const GyrodConfig& config, const LoadedRateModel& rate_model);
  std::string rateModelDescription() const;
  std::string startCalibrationKeeper();
  void startRecorder(const std::string& started_from);
  void startLiveCheck();
  // The live check's change as an EFFECT line for the delivery thread (sample thread).
  void queueEffect(const processing::LiveEffect& e);
  void logStillPeriodVerdict();
  void serviceDriver();
  void rearmDriverTimer();
  void pumpVirtualClock();
  static ReloadedFilter loadReload(const std::string& config_file, double device_rate_hz);
  void applyReload(ReloadedFilter&& reloaded);
  void petWatchdog();
  void notifyReadyOnce();
  // One processed sample to the clients and the recording.
  void publish(const driver::GyroSample& s, const ProcessedSample& out);
  void publishGap(const driver::SampleGap& gap);
  // The start-up still window, evaluated off the loop (SamplePipeline::takeStillWindow).
  void startStillWindowIfWaiting();
  void finishStillWindow(StillWindowOutcome&& outcome);
  // The hand-over to the delivery thread (sample thread: queue and wake; delivery thread: take).
  void queueForClients(const LineForClients& line);
  void wakeDeliveryThread();
  void publishQueuedLines();
  // The sample thread's policy and priority, as run() found them.
  void deliveryThreadMain(int sample_policy, int sample_priority);
  void clientThreadMain();
  void startMqtt();
  MqttDerivedSources mqttDerivedSources();
  std::string biasDescription() const;
  void stopDeliveryThread();
  void stopClientThread();

  GyrodConfig config_;
  std::string config_file_;
  // Held by the sample loop while it dispatches, by the client thread while it copies a report.
  PriorityInheritanceMutex state_mutex_;
  EventLoop loop_;              // the sample thread's
  EventLoop client_loop_;       // the client thread's
  LoadedRateModel rate_model_;  // first: a bad model file is a configuration error (exit 78)
  DeviceParts device_;
  std::unique_ptr<driver::Mpu6050Driver> driver_;
  SamplePipeline pipeline_;
  std::unique_ptr<CalibrationKeeper> calibration_;  // with a state directory
  std::unique_ptr<LiveChecker> live_;               // [check] enabled, with filter.model's still detector
  std::string live_check_off_;                      // without live_: why (set before the threads start)
  // EFFECT lines from the sample thread to the delivery thread (a few an hour at most): the
  // sample thread appends, the delivery thread takes them all; each holds it for a move.
  PriorityInheritanceMutex effects_mutex_;
  std::vector<std::string> effect_lines_;
  std::atomic<std::size_t> effects_queued_{0};  // the delivery thread takes the mutex only when > 0
  NoiseRefitWorker noise_refit_;
  AllanReplyCache allan_reply_;
  std::unique_ptr<UnixSocketServer> server_;
  std::unique_ptr<Recorder> recorder_;
  std::unique_ptr<MqttPublisher> mqtt_;
  ReloadWorker<ReloadedFilter> reload_;
  OffLoopJob<StillWindowOutcome> still_window_;
  // While a still window is evaluated, the samples (and gaps) in the order they came.
  struct HeldEvent {
    bool is_gap = false;
    driver::GyroSample sample;
    driver::SampleGap gap;
  };
  std::vector<HeldEvent> held_;
  Fd driver_timer_;  // absolute CLOCK_MONOTONIC deadline of the driver (real-time clocks)
  SpscRing<LineForClients> to_clients_;
  Fd to_clients_fd_;                    // eventfd: lines wait in to_clients_
  Fd stop_delivery_fd_;                 // eventfd: the delivery thread stops
  Fd stop_clients_fd_;                  // eventfd: the client thread's loop stops
  bool clients_to_wake_ = false;        // sample thread: lines queued since the last wake-up
  std::uint64_t behind_first_seq_ = 0;  // sample thread: lines the ring could not take,
  std::uint64_t behind_count_ = 0;      //   sent as one GAP delivery_behind when it can
  std::uint64_t behind_total_ = 0;
  std::atomic<bool> running_{false};                      // run() has begun: every member is built
  std::atomic<std::uint64_t> refit_cycles_{0};            // completed by the sample thread
  std::uint64_t allan_cycle_served_ = ~std::uint64_t{0};  // client thread: the cached line's cycle
  std::thread delivery_thread_;
  std::thread client_thread_;

  std::int64_t start_real_ns_ = 0;
  std::int64_t last_pump_real_ns_ = 0;
  std::int64_t last_sample_real_ns_ = 0;
  std::uint64_t watchdog_usec_ = 0;
  bool ready_sent_ = false;
  bool pump_lagging_warned_ = false;
  std::int64_t max_virtual_step_ns_ = 0;  // the accelerated mock's longest step of sensor time
  std::uint64_t samples_published_ = 0;
  std::uint64_t gaps_ = 0;
  std::uint64_t missing_samples_ = 0;
  std::optional<double> last_temp_c_;
  std::optional<double> last_t_s_;
  std::uint64_t still_verdicts_logged_ = 0;  // StillPeriodReport::verdicts already logged
  std::uint64_t reloads_ = 0;
};

}  // namespace gyrod::daemon
