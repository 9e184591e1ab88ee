#include "kauri/render/renderer.h"
#include "kauri/render/ray_replay.h"

#include <sys/resource.h>
#include <unistd.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "kauri/integrator/path_lanes.h"
#include "kauri/integrator/path_tracer.h"
#include "kauri/film/splat_lanes.h"
#include "kauri/render/light_aa.h"
#include "kauri/render/sample_lanes.h"

namespace kauri {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string format_duration(double s) {
  char buf[32];
  if (!std::isfinite(s)) return "--:--";
  int t = int(s + 0.5);
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%d:%02d:%02d", t / 3600, (t / 60) % 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%02d:%02d", t / 60, t % 60);
  return buf;
}

std::string format_rate(double v) {
  char buf[32];
  if (v >= 1e9) std::snprintf(buf, sizeof buf, "%.2fG", v / 1e9);
  else if (v >= 1e6) std::snprintf(buf, sizeof buf, "%.2fM", v / 1e6);
  else if (v >= 1e3) std::snprintf(buf, sizeof buf, "%.1fk", v / 1e3);
  else std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

/// Progress bar on stderr, redrawn at most 4 times a second by whichever thread gets there.
class ProgressBar {
 public:
  ProgressBar(bool enabled, uint64_t total, double time_limit)
      : enabled_(enabled), total_(total), time_limit_(time_limit), start_(Clock::now()) {}
  void add(uint64_t samples) {
    uint64_t done = done_.fetch_add(samples) + samples;
    if (!enabled_) return;
    double t = seconds_since(start_);
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || t - last_draw_ < 0.25) return;
    last_draw_ = t;
    draw(done, t, false);
  }
  void finish() {
    if (enabled_) draw(done_.load(), seconds_since(start_), true);
  }

 private:
  void draw(uint64_t done, double t, bool final) {
    double frac = total_ ? std::min(1.0, double(done) / double(total_)) : 1;
    if (time_limit_ > 0) frac = std::max(frac, std::min(1.0, t / time_limit_));
    double eta = frac > 0 ? t * (1 - frac) / frac : double(INFINITY);
    if (time_limit_ > 0) eta = std::min(eta, std::max(0.0, time_limit_ - t));
    const int width = 30;
    int filled = int(frac * width);
    std::string bar(size_t(filled), '#');
    bar.resize(width, '-');
    std::fprintf(stderr, "\r[%s] %5.1f%%  %s samples/s  elapsed %s  ETA %s ", bar.c_str(), 100 * frac,
                 format_rate(t > 0 ? double(done) / t : 0).c_str(), format_duration(t).c_str(),
                 final ? "00:00" : format_duration(eta).c_str());
    if (final) std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  bool enabled_;
  uint64_t total_;
  double time_limit_;
  Clock::time_point start_;
  std::atomic<uint64_t> done_{0};
  std::mutex mutex_;
  double last_draw_ = -1;
};

struct TileContext {
  const CompiledScene& scene;
  const RenderSettings& cfg;
  FilmView film;
  Float splat_q;        // gaussian_step_ratio(cfg.filter), once per render
  PixelAOVAccum* aovs;  // film.width × film.height, row-major
  std::atomic<uint64_t>& rays;
  std::atomic<uint64_t>& nan_samples;
  std::vector<NaNReport>& nan_pixels;
  std::mutex& nan_mutex;
  // Light antialiasing: per pixel 0 (not probed yet), 1 (off) or 2 (flagged); null: off.
  uint8_t* light_aa_flags = nullptr;
  Float light_aa_min_spread = 0;  // light_colours_differ's threshold
  const LaneTriangles* lane_triangles = nullptr;  // non-null: the group's paths in vector lanes
};

/// Settings the render loop relies on (the Python layer checks them first, with its names).
void check_settings(const RenderSettings& cfg) {
  if (cfg.width <= 0 || cfg.height <= 0) throw std::invalid_argument("render: the image size must be positive");
  if (!(cfg.filter.radius > 0 && cfg.filter.radius <= kMaxFilterRadius))
    throw std::invalid_argument("render: filter radius must be in (0, 8] pixels");
  if (cfg.light_aa < 0 || cfg.light_aa > kLightAAMaxRays)
    throw std::invalid_argument("render: light_aa must be in [0, " + std::to_string(kLightAAMaxRays) + "]");
}

/// Beauty sample into the film: splatted, or into its own pixel with weight 1. kAddWeight
/// false: into the sums alone (splat_sample's; light antialiasing's extra rays).
template <bool kAddWeight = true>
void add_beauty(const TileContext& c, PixelAccum& px, Vec2 film_pos, Vec3 rgb, Float alpha) {
  if (c.cfg.reconstruction == FilmReconstruction::Splat) {
    splat_sample<kAddWeight>(c.film, c.cfg.filter, c.splat_q, film_pos, rgb, alpha);
    return;
  }
  px.rgb[0] += double(rgb.x);
  px.rgb[1] += double(rgb.y);
  px.rgb[2] += double(rgb.z);
  px.alpha += double(alpha);
  if (kAddWeight) px.weight += 1;
}

/// Closest hits of a pixel's camera rays: one Embree packet (coherent rays traverse the
/// BVH together), or ray by ray for other accelerators (the ray recorder).
template <class Accel>
void intersect_camera_rays(const Accel& accel, const Ray* r, int n, HitRecord* h, bool* found) {
  for (int k = 0; k < n; ++k) found[k] = accel.intersect(r[k], &h[k]);
}
void intersect_camera_rays(const EmbreeAccel& accel, const Ray* r, int n, HitRecord* h, bool* found) {
  accel.intersect_packet(r, n, h, found);
}

/// The camera ray of sample `s` of pixel (x, y) in the sequence of `seed`: starts
/// `sampler` on that sample and draws the film position, lens point and wavelengths (the
/// sample's first dimensions).
Ray camera_sample(const TileContext& c, int x, int y, uint32_t s, uint64_t seed, Sampler& sampler, Vec2* film_pos,
                  SampledWavelengths* lambda) {
  const SceneView& sv = c.scene.view();
  sampler.start_pixel_sample(x, y, s, seed);
  *film_pos =
      sample_film_position(c.cfg.reconstruction == FilmReconstruction::Splat, c.cfg.filter, x, y, sampler.get_2d());
  Vec2 u_lens;
  if (sv.camera.lens_radius > 0) u_lens = sampler.get_2d();
  else sampler.skip_2d();  // a pinhole needs no lens sample
  *lambda = sample_wavelengths(sv.wavelengths, sampler.get_1d());
  return sv.camera.generate_ray(*film_pos, u_lens);
}

/// A NaN/Inf sample (sample `s` of pixel (x, y)): counted and reported, and entered in the
/// film as black with its full weight, so the estimate stays normalised by what was traced.
[[gnu::noinline, gnu::cold]] void report_non_finite(const TileContext& c, int x, int y, uint32_t s,
                                                    float beauty[4]) {
  c.nan_samples.fetch_add(1);
  {
    std::lock_guard<std::mutex> lock(c.nan_mutex);
    if (c.nan_pixels.size() < 32) c.nan_pixels.push_back({x, y, s});
  }
  beauty[0] = beauty[1] = beauty[2] = beauty[3] = 0;
}

/// A finite sample's first-hit data into its pixel's AOV sums (renders with cfg.aovs).
[[gnu::noinline]] void add_sample_aovs(const TileContext& c, const PathOutput& out, const SampledWavelengths& lambda,
                                       PixelAOVAccum* aov) {
  const SceneView& sv = c.scene.view();
  if (out.hit) {
    aov->normal[0] += double(out.normal.x);
    aov->normal[1] += double(out.normal.y);
    aov->normal[2] += double(out.normal.z);
    if (std::isfinite(out.depth)) {
      aov->depth += double(out.depth);
      ++aov->depth_count;
    }
  }
  if (out.albedo_set) {
    // Albedo: the colour of the reflectance under the working space's white.
    const SampledXYZWeights to_xyz(lambda);
    SampledSpectrum white = sv.illuminant.sample(lambda);
    Vec3 num = to_xyz(out.albedo * white), den = to_xyz(white);
    if (is_finite(num)) {
      for (int k = 0; k < 3; ++k) {
        aov->albedo_xyz[k] += double(num[k]);
        aov->white_xyz[k] += double(den[k]);
      }
    }
  }
}

/// Sample `s` of pixel (x, y) before it enters the film: its beauty (r, g, b, α) from its
/// colour `rgb` (sample_rgb_lanes), and its path's first-hit data into the pixel's AOV
/// sums. Inline: the common case, a finite beauty without AOVs, is four stores, where the
/// out-of-line call with the rare cases in its body cost ~85 instructions a sample (3% of
/// the hangar's).
KAURI_FORCE_INLINE void finish_sample(const TileContext& c, int x, int y, uint32_t s, Vec3 rgb, const PathOutput& out,
                                      const SampledWavelengths& lambda, PixelAOVAccum* aov, float beauty[4]) {
  if (!is_finite(rgb)) return report_non_finite(c, x, y, s, beauty);
  beauty[0] = rgb.x;
  beauty[1] = rgb.y;
  beauty[2] = rgb.z;
  beauty[3] = out.hit ? 1 : 0;
  if (c.cfg.aovs) add_sample_aovs(c, out, lambda, aov);
}

/// Camera rays of samples first … first + n − 1 (n ≤ kSampleLanes) of pixel (x, y) in the
/// sequence of `seed`, in vector lanes where the sampler allows (sample_lanes.h). s[0]
/// carries the sampler type and samples per pixel of that sequence; every array holds
/// kSampleLanes entries.
void camera_group(const TileContext& c, int x, int y, uint32_t first, int n, uint64_t seed, Sampler* s, Ray* rays,
                  Vec2* film_pos, SampledWavelengths* lambdas) {
  const SceneView& sv = c.scene.view();
  if (start_pixel_samples_lanes(s, n, x, y, first, seed)) {
    camera_rays_lanes(sv.camera, sv.wavelengths, c.cfg.reconstruction == FilmReconstruction::Splat, c.cfg.filter, x,
                      y, s, n, rays, film_pos, lambdas);
    return;
  }
  for (int k = 0; k < n; ++k) {
    // Copies of the first sampler share its per-pixel state (ZSobol's block and seed).
    if (k > 0) s[k] = s[0];
    rays[k] = camera_sample(c, x, y, first + uint32_t(k), seed, s[k], &film_pos[k], &lambdas[k]);
  }
}

/// The lamps' colour a probe ray sees (light_aa.h): rgb_seen_directly without the
/// constant environments, which never flag a pixel.
Vec3 probe_colour(const SceneView& s, const Ray& ray, bool found, const HitRecord& h) {
  if (found) return rgb_seen_directly(s, ray, found, h);
  Vec3 rgb{0, 0, 0};
  for (int i = 0; i < s.n_infinite_lights; ++i) {
    const Light& l = s.lights[s.infinite_lights[i]];
    if (l.type == LightType::Distant) path_detail::add_seen_directly(l, ray.d, &rgb);
  }
  return rgb;
}

/// Light antialiasing's probe of pixel (x, y) (light_aa.h): whether the colours of the
/// lights its probe rays meet directly differ. *rays counts the probe's rays.
template <class Accel>
bool probe_light_edges(const TileContext& c, const Accel& accel, int x, int y, uint64_t* rays) {
  constexpr int kN = kLightAAProbeRays;
  static_assert(kN <= kSampleLanes, "the probe is one group of camera rays");
  Sampler s[kSampleLanes];
  s[0].type = c.cfg.sampler;
  s[0].set_samples_per_pixel(kN);
  Ray r[kSampleLanes];
  Vec2 film_pos[kSampleLanes];
  SampledWavelengths lambdas[kSampleLanes]{};
  HitRecord h[kSampleLanes];
  bool found[kSampleLanes];
  camera_group(c, x, y, 0, kN, light_aa_probe_seed(c.cfg.seed), s, r, film_pos, lambdas);
  intersect_camera_rays(accel, r, kN, h, found);
  Vec3 rgb[kN];
  for (int k = 0; k < kN; ++k) rgb[k] = probe_colour(c.scene.view(), r[k], found[k], h[k]);
  *rays += kN;
  return light_colours_differ(rgb, kN, c.light_aa_min_spread);
}

/// Light antialiasing's per-pixel flags at the start of a render (TileContext::
/// light_aa_flags): 0 (to probe) where light_aa_candidates marks the pixel, else 1 (off);
/// empty where the render has no use for it. *min_spread gets the probe's threshold.
/// Off, too, where a pixel's extra rays would outnumber the sampler's 32-bit indices.
std::vector<uint8_t> light_aa_start(const SceneView& sv, const RenderSettings& cfg, Float* min_spread) {
  *min_spread = 0;
  if (cfg.light_aa == 0 || uint64_t(cfg.spp) * uint64_t(cfg.light_aa) >= (uint64_t(1) << 31)) return {};
  const int margin = cfg.reconstruction == FilmReconstruction::Splat ? 1 : 1 + int(std::ceil(cfg.filter.radius));
  LightAAMask mask = light_aa_candidates(sv, cfg.width, cfg.height, kLightAASpreadShare, margin);
  *min_spread = mask.min_spread;
  bool any = false;
  for (uint8_t& f : mask.pixels) {
    any = any || f;
    f = f ? 0 : 1;
  }
  if (!any) return {};
  return std::move(mask.pixels);
}

/// Whether pixel (x, y) takes light antialiasing's extra rays: probed on its first visit.
template <class Accel>
bool light_aa_pixel(const TileContext& c, const Accel& accel, int x, int y, uint64_t* rays) {
  if (!c.light_aa_flags) return false;
  uint8_t& flag = c.light_aa_flags[size_t(y) * size_t(c.film.width) + size_t(x)];
  if (flag == 0) flag = probe_light_edges(c, accel, x, y, rays) ? 2 : 1;
  return flag == 2;
}

/// Light antialiasing's extra rays for camera samples first … first + n − 1 of pixel
/// (x, y): E = cfg.light_aa rays each, points E·first … E·(first + n) − 1 of the pixel's
/// extra sequence, each adding Le_rgb / E at its film position to the film's sums but not
/// to their weights (light_aa.h). *rays counts them.
template <class Accel>
void light_aa_rays(const TileContext& c, const Accel& accel, int x, int y, uint32_t first, int n, uint64_t* rays) {
  constexpr int kGroup = EmbreeAccel::kPacketSize;
  const uint32_t e = uint32_t(c.cfg.light_aa);
  const Float inv_e = 1 / Float(e);
  Sampler s[kSampleLanes];
  s[0].type = c.cfg.sampler;
  s[0].set_samples_per_pixel(uint32_t(c.cfg.spp) * e);
  Ray r[kSampleLanes];
  Vec2 film_pos[kSampleLanes];
  SampledWavelengths lambdas[kSampleLanes]{};
  HitRecord h[kSampleLanes];
  bool found[kSampleLanes];
  float beauty[kSampleLanes][4];
  const bool splat = c.cfg.reconstruction == FilmReconstruction::Splat;
  const uint64_t seed = light_aa_extra_seed(c.cfg.seed);
  const uint32_t end = (first + uint32_t(n)) * e;
  for (uint32_t g0 = first * e; g0 < end; g0 += kGroup) {
    const int m = int(std::min<uint32_t>(kGroup, end - g0));
    camera_group(c, x, y, g0, m, seed, s, r, film_pos, lambdas);
    intersect_camera_rays(accel, r, m, h, found);
    for (int k = 0; k < m; ++k) {
      Vec3 rgb = rgb_seen_directly(c.scene.view(), r[k], found[k], h[k]) * inv_e;
      if (!is_finite(rgb)) {  // as a path's non-finite sample: counted, and black
        c.nan_samples.fetch_add(1);
        rgb = Vec3{0, 0, 0};
      }
      beauty[k][0] = rgb.x, beauty[k][1] = rgb.y, beauty[k][2] = rgb.z, beauty[k][3] = 0;
    }
    *rays += uint64_t(m);
    if (splat && splat_group<false>(c.film, c.cfg.filter, x, y, film_pos, beauty, m)) continue;
    for (int k = 0; k < m; ++k)
      add_beauty<false>(c, c.film.at(x, y), film_pos[k], Vec3{beauty[k][0], beauty[k][1], beauty[k][2]}, 0);
  }
}

/// The paths of a group of n camera samples, their radiance sums into `cols`: in vector
/// lanes where the render allows it (TileContext::lane_triangles, Embree's packets at
/// hand), which find the hits of the camera rays in `cols` themselves, else one by one
/// from `camera_rays` and their hits `primary` (null where the lanes trace).
template <class Accel>
void trace_group(const TileContext& c, const Accel& accel, const Ray* camera_rays, BatchColumns& cols,
                 SampledWavelengths* lambdas, Sampler* samplers, PathOutput* outs, const HitRecord* primary,
                 const bool* primary_found, int n) {
  for (int k = 0; k < n; ++k) outs[k] = PathOutput{};
#if KAURI_PATH_LANES
  if constexpr (std::is_same_v<Accel, EmbreeAccel>) {
    if (c.lane_triangles) {
      trace_paths_lanes(c.scene.view(), *c.lane_triangles, accel, c.cfg.integrator, cols, lambdas, samplers, outs, n);
      return;
    }
  }
#endif
  for (int k = 0; k < n; ++k) {
    trace_path(c.scene.view(), accel, c.cfg.integrator, camera_rays[k], lambdas[k], samplers[k], &outs[k],
               &primary[k], primary_found[k]);
    cols.set_radiance(k, outs[k]);
  }
}

template <class Accel>
void render_pixel_samples(const TileContext& c, const Accel& accel, int x, int y, uint32_t s0, uint32_t s1,
                          uint64_t* rays) {
  const SceneView& sv = c.scene.view();
  PixelAccum& px = c.film.at(x, y);
  // Data AOV sums: allocated only when the render gathers them (cfg.aovs).
  PixelAOVAccum* aov = c.cfg.aovs ? c.aovs + (size_t(y) * size_t(c.film.width) + size_t(x)) : nullptr;
  // The pixel's samples go in groups of a packet, in three stages: their camera rays (in
  // vector lanes, sample_lanes.h); the paths from their first hits, traced together
  // kPathLanes at a time (two groups with AVX-512's 16 lanes); their colours (in lanes)
  // into the film, splatted together (splat_lanes.h). Every sample keeps its own sampler,
  // so each path draws the dimensions it would draw alone and the image is as with one
  // sample at a time.
  constexpr int kGroup = EmbreeAccel::kPacketSize;
  static_assert(kGroup == kSampleLanes, "a group's samples fill one vector");
  constexpr int kTrace = kPathLanes > kGroup ? kPathLanes : kGroup;  // samples traced together
  static_assert(kTrace % kGroup == 0, "whole groups traced together");
  Sampler samplers[kTrace];
  Ray camera_rays[kTrace];  // where the lanes do not trace (they take the rays in `cols`)
  static_assert(kTrace <= kBatchColumns, "the traced samples are one batch of columns");
  BatchColumns cols;
  Vec2 film_pos[kTrace];
  SampledWavelengths lambdas[kTrace]{};  // every lane initialised: the vector stages read all
  HitRecord primary[kTrace];
  bool primary_found[kTrace];
  PathOutput outs[kTrace];
  Vec3 rgb[kGroup];
  float beauty[kTrace][4];
  static_assert(kTrace <= SplatWindow::kLanes, "the traced samples splat at once");
  const bool splat = c.cfg.reconstruction == FilmReconstruction::Splat;
  // The radius-2 Gaussian's splats summed over the pixel's groups, added to the film once.
  const bool splat_window = splat && SplatWindow::applies(c.cfg.filter);
  SplatWindow window;
  const bool light_aa = light_aa_pixel(c, accel, x, y, rays);
  // Where the path lanes trace the group, they find the camera rays' hits too (in one
  // coherent packet of their width); trace_group passes them no `primary`.
  bool lanes_find_hits = false;
#if KAURI_PATH_LANES
  if constexpr (std::is_same_v<Accel, EmbreeAccel>) lanes_find_hits = c.lane_triangles != nullptr;
#endif
  SobolSeedCache seeds;  // the pixel's pair seeds, hashed once for all its samples
  for (int g = 0; g < kTrace; g += kGroup) {  // each group's first sampler carries the sequence
    samplers[g].type = c.cfg.sampler;
    samplers[g].set_samples_per_pixel(uint32_t(c.cfg.spp));
    samplers[g].seeds = &seeds;
  }
  for (uint32_t t0 = s0; t0 < s1; t0 += kTrace) {
    const int m = int(std::min<uint32_t>(kTrace, s1 - t0));
    // The samplers of all traced samples started at once where the core's vectors hold
    // them (16 in the v4 core), else per group in camera_group.
    const bool started = kStartLanes >= kTrace && kTrace > kGroup &&
                         start_pixel_samples_wide(samplers, m, x, y, t0, c.cfg.seed);
    for (int g = 0; g < m; g += kGroup) {
      const int n = std::min(kGroup, m - g);
      if (started) {
        camera_rays_lanes(sv.camera, sv.wavelengths, splat, c.cfg.filter, x, y, samplers + g, n, camera_rays + g,
                          film_pos + g, lambdas + g, lanes_find_hits ? &cols : nullptr, g);
      } else {
        camera_group(c, x, y, t0 + uint32_t(g), n, c.cfg.seed, samplers + g, camera_rays + g, film_pos + g,
                     lambdas + g);
        for (int k = 0; lanes_find_hits && k < n; ++k) {
          cols.set_ray(g + k, camera_rays[g + k]);
          cols.set_wavelengths(g + k, lambdas[g + k]);
        }
      }
      if (!lanes_find_hits) intersect_camera_rays(accel, camera_rays + g, n, primary + g, primary_found + g);
    }
    trace_group(c, accel, camera_rays, cols, lambdas, samplers, outs, lanes_find_hits ? nullptr : primary,
                primary_found, m);
    for (int g = 0; g < m; g += kGroup) {
      const int n = std::min(kGroup, m - g);
      const uint32_t g0 = t0 + uint32_t(g);
      PathOutput* o = outs + g;
      for (int k = 0; k < n; ++k) {
        *rays += o[k].rays;
        if (light_aa) o[k].rgb_exact = Vec3{0, 0, 0};  // the extra rays below estimate it
      }
      if (light_aa) light_aa_rays(c, accel, x, y, g0, n, rays);
      sample_rgb_lanes(sv, c.cfg.integrator.clamp, cols, g, o, lambdas + g, n, rgb);
      for (int k = 0; k < n; ++k)
        finish_sample(c, x, y, g0 + uint32_t(k), rgb[k], o[k], lambdas[g + k], aov, beauty[g + k]);
    }
    if (splat_window)
      window.add(c.film, c.cfg.filter, x, y, film_pos, beauty, m);
    else
      for (int k = 0; k < m; ++k)
        add_beauty(c, px, film_pos[k], Vec3{beauty[k][0], beauty[k][1], beauty[k][2]}, beauty[k][3]);
  }
  if (splat_window) window.flush(c.film, x, y);
}

/// Film sums → pixel values: beauty, and the AOVs when they were gathered.
RenderResult resolve(const std::vector<PixelAccum>& film, const std::vector<PixelAOVAccum>& aov_sums, int w, int h,
                     const SceneView& sv, Vec3 white_xyz, bool aovs) {
  RenderResult r;
  r.width = w;
  r.height = h;
  const size_t n = size_t(w) * size_t(h);
  r.rgba.resize(4 * n);
  for (size_t i = 0; i < n; ++i) {
    const PixelAccum& p = film[i];
    double inv = p.weight > 0 ? 1.0 / p.weight : 0;
    for (int k = 0; k < 3; ++k) r.rgba[4 * i + size_t(k)] = float(p.rgb[k] * inv);
    r.rgba[4 * i + 3] = float(p.alpha * inv);
  }
  if (!aovs) return r;
  r.albedo.resize(3 * n);
  r.normal.resize(3 * n);
  r.depth.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const PixelAOVAccum& p = aov_sums[i];
    Vec3 albedo_xyz;
    for (int k = 0; k < 3; ++k)
      albedo_xyz[k] = p.white_xyz[k] > 0 ? Float(p.albedo_xyz[k] / p.white_xyz[k]) * white_xyz[k] : 0;
    Vec3 albedo = sv.to_rgb(albedo_xyz);
    for (int k = 0; k < 3; ++k) r.albedo[3 * i + size_t(k)] = albedo[k];
    Vec3 nrm{Float(p.normal[0]), Float(p.normal[1]), Float(p.normal[2])};
    Float l = length(nrm);
    if (l > 0) nrm = nrm / l;
    r.normal[3 * i] = nrm.x;
    r.normal[3 * i + 1] = nrm.y;
    r.normal[3 * i + 2] = nrm.z;
    r.depth[i] = p.depth_count ? float(p.depth / p.depth_count) : INFINITY;
  }
  return r;
}

/// Samples per pixel of the first pass. A render without a time limit is one pass: the
/// pixel's samples go through the vector stages of render_pixel_samples in groups of 8, so
/// passes of 1, 2 or 4 samples would run those stages with 1/8 to 1/2 of their lanes, and
/// every pass ends at a barrier (16 spp of the Cornell box at 64 × 64, two threads: 43 ms
/// in the ramp of passes, 38 ms in one). A time limit needs boundaries to stop at: its
/// passes start at one sample per pixel and grow (next_pass_spp).
uint32_t first_pass_spp(const RenderSettings& cfg) { return cfg.time_limit > 0 ? 1 : uint32_t(cfg.spp); }

/// The pass after `done` samples per pixel, under a time limit: 1, 1, 2, 4, 8, 16, 16, …,
/// so the render stops at 1, 2, 4, 8, 16, 32, 48, … samples per pixel. From 8 on the passes
/// fill whole groups, and the early stops are powers of two, the counts at which Sobol'
/// points are stratified in every elementary interval.
uint32_t next_pass_spp(uint32_t done) { return std::min<uint32_t>(std::max<uint32_t>(done, 1), 16); }

}  // namespace

TileGrid make_tile_grid(const RenderSettings& cfg) {
  TileGrid g;
  const int w = cfg.width, h = cfg.height;
  auto count = [&](int ts) { return ((w + ts - 1) / ts) * ((h + ts - 1) / ts); };
  int ts = std::max(1, cfg.tile_size);
  const int m = cfg.reconstruction == FilmReconstruction::Splat ? cfg.filter.margin() : 0;
  if (m > 0) {
    ts = std::max(ts, 2 * m);
    // Small images: smaller tiles until each phase has enough tiles to balance the
    // threads. A function of the image and filter only (never of the thread count).
    while (ts / 2 >= 2 * m && count(ts) < 4 * 64) ts /= 2;
  }
  g.size = ts;
  g.nx = (w + ts - 1) / ts;
  g.ny = (h + ts - 1) / ts;
  g.phases.resize(m > 0 ? 4 : 1);
  for (int t = 0; t < g.nx * g.ny; ++t) {
    int phase = m > 0 ? (t % g.nx) % 2 + 2 * ((t / g.nx) % 2) : 0;
    g.phases[size_t(phase)].push_back(t);
  }
  return g;
}

size_t peak_rss_bytes() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return size_t(ru.ru_maxrss) * 1024;
}

std::string RenderStats::summary() const {
  std::ostringstream os;
  os << "render time " << format_duration(seconds) << " (" << seconds << " s), " << spp << " spp, "
     << format_rate(samples_per_second()) << " samples/s, " << rays << " rays, " << format_rate(rays_per_second())
     << " rays/s, scene " << (scene_bytes >> 20) << " MiB, peak memory " << (peak_rss_bytes >> 20) << " MiB, "
     << materials << " materials sharing " << layer_layouts << " layer layouts, "
     << (scene_reused ? std::string("compiled scene reused")
                      : "scene compiled in " + std::to_string(compile_seconds) + " s");
  if (light_aa_pixels) os << ", light antialiasing in " << light_aa_pixels << " pixels";
  if (nan_samples) {
    os << "\nwarning: " << nan_samples << " non-finite samples discarded, first at pixel";
    for (size_t i = 0; i < nan_pixels.size() && i < 4; ++i)
      os << " (" << nan_pixels[i].x << ", " << nan_pixels[i].y << ")";
  }
  return os.str();
}

RenderResult render(const CompiledScene& scene, const RenderSettings& settings) {
  check_settings(settings);
  RenderSettings cfg = settings;
  cfg.integrator.albedo_aov = cfg.aovs;
  const int w = cfg.width, h = cfg.height;
  std::vector<PixelAccum> film(size_t(w) * size_t(h));
  std::vector<PixelAOVAccum> aov_sums(cfg.aovs ? film.size() : 0);
  std::atomic<uint64_t> rays{0}, nan_samples{0};
  std::vector<NaNReport> nan_pixels;
  std::mutex nan_mutex;
  Float min_spread = 0;
  std::vector<uint8_t> light_aa_flags = light_aa_start(scene.view(), cfg, &min_spread);
  TileContext ctx{scene, cfg, FilmView{film.data(), w, h}, gaussian_step_ratio(cfg.filter),
                  aov_sums.data(), rays, nan_samples, nan_pixels, nan_mutex,
                  light_aa_flags.empty() ? nullptr : light_aa_flags.data(), min_spread};
  // The paths in vector lanes, where every surface of the scene is of their kind.
  LaneTrianglesStore lane_triangles;
  LaneTriangles lane_view;
  if (cfg.integrator.path_lanes && path_lanes_supported(scene.view())) {
    lane_triangles = build_lane_triangles(scene.view(), scene.accel().root_quads());
    lane_view = lane_triangles.view();
    ctx.lane_triangles = &lane_view;
  }
  const TileGrid grid = make_tile_grid(cfg);
  const int ts = grid.size;
  const int threads = cfg.threads > 0 ? cfg.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  ProgressBar progress(cfg.progress, uint64_t(w) * uint64_t(h) * uint64_t(cfg.spp), cfg.time_limit);

  auto t0 = Clock::now();
  uint32_t done_spp = 0, pass_spp = first_pass_spp(cfg);
  while (done_spp < uint32_t(cfg.spp)) {
    uint32_t s0 = done_spp, s1 = std::min<uint32_t>(uint32_t(cfg.spp), done_spp + pass_spp);
    arena.execute([&] {
      for (const std::vector<int>& phase : grid.phases) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, phase.size()), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i != r.end(); ++i) {
            const int t = phase[i];
            int x0 = (t % grid.nx) * ts, y0 = (t / grid.nx) * ts;
            uint64_t tile_rays = 0;
            for (int y = y0; y < std::min(h, y0 + ts); ++y)
              for (int x = x0; x < std::min(w, x0 + ts); ++x) render_pixel_samples(ctx, scene.accel(), x, y, s0, s1, &tile_rays);
            rays.fetch_add(tile_rays);
            progress.add(uint64_t(std::min(h, y0 + ts) - y0) * uint64_t(std::min(w, x0 + ts) - x0) * (s1 - s0));
          }
        });
      }
    });
    done_spp = s1;
    pass_spp = next_pass_spp(done_spp);
    if (cfg.time_limit > 0 && seconds_since(t0) >= cfg.time_limit) break;
  }
  progress.finish();

  RenderResult result = resolve(film, aov_sums, w, h, scene.view(), spectrum_to_xyz(scene.view().illuminant), cfg.aovs);
  RenderStats& st = result.stats;
  st.seconds = seconds_since(t0);
  st.spp = int(done_spp);
  st.samples = uint64_t(w) * uint64_t(h) * done_spp;
  st.rays = rays.load();
  st.nan_samples = nan_samples.load();
  std::sort(nan_pixels.begin(), nan_pixels.end(),
            [](const NaNReport& a, const NaNReport& b) { return std::tie(a.sample, a.y, a.x) < std::tie(b.sample, b.y, b.x); });
  st.nan_pixels = nan_pixels;
  st.scene_bytes = scene.bytes();
  st.materials = scene.material_count();
  st.layer_layouts = scene.layout_count();
  st.peak_rss_bytes = peak_rss_bytes();
  st.path_lanes = ctx.lane_triangles != nullptr;
  st.light_aa_pixels = uint64_t(std::count(light_aa_flags.begin(), light_aa_flags.end(), uint8_t(2)));
  return result;
}

/// Forwards ray queries to Embree and records them (single-threaded use only).
struct RecordingAccel {
  const EmbreeAccel& accel;
  RayLog* log;
  size_t max_rays;
  bool full() const { return log->closest.size() + log->shadow.size() >= max_rays; }
  bool intersect(const Ray& r, HitRecord* h) const {
    bool hit = accel.intersect(r, h);
    if (!full()) {
      log->closest.push_back(r);
      log->closest_hits += hit ? 1 : 0;
    }
    return hit;
  }
  bool occluded(const Ray& r) const {
    bool hit = accel.occluded(r);
    if (!full()) {
      log->shadow.push_back(r);
      log->shadow_hits += hit ? 1 : 0;
    }
    return hit;
  }
};

RayLog record_rays(const CompiledScene& scene, const RenderSettings& cfg, size_t max_rays) {
  check_settings(cfg);
  std::vector<PixelAccum> film(size_t(cfg.width) * size_t(cfg.height));
  std::vector<PixelAOVAccum> aov_sums(film.size());
  std::atomic<uint64_t> rays{0}, nan_samples{0};
  std::vector<NaNReport> nan_pixels;
  std::mutex nan_mutex;
  Float min_spread = 0;
  std::vector<uint8_t> light_aa_flags = light_aa_start(scene.view(), cfg, &min_spread);
  TileContext ctx{scene, cfg, FilmView{film.data(), cfg.width, cfg.height}, gaussian_step_ratio(cfg.filter),
                  aov_sums.data(), rays, nan_samples, nan_pixels, nan_mutex,
                  light_aa_flags.empty() ? nullptr : light_aa_flags.data(), min_spread};
  RayLog log;
  RecordingAccel rec{scene.accel(), &log, max_rays};
  uint64_t n = 0;
  for (int y = 0; y < cfg.height && !rec.full(); ++y)
    for (int x = 0; x < cfg.width && !rec.full(); ++x) render_pixel_samples(ctx, rec, x, y, 0, uint32_t(cfg.spp), &n);
  return log;
}

}  // namespace kauri
