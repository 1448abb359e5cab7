#pragma once
// The team as a viewer sees it (cvslam_view, docs/view.md): per UAV the estimated track with its
// position covariance, the ground truth when known, the landmark map (active / archived), the
// ground station's estimate in CC; links between UAVs while they exchange landmarks; per UAV
// position σ, NEES, frame latency and bytes/s over time. No transport: the process feeds it
// plain structs decoded from the bus, and clients take JSON deltas from it (a ViewCursor per
// client), so a slow client never holds the producer.
//
// Frames and units: NED positions [m], dataset time t [s]; bytes/s and latency use wall time.
// Thread-safety: none; the caller serialises access (one mutex in the process).

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/core/status.h"
#include "cvslam/io/config_node.h"
#include "cvslam/io/json_file.h"

namespace cvslam::view {

struct TeamViewOptions {
  /// A new track sample is kept when the UAV moved this far or `track_max_gap_s` passed
  /// since the last kept one (the page draws lines between samples) [m].
  double track_min_step_m = 0.05;
  double track_max_gap_s = 0.5;  ///< [s] dataset time
  /// Samples kept per UAV (estimate and truth each); beyond, every other old one is dropped,
  /// so memory is bounded on long runs.
  int max_samples_per_uav = 20000;
  /// A link stays drawn this long after the exchange that made it (dataset time) [s].
  double link_hold_s = 1.0;
  int max_links = 5000;             ///< exchanges remembered (oldest forgotten)
  double rate_window_s = 2.0;       ///< bytes/s averaged over this wall-time window [s]
  double truth_tolerance_s = 0.02;  ///< truth within this of an estimate is its truth (NEES) [s]
  int max_agents = 64;              ///< UAVs tracked at most (ids beyond are counted, ignored)

  /// view.yaml (config/view.yaml): the keys above.
  Status load(const ConfigNode& node);
};

/// An estimate of one UAV (its POSE, or the ground station's GS_STATE).
struct ViewEstimate {
  int agent_id = 0;
  double t = 0.0;                               ///< [s]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< NED [m]
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();  ///< position covariance [m²]
  double yaw = 0.0;                             ///< heading [rad] (arrow on the page)
  int landmarks_active = -1;                    ///< −1: unknown (GS_STATE)
  int landmarks_archived = -1;
  /// Figures a finished run recorded (run_view.h); live, they come from the arrivals.
  std::optional<double> latency_ms, bytes_per_s;
};

struct ViewLandmark {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();  ///< NED [m]
  float std_m = 0.0f;                           ///< sqrt(trace(P_LL)/3) [m]
  bool active = false;                          ///< in the filter state (k nearest)
};

/// Kinds of link between two participants (0 = the ground station).
enum class LinkKind { kRequest, kLandmarks, kObservations };
const char* linkKindName(LinkKind kind);

/// One client's position in the stream of deltas.
struct ViewCursor {
  bool started = false;
  std::map<int, std::size_t> samples, truth;  ///< per UAV: samples already sent
  std::map<int, int64_t> map_version, samples_epoch;
  int64_t joint_map_version = -1;
  int64_t links = 0;  ///< links already sent (global sequence)
};

class TeamView {
 public:
  explicit TeamView(TeamViewOptions options = {});

  void addEstimate(const ViewEstimate& e, double wall_s);
  void addGroundStationEstimate(const ViewEstimate& e);
  void addTruth(int agent_id, double t, const Eigen::Vector3d& p);
  void setMap(int agent_id, double t, std::vector<ViewLandmark> landmarks);
  void setJointMap(double t, std::vector<ViewLandmark> landmarks);
  /// A frame reached UAV `agent_id` at wall time `wall_s` (its estimate's arrival gives the
  /// latency).
  void addFrameArrival(int agent_id, double t, double wall_s);
  void addLink(int from, int to, double t, LinkKind kind);
  /// Bytes a UAV sent on its cooperation channels (summary, index, requests, landmarks,
  /// observations to the ground station).
  void addTraffic(int agent_id, std::size_t bytes, double wall_s);
  void setAgentInfo(int agent_id, const std::string& mode, int64_t boot_id);
  void setLandmarkCounts(int agent_id, int active, int archived);
  /// A message that failed to decode or validate (or came from an id beyond max_agents).
  /// A process's STATUS (status_t health and one-line message): an agent's own (id > 0) or
  /// the ground station's (id 0, e.g. the batches it refused per UAV).
  void setStatus(int process_id, int health, const std::string& message);
  void countMalformed(const std::string& channel);
  void countMessage() { ++messages_; }

  /// Everything the client has not seen yet, and moves its cursor; the first call of a cursor
  /// gives the whole state ("reset": true).
  Json delta(ViewCursor& cursor, double wall_s) const;

  std::size_t agentCount() const { return agents_.size(); }
  int64_t malformed() const { return malformed_total_; }
  int64_t messages() const { return messages_; }

 private:
  struct Sample {
    double t;
    Eigen::Vector3d p;
    double cxx, cxy, cyy;  ///< N-E block of the position covariance [m²]
    double sigma;          ///< sqrt(trace P_pos) [m]
    double yaw;
    std::optional<double> nees, latency_ms, bytes_per_s;
    int landmarks_active;
  };
  struct Agent {
    std::string mode;
    int64_t boot_id = 0;
    std::vector<Sample> samples;
    int64_t samples_epoch = 0;  ///< +1 when old samples were thinned (clients restart)
    std::vector<std::pair<double, Eigen::Vector3d>> truth;
    std::deque<std::pair<double, Eigen::Vector3d>> recent_truth;
    std::optional<Sample> last;  ///< the latest estimate, kept or not
    double last_kept_t = -1e300;
    int landmarks_active = 0, landmarks_archived = 0;
    std::vector<ViewLandmark> map;
    double map_t = 0.0;
    int64_t map_version = 0;
    std::optional<ViewEstimate> gs;
    std::deque<std::pair<double, double>> frame_arrivals;  ///< (t, wall)
    std::deque<std::pair<double, std::size_t>> traffic;    ///< (wall, bytes)
    int64_t bytes_total = 0;
    int health = 0;      ///< status_t HEALTH_* of its last STATUS
    std::string status;  ///< its message
  };
  struct Link {
    int from, to;
    double t;
    LinkKind kind;
  };

  Agent* agent(int agent_id);
  std::optional<double> bytesPerSecond(const Agent& a, double wall_s) const;
  template <typename T>
  void bound(std::vector<T>& v, int64_t* epoch);

  TeamViewOptions o_;
  std::map<int, Agent> agents_;
  std::deque<Link> links_;
  int64_t links_total_ = 0;  ///< links ever added (links_ holds the last max_links)
  std::vector<ViewLandmark> joint_map_;
  double joint_map_t_ = 0.0;
  int64_t joint_map_version_ = 0;
  double latest_t_ = 0.0;
  std::map<std::string, int64_t> malformed_;
  int64_t malformed_total_ = 0, messages_ = 0, ignored_agents_ = 0;
  std::optional<std::pair<int, std::string>> gs_status_;  ///< the ground station's health, message
};

}  // namespace cvslam::view
