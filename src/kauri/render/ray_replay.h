// Closeness to the limit: record the ray queries a render makes, then replay them
// through the accelerator alone (Embree's rtcIntersect1 / rtcOccluded1, one ray per call,
// as the path tracer issues them, or in packets of 8 or 16; and the direct tests of a few
// analytic shapes). The ratio of the render's rays/s to the replay's rays/s says how much
// of the time goes to everything that is not ray traversal. Host code.
#pragma once

#include <cstdint>
#include <vector>

#include "kauri/render/renderer.h"

namespace kauri {

struct RayLog {
  std::vector<Ray> closest;  // closest-hit queries (camera and bounce rays)
  std::vector<Ray> shadow;   // any-hit queries (next-event shadow rays)
  uint64_t closest_hits = 0, shadow_hits = 0;  // what the render saw
};

/// Traces the paths of `cfg` (same pixels, samples and seed as render()) on one thread,
/// recording every ray query; the image is discarded. Stops recording once the log holds
/// `max_rays` rays.
RayLog record_rays(const CompiledScene& scene, const RenderSettings& cfg, size_t max_rays);

struct ReplayResult {
  double closest_seconds = 0, shadow_seconds = 0;  // best of the repetitions
  uint64_t closest_hits = 0, shadow_hits = 0;      // must equal the log's counts
  double rays_per_second(const RayLog& log) const {
    double t = closest_seconds + shadow_seconds;
    return t > 0 ? double(log.closest.size() + log.shadow.size()) / t : 0;
  }
};

/// Replays `log` through `accel` on `threads` threads (0 = all cores), `repeats` times.
/// `packet` 1: every query alone (rtcIntersect1 / rtcOccluded1, as the path tracer issues
/// them); 8 or 16: the log's queries in order, `packet` at a time, as Embree packets of
/// incoherent rays (rtcIntersect8/16, rtcOccluded8/16): what traversal would cost a
/// wavefront integrator that hands Embree a packet of paths' rays (consecutive recorded
/// rays are one path's bounces and its neighbours', about as incoherent as such a packet).
ReplayResult replay_rays(const EmbreeAccel& accel, const RayLog& log, int threads, int repeats, int packet = 1);

}  // namespace kauri
