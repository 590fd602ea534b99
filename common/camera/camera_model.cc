#include "common/camera/camera_model.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <Eigen/LU>  // determinant(), inverse()

#include "common/config/config.h"

namespace vimot {

namespace {

// A rotation read from a calibration file carries ~12 significant digits, so
// its orthonormality error is ~1e-12 (EuRoC: 6e-13); 1e-6 still rejects one
// that was scaled, mistyped or given as a reflection.
constexpr double kRotationTolerance = 1e-6;

// Newton's method (Gauss-Newton on a square system) converges quadratically,
// so a last step below 1e-12 leaves an error of order 1e-24 in normalized
// units. From the distorted point as the first guess, the EuRoC cameras need
// at most 6 iterations anywhere in the image (7 for a k1 = -0.4 lens); 20
// leaves room for stronger lenses and for the step halving below.
constexpr double kUndistortStepTolerance = 1e-12;
constexpr int kMaxUndistortIterations = 20;

std::string fmt(double v) {
  std::ostringstream ss;
  ss.precision(17);
  ss << v;
  return ss.str();
}

std::string fmt_pixel(const Eigen::Vector2d& p) { return "(" + fmt(p.x()) + ", " + fmt(p.y()) + ")"; }

// Always-on input check: a calibration that fails here would make every
// projection silently wrong, so refuse it with the offending value.
void validate(const CameraCalibration& c) {
  if (c.width <= 0 || c.height <= 0) {
    throw std::invalid_argument("camera calibration: image size must be positive, got width " +
                                std::to_string(c.width) + ", height " + std::to_string(c.height));
  }
  const char* kIntrinsicNames[] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(c.intrinsics(i))) {
      throw std::invalid_argument(std::string("camera calibration: intrinsic ") + kIntrinsicNames[i] +
                                  " must be finite, got " + fmt(c.intrinsics(i)));
    }
  }
  for (int i = 0; i < 2; ++i) {
    if (!(c.intrinsics(i) > 0.0)) {
      throw std::invalid_argument(std::string("camera calibration: focal length ") + kIntrinsicNames[i] +
                                  " must be positive, got " + fmt(c.intrinsics(i)));
    }
  }
  const char* kRadtanNames[] = {"k1", "k2", "p1", "p2"};
  const char* kEquidistantNames[] = {"k1", "k2", "k3", "k4"};
  const bool radtan = c.distortion_model == DistortionModel::kRadialTangential;
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(c.distortion(i))) {
      throw std::invalid_argument(std::string("camera calibration: distortion ") +
                                  (radtan ? kRadtanNames[i] : kEquidistantNames[i]) +
                                  " must be finite, got " + fmt(c.distortion(i)));
    }
  }
  if (!c.R_ItoC.allFinite()) throw std::invalid_argument("camera calibration: R_ItoC has a non-finite entry");
  if (!c.p_IinC.allFinite()) throw std::invalid_argument("camera calibration: p_IinC has a non-finite entry");
  const double ortho_error = (c.R_ItoC.transpose() * c.R_ItoC - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  const double det = c.R_ItoC.determinant();
  if (ortho_error > kRotationTolerance || std::abs(det - 1.0) > kRotationTolerance) {
    throw std::invalid_argument("camera calibration: R_ItoC is not a rotation: max |R^T R - I| = " + fmt(ortho_error) +
                                ", det = " + fmt(det) + " (tolerance " + fmt(kRotationTolerance) + ")");
  }
}

}  // namespace

CameraModel::CameraModel(const CameraCalibration& calibration) : calib_(calibration) { validate(calib_); }

namespace {

// Below this radius the equidistant factor θd / r equals 1 + (k1 - 1/3) r² to
// within r⁴ < 1e-32: the closed form would divide 0 by 0 at the centre.
constexpr double kEquidistantSmallRadius = 1e-8;

// Equidistant model: x_d = s(r) x with s = θd(θ(r)) / r, θ = atan r.
// Returns s and (ds/dr) / r, which is finite at r = 0.
void equidistant_scale(const Eigen::Vector4d& k, double r, double* s, double* ds_dr_over_r) {
  if (r < kEquidistantSmallRadius) {
    *s = 1.0;
    *ds_dr_over_r = 2.0 * (k(0) - 1.0 / 3.0);
    return;
  }
  const double theta = std::atan(r);
  const double t2 = theta * theta;
  const double poly = 1.0 + t2 * (k(0) + t2 * (k(1) + t2 * (k(2) + t2 * k(3))));
  const double theta_d = theta * poly;
  // dθd/dθ = 1 + 3 k1 θ² + 5 k2 θ⁴ + 7 k3 θ⁶ + 9 k4 θ⁸; dθ/dr = 1 / (1 + r²).
  const double dtheta_d = 1.0 + t2 * (3.0 * k(0) + t2 * (5.0 * k(1) + t2 * (7.0 * k(2) + t2 * 9.0 * k(3))));
  const double dtheta_d_dr = dtheta_d / (1.0 + r * r);
  *s = theta_d / r;
  *ds_dr_over_r = (dtheta_d_dr * r - theta_d) / (r * r * r);
}

}  // namespace

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& normalized) const {
  const double x = normalized.x(), y = normalized.y();
  double xd = 0.0, yd = 0.0;
  if (calib_.distortion_model == DistortionModel::kEquidistant) {
    double s = 0.0, unused = 0.0;
    equidistant_scale(calib_.distortion, normalized.norm(), &s, &unused);
    xd = s * x;
    yd = s * y;
  } else {
    const double k1 = calib_.distortion(0), k2 = calib_.distortion(1);
    const double p1 = calib_.distortion(2), p2 = calib_.distortion(3);
    const double r2 = x * x + y * y;
    const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
    xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x);
    yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y;
  }
  return Eigen::Vector2d(calib_.intrinsics(0) * xd + calib_.intrinsics(2),
                         calib_.intrinsics(1) * yd + calib_.intrinsics(3));
}

Eigen::Matrix2d CameraModel::distort_jacobian(const Eigen::Vector2d& normalized) const {
  Eigen::Matrix2d J;
  if (calib_.distortion_model == DistortionModel::kEquidistant) {
    // d(s x)/dx = s I + x (ds/dr) dr/dx = s I + (ds/dr / r) x xᵀ.
    double s = 0.0, ds_dr_over_r = 0.0;
    equidistant_scale(calib_.distortion, normalized.norm(), &s, &ds_dr_over_r);
    J = s * Eigen::Matrix2d::Identity() + ds_dr_over_r * normalized * normalized.transpose();
  } else {
    const double x = normalized.x(), y = normalized.y();
    const double k1 = calib_.distortion(0), k2 = calib_.distortion(1);
    const double p1 = calib_.distortion(2), p2 = calib_.distortion(3);
    const double r2 = x * x + y * y;
    const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
    // d radial / d(x, y) = (k1 + 2 k2 r²) d r² / d(x, y), with d r² = (2x, 2y).
    const double dradial_dr2 = k1 + 2.0 * k2 * r2;
    const double dradial_dx = 2.0 * x * dradial_dr2;
    const double dradial_dy = 2.0 * y * dradial_dr2;
    J(0, 0) = radial + x * dradial_dx + 2.0 * p1 * y + 6.0 * p2 * x;
    J(0, 1) = x * dradial_dy + 2.0 * p1 * x + 2.0 * p2 * y;
    J(1, 0) = y * dradial_dx + 2.0 * p1 * x + 2.0 * p2 * y;
    J(1, 1) = radial + y * dradial_dy + 6.0 * p1 * y + 2.0 * p2 * x;
  }
  J.row(0) *= calib_.intrinsics(0);
  J.row(1) *= calib_.intrinsics(1);
  return J;
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& pixel) const {
  if (!pixel.allFinite()) {
    throw std::runtime_error("CameraModel::undistort: pixel " + fmt_pixel(pixel) + " is not finite");
  }
  if (calib_.distortion_model == DistortionModel::kEquidistant) return undistort_equidistant(pixel);
  // The distorted normalized point is the first guess: distortion moves a
  // point by a fraction of its radius, so it starts on the right branch.
  Eigen::Vector2d x((pixel.x() - calib_.intrinsics(2)) / calib_.intrinsics(0),
                    (pixel.y() - calib_.intrinsics(3)) / calib_.intrinsics(1));
  Eigen::Vector2d residual = distort(x) - pixel;
  for (int iter = 0; iter < kMaxUndistortIterations; ++iter) {
    const Eigen::Matrix2d J = distort_jacobian(x);
    // The model folds over where det J <= 0 (strong barrel distortion far
    // out): no real lens images there, and Newton would leave the branch.
    if (!(J.determinant() > 0.0)) break;
    const Eigen::Vector2d step = -J.inverse() * residual;
    if (!step.allFinite()) break;
    if (step.norm() < kUndistortStepTolerance) {
      x += step;
      // The fold check again at the solution: a root beyond the fold is a
      // spurious second preimage, not the ray the pixel came from.
      if (distort_jacobian(x).determinant() > 0.0) return x;
      break;
    }
    // Halve the step while it does not reduce the pixel residual, so a first
    // guess far from the solution cannot overshoot into divergence. After six
    // halvings the step is taken anyway: it still points downhill, and the
    // iteration limit ends a search that makes no progress.
    double scale = 1.0;
    Eigen::Vector2d candidate = x + step;
    Eigen::Vector2d candidate_residual = distort(candidate) - pixel;
    while (!(candidate_residual.squaredNorm() < residual.squaredNorm()) && scale > 1.0 / 64.0) {
      scale *= 0.5;
      candidate = x + scale * step;
      candidate_residual = distort(candidate) - pixel;
    }
    x = candidate;
    residual = candidate_residual;
  }
  throw std::runtime_error("CameraModel::undistort: no convergence for pixel " + fmt_pixel(pixel) +
                           " within " + std::to_string(kMaxUndistortIterations) +
                           " iterations (far outside the image of a " + std::to_string(calib_.width) + "x" +
                           std::to_string(calib_.height) +
                           " camera, or beyond the range where the distortion model is invertible)");
}

Eigen::Vector2d CameraModel::undistort_equidistant(const Eigen::Vector2d& pixel) const {
  // The model is radial, so inverting it is one equation in the angle θ off
  // the optical axis: θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸), solved by
  // Newton from θ = θd; then r = tan θ. (Newton on x itself would chase r to
  // infinity near 90° where tan θ blows up.)
  const Eigen::Vector2d xd((pixel.x() - calib_.intrinsics(2)) / calib_.intrinsics(0),
                           (pixel.y() - calib_.intrinsics(3)) / calib_.intrinsics(1));
  const double theta_d = xd.norm();
  if (theta_d < kEquidistantSmallRadius) return xd;
  const Eigen::Vector4d& k = calib_.distortion;
  double theta = theta_d;
  for (int iter = 0; iter < kMaxUndistortIterations; ++iter) {
    const double t2 = theta * theta;
    const double f = theta * (1.0 + t2 * (k(0) + t2 * (k(1) + t2 * (k(2) + t2 * k(3))))) - theta_d;
    const double df = 1.0 + t2 * (3.0 * k(0) + t2 * (5.0 * k(1) + t2 * (7.0 * k(2) + t2 * 9.0 * k(3))));
    // dθd/dθ <= 0: past the angle where the lens model turns back, no ray.
    if (!(df > 0.0)) break;
    const double step = f / df;
    theta -= step;
    if (std::abs(step) < kUndistortStepTolerance) {
      // A ray at 90° or more from the axis has no point on the plane z = 1.
      if (!(theta > 0.0 && theta < 0.5 * M_PI)) break;
      return xd * (std::tan(theta) / theta_d);
    }
  }
  throw std::runtime_error("CameraModel::undistort: no ray in front of the equidistant camera for pixel " +
                           fmt_pixel(pixel) + " (the model does not invert there, or the ray is 90 degrees or more "
                           "off the optical axis)");
}

bool CameraModel::in_image(const Eigen::Vector2d& pixel, double border) const {
  // Pixel centres are at integer coordinates 0 .. width-1 (OpenCV), so a
  // pixel inside [border, width-1-border] can be sampled, also bilinearly,
  // without reading outside the image. NaN compares false and is rejected.
  return pixel.x() >= border && pixel.x() <= calib_.width - 1 - border && pixel.y() >= border &&
         pixel.y() <= calib_.height - 1 - border;
}

CameraCalibration camera_from_config(const Config& node) {
  const std::string where = "config '" + node.source() + "': ";
  // The header promises a pinhole model; an ASL file naming another
  // projection (omni, ...) means intrinsics of a different meaning.
  if (node.has("camera_model")) {
    const std::string model = node.get<std::string>("camera_model");
    if (model != "pinhole") {
      node.fail("camera_model", "must be 'pinhole', got '" + model + "'");
    }
  }
  CameraCalibration c;
  const std::string distortion_model = node.get<std::string>("distortion_model");
  if (distortion_model == "radial-tangential") {
    c.distortion_model = DistortionModel::kRadialTangential;
  } else if (distortion_model == "equidistant") {
    c.distortion_model = DistortionModel::kEquidistant;
  } else {
    node.fail("distortion_model", "must be 'radial-tangential' or 'equidistant', got '" + distortion_model + "'");
  }

  const Eigen::Vector2d resolution = node.get_vec<2>("resolution");
  if (resolution.x() != std::floor(resolution.x()) || resolution.y() != std::floor(resolution.y())) {
    node.fail("resolution", "must be two integers [width, height], got [" + fmt(resolution.x()) + ", " +
                                  fmt(resolution.y()) + "]");
  }
  c.width = static_cast<int>(resolution.x());
  c.height = static_cast<int>(resolution.y());
  c.intrinsics = node.get_vec<4>("intrinsics");
  c.distortion = node.get_vec<4>("distortion_coefficients");

  const Eigen::Matrix4d T_BS = node.get_matrix("T_BS", 4, 4);
  if (T_BS.row(3) != Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0)) {
    node.fail("T_BS", "must have last row [0, 0, 0, 1]");
  }
  // T_BS maps camera (sensor) points into the body = IMU frame:
  // p_I = R_BS p_C + t_BS, hence p_C = R_BS^T p_I - R_BS^T t_BS.
  const Eigen::Matrix3d R_BS = T_BS.topLeftCorner<3, 3>();
  c.R_ItoC = R_BS.transpose();
  c.p_IinC = -R_BS.transpose() * T_BS.topRightCorner<3, 1>();

  try {
    validate(c);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(where + e.what());
  }
  return c;
}

std::vector<CameraCalibration> load_euroc_cameras(const std::string& mav0_dir) {
  std::vector<CameraCalibration> cameras;
  cameras.push_back(camera_from_config(Config::load_file(mav0_dir + "/cam0/sensor.yaml")));
  const std::string cam1 = mav0_dir + "/cam1/sensor.yaml";
  if (std::ifstream(cam1).good()) cameras.push_back(camera_from_config(Config::load_file(cam1)));
  return cameras;
}

}  // namespace vimot
