#include "drivers/camera/camera_config.h"

#include <sstream>

#include "common/time/utime.h"

namespace vimot::camera {

CameraConfig camera_config_from(const Config& config) {
  config.check_keys("", {"mode", "sources", "image", "timing", "reopen", "channels"});
  config.check_keys("sources", {"left", "right"});
  config.check_keys("image", {"width", "height", "fps", "exposure", "resize"});
  config.check_keys("timing", {"latency", "stereo_tolerance", "file_timestamps", "file_start"});
  config.check_keys("reopen", {"stall_timeout", "initial_interval", "max_interval"});
  config.check_keys("channels", {"cam_left", "cam_right", "heartbeat"});

  CameraConfig c;
  CameraOptions& o = c.driver;
  const std::string mode = config.get<std::string>("mode");
  if (mode != "mono" && mode != "stereo") config.fail("mode", "must be 'mono' or 'stereo', got '" + mode + "'");
  o.stereo = mode == "stereo";
  const Config sources = config.sub("sources");
  for (const char* side : {"left", "right"}) {
    if (side == std::string("right") && !o.stereo) {
      if (sources.has("right")) sources.fail("right", "is given but mode is mono");
      break;
    }
    const std::string spec = sources.get<std::string>(side);
    c.sources.push_back(is_device_spec(spec) ? spec : config.resolve_path(spec));
  }

  const Config image = config.sub("image");
  o.width = image.get<int>("width");
  o.height = image.get<int>("height");
  if (o.width <= 0) image.fail("width", "must be > 0 px, got " + std::to_string(o.width));
  if (o.height <= 0) image.fail("height", "must be > 0 px, got " + std::to_string(o.height));
  o.fps = image.get_or<double>("fps", 0.0);
  if (o.fps < 0.0) image.fail("fps", "must be >= 0 Hz (0: the device's own rate)");
  o.resize = image.get_or<bool>("resize", false);
  c.request.width = o.width;
  c.request.height = o.height;
  c.request.fps = o.fps;
  const std::string exposure = image.get_or<std::string>("exposure", "auto");
  if (exposure != "auto") {
    c.request.auto_exposure = false;
    c.request.exposure_s = image.get<double>("exposure");
    if (c.request.exposure_s <= 0.0) image.fail("exposure", "must be 'auto' or > 0 s, got " + exposure);
  }

  if (config.has("timing")) {
    const Config t = config.sub("timing");
    o.latency_s = t.get_or<double>("latency", o.latency_s);
    if (o.latency_s < 0.0) t.fail("latency", "must be >= 0 s (the frame reaches the host after its exposure)");
    o.stereo_tolerance_s = t.get_or<double>("stereo_tolerance", o.stereo_tolerance_s);
    if (o.stereo_tolerance_s < 0.0) t.fail("stereo_tolerance", "must be >= 0 s");
    const std::string stamps = t.get_or<std::string>("file_timestamps", "file_rate");
    if (stamps != "file_rate" && stamps != "host") {
      t.fail("file_timestamps", "must be 'file_rate' or 'host', got '" + stamps + "'");
    }
    o.file_timestamps = stamps == "host" ? TimestampMode::kHost : TimestampMode::kFileRate;
    const double start = t.get_or<double>("file_start", 0.0);
    if (start < 0.0) t.fail("file_start", "must be >= 0 s");
    o.file_start_utime = seconds_to_utime(start);
  }
  if (config.has("reopen")) {
    const Config r = config.sub("reopen");
    o.reopen_initial_s = r.get_or<double>("initial_interval", o.reopen_initial_s);
    o.reopen_max_s = r.get_or<double>("max_interval", o.reopen_max_s);
    if (o.reopen_initial_s <= 0.0) r.fail("initial_interval", "must be > 0 s");
    if (o.reopen_max_s < o.reopen_initial_s) r.fail("max_interval", "must be >= initial_interval");
    c.stall_timeout_s = r.get_or<int>("stall_timeout", c.stall_timeout_s);
    if (c.stall_timeout_s < 1) r.fail("stall_timeout", "must be >= 1 s (whole seconds)");
  }
  return c;
}

SourceOpener source_opener(const CameraConfig& config, std::size_t index,
                           const std::function<void(const std::string&)>& log) {
  const std::string name = index == 0 ? "left" : "right";
  return [name, spec = config.sources.at(index), request = config.request, log] {
    DeviceReport report;
    std::unique_ptr<FrameSource> source = open_video_source(name, spec, request, &report);
    std::ostringstream text;
    if (source->is_file()) {
      text << "camera " << name << ": file " << spec << " at " << source->file_fps() << " Hz";
    } else {
      text << "camera " << name << ": device " << spec << " accepted " << report.width << "x" << report.height << " at "
           << report.fps << " Hz, exposure " << report.exposure << " x 100 us (asked " << request.width << "x"
           << request.height << " at " << request.fps << " Hz, exposure "
           << (request.auto_exposure ? "auto" : std::to_string(request.exposure_s) + " s") << ")";
    }
    log(text.str());
    return source;
  };
}

}  // namespace vimot::camera
