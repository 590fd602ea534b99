#include "common/estimator/checkpoint.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "common/estimator/nav_state_of.h"
#include "common/estimator/state_helper.h"

namespace vimot {
namespace estimator {

namespace {

constexpr char kMagic[8] = {'V', 'I', 'M', 'O', 'T', 'C', 'K', '2'};
constexpr std::size_t kFixedDoubles = 16 + 6;  // q p v bg ba, the reading's w a

uint64_t fnv1a(const char* data, std::size_t n) {
  uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// The fixed doubles in file order, as views into the checkpoint.
std::vector<double*> fixed_fields(RobotCheckpoint& c) {
  std::vector<double*> out;
  auto add = [&out](double* p, int n) {
    for (int i = 0; i < n; ++i) out.push_back(p + i);
  };
  NavState& s = c.state;
  add(s.q_GtoI.data(), 4);
  add(s.p_IinG.data(), 3);
  add(s.v_IinG.data(), 3);
  add(s.bias_gyro.data(), 3);
  add(s.bias_accel.data(), 3);
  add(c.last_imu.w_IinI.data(), 3);
  add(c.last_imu.a_IinI.data(), 3);
  return out;
}

std::size_t payload_size(std::size_t n) {
  const std::size_t dim = 15 + 3 * n;
  return (3 + n) * sizeof(int64_t) + (kFixedDoubles + 6 * n + dim * dim) * sizeof(double);
}

template <typename T>
void put(std::string* out, const T& v) {
  out->append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <typename T>
T take(const char** at) {
  T v;
  std::memcpy(&v, *at, sizeof(T));
  *at += sizeof(T);
  return v;
}

}  // namespace

RobotCheckpoint checkpoint_of(const VioEstimator& estimator) {
  RobotCheckpoint c;
  c.state = nav_state_of(estimator, /*updated=*/true);
  // After an update the buffer starts with the last sample at or before
  // the state time (Propagator::clean_older_than).
  for (const ImuData& imu : estimator.propagator().buffer()) {
    if (imu.utime > c.state.utime) break;
    c.last_imu = imu;
  }
  const State& st = estimator.state();
  std::vector<TypePtr> vars = {st.imu()};
  for (const auto& [id, lm] : st.slam_features()) {
    if (lm->representation() != LandmarkRepresentation::kGlobalXyz) continue;  // its anchor clone is not kept
    c.landmarks.push_back({id, lm->value(), lm->fej()});
    vars.push_back(lm);
  }
  c.covariance = StateHelper::marginal_covariance(st, vars);
  return c;
}

void restore(const RobotCheckpoint& checkpoint, VioEstimator* estimator) {
  const NavState& s = checkpoint.state;
  ImuValue x;
  x.q_GtoI = s.q_GtoI;
  x.p_IinG = s.p_IinG;
  x.v_IinG = s.v_IinG;
  x.bg = s.bias_gyro;
  x.ba = s.bias_accel;
  estimator->initialize(x, s.utime, s.covariance);
  State& st = estimator->mutable_state();
  for (std::size_t i = 0; i < checkpoint.landmarks.size(); ++i) {
    const CheckpointLandmark& l = checkpoint.landmarks[i];
    auto lm = std::make_shared<Landmark>(l.feature_id, LandmarkRepresentation::kGlobalXyz);
    lm->set_value(l.p_FinG);
    lm->set_fej(l.p_FinG_fej);
    const int row = 15 + 3 * static_cast<int>(i);
    StateHelper::add_variable(st, lm, checkpoint.covariance.block(row, row, 3, 3),
                              checkpoint.covariance.block(row, 0, 3, row));
    StateHelper::register_slam_feature(st, lm);
  }
  estimator->prepend_imu(checkpoint.last_imu);
}

bool write_checkpoint(const std::string& path, const RobotCheckpoint& checkpoint, std::string* why) {
  RobotCheckpoint c = checkpoint;
  const std::size_t n = c.landmarks.size();
  const std::size_t dim = 15 + 3 * n;
  if (static_cast<std::size_t>(c.covariance.rows()) != dim || static_cast<std::size_t>(c.covariance.cols()) != dim) {
    *why = "checkpoint covariance is not " + std::to_string(dim) + " square";
    return false;
  }
  std::string payload;
  payload.reserve(payload_size(n));
  put(&payload, c.state.utime);
  put(&payload, c.last_imu.utime);
  put(&payload, static_cast<int64_t>(n));
  for (const auto& l : c.landmarks) put(&payload, l.feature_id);
  for (const double* v : fixed_fields(c)) put(&payload, *v);
  for (const auto& l : c.landmarks) {
    for (int k = 0; k < 3; ++k) put(&payload, l.p_FinG[k]);
    for (int k = 0; k < 3; ++k) put(&payload, l.p_FinG_fej[k]);
  }
  payload.append(reinterpret_cast<const char*>(c.covariance.data()), dim * dim * sizeof(double));
  const uint64_t hash = fnv1a(payload.data(), payload.size());
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(kMagic, sizeof(kMagic));
    out.write(payload.data(), static_cast<std::streamsize>(payload.size()));
    out.write(reinterpret_cast<const char*>(&hash), sizeof(hash));
    if (!out.flush()) {
      *why = "cannot write checkpoint " + tmp + ": " + std::strerror(errno);
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *why = "cannot rename " + tmp + " to " + path + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

bool read_checkpoint(const std::string& path, RobotCheckpoint* checkpoint, std::string* why) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *why = "no checkpoint " + path + " (" + std::strerror(errno) + ")";
    return false;
  }
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto reject = [&](const std::string& what) {
    *why = "checkpoint " + path + " rejected: " + what;
    return false;
  };
  const std::size_t head = sizeof(kMagic) + 3 * sizeof(int64_t);
  if (bytes.size() < head + sizeof(uint64_t)) return reject(std::to_string(bytes.size()) + " bytes, too short");
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) return reject("not a vimot checkpoint (bad magic)");
  const char* payload = bytes.data() + sizeof(kMagic);
  const std::size_t payload_bytes = bytes.size() - sizeof(kMagic) - sizeof(uint64_t);
  uint64_t hash = 0;
  std::memcpy(&hash, payload + payload_bytes, sizeof(hash));
  if (hash != fnv1a(payload, payload_bytes)) return reject("hash mismatch (truncated or corrupt)");
  RobotCheckpoint c;
  const char* at = payload;
  c.state.utime = take<int64_t>(&at);
  c.last_imu.utime = take<int64_t>(&at);
  const int64_t n = take<int64_t>(&at);
  if (n < 0 || n > 100000 || payload_size(static_cast<std::size_t>(n)) != payload_bytes) {
    return reject("size does not match its " + std::to_string(n) + " landmarks");
  }
  c.landmarks.resize(static_cast<std::size_t>(n));
  for (auto& l : c.landmarks) l.feature_id = take<int64_t>(&at);
  for (double* v : fixed_fields(c)) *v = take<double>(&at);
  for (auto& l : c.landmarks) {
    for (int k = 0; k < 3; ++k) l.p_FinG[k] = take<double>(&at);
    for (int k = 0; k < 3; ++k) l.p_FinG_fej[k] = take<double>(&at);
  }
  const int dim = 15 + 3 * static_cast<int>(n);
  c.covariance.resize(dim, dim);
  std::memcpy(c.covariance.data(), at, static_cast<std::size_t>(dim) * dim * sizeof(double));
  bool finite = c.covariance.allFinite();
  for (double* v : fixed_fields(c)) finite = finite && std::isfinite(*v);
  for (const auto& l : c.landmarks) finite = finite && l.p_FinG.allFinite() && l.p_FinG_fej.allFinite();
  if (!finite) return reject("non-finite value");
  const double qn = c.state.q_GtoI.norm();
  if (std::abs(qn - 1.0) > 1e-6) {
    std::ostringstream msg;
    msg << "quaternion norm " << qn << " is not 1";
    return reject(msg.str());
  }
  const Eigen::MatrixXd& P = c.covariance;
  if (!(P.diagonal().minCoeff() > 0.0) || (P - P.transpose()).cwiseAbs().maxCoeff() > 1e-9 * P.cwiseAbs().maxCoeff()) {
    return reject("covariance not symmetric with a positive diagonal");
  }
  if (c.last_imu.utime > c.state.utime) return reject("IMU reading after the state time");
  c.state.covariance = P.topLeftCorner<15, 15>();
  c.state.updated = true;
  c.state.num_slam_features = static_cast<int>(n);
  *checkpoint = std::move(c);
  return true;
}

}  // namespace estimator
}  // namespace vimot
