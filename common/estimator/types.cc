#include "common/estimator/types.h"

#include <stdexcept>
#include <string>

#include "common/math/quat.h"

namespace vimot {
namespace estimator {

namespace {
void check_size(const Eigen::VectorXd& v, int expected, const char* what) {
  if (v.size() != expected) {
    throw std::invalid_argument(std::string(what) + ": expected size " + std::to_string(expected) + ", got " +
                                std::to_string(v.size()));
  }
}
}  // namespace

// ---------------------------------------------------------------- Vec
Vec::Vec(int dim) : Type(dim) {
  value_ = Eigen::VectorXd::Zero(dim);
  fej_ = Eigen::VectorXd::Zero(dim);
}

void Vec::update(const Eigen::VectorXd& dx) {
  check_size(dx, size_, "Vec::update");
  set_value(value_ + dx);
}

std::shared_ptr<Type> Vec::clone_type() const {
  auto c = std::make_shared<Vec>(size_);
  c->set_value(value_);
  c->set_fej(fej_);
  return c;
}

// ---------------------------------------------------------------- JplQuat
JplQuat::JplQuat() : Type(3) {
  value_ = Eigen::Vector4d(0.0, 0.0, 0.0, 1.0);
  fej_ = value_;
}

void JplQuat::update(const Eigen::VectorXd& dx) {
  check_size(dx, 3, "JplQuat::update");
  set_value(quat_boxplus(Eigen::Vector4d(value_), Eigen::Vector3d(dx)));
}

void JplQuat::set_value(const Eigen::VectorXd& value) {
  check_size(value, 4, "JplQuat::set_value");
  value_ = quat_normalize(Eigen::Vector4d(value));
  R_ = quat_to_rot(Eigen::Vector4d(value_));
}

void JplQuat::set_fej(const Eigen::VectorXd& fej) {
  check_size(fej, 4, "JplQuat::set_fej");
  fej_ = quat_normalize(Eigen::Vector4d(fej));
  R_fej_ = quat_to_rot(Eigen::Vector4d(fej_));
}

void JplQuat::set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) {
  check_size(value, 4, "JplQuat::set_exact");
  check_size(fej, 4, "JplQuat::set_exact");
  Type::set_exact(value, fej);
  R_ = quat_to_rot(Eigen::Vector4d(value_));
  R_fej_ = quat_to_rot(Eigen::Vector4d(fej_));
}

std::shared_ptr<Type> JplQuat::clone_type() const {
  auto c = std::make_shared<JplQuat>();
  c->set_value(value_);
  c->set_fej(fej_);
  return c;
}

// ---------------------------------------------------------------- PoseJPL
PoseJPL::PoseJPL() : Type(6), q_(std::make_shared<JplQuat>()), p_(std::make_shared<Vec>(3)) {
  Eigen::VectorXd x(7);
  x << 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0;
  set_value(x);
  set_fej(x);
}

void PoseJPL::set_local_id(int new_id) {
  id_ = new_id;
  q_->set_local_id(new_id);
  p_->set_local_id(new_id < 0 ? -1 : new_id + 3);
}

void PoseJPL::update(const Eigen::VectorXd& dx) {
  check_size(dx, 6, "PoseJPL::update");
  Eigen::VectorXd x(7);
  x.head<4>() = quat_boxplus(Eigen::Vector4d(value_.head<4>()), Eigen::Vector3d(dx.head<3>()));
  x.tail<3>() = value_.tail<3>() + dx.tail<3>();
  set_value(x);
}

void PoseJPL::set_value(const Eigen::VectorXd& value) {
  check_size(value, 7, "PoseJPL::set_value");
  q_->set_value(value.head<4>());
  p_->set_value(value.tail<3>());
  value_.resize(7);
  value_ << q_->value(), p_->value();
}

void PoseJPL::set_fej(const Eigen::VectorXd& fej) {
  check_size(fej, 7, "PoseJPL::set_fej");
  q_->set_fej(fej.head<4>());
  p_->set_fej(fej.tail<3>());
  fej_.resize(7);
  fej_ << q_->fej(), p_->fej();
}

void PoseJPL::set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) {
  check_size(value, 7, "PoseJPL::set_exact");
  check_size(fej, 7, "PoseJPL::set_exact");
  q_->set_exact(value.head<4>(), fej.head<4>());
  p_->set_exact(value.tail<3>(), fej.tail<3>());
  Type::set_exact(value, fej);
}

std::shared_ptr<Type> PoseJPL::clone_type() const {
  auto c = std::make_shared<PoseJPL>();
  c->set_value(value_);
  c->set_fej(fej_);
  return c;
}

bool PoseJPL::contains(const Type* other) const { return other == this || other == q_.get() || other == p_.get(); }

// ---------------------------------------------------------------- ImuValue
Eigen::Matrix<double, 16, 1> ImuValue::to_vector() const {
  Eigen::Matrix<double, 16, 1> x;
  x << q_GtoI, p_IinG, v_IinG, bg, ba;
  return x;
}

ImuValue ImuValue::from_vector(const Eigen::Matrix<double, 16, 1>& x) {
  ImuValue v;
  v.q_GtoI = x.segment<4>(0);
  v.p_IinG = x.segment<3>(4);
  v.v_IinG = x.segment<3>(7);
  v.bg = x.segment<3>(10);
  v.ba = x.segment<3>(13);
  return v;
}

ImuValue boxplus(const ImuValue& x, const Eigen::Matrix<double, 15, 1>& dx) {
  ImuValue y = x;
  y.q_GtoI = quat_boxplus(x.q_GtoI, dx.segment<3>(0));
  y.p_IinG += dx.segment<3>(3);
  y.v_IinG += dx.segment<3>(6);
  y.bg += dx.segment<3>(9);
  y.ba += dx.segment<3>(12);
  return y;
}

Eigen::Matrix<double, 15, 1> boxminus(const ImuValue& y, const ImuValue& x) {
  Eigen::Matrix<double, 15, 1> d;
  d.segment<3>(0) = -log_so3(quat_to_rot(y.q_GtoI) * quat_to_rot(x.q_GtoI).transpose());
  d.segment<3>(3) = y.p_IinG - x.p_IinG;
  d.segment<3>(6) = y.v_IinG - x.v_IinG;
  d.segment<3>(9) = y.bg - x.bg;
  d.segment<3>(12) = y.ba - x.ba;
  return d;
}

// ---------------------------------------------------------------- ImuState
ImuState::ImuState()
    : Type(15),
      pose_(std::make_shared<PoseJPL>()),
      v_(std::make_shared<Vec>(3)),
      bg_(std::make_shared<Vec>(3)),
      ba_(std::make_shared<Vec>(3)) {
  const Eigen::VectorXd x = ImuValue().to_vector();
  set_value(x);
  set_fej(x);
}

void ImuState::set_local_id(int new_id) {
  id_ = new_id;
  pose_->set_local_id(new_id);
  v_->set_local_id(new_id < 0 ? -1 : new_id + 6);
  bg_->set_local_id(new_id < 0 ? -1 : new_id + 9);
  ba_->set_local_id(new_id < 0 ? -1 : new_id + 12);
}

void ImuState::update(const Eigen::VectorXd& dx) {
  check_size(dx, 15, "ImuState::update");
  Eigen::VectorXd x = value_;
  x.head<4>() = quat_boxplus(Eigen::Vector4d(value_.head<4>()), Eigen::Vector3d(dx.head<3>()));
  x.segment<3>(4) += dx.segment<3>(3);
  x.segment<3>(7) += dx.segment<3>(6);
  x.segment<3>(10) += dx.segment<3>(9);
  x.segment<3>(13) += dx.segment<3>(12);
  set_value(x);
}

void ImuState::set_value(const Eigen::VectorXd& value) {
  check_size(value, 16, "ImuState::set_value");
  pose_->set_value(value.head<7>());
  v_->set_value(value.segment<3>(7));
  bg_->set_value(value.segment<3>(10));
  ba_->set_value(value.segment<3>(13));
  value_.resize(16);
  value_ << pose_->value(), v_->value(), bg_->value(), ba_->value();
}

void ImuState::set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) {
  check_size(value, 16, "ImuState::set_exact");
  check_size(fej, 16, "ImuState::set_exact");
  pose_->set_exact(value.head<7>(), fej.head<7>());
  v_->set_exact(value.segment<3>(7), fej.segment<3>(7));
  bg_->set_exact(value.segment<3>(10), fej.segment<3>(10));
  ba_->set_exact(value.segment<3>(13), fej.segment<3>(13));
  Type::set_exact(value, fej);
}

void ImuState::set_fej(const Eigen::VectorXd& fej) {
  check_size(fej, 16, "ImuState::set_fej");
  pose_->set_fej(fej.head<7>());
  v_->set_fej(fej.segment<3>(7));
  bg_->set_fej(fej.segment<3>(10));
  ba_->set_fej(fej.segment<3>(13));
  fej_.resize(16);
  fej_ << pose_->fej(), v_->fej(), bg_->fej(), ba_->fej();
}

std::shared_ptr<Type> ImuState::clone_type() const {
  auto c = std::make_shared<ImuState>();
  c->set_value(value_);
  c->set_fej(fej_);
  return c;
}

bool ImuState::contains(const Type* other) const {
  return other == this || pose_->contains(other) || other == v_.get() || other == bg_.get() || other == ba_.get();
}

// ---------------------------------------------------------------- Landmark
Landmark::Landmark(int64_t feature_id, LandmarkRepresentation representation)
    : Vec(3), feature_id_(feature_id), representation_(representation) {}

std::shared_ptr<Type> Landmark::clone_type() const {
  auto c = std::make_shared<Landmark>(feature_id_, representation_);
  c->set_value(value_);
  c->set_fej(fej_);
  c->anchor_utime = anchor_utime;
  c->anchor_camera = anchor_camera;
  return c;
}

}  // namespace estimator
}  // namespace vimot
