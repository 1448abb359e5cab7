#pragma once
// The ground station's joint filter of centralised cooperative VSLAM (CC-VSLAM, thesis
// §6.1–6.5; docs/cooperation.md). One SlamState holds a vehicle block per UAV
// (VariableKey::vehicle(agent_id), with bias states as configured) and ONE shared map; the
// chapter-5 recipe of visual_inertial_slam.h runs per batch on the batch's vehicle with the
// same models (StereoUpdater, LandmarkInitialiser, LoopCloser, KNearestMapManager), so a joint
// filter with one vehicle is VisualInertialSlam.
//
// Per batch of UAV j (processBatch), in the order the caller gives (batches in time order,
// ties by agent id):
//   0. validate (cc_observation_batch.h); a batch of an unknown agent, older than or as old as
//      the vehicle's last batch, or before its start time is rejected and counted, nothing
//      changes;
//   1. propagate vehicle j through the batch's IMU samples to t_us (InsPropagator on its block,
//      cross-covariances with every other vehicle and landmark follow: CovarianceHelper);
//   2. associate: each observation gets a joint landmark id — the true id (association
//      `true_ids`, feature-level simulation) or, for `local_ids`, the joint id its
//      (agent, local id) was mapped to, a new local id being matched to a joint landmark of the
//      same feature index by descriptor distance and position (else a fresh joint id); and a
//      type of §6.3.1: 1 = in UAV j's map, 2 = in the joint map from another UAV only, 3 = new;
//   3. k-nearest map management for UAV j over the joint map: the candidates are j's active
//      landmarks, the state landmarks j observes now (type 2 included) and the archived ones j
//      itself mapped that it observes now; j keeps its k nearest to its m* active; a landmark
//      active for no UAV is archived; chosen archived ones are re-activated as
//      slam.recent_reentry / slam.reactivation say: held ones exactly, by covariance
//      intersection with the whole joint state (ω by the log-determinant of every UAV's block
//      after the update: the team pays 1/ω), or independent with the UAV's position
//      covariance on top (reactivation_inflation).
//      Another UAV's archived landmark is not re-activated but mapped anew by j (step 5): as an
//      independent prior it would repeat information the team already used. The state holds
//      the union of the UAVs' active sets (≤ M·(vehicle + 3(k + max_new)));
//   4. rendezvous (see the options), loop closing (LoopCloser on j's landmark book; a
//      landmark's last-seen time is the latest of any UAV's, so a landmark another UAV kept
//      observing is no loop; one nobody saw for loop_closure_min_age_s is, also across UAVs;
//      the loop's iterated update moves what is correlated with j and every UAV's book
//      follows, followCorrection), then the gated stereo update of the
//      other observations. A type-2 observation updates j's vehicle, the shared landmark and,
//      through their cross-covariances, the UAV that mapped it;
//   5. initialise j's never-seen landmarks (type 3). A landmark first seen by two UAVs in the
//      same camera epoch is initialised from the first batch processed and updated by the
//      other's batch right after it (type 2 there): the same information as initialising from
//      both, without a joint inverse model.
// Each UAV has its own landmark book (landmark_book.h): the landmarks of the state it has
// observed, with the landmark's first estimate and OC yaw direction copied from the book that
// holds it (one linearisation point and one null-space direction per landmark, shared by every
// observer), its own last-seen time and pending loops, and its own u_v.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/coop/cc_observation_batch.h"
#include "cvslam/core/status.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/filter/update_policy.h"
#include "cvslam/ins/ins_propagator.h"
#include "cvslam/slam/vehicle_estimate.h"
#include "cvslam/slam/visual_inertial_slam.h"

namespace cvslam {
class ConfigNode;
}

namespace cvslam::coop {

struct CcVehicle;

/// How the ground station names the landmarks of the batches.
enum class CcAssociation {
  kTrueIds,   ///< landmark_id is the true id, shared by every UAV (feature-level simulation)
  kLocalIds,  ///< landmark_id is the agent's local id; joint ids by index + descriptor
};

/// Options of the joint filter (config/ground_station.yaml).
struct CcTeamFilterOptions {
  /// The joint filter uses the invariant error chart, each landmark with the rotation error of
  /// the vehicle that mapped it (SlamState::landmarkAnchor), and Euler angles: more accurate
  /// and closer to its NEES than the additive chart with first estimates and the constraint on
  /// every UAV of seeds 31–40 (docs/results/cc_vs_dc.md "Error chart").
  CcTeamFilterOptions() { setJointEstimator(); }
  /// The agents' sections as `slam` (cvslam_run --mode cc without --gs-config), with the
  /// joint filter's estimator choices above.
  void useAgentOptions(const VisualInertialSlamOptions& agent) {
    slam = agent;
    setJointEstimator();
  }
  /// The image keypoints' measurement model below (image_*) from the agents' slam options as
  /// their image path runs them (VisualFrontEndOptions::resolve).
  void useAgentImageModel(const SlamOptions& images) {
    image_second_order_noise = images.second_order_noise;
    image_second_order_mean = images.second_order_mean;
    image_pixel_sigma = images.pixel_sigma;
  }
  /// The recipe's options, sections `filter:`, `ins:`, `map:`, `slam:` as in agent.yaml (the
  /// per-vehicle IMU noise may be given to addVehicle).
  VisualInertialSlamOptions slam;
  // Section `cc:`.
  CcAssociation association = CcAssociation::kTrueIds;  ///< `true_ids` or `local_ids`
  /// local_ids (image keypoints): slam.second_order_noise is this instead, as the agents'
  /// frontend.second_order_noise (real keypoints are closer than the assumed pixel σ, and the
  /// term cost the recordings; docs/filter.md "The first second").
  bool image_second_order_noise = false;
  /// local_ids: slam.second_order_mean is this instead, as the agents' frontend.second_order_mean.
  bool image_second_order_mean = false;
  /// local_ids: slam.pixel_sigma is this instead, as the agents' frontend.pixel_sigma (detected
  /// keypoints are localised tighter than the feature-level simulator's noise).
  double image_pixel_sigma = 0.3;
  /// local_ids: a new local id matches a joint landmark of the same feature index only with a
  /// descriptor L2 distance at most this (as DC's coop.max_descriptor_distance).
  double max_descriptor_distance = 250.0;
  /// local_ids: ... and, for a joint landmark in the state, when the observation's squared
  /// Mahalanobis distance from its prediction from this UAV, with the innovation covariance
  /// H P Hᵀ + R of the joint state, is at most this (χ²(4) 99.9 %: as the agents' gate). Two
  /// UAVs that have drifted metres apart still meet where their joint covariance says they may.
  double association_gate_chi2 = 18.47;
  /// local_ids: an archived joint landmark (no correlation left) only when the landmark
  /// triangulated from the observation at the vehicle's estimate lies at most this far from it [m].
  double max_association_distance_m = 3.0;
  int max_vehicles = 16;  ///< addVehicle beyond this fails (bounded state)
  /// A vehicle's IMU gap longer than slam.ins.max_dt and at most this (the samples of batches
  /// lost on the way: one 20 Hz batch is 50 ms) is bridged by samples interpolated linearly
  /// between its two ends at the rate of the batch's own samples; a longer gap refuses the
  /// batch (kPropagation) [s].
  double max_imu_gap_s = 0.25;
  /// A landmark re-activated independently (slam.reactivation / recent_reentry: independent)
  /// re-enters with its archived covariance plus this times the re-activating UAV's position
  /// covariance (the landmark is correlated with the whole team, which an independent re-entry
  /// would forget); 0: the archived covariance alone. Not used by intersection re-entry.
  double reactivation_inflation = 1.0;
  /// Rendezvous: when a UAV whose position 1σ is at least this meets another UAV's map for
  /// the first time (or first after slam.loop_closure_min_age_s) and is much more uncertain
  /// than that UAV (rendezvous_sigma_ratio), its observations of that map are applied first, as
  /// one iterated EKF update (slam.loop_closure_passes iterations) linearised first at the UAV
  /// shifted onto the met landmarks; the books follow the correction [m]; 0: never. 0.1: a
  /// first meeting of practically any UAV (0.5 left UAVs with a 1σ of 0.3 m, metres and
  /// degrees off, to a single EKF update; docs/ground_station.md "Rendezvous").
  double rendezvous_min_sigma_m = 0.1;
  /// ... and only when its position 1σ is at least this times the other UAV's; 0: whatever the
  /// other's. Through per-observation gated updates instead, linearised metres from where the
  /// other map has the landmarks, thesis_loop's two drifted UAVs came out of their meeting with
  /// a common yaw error of 1° (3.7σ) and CC worse than DC (docs/cooperation.md "Rendezvous").
  double rendezvous_sigma_ratio = 0.0;

  /// Reads the sections (does not call root.finish(): the caller may read its own sections).
  Status load(const ConfigNode& root);
  /// Loads and validates a YAML file (unknown keys are errors; `ground_station:`, the
  /// process's own section, is skipped).
  static Expected<CcTeamFilterOptions> loadFile(const std::string& path);

 private:
  /// Euler angles, the invariant chart, neither first-estimate Jacobians nor the constraint;
  /// held landmarks kept by their distance to the UAVs' views (SlamOptions::HeldEviction).
  void setJointEstimator();
};

/// Why processBatch refused a batch. Each names something true of the batch or of the filter
/// at it, never one for another: a filter that fails on a well-formed batch is kPropagation or
/// kUpdate, not invalid input.
enum class CcRefusal {
  kNone,          ///< accepted
  kUnknownAgent,  ///< no vehicle with that agent id (not started, or removed)
  kStale,         ///< not after the vehicle's last batch or its start time
  kInvalid,       ///< validateBatch failed, or local landmark ids under true-id association
                  ///< (CcStepReport::defect names the kind; local_ids for the latter)
  kPropagation,   ///< the vehicle's IMU cannot take it to the frame time (a gap longer than
                  ///< cc.max_imu_gap_s, or a non-finite INS step); the vehicle needs a restart
  kUpdate,        ///< the recipe after the propagation failed (association, map management,
                  ///< loop closing, the update or initialisation): the vehicle stays propagated
};

/// The reason's key in the counts, the report line and stats.json: unknown_agent, stale,
/// invalid_<defect> (validateBatch), propagation, update.
std::string refusalKey(CcRefusal refusal, const std::string& defect);

/// What one processBatch did.
struct CcStepReport {
  int agent_id = 0;
  int64_t t_us = 0;
  bool accepted = false;  ///< false: refused (refusal, reason)
  CcRefusal refusal = CcRefusal::kNone;
  std::string defect;              ///< kInvalid: the kind validateBatch named
  std::string reason;              ///< why refused, one line
  FrameReport frame;               ///< the recipe's report (slam/visual_inertial_slam.h)
  int type1 = 0;                   ///< observations of landmarks in this UAV's map (§6.3.1)
  int type2 = 0;                   ///< of landmarks in the joint map from other UAVs only
  int type3 = 0;                   ///< of landmarks new to the joint map
  double imu_gap_bridged_s = 0.0;  ///< IMU bridged before this batch (a batch lost on the way)
  double step_ms = 0.0;            ///< wall time of the step
  int state_size = 0;              ///< joint state size after the step
  int vehicles = 0;                ///< vehicles in the state after the step
};

/// Per-UAV counts.
struct CcAgentCounts {
  long batches = 0;                     ///< accepted
  long rejected = 0;                    ///< refused batches of this (known) agent, every reason
  std::map<std::string, long> refused;  ///< per reason (refusalKey)
  long imu_gaps_bridged = 0;            ///< IMU gaps bridged (batches lost on the way)
  double imu_gap_bridged_s = 0.0;       ///< their total length [s]
  long observations = 0;
  long type1 = 0, type2 = 0, type3 = 0;
  long loop_closures = 0;
  long rendezvous = 0;  ///< first contacts with another UAV's map taken as a rendezvous
};

/// Running statistics of the joint filter.
struct CcTeamStatistics {
  long batches = 0;                 ///< accepted
  long rejected_invalid = 0;        ///< validateBatch failed
  long rejected_stale = 0;          ///< not after the vehicle's last batch / start time
  long rejected_unknown_agent = 0;  ///< no vehicle with that agent id
  long rejected_propagation = 0;    ///< the vehicle's IMU could not reach the frame
  long rejected_update = 0;         ///< the recipe failed after the propagation
  std::vector<double> step_ms;      ///< wall time per accepted step [ms]
  int max_state_size = 0;
  std::map<int, CcAgentCounts> agents;
  FilterStatistics filter;  ///< over every update of the joint state

  long rejected() const {
    return rejected_invalid + rejected_stale + rejected_unknown_agent + rejected_propagation +
           rejected_update;
  }
  /// "UAV3 propagation 1, invalid_pixels 2; UAV4 …" over the UAVs with refusals; "none".
  std::string refusalSummary() const;
};

/// local_ids: a landmark new to one UAV that the ground station took for another UAV's (its
/// observations are type 2 from then on). For audits against a simulator's truth (cvslam_run).
struct CcCrossAssociation {
  int agent = 0;                 ///< the UAV whose agent landmark was associated
  int64_t local_id = -1;         ///< that agent's landmark id
  int mapper = 0;                ///< the UAV whose agent's landmark first made the joint one
  int64_t mapper_local_id = -1;  ///< that agent's landmark id
};

class CcTeamFilter {
 public:
  explicit CcTeamFilter(const CcTeamFilterOptions& options);
  ~CcTeamFilter();
  CcTeamFilter(CcTeamFilter&&) noexcept;
  CcTeamFilter& operator=(CcTeamFilter&&) noexcept;

  /// Adds UAV `agent_id` with its rectified stereo camera at a known pose (§6.3.1): x_v, P_v
  /// at t_us (9 or 15 entries, matching options.slam.ins.estimate_imu_bias), independent of
  /// the rest of the state. `ins`: its IMU noise (null: options.slam.ins; estimate_imu_bias
  /// must agree). Adding a vehicle already present re-initialises it (its block is replaced,
  /// uncorrelated; its landmark bookkeeping and the joint map stay): an agent's own estimate after
  /// a restart.
  Status addVehicle(int agent_id, const StereoCamera& camera, int64_t t_us,
                    const Eigen::VectorXd& x_v, const Eigen::MatrixXd& P_v,
                    const InsPropagatorOptions* ins = nullptr);
  bool hasVehicle(int agent_id) const;
  /// Marginalises the vehicle out; its landmarks stay in the joint map (archived when no
  /// other UAV keeps them active).
  Status removeVehicle(int agent_id);
  /// Agent ids of the vehicles, ascending.
  std::vector<int> vehicles() const;

  /// One batch (see the recipe above). A refused batch returns an error Status and is counted
  /// in statistics() per reason; `report` (may be null) says why. Refused as unknown agent,
  /// stale, invalid or for the propagation, it leaves the filter unchanged; refused for the
  /// update, the vehicle stays propagated to the batch time (a consistent state, without this
  /// frame's observations). An IMU gap from the vehicle's last sample to the batch's first
  /// longer than ins.max_dt (a batch lost on the way) is bridged by samples interpolated
  /// between the two, when it is at most cc.max_imu_gap_s; after a kPropagation refusal the
  /// vehicle must be started again (addVehicle) from the agent's own estimate.
  Status processBatch(const CcObservationBatch& batch, CcStepReport* report = nullptr);

  /// The vehicle's estimate at the time of its last batch (or its start).
  Expected<VehicleEstimate> estimate(int agent_id) const;
  /// Joint map: landmarks in the state and archived, sorted by id.
  std::vector<MapLandmark> map() const;
  /// Increments with every change of the map (accepted batch, vehicle added or removed).
  int64_t mapVersion() const { return map_version_; }
  const CcTeamStatistics& statistics() const { return stats_; }
  const SlamState& state() const;
  const CcTeamFilterOptions& options() const { return o_; }
  /// local_ids: the cross-UAV associations made since the last call (at most the latest
  /// kMaxCrossAssociations are kept between calls).
  std::vector<CcCrossAssociation> takeCrossAssociations();
  static constexpr std::size_t kMaxCrossAssociations = 4096;
  /// Landmark ids active for this UAV (its k nearest), ascending; empty if unknown.
  std::vector<int64_t> activeLandmarks(int agent_id) const;
  /// UAV `agent_id`'s models take their Jacobians at the truth this oracle gives (the ideal
  /// EKF, slam/linearisation_oracle.h: a diagnostic of simulation; null: off), now and
  /// whenever the vehicle is (re-)added. The oracle must outlive the filter.
  void setLinearisationOracle(int agent_id, const LinearisationOracle* oracle);

 private:
  struct Impl;
  /// Steps 2–5 of the recipe for vehicle v (propagated to the batch time).
  Status runRecipe(CcVehicle& v, const CcObservationBatch& batch, CcStepReport* r);
  /// The rendezvous update of vehicle v with the other maps' landmarks it meets.
  Status meetMap(CcVehicle& v, FrameReport* fr);
  CcTeamFilterOptions o_;
  std::unique_ptr<Impl> impl_;
  CcTeamStatistics stats_;
  int64_t map_version_ = 0;
};

}  // namespace cvslam::coop
