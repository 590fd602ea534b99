#pragma once
// Typed variable blocks of the estimator state.
//
// Every variable knows its size (the dimension of its error state), its place
// in the covariance (id(), the first row/column of its block, -1 while it is
// not in the state), its current estimate value() and its first estimate
// fej() (first-estimates Jacobians, Huang/Mourikis/Roumeliotis 2008). The
// estimate is changed by update(dx): x ← x ⊞ dx, with the manifold ⊞ of the
// type:
//   Vec      x ← x + dx
//   JplQuat  q ← δq(dx) ⊗ q,  δq ≈ [dx/2; 1]   (R = exp(-dx) R̂, left error)
//   PoseJPL  [q; p], error [δθ; δp]
//   ImuState [q_GtoI; p_IinG; v_IinG; bg; ba], error [δθ; δp; δv; δbg; δba]
// Only StateHelper changes ids and the covariance; updaters change estimates
// only through StateHelper as well.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

namespace vimot {
namespace estimator {

class Type {
 public:
  explicit Type(int size) : size_(size) {}
  virtual ~Type() = default;
  Type(const Type&) = delete;
  Type& operator=(const Type&) = delete;

  /// First covariance row/column of this block; -1 when not in the state.
  int id() const { return id_; }
  /// Dimension of the error state (the covariance block).
  int size() const { return size_; }

  /// Sets the block position; composite types also place their parts.
  virtual void set_local_id(int new_id) { id_ = new_id; }

  /// x ← x ⊞ dx (dx.size() == size()).
  virtual void update(const Eigen::VectorXd& dx) = 0;

  const Eigen::VectorXd& value() const { return value_; }
  const Eigen::VectorXd& fej() const { return fej_; }
  virtual void set_value(const Eigen::VectorXd& value) { value_ = value; }
  virtual void set_fej(const Eigen::VectorXd& fej) { fej_ = fej; }
  /// Value and fej exactly as given (a checkpoint's, checkpoint.h): no
  /// re-normalisation, which would change the last bits of a quaternion.
  virtual void set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) {
    value_ = value;
    fej_ = fej;
  }

  /// A deep copy of value and fej, not in the state (id -1).
  virtual std::shared_ptr<Type> clone_type() const = 0;

  /// If `other` is this variable or one of its parts, returns it.
  virtual bool contains(const Type* other) const { return other == this; }

 protected:
  Eigen::VectorXd value_;
  Eigen::VectorXd fej_;
  int id_{-1};
  int size_{0};
};

using TypePtr = std::shared_ptr<Type>;

/// A Euclidean vector of fixed dimension.
class Vec : public Type {
 public:
  explicit Vec(int dim);
  void update(const Eigen::VectorXd& dx) override;
  std::shared_ptr<Type> clone_type() const override;
};

/// JPL quaternion q_GtoI = [qx qy qz qw] with the left error of common/math/quat.h.
class JplQuat : public Type {
 public:
  JplQuat();
  void update(const Eigen::VectorXd& dx) override;
  void set_value(const Eigen::VectorXd& value) override;
  void set_fej(const Eigen::VectorXd& fej) override;
  void set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) override;
  std::shared_ptr<Type> clone_type() const override;

  const Eigen::Matrix3d& Rot() const { return R_; }
  const Eigen::Matrix3d& Rot_fej() const { return R_fej_; }

 private:
  Eigen::Matrix3d R_{Eigen::Matrix3d::Identity()};
  Eigen::Matrix3d R_fej_{Eigen::Matrix3d::Identity()};
};

/// Pose [q_GtoI; p_IinG] (value 7, error 6 = [δθ; δp]).
class PoseJPL : public Type {
 public:
  PoseJPL();
  void set_local_id(int new_id) override;
  void update(const Eigen::VectorXd& dx) override;
  void set_value(const Eigen::VectorXd& value) override;
  void set_fej(const Eigen::VectorXd& fej) override;
  void set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) override;
  std::shared_ptr<Type> clone_type() const override;
  bool contains(const Type* other) const override;

  const Eigen::Matrix3d& Rot() const { return q_->Rot(); }
  const Eigen::Matrix3d& Rot_fej() const { return q_->Rot_fej(); }
  Eigen::Vector4d quat() const { return value_.head<4>(); }
  Eigen::Vector3d pos() const { return value_.tail<3>(); }
  Eigen::Vector3d pos_fej() const { return fej_.tail<3>(); }
  std::shared_ptr<JplQuat> q() const { return q_; }
  std::shared_ptr<Vec> p() const { return p_; }

 private:
  std::shared_ptr<JplQuat> q_;
  std::shared_ptr<Vec> p_;
};

/// Plain value of the IMU state (inputs and outputs of the estimator API).
struct ImuValue {
  Eigen::Vector4d q_GtoI{0.0, 0.0, 0.0, 1.0};      // JPL
  Eigen::Vector3d p_IinG{Eigen::Vector3d::Zero()};  // m
  Eigen::Vector3d v_IinG{Eigen::Vector3d::Zero()};  // m/s
  Eigen::Vector3d bg{Eigen::Vector3d::Zero()};      // rad/s
  Eigen::Vector3d ba{Eigen::Vector3d::Zero()};      // m/s²

  Eigen::Matrix<double, 16, 1> to_vector() const;
  static ImuValue from_vector(const Eigen::Matrix<double, 16, 1>& x);
};

/// x ⊞ δ with the error state [δθ; δp; δv; δbg; δba] of ImuState::update:
/// q ← quat_boxplus(q, δθ) (R = Exp(−δθ) R̂), the rest additive.
ImuValue boxplus(const ImuValue& x, const Eigen::Matrix<double, 15, 1>& dx);
/// y ⊟ x: the δ with y = x ⊞ δ.
Eigen::Matrix<double, 15, 1> boxminus(const ImuValue& y, const ImuValue& x);

/// IMU state: value 16 [q_GtoI; p_IinG; v_IinG; bg; ba], error 15
/// [δθ; δp; δv; δbg; δba]. pose() (error rows 0..5), v(), bg(), ba() are
/// addressable parts for measurement Jacobians.
class ImuState : public Type {
 public:
  ImuState();
  void set_local_id(int new_id) override;
  void update(const Eigen::VectorXd& dx) override;
  void set_value(const Eigen::VectorXd& value) override;
  void set_fej(const Eigen::VectorXd& fej) override;
  void set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) override;
  std::shared_ptr<Type> clone_type() const override;
  bool contains(const Type* other) const override;

  ImuValue get() const { return ImuValue::from_vector(value_); }
  ImuValue get_fej() const { return ImuValue::from_vector(fej_); }

  const Eigen::Matrix3d& Rot() const { return pose_->Rot(); }
  const Eigen::Matrix3d& Rot_fej() const { return pose_->Rot_fej(); }
  std::shared_ptr<PoseJPL> pose() const { return pose_; }
  std::shared_ptr<Vec> v() const { return v_; }
  std::shared_ptr<Vec> bg() const { return bg_; }
  std::shared_ptr<Vec> ba() const { return ba_; }

 private:
  std::shared_ptr<PoseJPL> pose_;
  std::shared_ptr<Vec> v_;
  std::shared_ptr<Vec> bg_;
  std::shared_ptr<Vec> ba_;
};

/// How a SLAM landmark is parametrised.
enum class LandmarkRepresentation {
  kGlobalXyz,              // p_FinG (3)
  kAnchoredInverseDepth,   // [α β ρ] = [x/z y/z 1/z] of the point in the anchor camera
};

/// A 3D point feature kept in the state (a SLAM feature).
class Landmark : public Vec {
 public:
  Landmark(int64_t feature_id, LandmarkRepresentation representation);
  std::shared_ptr<Type> clone_type() const override;

  int64_t feature_id() const { return feature_id_; }
  LandmarkRepresentation representation() const { return representation_; }

  /// Anchor (anchored representation only): clone time and camera index.
  int64_t anchor_utime{-1};
  int anchor_camera{0};
  /// Set by the updater when this landmark has to leave the state.
  bool should_marginalize{false};
  /// Consecutive chi² rejections of its updates.
  int chi2_failures{0};

 private:
  int64_t feature_id_{0};
  LandmarkRepresentation representation_;
};

}  // namespace estimator
}  // namespace vimot
