// OpenCV contrib's rgbd odometries (opencv2/rgbd/depth.hpp, OpenCV 4.x) as external trackers:
//   RgbdOdometry     photometric, Steinbruecker, Sturm, Cremers, ICCV 2011
//   ICPOdometry      point-to-plane ICP over a depth pyramid
//   RgbdICPOdometry  both terms in one solve
//   FastICPOdometry  the KinectFusion ICP of OpenCV's kinfu (bilateral filter, projective association)
// All with the library's defaults (as OpenCV's own samples/odometry_evaluation.cpp uses them); only
// the camera matrix comes from the source. Compiled only when SEAMLESS_HAS_OPENCV.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd.hpp>

#include <limits>

#include "core/error.hpp"
#include "recon/external/frame_cache.hpp"
#include "recon/external/odometry.hpp"

namespace seamless::external {

namespace {

cv::Mat camera_matrix(const Intrinsics& K) { return (cv::Mat_<float>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1); }

cv::Ptr<cv::rgbd::Odometry> make_cv_odometry(OpenCvMethod m, const Intrinsics& K) {
  cv::Mat cam = camera_matrix(K);
  switch (m) {
    case OpenCvMethod::rgbd: return cv::rgbd::RgbdOdometry::create(cam);
    case OpenCvMethod::icp: return cv::rgbd::ICPOdometry::create(cam);
    case OpenCvMethod::rgbd_icp: return cv::rgbd::RgbdICPOdometry::create(cam);
    case OpenCvMethod::fast_icp: return cv::rgbd::FastICPOdometry::create(cam);
  }
  throw Error("unknown OpenCV odometry method");
}

const char* method_name(OpenCvMethod m) {
  switch (m) {
    case OpenCvMethod::rgbd: return "OpenCV RgbdOdometry";
    case OpenCvMethod::icp: return "OpenCV ICPOdometry";
    case OpenCvMethod::rgbd_icp: return "OpenCV RgbdICPOdometry";
    case OpenCvMethod::fast_icp: return "OpenCV FastICPOdometry";
  }
  return "OpenCV odometry";
}

// Depth as OpenCV's odometry wants it: CV_32FC1 metres, NaN where there is no reading (its
// pyramids and masks skip NaN; a 0 would be averaged into the coarser levels). Gray CV_8UC1.
cv::Ptr<cv::rgbd::OdometryFrame> to_cv_frame(const RgbdFrame& f) {
  const int w = f.depth.width(), h = f.depth.height();
  std::vector<float> d = f.depth.to_host();
  cv::Mat depth(h, w, CV_32FC1);
  for (int i = 0; i < w * h; ++i)
    depth.at<float>(i / w, i % w) = d[i] > 0.f ? d[i] : std::numeric_limits<float>::quiet_NaN();
  cv::Mat gray(h, w, CV_8UC1, cv::Scalar(0));
  if (f.rgb.width() == w && f.rgb.height() == h) {
    std::vector<uchar3> c = f.rgb.to_host();
    cv::Mat rgb(h, w, CV_8UC3, c.data());
    cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);  // copies out of c
  }
  return cv::rgbd::OdometryFrame::create(gray, depth);
}

cv::Mat to_cv(const SE3& T) {
  cv::Mat m = cv::Mat::eye(4, 4, CV_64FC1);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = T.R.m[r][c];
    m.at<double>(r, 3) = (&T.t.x)[r];
  }
  return m;
}

SE3 from_cv(const cv::Mat& m) {
  double a[4][4];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a[r][c] = m.at<double>(r, c);
  return rigid_from_matrix(a);
}

class OpenCvOdometry : public Odometry {
 public:
  OpenCvOdometry(OpenCvMethod m, const Intrinsics& K) : method_(m), odo_(make_cv_odometry(m, K)) {
    if (K.dist[0] != 0.f || K.dist[1] != 0.f || K.dist[2] != 0.f || K.dist[3] != 0.f || K.dist[4] != 0.f)
      throw Error(std::string(method_name(m)) + " needs undistorted images: the source's intrinsics carry distortion");
  }

  std::optional<OdometryEstimate> prev_T_cur(const RgbdFrame& prev, const RgbdFrame& cur,
                                             const std::optional<SE3>& guess) override {
    // Each frame is converted and its pyramids built once (OpenCV keeps them in the OdometryFrame).
    auto prepare = [this](const RgbdFrame& f) {
      cv::Ptr<cv::rgbd::OdometryFrame> o = to_cv_frame(f);
      odo_->prepareFrameCache(o, cv::rgbd::OdometryFrame::CACHE_ALL);
      return o;
    };
    cv::Ptr<cv::rgbd::OdometryFrame> p = cache_.get(prev, prepare), c = cache_.get(cur, prepare);
    cv::Mat Rt;
    // OpenCV's Rt maps source points into the destination frame (dst_p = Rt src_p): with the
    // current frame as source and the previous as destination it is prev_T_cur.
    bool ok = odo_->compute(c, p, Rt, guess ? to_cv(*guess) : cv::Mat());
    if (!ok || Rt.empty()) return std::nullopt;
    OdometryEstimate e;
    e.prev_T_cur = from_cv(Rt);
    return e;
  }
  std::string name() const override { return method_name(method_); }

 private:
  OpenCvMethod method_;
  cv::Ptr<cv::rgbd::Odometry> odo_;
  TwoFrameCache<cv::Ptr<cv::rgbd::OdometryFrame>> cache_;
};

}  // namespace

std::unique_ptr<Odometry> make_opencv_odometry(OpenCvMethod m, const Intrinsics& K) {
  return std::make_unique<OpenCvOdometry>(m, K);
}

}  // namespace seamless::external
