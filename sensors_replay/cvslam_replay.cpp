// cvslam_replay — publishes EuRoC folders, or a scenario simulated (and rendered) live, over
// LCM on UAV<id>/IMU, UAV<id>/STEREO (or UAV<id>/FEATURES), UAV<id>/GT (docs/architecture.md,
// docs/run_format.md). Real time, scaled, as fast as possible, or in lockstep with the subscribers'
// STATUS.
//
//   cvslam_replay --scenario config/scenarios/team3_aerial.yaml --rate 1
//   cvslam_replay --dataset 1:data/team3/uav1 --dataset 2:data/team3/uav2 --lockstep

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "cvslam/io/process_shell.h"
#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/lcm_bus.h"
#include "cvslam/lcm/lcm_log_sensor_stream.h"
#include "cvslam/lcm/sensor_publisher.h"
#include "cvslam/sensors/euroc_sensor_stream.h"
#include "cvslam/sensors/lockstep_tracker.h"
#include "cvslam/sensors/merged_sensor_source.h"
#include "cvslam/simrun/render_world_choice.h"
#include "cvslam/simrun/simulated_sensor_stream.h"
#include "replay_args.h"

namespace {

using cvslam::Status;
using Clock = std::chrono::steady_clock;

// Its stop flag (SIGINT/SIGTERM) is polled by the publishing loop.
const cvslam::cli::ProcessShell shell("cvslam_replay");
int fail(const std::string& message) {
  return shell.fail(message);
}

cvslam::Expected<cvslam::MergedSensorSource> makeSource(const cvslam::replay::Args& a,
                                                        bool verbose) {
  cvslam::PlayWindow window{a.start, a.duration};
  std::vector<std::unique_ptr<cvslam::AgentSensorStream>> streams;
  if (!a.scenario.empty()) {
    auto scenario = cvslam::sim::Scenario::loadFile(a.scenario);
    if (!scenario.ok()) return scenario.status();
    if (a.seed >= 0) scenario->seed = static_cast<uint64_t>(a.seed);
    if (a.duration > 0.0) scenario->duration = std::min(scenario->duration, a.start + a.duration);
    cvslam::SimulatedSensorOptions o;
    o.render = a.sensing == "images";
    o.start = a.start;
    if (o.render) {
      auto world = cvslam::chooseRenderWorld(*scenario, a.world);
      if (!world.ok()) return world.status();
      o.render_world = world->options;
      o.render_options = world->render;
      if (verbose)
        std::fprintf(stderr, "cvslam_replay: rendering world %s\n", world->reason.c_str());
    } else if (verbose) {
      std::fprintf(stderr, "cvslam_replay: feature-only simulation, index = true landmark id\n");
    }
    auto team = cvslam::simulateTeam(*scenario, o);
    if (!team.ok()) return team.status();
    // The simulator and world stay alive through the streams' shared pointers.
    streams = std::move(team->streams);
  } else if (!a.log.empty()) {
    auto ids = cvslam::transport::LcmLogSensorStream::agentsIn(a.log);
    if (!ids.ok()) return ids.status();
    for (int id : *ids) {
      auto s = cvslam::transport::LcmLogSensorStream::open(a.log, id);
      if (!s.ok()) return s.status();
      streams.push_back(std::move(*s));
    }
  } else {
    for (const auto& d : a.datasets) {
      auto s = cvslam::EurocSensorStream::open(d.id, d.path, a.start,
                                               std::llround(a.camera_time_offset * 1e6));
      if (!s.ok()) return s.status();
      streams.push_back(std::move(*s));
    }
  }
  if (!a.agents.empty()) {
    std::vector<std::unique_ptr<cvslam::AgentSensorStream>> kept;
    for (auto& s : streams)
      if (std::find(a.agents.begin(), a.agents.end(), s->agentId()) != a.agents.end())
        kept.push_back(std::move(s));
    if (kept.size() != a.agents.size())
      return cvslam::Status::Error("--agents names a UAV the source does not have");
    streams = std::move(kept);
  }
  return cvslam::MergedSensorSource(std::move(streams), window);
}

/// Lockstep state shared with the bus's receive thread.
struct Lockstep {
  std::mutex mutex;
  std::condition_variable changed;
  std::unique_ptr<cvslam::LockstepTracker> tracker;
};

/// Waits until every participant acknowledged the closed epochs; false on stop or timeout.
Status waitForAcks(Lockstep& lock, double timeout_s) {
  std::unique_lock<std::mutex> guard(lock.mutex);
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (!lock.tracker->ready()) {
    if (shell.stopping()) return Status::Ok();
    if (Clock::now() > deadline) {
      std::string who;
      for (int id : lock.tracker->waitingFor())
        who += " " + cvslam::transport::channels::status(id);
      return Status::Error("lockstep: no acknowledgement within " + std::to_string(timeout_s) +
                           " s on" + who);
    }
    lock.changed.wait_for(guard, std::chrono::milliseconds(50));
  }
  return Status::Ok();
}

/// Subscribes to the participants' STATUS and starts the bus: lockstep publishing.
Status startLockstep(cvslam::transport::LcmBus& bus, const cvslam::replay::Args& args,
                     const std::vector<int>& agents, Lockstep& lockstep) {
  const std::vector<int> participants = args.participants.empty() ? agents : args.participants;
  lockstep.tracker = std::make_unique<cvslam::LockstepTracker>(participants, agents);
  for (int id : participants) {
    Status s = bus.subscribe<cvslam::status_t>(cvslam::transport::channels::status(id),
                                               [&lockstep, id](const cvslam::status_t& m) {
                                                 std::lock_guard<std::mutex> guard(lockstep.mutex);
                                                 lockstep.tracker->onStatus(id, m.processed_utime);
                                                 lockstep.changed.notify_all();
                                               });
    if (!s.ok()) return s;
  }
  Status s = bus.start();
  if (!s.ok()) return s;
  if (!args.quiet)
    std::fprintf(stderr, "cvslam_replay: lockstep, waiting for STATUS of %zu participant(s)\n",
                 participants.size());
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  cvslam::replay::Args args;
  if (auto exit_code = cvslam::replay::parseArgs(argc, argv, args)) return *exit_code;
  shell.stopOnSignals();

  auto source = makeSource(args, !args.quiet);
  if (!source.ok()) return fail(source.status().message());
  const std::vector<int> agents = source->agentIds();

  cvslam::transport::BusOptions bus_options;
  bus_options.url = args.lcm_url;
  auto bus = cvslam::transport::LcmBus::create(bus_options);
  if (!bus.ok()) return fail(bus.status().message());

  Lockstep lockstep;
  if (args.lockstep) {
    Status s = startLockstep(**bus, args, agents, lockstep);
    if (!s.ok()) return fail(s.message());
  }

  cvslam::transport::SensorPublisherOptions publish_options;
  publish_options.png = args.compress;
  publish_options.ground_truth = !args.no_gt;
  cvslam::transport::SensorPublisher publisher(**bus, publish_options);

  const bool tty = isatty(STDERR_FILENO) != 0 && !args.quiet;
  const double end_s = static_cast<double>(source->endPlayUs()) * 1e-6;
  Clock::time_point wall0;
  int64_t play0 = 0;
  bool first = true;
  double max_lag_s = 0.0;  // worst delay behind the --rate schedule
  auto last_print = Clock::now();
  if (args.start_at > 0.0) {  // one clock for replays started apart (several hosts)
    const auto begin = std::chrono::system_clock::time_point(
        std::chrono::duration_cast<std::chrono::system_clock::duration>(
            std::chrono::duration<double>(args.start_at)));
    while (!shell.stopping() && std::chrono::system_clock::now() < begin)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  cvslam::SensorEvent e;
  while (!shell.stopping() && source->next(e)) {
    if (lockstep.tracker) {
      bool wait = false;
      {
        std::lock_guard<std::mutex> guard(lockstep.mutex);
        if (first || lockstep.tracker->startsNewEpoch(e.type, e.play_us)) {
          if (!first) lockstep.tracker->closeEpoch();
          wait = true;
        }
      }
      if (wait) {
        Status s = waitForAcks(lockstep, args.lockstep_timeout);
        if (!s.ok()) return fail(s.message());
      }
    }
    if (first) {
      wall0 = Clock::now();
      play0 = e.play_us;
      first = false;
    }
    if (!lockstep.tracker && args.rate > 0.0) {
      const auto target =
          wall0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                      static_cast<double>(e.play_us - play0) * 1e-6 / args.rate));
      // Sleep in slices so that Ctrl-C is honoured promptly.
      while (!shell.stopping() && Clock::now() < target)
        std::this_thread::sleep_until(
            std::min(target, Clock::now() + std::chrono::milliseconds(100)));
      if (shell.stopping()) break;
      // Rendering or decoding slower than the requested rate shows up here.
      max_lag_s = std::max(max_lag_s, std::chrono::duration<double>(Clock::now() - target).count());
    }
    Status s = publisher.publish(e);
    if (!s.ok()) return fail(s.message());
    if (lockstep.tracker) {
      std::lock_guard<std::mutex> guard(lockstep.mutex);
      lockstep.tracker->published(e.agent_id, e.type, e.t_us, e.play_us);
    }
    if (tty && Clock::now() - last_print > std::chrono::milliseconds(500)) {
      last_print = Clock::now();
      std::fprintf(stderr, "\rcvslam_replay: %7.2f / %.2f s  %lld msgs  %.1f MB   ",
                   static_cast<double>(e.play_us) * 1e-6, end_s,
                   static_cast<long long>(publisher.messages()),
                   static_cast<double>(publisher.bytes()) / 1e6);
    }
  }
  if (!source->status().ok()) return fail(source->status().message());
  if (lockstep.tracker && !shell.stopping() && !first) {
    // The last epoch: wait for it too, so that a lockstep run ends fully processed.
    {
      std::lock_guard<std::mutex> guard(lockstep.mutex);
      lockstep.tracker->closeEpoch();
    }
    Status s = waitForAcks(lockstep, args.lockstep_timeout);
    if (!s.ok()) return fail(s.message());
  }
  const double wall = first ? 0.0 : std::chrono::duration<double>(Clock::now() - wall0).count();
  if (!args.quiet) {
    std::fprintf(
        stderr, "%scvslam_replay: %s %lld messages, %.1f MB in %.2f s (%.0f msgs/s, %.2f MB/s)%s\n",
        tty ? "\n" : "", shell.stopping() ? "stopped after" : "published",
        static_cast<long long>(publisher.messages()), static_cast<double>(publisher.bytes()) / 1e6,
        wall, wall > 0 ? static_cast<double>(publisher.messages()) / wall : 0.0,
        wall > 0 ? static_cast<double>(publisher.bytes()) / 1e6 / wall : 0.0,
        lockstep.tracker
            ? (", " + std::to_string(lockstep.tracker->epochsClosed()) + " epochs").c_str()
            : "");
    if (max_lag_s > 0.1) {
      std::fprintf(stderr, "cvslam_replay: fell behind the --rate %g schedule by up to %.2f s\n",
                   args.rate, max_lag_s);
    }
  }
  (*bus)->stop();
  return 0;
}
