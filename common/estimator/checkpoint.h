#pragma once
// Checkpoint of an estimator's whole state, so a process that was killed
// and respawned goes on from its own estimate as if it had bridged an input
// gap of the outage's length (docs/sheriff.md, "Recovery"): every variable
// of the State in its order (IMU, clones, SLAM landmarks with their anchors,
// and an extension's — the target filter's — variables) with value and
// first estimate, the whole covariance, the MSCKF feature tracks, the last
// IMU reading at or before the state time (from which the gap to the new
// input is interpolated, ImuGapNoise) and the extension's bookkeeping. A
// restore continues bit for bit like the process that wrote it would have
// on the same input. No LCM here.
//
// File: "VIMOTCK3", the payload (native byte order: the same machine reads
// it) and its 64-bit hash; written to PATH.tmp and renamed, so a reader
// sees a whole checkpoint or the previous one.

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/estimator/feature_database.h"
#include "common/estimator/vio_estimator.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace estimator {

/// Kinds of the State's variables in a checkpoint; an extension's are >= kFirstExtensionKind.
enum CheckpointKind : int32_t { kCheckpointImu = 0, kCheckpointClone = 1, kCheckpointLandmark = 2, kFirstExtensionKind = 16 };

struct CheckpointVariable {
  int32_t kind{kCheckpointImu};
  int64_t key{0};  // clone: its utime; landmark: its feature id; extension: its own
  int32_t size{0};  // error-state dimension (its covariance block)
  Eigen::VectorXd value, fej;
  // Landmarks only (Landmark's members).
  int32_t representation{0};
  int64_t anchor_utime{-1};
  int32_t anchor_camera{0};
  int32_t chi2_failures{0};
};

/// Appends plain values to a byte string (checkpoint payloads).
class CheckpointWriter {
 public:
  template <typename T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <int N, typename = std::enable_if_t<(N > 0)>>
  void put(const Eigen::Matrix<double, N, 1>& v) {
    bytes_.append(reinterpret_cast<const char*>(v.data()), N * sizeof(double));
  }
  void put(const Eigen::VectorXd& v);  // length, then values
  void put(const std::string& s);      // length, then bytes
  void put(const FeatureDatabase& tracks);
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

/// Reads what CheckpointWriter wrote; any read past the end makes ok() false
/// (and returns zeros), so a reader checks once at the end.
class CheckpointReader {
 public:
  CheckpointReader(const char* data, std::size_t size) : at_(data), end_(data + size) {}
  template <typename T>
  T take() {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    T v{};
    if (!need(sizeof(T))) return v;
    std::memcpy(&v, at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> take_fixed() {
    Eigen::Matrix<double, N, 1> v = Eigen::Matrix<double, N, 1>::Zero();
    take_raw(v.data(), N * sizeof(double));
    return v;
  }
  /// n raw bytes into out; false (nothing read) if fewer are left.
  bool take_raw(void* out, std::size_t n);
  Eigen::VectorXd take_vector();
  std::string take_string();
  FeatureDatabase take_tracks();
  bool ok() const { return ok_; }
  bool at_end() const { return at_ == end_; }
  std::size_t left() const { return static_cast<std::size_t>(end_ - at_); }

 private:
  bool need(std::size_t n);
  const char* at_;
  const char* end_;
  bool ok_{true};
};

/// How an estimator extension (the target filter) puts its variables and
/// the rest of its memory into a checkpoint and takes them back.
class CheckpointExtension {
 public:
  virtual ~CheckpointExtension() = default;
  /// Kind (>= kFirstExtensionKind) and key of `var` if it is one of the extension's.
  virtual bool describe(const Type* var, int32_t* kind, int64_t* key) const = 0;
  /// A new variable of that kind (its value and fej are set after); nullptr if unknown.
  virtual TypePtr make(int32_t kind, int64_t key) const = 0;
  /// Everything else the extension needs to go on, and what it must match (its configuration).
  virtual std::string save() const = 0;
  /// Takes over its variables (already in the estimator's state, with the
  /// descriptions they were saved with) and its memory; false with *why if
  /// they do not fit (e.g. another configuration wrote them).
  virtual bool load(const std::vector<std::pair<const CheckpointVariable*, TypePtr>>& variables,
                    const std::string& memory, std::string* why) = 0;
};

struct EstimatorCheckpoint {
  int64_t utime{0};  // the state time
  ImuData last_imu;  // utime <= the state time
  std::vector<CheckpointVariable> variables;  // in State::variables() order
  Eigen::MatrixXd covariance;                 // of the whole state
  FeatureDatabase tracks;                     // the MSCKF tracks
  bool has_extension{false};
  std::string extension;  // the extension's memory

  /// The IMU variable's value (a checkpoint has exactly one).
  ImuValue imu_value() const;
};

/// The initialised estimator's checkpoint (its extension's part from
/// `extension`, nullptr: none): its state at the last update and the newest
/// buffered IMU reading at or before it. Throws std::logic_error if a
/// variable of the state is not the estimator's and `extension` does not describe it.
EstimatorCheckpoint checkpoint_of(const VioEstimator& estimator, const CheckpointExtension* extension = nullptr);

/// Puts the estimator (and `extension`, which must be attached to it if the
/// checkpoint has an extension part) in the checkpoint's state; the reading
/// goes before the buffered IMU samples. False with *why, the estimator left
/// uninitialised, if the checkpoint does not fit (extension part present or
/// not, unknown kinds, sizes, the extension's refusal).
bool restore(const EstimatorCheckpoint& checkpoint, VioEstimator* estimator, CheckpointExtension* extension,
             std::string* why);

/// Writes atomically; false (with *why) if the file cannot be written.
/// *bytes (if given) gets the file's size.
bool write_checkpoint(const std::string& path, const EstimatorCheckpoint& checkpoint, std::string* why,
                      std::size_t* bytes = nullptr);

/// Reads and validates (magic, hash, sizes, finite values, unit
/// quaternions of the IMU and clones, a symmetric covariance with a positive
/// diagonal of the variables' total size, reading not after the state);
/// false with *why (naming the file) if absent or unusable.
bool read_checkpoint(const std::string& path, EstimatorCheckpoint* checkpoint, std::string* why);

}  // namespace estimator
}  // namespace vimot
