#include "common/estimator/state_helper.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <stdexcept>
#include <string>

#include "common/estimator/chi_square.h"
#include "common/estimator/linear_algebra.h"

namespace vimot {
namespace estimator {

namespace {

// Gathers the columns of P for the given blocks: P(:, blocks).
Eigen::MatrixXd gather_cols(const Eigen::MatrixXd& P, const std::vector<std::pair<int, int>>& blocks, int total) {
  Eigen::MatrixXd M(P.rows(), total);
  int c = 0;
  for (const auto& b : blocks) {
    M.middleCols(c, b.second) = P.middleCols(b.first, b.second);
    c += b.second;
  }
  return M;
}

// Gathers the rows `blocks` of M (already restricted in columns).
Eigen::MatrixXd gather_rows(const Eigen::MatrixXd& M, const std::vector<std::pair<int, int>>& blocks, int total) {
  Eigen::MatrixXd out(total, M.cols());
  int r = 0;
  for (const auto& b : blocks) {
    out.middleRows(r, b.second) = M.middleRows(b.first, b.second);
    r += b.second;
  }
  return out;
}

}  // namespace

bool StateHelper::blocks_of(const std::vector<TypePtr>& vars, std::vector<std::pair<int, int>>* blocks, int* total) {
  blocks->clear();
  *total = 0;
  for (const auto& v : vars) {
    if (!v || v->id() < 0) return false;
    blocks->emplace_back(v->id(), v->size());
    *total += v->size();
  }
  return true;
}

void StateHelper::apply_correction(State& state, const Eigen::VectorXd& dx) {
  for (const auto& v : state.variables_) v->update(dx.segment(v->id(), v->size()));
}

void StateHelper::propagate(State& state, const std::vector<TypePtr>& order, const Eigen::MatrixXd& Phi,
                            const Eigen::MatrixXd& Q) {
  std::vector<std::pair<int, int>> blocks;
  int n = 0;
  if (!blocks_of(order, &blocks, &n)) throw std::invalid_argument("StateHelper::propagate: variable not in state");
  if (Phi.rows() != n || Phi.cols() != n || Q.rows() != n || Q.cols() != n) {
    throw std::invalid_argument("StateHelper::propagate: Phi and Q must be " + std::to_string(n) + " square");
  }
  Eigen::MatrixXd& P = state.cov_;
  const Eigen::MatrixXd rows = gather_rows(P, blocks, n);            // P_x,: (n × N)
  const Eigen::MatrixXd P_xx = gather_cols(rows, blocks, n);         // n × n
  const Eigen::MatrixXd new_rows = Phi * rows;                        // Φ P_x,:
  Eigen::MatrixXd new_xx = Phi * P_xx * Phi.transpose() + Q;
  new_xx = 0.5 * (new_xx + new_xx.transpose()).eval();
  int r = 0;
  for (const auto& b : blocks) {
    P.middleRows(b.first, b.second) = new_rows.middleRows(r, b.second);
    P.middleCols(b.first, b.second) = new_rows.middleRows(r, b.second).transpose();
    r += b.second;
  }
  int ri = 0;
  for (const auto& bi : blocks) {
    int ci = 0;
    for (const auto& bj : blocks) {
      P.block(bi.first, bj.first, bi.second, bj.second) = new_xx.block(ri, ci, bi.second, bj.second);
      ci += bj.second;
    }
    ri += bi.second;
  }
}

bool StateHelper::ekf_update(State& state, const std::vector<TypePtr>& H_order, const Eigen::MatrixXd& H,
                             const Eigen::VectorXd& res, const Eigen::MatrixXd& R) {
  return schmidt_update(state, H_order, H, res, R, {});
}

bool StateHelper::schmidt_update(State& state, const std::vector<TypePtr>& H_order, const Eigen::MatrixXd& H,
                                 const Eigen::VectorXd& res, const Eigen::MatrixXd& R,
                                 const std::vector<TypePtr>& nuisance) {
  std::vector<std::pair<int, int>> blocks;
  int n = 0;
  if (!blocks_of(H_order, &blocks, &n)) return false;
  const int m = static_cast<int>(res.size());
  if (H.rows() != m || H.cols() != n || R.rows() != m || R.cols() != m) {
    throw std::invalid_argument("StateHelper::update: H is " + std::to_string(H.rows()) + "x" +
                                std::to_string(H.cols()) + ", expected " + std::to_string(m) + "x" +
                                std::to_string(n) + " (R " + std::to_string(R.rows()) + "x" +
                                std::to_string(R.cols()) + ")");
  }
  if (m == 0) return true;
  std::vector<std::pair<int, int>> nblocks;
  int nn = 0;
  if (!blocks_of(nuisance, &nblocks, &nn)) return false;

  Eigen::MatrixXd& P = state.cov_;
  // L = P_{:,H} Hᵀ (N × m) and S = H P_HH Hᵀ + R, exploiting the block
  // sparsity of H: block b only contributes to the rows where H_b ≠ 0, so
  // the cost is O(N · nnz(H)) and O(m · nnz(H)) (SLAM rows touch one clone
  // and one landmark each).
  const int N = static_cast<int>(P.rows());
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(N, m);
  std::vector<std::vector<int>> rows_of(blocks.size());
  int hc = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int sz = blocks[b].second;
    std::vector<int>& rows = rows_of[b];
    for (int i = 0; i < m; ++i) {
      if (H.row(i).segment(hc, sz).cwiseAbs().maxCoeff() > 0.0) rows.push_back(i);
    }
    if (!rows.empty()) {
      Eigen::MatrixXd Hb(rows.size(), sz);
      for (size_t k = 0; k < rows.size(); ++k) Hb.row(k) = H.row(rows[k]).segment(hc, sz);
      const Eigen::MatrixXd Lb = P.middleCols(blocks[b].first, sz) * Hb.transpose();  // N × |rows|
      for (size_t k = 0; k < rows.size(); ++k) L.col(rows[k]) += Lb.col(k);
    }
    hc += sz;
  }
  // P_HH Hᵀ is L at the rows of the involved blocks; S = H (P_HH Hᵀ) + R.
  Eigen::MatrixXd S = R;
  hc = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int sz = blocks[b].second;
    for (int i : rows_of[b]) {
      S.row(i).noalias() += H.row(i).segment(hc, sz) * L.middleRows(blocks[b].first, sz);
    }
    hc += sz;
  }
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success) return false;
  Eigen::VectorXd dx = L * llt.solve(res);                      // K r
  for (const auto& a : nblocks) dx.segment(a.first, a.second).setZero();  // K_n = 0
  // P ← P − L S⁻¹ Lᵀ as a symmetric rank-m downdate with X = L C⁻ᵀ
  // (S = C Cᵀ): X Xᵀ = L S⁻¹ Lᵀ, half the flops of the general product and
  // no N × N temporary. The nuisance blocks are restored afterwards.
  Eigen::MatrixXd X = L.transpose();
  llt.matrixL().solveInPlace(X);                                // C⁻¹ Lᵀ (m × N)
  std::vector<Eigen::MatrixXd> saved;
  for (const auto& a : nblocks) {
    for (const auto& b : nblocks) saved.push_back(P.block(a.first, b.first, a.second, b.second));
  }
  P.selfadjointView<Eigen::Lower>().rankUpdate(X.transpose(), -1.0);
  P.triangularView<Eigen::StrictlyUpper>() = P.transpose();
  size_t k = 0;
  for (const auto& a : nblocks) {
    for (const auto& b : nblocks) P.block(a.first, b.first, a.second, b.second) = saved[k++];
  }
  apply_correction(state, dx);
  return true;
}

Eigen::MatrixXd StateHelper::marginal_covariance(const State& state, const std::vector<TypePtr>& vars) {
  std::vector<std::pair<int, int>> blocks;
  int n = 0;
  if (!blocks_of(vars, &blocks, &n)) {
    throw std::invalid_argument("StateHelper::marginal_covariance: variable not in state");
  }
  Eigen::MatrixXd out(n, n);
  int r = 0;
  for (const auto& bi : blocks) {
    int c = 0;
    for (const auto& bj : blocks) {
      out.block(r, c, bi.second, bj.second) = state.cov_.block(bi.first, bj.first, bi.second, bj.second);
      c += bj.second;
    }
    r += bi.second;
  }
  return out;
}

void StateHelper::marginalize(State& state, const TypePtr& var) {
  const auto it = std::find(state.variables_.begin(), state.variables_.end(), var);
  if (it == state.variables_.end()) {
    throw std::invalid_argument("StateHelper::marginalize: not a top-level variable of the state");
  }
  const int id = var->id();
  const int sz = var->size();
  const int N = state.cov_size();
  const int after = N - id - sz;
  Eigen::MatrixXd P(N - sz, N - sz);
  const Eigen::MatrixXd& C = state.cov_;
  P.topLeftCorner(id, id) = C.topLeftCorner(id, id);
  P.topRightCorner(id, after) = C.topRightCorner(id, after);
  P.bottomLeftCorner(after, id) = C.bottomLeftCorner(after, id);
  P.bottomRightCorner(after, after) = C.bottomRightCorner(after, after);
  state.cov_ = std::move(P);
  state.variables_.erase(it);
  for (const auto& v : state.variables_) {
    if (v->id() > id) v->set_local_id(v->id() - sz);
  }
  var->set_local_id(-1);
}

TypePtr StateHelper::clone(State& state, const TypePtr& var) {
  if (!var || var->id() < 0) throw std::invalid_argument("StateHelper::clone: variable not in state");
  const int id = var->id();
  const int sz = var->size();
  const int N = state.cov_size();
  Eigen::MatrixXd& P = state.cov_;
  P.conservativeResize(N + sz, N + sz);
  P.block(N, 0, sz, N) = P.block(id, 0, sz, N);
  P.block(0, N, N, sz) = P.block(0, id, N, sz);
  P.block(N, N, sz, sz) = P.block(id, id, sz, sz);
  TypePtr copy = var->clone_type();
  copy->set_local_id(N);
  state.variables_.push_back(copy);
  return copy;
}

void StateHelper::add_variable(State& state, const TypePtr& var, const Eigen::MatrixXd& P_vv,
                               const Eigen::MatrixXd& P_vx) {
  if (!var || var->id() >= 0) throw std::invalid_argument("StateHelper::add_variable: variable already in a state");
  const int sz = var->size();
  const int N = state.cov_size();
  if (P_vv.rows() != sz || P_vv.cols() != sz) {
    throw std::invalid_argument("StateHelper::add_variable: P_vv must be " + std::to_string(sz) + " square");
  }
  if (P_vx.size() != 0 && (P_vx.rows() != sz || P_vx.cols() != N)) {
    throw std::invalid_argument("StateHelper::add_variable: P_vx must be " + std::to_string(sz) + "x" +
                                std::to_string(N));
  }
  Eigen::MatrixXd& P = state.cov_;
  P.conservativeResize(N + sz, N + sz);
  if (P_vx.size() == 0) {
    P.block(N, 0, sz, N).setZero();
    P.block(0, N, N, sz).setZero();
  } else {
    P.block(N, 0, sz, N) = P_vx;
    P.block(0, N, N, sz) = P_vx.transpose();
  }
  P.block(N, N, sz, sz) = 0.5 * (P_vv + P_vv.transpose());
  var->set_local_id(N);
  state.variables_.push_back(var);
}

void StateHelper::initialize_invertible(State& state, const TypePtr& new_var, const std::vector<TypePtr>& H_order,
                                        const Eigen::MatrixXd& H_R, const Eigen::MatrixXd& H_L,
                                        const Eigen::VectorXd& res, const Eigen::MatrixXd& R) {
  std::vector<std::pair<int, int>> blocks;
  int n = 0;
  if (!blocks_of(H_order, &blocks, &n)) {
    throw std::invalid_argument("StateHelper::initialize_invertible: variable not in state");
  }
  const int sz = new_var->size();
  if (H_L.rows() != sz || H_L.cols() != sz || H_R.rows() != sz || H_R.cols() != n || res.size() != sz) {
    throw std::invalid_argument("StateHelper::initialize_invertible: inconsistent system sizes");
  }
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(H_L);
  if (!lu.isInvertible()) throw std::invalid_argument("StateHelper::initialize_invertible: H_L is singular");
  const Eigen::MatrixXd H_Linv = lu.inverse();
  const Eigen::MatrixXd M = gather_cols(state.cov_, blocks, n);   // P_{:,R}
  const Eigen::MatrixXd P_RR = gather_rows(M, blocks, n);
  const Eigen::MatrixXd P_vx = -H_Linv * H_R * M.transpose();     // −H_L⁻¹ H_R P_R,:
  Eigen::MatrixXd P_vv = H_Linv * (H_R * P_RR * H_R.transpose() + R) * H_Linv.transpose();
  new_var->update(H_Linv * res);
  add_variable(state, new_var, P_vv, P_vx);
}

bool StateHelper::initialize(State& state, const TypePtr& new_var, const std::vector<TypePtr>& H_order,
                             Eigen::MatrixXd H_R, Eigen::MatrixXd H_L, Eigen::VectorXd res, double noise_sigma,
                             double chi2_multiplier) {
  const int sz = new_var->size();
  const int m = static_cast<int>(res.size());
  if (H_L.rows() != m || H_R.rows() != m || H_L.cols() != sz) {
    throw std::invalid_argument("StateHelper::initialize: inconsistent system sizes");
  }
  if (m < sz) return false;
  givens_triangularize_inplace(H_L, H_R, res);
  const Eigen::MatrixXd U = H_L.topRows(sz);
  // Rank check on the triangular factor.
  const double dmax = U.diagonal().cwiseAbs().maxCoeff();
  if (!(dmax > 0.0) || U.diagonal().cwiseAbs().minCoeff() < 1e-10 * dmax) return false;

  const double var_n = noise_sigma * noise_sigma;
  const int m_up = m - sz;
  Eigen::MatrixXd H_up;
  Eigen::VectorXd r_up;
  if (m_up > 0) {
    H_up = H_R.bottomRows(m_up);
    r_up = res.tail(m_up);
    const Eigen::MatrixXd P_RR = marginal_covariance(state, H_order);
    Eigen::MatrixXd S = H_up * P_RR * H_up.transpose();
    S.diagonal().array() += var_n;
    const double chi2 = r_up.dot(S.llt().solve(r_up));
    if (!(chi2 < chi2_multiplier * chi2_95(m_up))) return false;
  }
  initialize_invertible(state, new_var, H_order, H_R.topRows(sz), U, res.head(sz),
                        var_n * Eigen::MatrixXd::Identity(sz, sz));
  if (m_up > 0) {
    ekf_update(state, H_order, H_up, r_up, var_n * Eigen::MatrixXd::Identity(m_up, m_up));
  }
  return true;
}

void StateHelper::transform_variable(State& state, const TypePtr& var, const std::vector<TypePtr>& order,
                                     const Eigen::MatrixXd& J) {
  std::vector<std::pair<int, int>> blocks;
  int n = 0;
  if (!var || var->id() < 0 || !blocks_of(order, &blocks, &n)) {
    throw std::invalid_argument("StateHelper::transform_variable: variable not in state");
  }
  if (std::find(order.begin(), order.end(), var) == order.end()) {
    throw std::invalid_argument("StateHelper::transform_variable: order must contain the variable");
  }
  const int sz = var->size();
  if (J.rows() != sz || J.cols() != n) {
    throw std::invalid_argument("StateHelper::transform_variable: J must be " + std::to_string(sz) + "x" +
                                std::to_string(n));
  }
  Eigen::MatrixXd& P = state.cov_;
  Eigen::MatrixXd row = Eigen::MatrixXd::Zero(sz, P.cols());  // J P_order,:
  int c = 0;
  for (const auto& b : blocks) {
    row.noalias() += J.middleCols(c, b.second) * P.middleRows(b.first, b.second);
    c += b.second;
  }
  Eigen::MatrixXd P_vv = Eigen::MatrixXd::Zero(sz, sz);  // J P_order,order Jᵀ
  c = 0;
  for (const auto& b : blocks) {
    P_vv.noalias() += row.middleCols(b.first, b.second) * J.middleCols(c, b.second).transpose();
    c += b.second;
  }
  const int id = var->id();
  P.middleRows(id, sz) = row;
  P.middleCols(id, sz) = row.transpose();
  P.block(id, id, sz, sz) = 0.5 * (P_vv + P_vv.transpose());
}

void StateHelper::augment_clone(State& state, int64_t utime) {
  if (state.clones_.count(utime) != 0) {
    throw std::invalid_argument("StateHelper::augment_clone: a clone at utime " + std::to_string(utime) +
                                " already exists");
  }
  auto pose = std::dynamic_pointer_cast<PoseJPL>(clone(state, state.imu_->pose()));
  state.clones_[utime] = pose;
}

void StateHelper::marginalize_old_clones(State& state) {
  while (static_cast<int>(state.clones_.size()) > state.options_.max_clones) {
    const auto it = state.clones_.begin();
    marginalize(state, it->second);
    state.clones_.erase(it);
  }
}

void StateHelper::register_slam_feature(State& state, const std::shared_ptr<Landmark>& landmark) {
  if (!landmark || landmark->id() < 0) {
    throw std::invalid_argument("StateHelper::register_slam_feature: landmark not in the covariance");
  }
  state.slam_[landmark->feature_id()] = landmark;
}

int StateHelper::marginalize_flagged_slam(State& state) {
  int count = 0;
  for (auto it = state.slam_.begin(); it != state.slam_.end();) {
    if (it->second->should_marginalize) {
      marginalize(state, it->second);
      it = state.slam_.erase(it);
      ++count;
    } else {
      ++it;
    }
  }
  return count;
}

void StateHelper::restore_layout(State& state, const std::vector<TypePtr>& variables, const Eigen::MatrixXd& cov,
                                 std::map<int64_t, std::shared_ptr<PoseJPL>> clones,
                                 std::map<int64_t, std::shared_ptr<Landmark>> slam) {
  int id = 0;
  for (const TypePtr& v : variables) {
    v->set_local_id(id);
    id += v->size();
  }
  if (id != cov.rows() || cov.rows() != cov.cols()) {
    throw std::invalid_argument("StateHelper::restore_layout: covariance is not " + std::to_string(id) + " square");
  }
  state.variables_ = variables;
  state.cov_ = cov;
  state.clones_ = std::move(clones);
  state.slam_ = std::move(slam);
}

void StateHelper::reset_imu(State& state, const ImuValue& value, const Eigen::Matrix<double, 15, 15>& P_imu) {
  const Eigen::VectorXd x = value.to_vector();
  state.imu_->set_value(x);
  state.imu_->set_fej(x);
  const int id = state.imu_->id();
  state.cov_.middleRows(id, 15).setZero();
  state.cov_.middleCols(id, 15).setZero();
  state.cov_.block(id, id, 15, 15) = 0.5 * (P_imu + P_imu.transpose());
}

}  // namespace estimator
}  // namespace vimot
