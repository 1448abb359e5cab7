#include "cvslam/filter/invariant_chart_transport.h"

#include "cvslam/filter/vehicle_model.h"
#include "cvslam/geometry/so3.h"
#include "cvslam/ins/vehicle_state_layout.h"

namespace cvslam {

InvariantChartTransport::InvariantChartTransport(const Eigen::VectorXd& x_from,
                                                 const std::vector<EstimatedPose>& poses_from,
                                                 const SlamState& to, const VariableKey* anchor) {
  struct Attitude {
    VariableKey key;
    int index;          // first row of the attitude
    Eigen::Matrix3d M;  // M at the "from" estimate
  };
  std::vector<Attitude> attitudes;
  std::size_t j = 0;
  for (const StateVariable& v : to.variables()) {
    if (v.key.kind != VariableKey::Kind::kVehicle) continue;
    const EstimatedPose& from = poses_from[j++];
    const EstimatedPose at = vehicle_model::pose(to, v);
    const Eigen::Matrix3d M_from = vehicle_model::navRotationPerAttitude(from);
    const Eigen::Matrix3d M_to = vehicle_model::navRotationPerAttitude(at);
    const int a = v.index + vehicle::kAttitude;
    attitudes.push_back({v.key, a, M_from});
    const Eigen::Vector3d dp = at.p_BinN - from.p_BinN;
    couplings_.push_back({v.index + vehicle::kPosition, a, -so3::skew<double>(dp) * M_from});
    rotations_.push_back({v.index + vehicle::kVelocity, at.R_BtoN.transpose() * from.R_BtoN});
    rotations_.push_back({a, M_to.inverse() * M_from});
  }
  if (attitudes.empty()) return;
  const auto find = [&](const VariableKey* key) -> const Attitude* {
    if (key == nullptr) return nullptr;
    for (const Attitude& a : attitudes) {
      if (a.key == *key) return &a;
    }
    return nullptr;
  };
  const Attitude* fallback = find(anchor);  // `anchor`, else the first vehicle
  if (fallback == nullptr) fallback = &attitudes.front();
  for (const StateVariable& v : to.variables()) {
    if (v.key.kind == VariableKey::Kind::kVehicle) continue;
    const Eigen::Vector3d dl = to.value(v).head<3>() - x_from.segment<3>(v.index);
    if (dl.isZero(0.0)) continue;  // held landmarks: their mean never moves
    const Attitude* own = find(to.landmarkAnchor(v.key));
    const Attitude& a = own != nullptr ? *own : *fallback;
    couplings_.push_back({v.index, a.index, -so3::skew<double>(dl) * a.M});
  }
}

std::vector<EstimatedPose> InvariantChartTransport::vehiclePoses(const SlamState& state) {
  std::vector<EstimatedPose> poses;
  for (const StateVariable& v : state.variables()) {
    if (v.key.kind == VariableKey::Kind::kVehicle) poses.push_back(vehicle_model::pose(state, v));
  }
  return poses;
}

void InvariantChartTransport::multiplyByTransposeFromRight(Eigen::MatrixXd& M) const {
  // By columns (contiguous in memory); every coupling reads the attitude columns before they
  // are rotated. Couplings write distinct columns: no aliasing.
  for (const Coupling& c : couplings_) {
    M.middleCols<3>(c.row).noalias() += M.middleCols<3>(c.attitude) * c.C.transpose();
  }
  for (const Rotation& r : rotations_) {
    M.middleCols<3>(r.row) = (M.middleCols<3>(r.row) * r.R.transpose()).eval();
  }
}

void InvariantChartTransport::multiplyFromLeft(Eigen::MatrixXd& M) const {
  // The same order by rows: every coupling reads the attitude rows before they are rotated.
  for (const Coupling& c : couplings_) {
    M.middleRows<3>(c.row).noalias() += c.C * M.middleRows<3>(c.attitude);
  }
  for (const Rotation& r : rotations_) {
    M.middleRows<3>(r.row) = (r.R * M.middleRows<3>(r.row)).eval();
  }
}

void InvariantChartTransport::multiplyJacobian(MeasurementBatch& batch) const {
  // (H J)(:, attitude) = H(:, attitude) M̄⁻¹M̂ + Σ H(:, coupled) C: rotate first, the coupled
  // position and landmark columns are never rotated.
  for (const Rotation& r : rotations_) batch.rotateColumns(r.row, r.R);
  for (const Coupling& c : couplings_) batch.addColumns(c.attitude, c.row, c.C);
}

const VariableKey* observingVehicle(const SlamState& state, const MeasurementBatch& batch) {
  for (const StateVariable& v : state.variables()) {
    if (v.key.kind == VariableKey::Kind::kVehicle &&
        !batch.H().middleCols(v.index + vehicle::kAttitude, 3).isZero(0.0)) {
      return &v.key;
    }
  }
  return nullptr;
}

}  // namespace cvslam
