#pragma once
// Steps 2–3 of the recipe (visual_inertial_slam.h) that move landmarks between the state and the
// archive (thesis §5.8), shared by VisualInertialSlam and the ground station's joint filter
// (coop/cc_team_filter.h), which decides per vehicle which landmarks leave or return:
//  - the virtual point m* of a frame seen from a vehicle of the state;
//  - archiving: exact marginalisation, the archive keeps the mean, the marginal covariance and
//    the landmark's book record;
//  - re-activation: the archived landmark re-enters with its archived mean and marginal
//    covariance, uncorrelated (loop closing, §5.5.2), and enters the given book; how a
//    landmark re-enters is the options' choice (reentryOf, SlamOptions::Reentry);
//  - holding (SlamOptions::held_landmarks): the most recently archived landmarks stay in the
//    state as Schmidt variables, and such a landmark re-enters exactly, correlations and all.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "cvslam/camera/stereo_camera.h"
#include "cvslam/camera/stereo_observation.h"
#include "cvslam/filter/slam_state.h"
#include "cvslam/slam/k_nearest_map_manager.h"
#include "cvslam/slam/landmark_archive.h"
#include "cvslam/slam/landmark_book.h"
#include "cvslam/slam/slam_options.h"

namespace cvslam {

/// m* of `frame` from `vehicle` of the state: on its camera's optical axis at the median
/// stereo depth of the observations (the map manager's scene depth).
Eigen::Vector3d frameVirtualPoint(const KNearestMapManager& manager, const StereoCamera& camera,
                                  const SlamState& state, const VariableKey& vehicle,
                                  const StereoFrameObservations& frame);

/// The landmark ids the frame's observations name (landmark_id ≥ 0), sorted: what the map
/// manager counts as observed now (MapCandidate::observed).
std::vector<int64_t> observedLandmarkIds(const StereoFrameObservations& frame);

/// Moves landmark `id` from the state to the archive at t_us with `record` (its book entry,
/// already removed from the book(s); none: an empty record). No-op when not in the state.
/// With held_capacity > 0 the landmark also stays in the state as a held (Schmidt) variable
/// (slam_state.h, kHeldLandmark), and held landmarks are marginalised until at most
/// held_capacity remain: with no `keep_near` points those archived longest ago, else those
/// farthest from the nearest of the points (SlamOptions::HeldEviction; ties: the older, then the
/// smaller id). With anchor_capacity > 0, of those beyond held_capacity up to anchor_capacity
/// more stay held as anchors spread over the map (SlamOptions::anchor_landmarks). Their archive
/// entries are exact either way (a held landmark's mean and marginal covariance do not change).
void archiveLandmark(SlamState& state, LandmarkArchive& archive, int64_t id,
                     std::optional<LandmarkBookEntry> record, int64_t t_us, int held_capacity = 0,
                     const std::vector<Eigen::Vector3d>& keep_near = {}, int anchor_capacity = 0);

/// True when archived landmark `id` is held in the state (it then re-enters exactly).
bool isHeld(const SlamState& state, int64_t id);

/// Whether archived landmark `id` (entry `a`) may re-enter the state at t_us: a held one at any
/// age, any other once it left at least options.reactivation_min_age_s ago.
bool mayReenter(const SlamState& state, int64_t id, const ArchivedLandmark& a, int64_t t_us,
                const SlamOptions& options);

/// How archived landmark `a`, chosen at t_us to re-enter the state, does so
/// (SlamOptions::Reentry): `recent_reentry` when it was seen less than loop_closure_min_age_s
/// ago (not a loop landmark), else `reactivation`.
SlamOptions::Reentry reentryOf(const ArchivedLandmark& a, int64_t t_us, const SlamOptions& options);

/// Moves archived landmark `id` into the state and `book`; false when not archived.
/// A held landmark keeps its slot and its cross-covariances (exact re-entry);
/// otherwise `extra_covariance` is added to its archived covariance (the joint filter's
/// conservative re-entry, coop/cc_team_filter.h; zero: the archived marginal as is).
bool reactivateLandmark(SlamState& state, LandmarkBook& book, LandmarkArchive& archive, int64_t id,
                        const Eigen::Matrix3d& extra_covariance = Eigen::Matrix3d::Zero());

}  // namespace cvslam
