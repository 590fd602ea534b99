#include "common/estimator/checkpoint.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "common/estimator/state_helper.h"

namespace vimot {
namespace estimator {

namespace {

constexpr char kMagic[8] = {'V', 'I', 'M', 'O', 'T', 'C', 'K', '3'};
constexpr int64_t kMaxVariables = 100000;

// FNV-1a over 8-byte words (then the tail bytes): a byte-wise hash of the
// ≈ 1 MB payload would cost milliseconds per frame.
uint64_t hash_of(const char* data, std::size_t n) {
  uint64_t h = 1469598103934665603ull;
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t w;
    std::memcpy(&w, data + i, 8);
    h = (h ^ w) * 1099511628211ull;
    h ^= h >> 29;
  }
  for (; i < n; ++i) h = (h ^ static_cast<unsigned char>(data[i])) * 1099511628211ull;
  return h;
}

bool unit_quaternion(const Eigen::VectorXd& v) { return std::abs(v.head<4>().norm() - 1.0) <= 1e-6; }

}  // namespace

void CheckpointWriter::put(const Eigen::VectorXd& v) {
  put(static_cast<int64_t>(v.size()));
  bytes_.append(reinterpret_cast<const char*>(v.data()), static_cast<std::size_t>(v.size()) * sizeof(double));
}

void CheckpointWriter::put(const std::string& s) {
  put(static_cast<int64_t>(s.size()));
  bytes_.append(s);
}

void CheckpointWriter::put(const FeatureDatabase& tracks) {
  put(static_cast<int64_t>(tracks.size()));
  for (const auto& [id, f] : tracks.features()) {
    put(id);
    put(static_cast<int32_t>(f->anchor_camera));
    put(f->anchor_utime);
    put(f->p_FinA);
    put(f->p_FinG);
    put(static_cast<int64_t>(f->obs.size()));
    for (const auto& [camera, obs] : f->obs) {
      put(static_cast<int32_t>(camera));
      put(static_cast<int64_t>(obs.size()));
      for (const FeatureObs& o : obs) {
        put(o.utime);
        put(o.uv);
      }
    }
  }
}

bool CheckpointReader::need(std::size_t n) {
  if (!ok_ || static_cast<std::size_t>(end_ - at_) < n) ok_ = false;
  return ok_;
}

bool CheckpointReader::take_raw(void* out, std::size_t n) {
  if (!need(n)) return false;
  std::memcpy(out, at_, n);
  at_ += n;
  return true;
}

Eigen::VectorXd CheckpointReader::take_vector() {
  const int64_t n = take<int64_t>();
  if (n < 0 || !need(static_cast<std::size_t>(n) * sizeof(double))) {
    ok_ = false;
    return {};
  }
  Eigen::VectorXd v(n);
  std::memcpy(v.data(), at_, static_cast<std::size_t>(n) * sizeof(double));
  at_ += n * static_cast<int64_t>(sizeof(double));
  return v;
}

std::string CheckpointReader::take_string() {
  const int64_t n = take<int64_t>();
  if (n < 0 || !need(static_cast<std::size_t>(n))) {
    ok_ = false;
    return {};
  }
  std::string s(at_, static_cast<std::size_t>(n));
  at_ += n;
  return s;
}

FeatureDatabase CheckpointReader::take_tracks() {
  FeatureDatabase tracks;
  const int64_t n = take<int64_t>();
  // Each entry takes more than 8 bytes: a count beyond the bytes left is corrupt.
  for (int64_t i = 0; ok_ && i < n; ++i) {
    Feature f;
    f.feature_id = take<int64_t>();
    f.anchor_camera = take<int32_t>();
    f.anchor_utime = take<int64_t>();
    f.p_FinA = take_fixed<3>();
    f.p_FinG = take_fixed<3>();
    const int64_t cameras = take<int64_t>();
    for (int64_t c = 0; ok_ && c < cameras; ++c) {
      const int32_t camera = take<int32_t>();
      const int64_t m = take<int64_t>();
      if (m < 0 || !need(static_cast<std::size_t>(m) * 24)) {
        ok_ = false;
        break;
      }
      std::vector<FeatureObs>& obs = f.obs[camera];
      obs.resize(static_cast<std::size_t>(m));
      for (FeatureObs& o : obs) {
        o.utime = take<int64_t>();
        o.uv = take_fixed<2>();
      }
    }
    tracks.insert(f);
  }
  if (n < 0) ok_ = false;
  return tracks;
}

ImuValue EstimatorCheckpoint::imu_value() const {
  for (const CheckpointVariable& v : variables) {
    if (v.kind == kCheckpointImu) return ImuValue::from_vector(v.value);
  }
  return {};
}

EstimatorCheckpoint checkpoint_of(const VioEstimator& estimator, const CheckpointExtension* extension) {
  const State& st = estimator.state();
  EstimatorCheckpoint c;
  c.utime = st.utime();
  // After an update the buffer starts with the last sample at or before
  // the state time (Propagator::clean_older_than).
  for (const ImuData& imu : estimator.propagator().buffer()) {
    if (imu.utime > c.utime) break;
    c.last_imu = imu;
  }
  std::map<const Type*, int64_t> clone_utime;
  for (const auto& [utime, pose] : st.clones()) clone_utime[pose.get()] = utime;
  c.variables.reserve(st.variables().size());
  for (const TypePtr& var : st.variables()) {
    CheckpointVariable v;
    v.size = var->size();
    v.value = var->value();
    v.fej = var->fej();
    const auto clone = clone_utime.find(var.get());
    const auto* landmark = dynamic_cast<const Landmark*>(var.get());
    if (var == st.imu()) {
      v.kind = kCheckpointImu;
    } else if (clone != clone_utime.end()) {
      v.kind = kCheckpointClone;
      v.key = clone->second;
    } else if (landmark != nullptr && st.slam_features().count(landmark->feature_id()) != 0) {
      v.kind = kCheckpointLandmark;
      v.key = landmark->feature_id();
      v.representation = static_cast<int32_t>(landmark->representation());
      v.anchor_utime = landmark->anchor_utime;
      v.anchor_camera = landmark->anchor_camera;
      v.chi2_failures = landmark->chi2_failures;
    } else if (extension == nullptr || !extension->describe(var.get(), &v.kind, &v.key)) {
      throw std::logic_error("checkpoint_of: a state variable of size " + std::to_string(var->size()) +
                             " is neither the estimator's nor described by its extension");
    }
    c.variables.push_back(std::move(v));
  }
  c.covariance = st.cov();
  c.tracks = estimator.tracks();  // shares the tracks: written before the estimator changes them
  c.has_extension = extension != nullptr;
  if (extension != nullptr) c.extension = extension->save();
  return c;
}

bool restore(const EstimatorCheckpoint& checkpoint, VioEstimator* estimator, CheckpointExtension* extension,
             std::string* why) {
  if (checkpoint.has_extension != (extension != nullptr)) {
    *why = checkpoint.has_extension ? "it holds a target filter's state, this process has no target filter"
                                    : "it has no target filter's state, this process has a target filter";
    return false;
  }
  auto state = std::make_unique<State>(estimator->options().state);
  std::vector<TypePtr> variables;
  std::map<int64_t, std::shared_ptr<PoseJPL>> clones;
  std::map<int64_t, std::shared_ptr<Landmark>> slam;
  std::vector<std::pair<const CheckpointVariable*, TypePtr>> extension_variables;
  int imus = 0;
  for (const CheckpointVariable& v : checkpoint.variables) {
    TypePtr var;
    bool duplicate = false;
    if (v.kind == kCheckpointImu) {
      var = state->imu();
      duplicate = ++imus > 1;
    } else if (v.kind == kCheckpointClone) {
      auto pose = std::make_shared<PoseJPL>();
      duplicate = !clones.emplace(v.key, pose).second;
      var = pose;
    } else if (v.kind == kCheckpointLandmark && (v.representation == 0 || v.representation == 1)) {
      auto lm = std::make_shared<Landmark>(v.key, static_cast<LandmarkRepresentation>(v.representation));
      lm->anchor_utime = v.anchor_utime;
      lm->anchor_camera = v.anchor_camera;
      lm->chi2_failures = v.chi2_failures;
      duplicate = !slam.emplace(v.key, lm).second;
      var = lm;
    } else if (extension != nullptr && v.kind >= kFirstExtensionKind) {
      var = extension->make(v.kind, v.key);
      if (var) extension_variables.emplace_back(&v, var);
    }
    std::ostringstream what;
    what << "variable " << variables.size() << " (kind " << v.kind << ", key " << v.key << ")";
    if (!var || duplicate) {
      *why = what.str() + (duplicate ? " is there twice" : " is of an unknown kind");
      return false;
    }
    if (var->size() != v.size || var->value().size() != v.value.size() || var->fej().size() != v.fej.size()) {
      *why = what.str() + " has the wrong size";
      return false;
    }
    var->set_exact(v.value, v.fej);
    variables.push_back(var);
  }
  if (imus != 1) {
    *why = "it has " + std::to_string(imus) + " IMU states";
    return false;
  }
  StateHelper::restore_layout(*state, variables, checkpoint.covariance, std::move(clones), std::move(slam));
  state->set_utime(checkpoint.utime);
  if (extension != nullptr && !extension->load(extension_variables, checkpoint.extension, why)) return false;
  FeatureDatabase tracks;  // copies: the estimator changes its tracks
  for (const auto& kv : checkpoint.tracks.features()) tracks.insert(*kv.second);
  estimator->restore(std::move(state), std::move(tracks));
  estimator->prepend_imu(checkpoint.last_imu);
  return true;
}

bool write_checkpoint(const std::string& path, const EstimatorCheckpoint& c, std::string* why, std::size_t* bytes) {
  int64_t dim = 0;
  for (const CheckpointVariable& v : c.variables) dim += v.size;
  if (c.covariance.rows() != dim || c.covariance.cols() != dim) {
    *why = "checkpoint covariance is not " + std::to_string(dim) + " square";
    return false;
  }
  CheckpointWriter w;
  w.bytes().reserve(sizeof(kMagic) + static_cast<std::size_t>(dim * dim) * sizeof(double) + 64 * c.variables.size() +
                    400 * c.tracks.size() + c.extension.size() + 256);
  w.bytes().append(kMagic, sizeof(kMagic));
  w.put(c.utime);
  w.put(c.last_imu.utime);
  w.put(c.last_imu.w_IinI);
  w.put(c.last_imu.a_IinI);
  w.put(static_cast<int64_t>(c.variables.size()));
  for (const CheckpointVariable& v : c.variables) {
    w.put(v.kind);
    w.put(v.key);
    w.put(v.size);
    w.put(v.value);
    w.put(v.fej);
    w.put(v.representation);
    w.put(v.anchor_utime);
    w.put(v.anchor_camera);
    w.put(v.chi2_failures);
  }
  w.bytes().append(reinterpret_cast<const char*>(c.covariance.data()),
                   static_cast<std::size_t>(dim * dim) * sizeof(double));
  w.put(c.tracks);
  w.put(static_cast<uint8_t>(c.has_extension));
  w.put(c.extension);
  const uint64_t hash = hash_of(w.bytes().data() + sizeof(kMagic), w.bytes().size() - sizeof(kMagic));
  w.put(hash);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(w.bytes().data(), static_cast<std::streamsize>(w.bytes().size()));
    if (!out.flush()) {
      *why = "cannot write checkpoint " + tmp + ": " + std::strerror(errno);
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *why = "cannot rename " + tmp + " to " + path + ": " + std::strerror(errno);
    return false;
  }
  if (bytes != nullptr) *bytes = w.bytes().size();
  return true;
}

bool read_checkpoint(const std::string& path, EstimatorCheckpoint* checkpoint, std::string* why) {
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
  if (bytes.size() < sizeof(kMagic) + sizeof(uint64_t)) return reject(std::to_string(bytes.size()) + " bytes, too short");
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) return reject("not a vimot checkpoint (bad magic)");
  const char* payload = bytes.data() + sizeof(kMagic);
  const std::size_t payload_bytes = bytes.size() - sizeof(kMagic) - sizeof(uint64_t);
  uint64_t hash = 0;
  std::memcpy(&hash, payload + payload_bytes, sizeof(hash));
  if (hash != hash_of(payload, payload_bytes)) return reject("hash mismatch (truncated or corrupt)");

  CheckpointReader r(payload, payload_bytes);
  EstimatorCheckpoint c;
  c.utime = r.take<int64_t>();
  c.last_imu.utime = r.take<int64_t>();
  c.last_imu.w_IinI = r.take_fixed<3>();
  c.last_imu.a_IinI = r.take_fixed<3>();
  const int64_t n = r.take<int64_t>();
  if (n < 1 || n > kMaxVariables) return reject(std::to_string(n) + " variables");
  int64_t dim = 0;
  bool finite = c.last_imu.w_IinI.allFinite() && c.last_imu.a_IinI.allFinite();
  bool sizes = true, quaternions = true;
  c.variables.resize(static_cast<std::size_t>(n));
  for (CheckpointVariable& v : c.variables) {
    v.kind = r.take<int32_t>();
    v.key = r.take<int64_t>();
    v.size = r.take<int32_t>();
    v.value = r.take_vector();
    v.fej = r.take_vector();
    v.representation = r.take<int32_t>();
    v.anchor_utime = r.take<int64_t>();
    v.anchor_camera = r.take<int32_t>();
    v.chi2_failures = r.take<int32_t>();
    if (!r.ok()) break;
    sizes = sizes && v.size > 0 && v.size <= 64 && v.value.size() >= v.size && v.fej.size() == v.value.size();
    finite = finite && v.value.allFinite() && v.fej.allFinite();
    if (v.kind == kCheckpointImu || v.kind == kCheckpointClone) {
      quaternions = quaternions && v.value.size() >= 4 && unit_quaternion(v.value) && unit_quaternion(v.fej);
    }
    dim += v.size;
  }
  if (!r.ok() || !sizes) return reject("variables cut short or of impossible sizes");
  const std::size_t cov_bytes = static_cast<std::size_t>(dim * dim) * sizeof(double);
  if (r.left() < cov_bytes) return reject("too short for the " + std::to_string(dim) + "-square covariance");
  c.covariance.resize(dim, dim);
  r.take_raw(c.covariance.data(), cov_bytes);
  c.tracks = r.take_tracks();
  c.has_extension = r.take<uint8_t>() != 0;
  c.extension = r.take_string();
  if (!r.ok() || !r.at_end()) return reject("its size does not match its contents");
  if (!finite || !c.covariance.allFinite()) return reject("non-finite value");
  if (!quaternions) return reject("a quaternion of the IMU or a clone is not of unit norm");
  const Eigen::MatrixXd& P = c.covariance;
  if (!(P.diagonal().minCoeff() > 0.0) || (P - P.transpose()).cwiseAbs().maxCoeff() > 1e-9 * P.cwiseAbs().maxCoeff()) {
    return reject("covariance not symmetric with a positive diagonal");
  }
  if (c.last_imu.utime > c.utime) return reject("IMU reading after the state time");
  *checkpoint = std::move(c);
  return true;
}

}  // namespace estimator
}  // namespace vimot
