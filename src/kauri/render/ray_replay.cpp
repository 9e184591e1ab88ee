#include "kauri/render/ray_replay.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <functional>

namespace kauri {

namespace {

/// Runs `query` over `rays` in parallel; returns (seconds, number of hits).
template <class Query>
std::pair<double, uint64_t> timed_queries(tbb::task_arena& arena, const std::vector<Ray>& rays, Query query) {
  uint64_t hits = 0;
  auto t0 = std::chrono::steady_clock::now();
  arena.execute([&] {
    hits = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, rays.size(), 4096), uint64_t(0),
        [&](const tbb::blocked_range<size_t>& r, uint64_t n) {
          for (size_t i = r.begin(); i != r.end(); ++i) n += query(rays[i]) ? 1 : 0;
          return n;
        },
        std::plus<uint64_t>());
  });
  return {std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), hits};
}

}  // namespace

ReplayResult replay_rays(const EmbreeAccel& accel, const RayLog& log, int threads, int repeats) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::this_task_arena::max_concurrency());
  ReplayResult best;
  best.closest_seconds = best.shadow_seconds = 1e300;
  for (int k = 0; k < std::max(1, repeats); ++k) {
    // The hit record is consumed (counted), so the traversal cannot be optimised away.
    auto c = timed_queries(arena, log.closest, [&](const Ray& r) {
      HitRecord h;
      return accel.intersect(r, &h);
    });
    auto s = timed_queries(arena, log.shadow, [&](const Ray& r) { return accel.occluded(r); });
    best.closest_seconds = std::min(best.closest_seconds, c.first);
    best.shadow_seconds = std::min(best.shadow_seconds, s.first);
    best.closest_hits = c.second;
    best.shadow_hits = s.second;
  }
  return best;
}

}  // namespace kauri
