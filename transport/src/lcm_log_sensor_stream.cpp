#include "cvslam/lcm/lcm_log_sensor_stream.h"

#include <lcm/eventlog.h>

#include <set>

#include "cvslam/lcm/channels.h"
#include "cvslam/lcm/codec.h"
#include "cvslam/lcm/header_peek.h"
#include "cvslam/lcm/sensor_convert.h"

namespace cvslam::transport {
namespace {

bool isSensorStream(Stream s) {
  return s == Stream::kImu || s == Stream::kGroundTruth || s == Stream::kFeatures ||
         s == Stream::kStereo;
}

template <typename Msg>
bool decodeEvent(const void* data, std::size_t size, int agent_id, SensorEvent& e) {
  auto m = decodeMessage<Msg>(data, size);
  return m.ok() && toSensorEvent(*m, agent_id, &e);
}

// Decodes one logged sensor message into `e`; false if it does not decode or validate.
bool toEvent(Stream stream, const void* data, std::size_t size, int agent_id, SensorEvent& e) {
  switch (stream) {
    case Stream::kImu:
      return decodeEvent<cvslam::imu_t>(data, size, agent_id, e);
    case Stream::kGroundTruth:
      return decodeEvent<cvslam::pose_t>(data, size, agent_id, e);
    case Stream::kFeatures:
      return decodeEvent<cvslam::stereo_features_t>(data, size, agent_id, e);
    case Stream::kStereo:
      return decodeEvent<cvslam::stereo_image_t>(data, size, agent_id, e);
    default:
      return false;
  }
}

}  // namespace

Expected<std::unique_ptr<LcmLogSensorStream>> LcmLogSensorStream::open(const std::string& path,
                                                                       int agent_id) {
  // A first pass for the UAV's time span (the merged source needs its end before playing).
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "r");
  if (log == nullptr) return Status::Error("cannot read the LCM log '" + path + "'");
  int64_t first = -1, last = -1;
  while (lcm_eventlog_event_t* ev = lcm_eventlog_read_next_event(log)) {
    const auto id = parseChannel(ev->channel);
    if (id && id->agent_id == agent_id && isSensorStream(id->stream)) {
      if (const auto h = peekHeader(ev->data, static_cast<std::size_t>(ev->datalen))) {
        if (first < 0) first = h->utime;
        last = std::max(last, h->utime);
      }
    }
    lcm_eventlog_free_event(ev);
  }
  lcm_eventlog_destroy(log);
  if (first < 0)
    return Status::Error("no sensor data of UAV " + std::to_string(agent_id) + " in '" + path +
                         "'");
  log = lcm_eventlog_create(path.c_str(), "r");
  if (log == nullptr) return Status::Error("cannot read the LCM log '" + path + "'");
  std::unique_ptr<LcmLogSensorStream> stream(new LcmLogSensorStream(agent_id, log));
  stream->first_us_ = first;
  stream->end_play_us_ = last - first;
  return stream;
}

Expected<std::vector<int>> LcmLogSensorStream::agentsIn(const std::string& path) {
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "r");
  if (log == nullptr) return Status::Error("cannot read the LCM log '" + path + "'");
  std::set<int> ids;
  while (lcm_eventlog_event_t* ev = lcm_eventlog_read_next_event(log)) {
    const auto id = parseChannel(ev->channel);
    if (id && id->agent_id && *id->agent_id >= 1 && isSensorStream(id->stream))
      ids.insert(*id->agent_id);
    lcm_eventlog_free_event(ev);
  }
  lcm_eventlog_destroy(log);
  if (ids.empty())
    return Status::Error("no UAV<id>/IMU, /GT, /FEATURES or /STEREO in '" + path + "'");
  return std::vector<int>(ids.begin(), ids.end());
}

LcmLogSensorStream::~LcmLogSensorStream() {
  lcm_eventlog_destroy(log_);
}

bool LcmLogSensorStream::next(SensorEvent& event) {
  while (lcm_eventlog_event_t* ev = lcm_eventlog_read_next_event(log_)) {
    const auto id = parseChannel(ev->channel);
    SensorEvent e;
    const bool mine = id && id->agent_id == agent_id_ && isSensorStream(id->stream);
    const bool ok = mine && toEvent(id->stream, ev->data, ev->datalen, agent_id_, e);
    if (mine && !ok) ++invalid_;
    lcm_eventlog_free_event(ev);
    if (!ok) continue;
    e.play_us = e.t_us - first_us_;
    event = std::move(e);
    return true;
  }
  return false;
}

}  // namespace cvslam::transport
