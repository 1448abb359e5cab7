#pragma once
// CcTeamFilter's private state (cc_team_filter.h), shared by its source files.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "cvslam/coop/cc_team_filter.h"
#include "cvslam/ins/imu_noise_monitor.h"
#include "cvslam/slam/k_nearest_map_manager.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/landmark_initialiser.h"
#include "cvslam/slam/loop_closer.h"
#include "cvslam/slam/reactivation_intersection.h"
#include "cvslam/slam/stereo_updater.h"
#include "cvslam/slam/vehicle_propagation.h"

namespace cvslam::coop {

/// One UAV of the joint state: its block's key, its models and its bookkeeping.
struct CcVehicle {
  CcVehicle(int id, const StereoCamera& cam, const InsPropagatorOptions& ins,
            const SlamOptions& slam)
      : agent_id(id),
        key(VariableKey::vehicle(static_cast<uint64_t>(id))),
        camera(cam),
        propagator(ins),
        noise_monitor(ins.noise_monitor),
        updater(key, cam, slam),
        initialiser(key, cam, slam),
        loop_closer(key, cam, slam) {}

  void setOracle(const LinearisationOracle* oracle) {
    propagation.setOracle(oracle);
    updater.setOracle(oracle);
    initialiser.setOracle(oracle);
  }

  int agent_id;
  VariableKey key;
  StereoCamera camera;
  InsPropagator propagator;
  ImuNoiseMonitor noise_monitor;  // the IMU's in-flight noise (ins.measure_noise_density)
  VehiclePropagation propagation;
  LandmarkBook book;  // the state landmarks this UAV observed
  StereoUpdater updater;
  LandmarkInitialiser initialiser;
  LoopCloser loop_closer;
  std::vector<int64_t> active;            // its k nearest (ascending), all in the state
  std::optional<Eigen::Vector3d> m_star;  // the virtual point of its latest batch (§5.8)
  int64_t last_batch_us = 0;
  bool has_batch = false;
  std::unordered_map<int64_t, int64_t> joint_of_local;  // local_ids association
};

/// What the ground station knows of a joint landmark besides the filter: for association.
struct CcLandmarkInfo {
  uint32_t index = 0;
  std::vector<uint8_t> descriptor;
  std::vector<int> observers;  // agent ids, ascending
  int mapped_by = -1;          // the agent whose batch initialised it
};

struct CcTeamFilter::Impl {
  SlamState state;
  LandmarkArchive archive;
  KNearestMapManager map_manager;
  /// Loop landmarks re-enter by covariance intersection with the whole joint state when
  /// SlamOptions::reactivation says so (reactivation_intersection.h); bounds set by the
  /// constructor.
  ReactivationIntersection reactivation{ReactivationOptions{}};
  UpdatePolicy policy;
  Status policy_status;
  std::map<int, std::unique_ptr<CcVehicle>> vehicles;
  std::map<int, const LinearisationOracle*> oracles;      // setLinearisationOracle
  std::unordered_map<int64_t, CcLandmarkInfo> landmarks;  // every landmark of the joint map
  std::unordered_map<uint32_t, std::vector<int64_t>> by_index;
  /// Last time two UAVs (lower id first) shared an observed landmark outside a pending loop.
  std::map<std::pair<int, int>, int64_t> contact;
  int64_t next_fresh_id = int64_t{1} << 40;  // ids for landmarks the agents left unnamed
  StereoFrameObservations frame;             // the batch with joint ids (reused)
  MeasurementBatch meet_batch;               // rendezvous updates (reused)
  StereoFrameObservations gate_frame;        // withinGate (reused)
  /// local_ids: the agent and agent landmark id that made each joint landmark.
  std::unordered_map<int64_t, std::pair<int, int64_t>> made_from;
  std::vector<CcCrossAssociation> cross;  // since the last takeCrossAssociations
  MeasurementBatch gate_batch;            // withinGate (reused)
  Eigen::MatrixXd gate_PHt, gate_S;       // withinGate (reused)
  std::vector<int> types;                 // per observation of `frame`: 1, 2, 3
  std::vector<int64_t> meet;              // rendezvous landmarks of `frame` (ascending)
  std::vector<int64_t> reentered;         // step 3: those it brought back (ascending)

  /// Step 2: `frame` = the batch with joint ids, `types` per observation; the state landmarks
  /// this UAV observes enter its book (a copy of their record, with the latest last-seen time).
  void associate(CcVehicle& v, const CcObservationBatch& batch, const CcTeamFilterOptions& o);
  /// local_ids: the joint id of an observation's local id (matched or fresh).
  int64_t jointOf(CcVehicle& v, const StereoObservation& obs, const CcTeamFilterOptions& o,
                  const std::vector<int64_t>& used);
  /// Whether `obs`, taken as an observation of state landmark `id` by v, passes the χ²(4) gate
  /// `chi2` at the joint estimate and covariance.
  bool withinGate(const CcVehicle& v, const StereoObservation& obs, int64_t id, double chi2);
  /// Step 3 for UAV v over the joint map; `reentered` lists what it brought back.
  Status manageMap(CcVehicle& v, int64_t t_us, const SlamOptions& slam,
                   double reactivation_inflation, FrameReport* r);
  /// After step 5: the new landmarks (state variables from `first_new` on) join v's active set;
  /// v becomes an observer of every landmark of the frame.
  void afterInitialisation(CcVehicle& v, std::size_t first_new);

  bool activeForAnother(int64_t id, int agent_id) const;
  /// The latest time any UAV saw landmark `id` (its books' last_seen_us).
  int64_t lastSeen(int64_t id) const;
  /// Whether v meeting the map of `other` now is a rendezvous (cc_team_filter.h).
  bool rendezvous(const CcVehicle& v, int other, int64_t t_us, const CcTeamFilterOptions& o) const;
  /// Whether v seeing a landmark these UAVs observed is a rendezvous with one of them.
  bool meetsAnotherMap(const CcVehicle& v, const std::vector<int>& observers, int64_t t_us,
                       const CcTeamFilterOptions& o) const;
  /// The landmarks step 3 brought back into the state (`reentered`; a held one comes back
  /// exactly, after associate() looked for meetings) are met as associate() meets a state
  /// landmark: added to `meet` when it is a rendezvous. Loop landmarks (`loop`, ascending) are
  /// the loop closer's.
  void meetReentered(const CcVehicle& v, const std::vector<int64_t>& loop, int64_t t_us,
                     const CcTeamFilterOptions& o);
  /// Rendezvous: the translation (median per axis) from where v sees the met landmarks to
  /// where the map has them.
  Eigen::Vector3d meetShift(const CcVehicle& v) const;
  /// After an update that moved the joint estimate far (rendezvous, loop closure): every
  /// UAV's book follows (followCorrection of loop_closer.h).
  void followCorrectionEverywhere(const Eigen::VectorXd& mean_before);
  /// 1σ of a vehicle's position [m] (√(trace/3)).
  double positionSigma(const CcVehicle& v) const;
  /// The book record of `id` in any vehicle's book (first by agent id), else null.
  const LandmarkBookEntry* recordOf(int64_t id) const;
  /// Archives `id`: removes it from every book, merges the records (latest last-seen); held
  /// in the state as a Schmidt variable as the joint map's `slam` options say (held_landmarks,
  /// held_eviction, anchor_landmarks; landmark_lifecycle.h).
  void archiveEverywhere(int64_t id, int64_t t_us, const SlamOptions& slam);
  void noteObserver(int64_t id, int agent_id, const StereoObservation& obs);
};

}  // namespace cvslam::coop
