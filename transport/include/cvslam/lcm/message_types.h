#pragma once
// All generated cvslam LCM message types (lcmtypes/*.lcm, docs/architecture.md) in one include.

#include "cvslam/agent_map_t.hpp"
#include "cvslam/agent_state_t.hpp"
#include "cvslam/agent_summary_t.hpp"
#include "cvslam/feature_index_t.hpp"
#include "cvslam/gs_state_t.hpp"
#include "cvslam/header_t.hpp"
#include "cvslam/imu_t.hpp"
#include "cvslam/map_t.hpp"
#include "cvslam/observation_batch_t.hpp"
#include "cvslam/pose_t.hpp"
#include "cvslam/shared_landmarks2_t.hpp"
#include "cvslam/shared_landmarks_t.hpp"
#include "cvslam/shared_request_t.hpp"
#include "cvslam/status_t.hpp"
#include "cvslam/stereo_features_t.hpp"
#include "cvslam/stereo_image_t.hpp"
