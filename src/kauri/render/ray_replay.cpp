#include "kauri/render/ray_replay.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>

namespace kauri {

namespace {

/// Runs `query(first, count, answers)` over `rays` in parallel, in chunks that are whole
/// packets of `packet` rays; returns (seconds, number of true answers).
template <class Query>
std::pair<double, uint64_t> timed_packets(tbb::task_arena& arena, const std::vector<Ray>& rays, size_t packet,
                                          Query query) {
  const size_t chunks = (rays.size() + packet - 1) / packet;
  uint64_t hits = 0;
  auto t0 = std::chrono::steady_clock::now();
  arena.execute([&] {
    hits = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, chunks, std::max<size_t>(1, 4096 / packet)), uint64_t(0),
        [&](const tbb::blocked_range<size_t>& r, uint64_t n) {
          bool answers[EmbreeAccel::kMaxStreamWidth] = {};
          for (size_t c = r.begin(); c != r.end(); ++c) {
            const size_t first = c * packet, count = std::min(packet, rays.size() - first);
            query(rays.data() + first, count, answers);
            for (size_t k = 0; k < count; ++k) n += answers[k] ? 1 : 0;
          }
          return n;
        },
        std::plus<uint64_t>());
  });
  return {std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), hits};
}

}  // namespace

ReplayResult replay_rays(const EmbreeAccel& accel, const RayLog& log, int threads, int repeats, int packet) {
  if (packet != 1 && !EmbreeAccel::stream_width_supported(packet))
    throw std::invalid_argument("replay_rays: packet must be 1, 8 or 16, not " + std::to_string(packet));
  tbb::task_arena arena(threads > 0 ? threads : tbb::this_task_arena::max_concurrency());
  ReplayResult best;
  best.closest_seconds = best.shadow_seconds = 1e300;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    // The answers are consumed (counted), so the traversal cannot be optimised away.
    std::pair<double, uint64_t> c, s;
    if (packet == 1) {
      c = timed_packets(arena, log.closest, 1, [&](const Ray* r, size_t, bool* found) {
        HitRecord h;
        found[0] = accel.intersect(*r, &h);
      });
      s = timed_packets(arena, log.shadow, 1, [&](const Ray* r, size_t, bool* blocked) { blocked[0] = accel.occluded(*r); });
    } else {
      const size_t w = size_t(packet);
      c = timed_packets(arena, log.closest, w, [&](const Ray* r, size_t n, bool* found) {
        HitRecord h[EmbreeAccel::kMaxStreamWidth];
        accel.intersect_stream(r, n, packet, h, found);
      });
      s = timed_packets(arena, log.shadow, w, [&](const Ray* r, size_t n, bool* blocked) {
        accel.occluded_stream(r, n, packet, blocked);
      });
    }
    best.closest_seconds = std::min(best.closest_seconds, c.first);
    best.shadow_seconds = std::min(best.shadow_seconds, s.first);
    best.closest_hits = c.second;
    best.shadow_hits = s.second;
  }
  return best;
}

}  // namespace kauri
