// The state a camera path carries from bounce to bounce, declared once.
//
// Extension points, so later features do not rewrite the integrator:
//  - every scattering event goes through record_scatter(): bounce-budget
//    counters live there today, a light-path-expression automaton state
//    (`lpe_state`) advances there tomorrow;
//  - every radiance contribution goes through PathOutput::add(): today it
//    sums into the beauty, LPE AOVs will route it by `lpe_state` and `kind`.
#pragma once

#include "kauri/bsdf/bsdf_types.h"

namespace kauri {

struct IntegratorSettings {
  int max_depth = 16;          // all bounces
  int max_diffuse = 6;         // diffuse reflection/transmission events
  int max_glossy = 8;          // glossy and specular reflection events
  int max_transmission = 12;   // refraction events
  int rr_min_depth = 4;        // Russian roulette starts after this many diffuse bounces
  Float clamp = 0;             // per-sample luminance clamp for indirect light; 0 = off
  bool albedo_aov = true;      // evaluate the first hit's directional albedo (albedo AOV)
  bool light_tree = true;      // NEE picks finite lights by the light tree (else ∝ power)
  bool path_lanes = true;      // a pixel's paths in vector lanes where the scene allows (path_lanes.h)
};

enum class ContributionKind : uint8_t { Emission, DirectLight };

struct PathState {
  SampledSpectrum beta{1};     // throughput f·cos/pdf along the path
  Float eta_scale = 1;         // Π η² of refractions, keeps RR unbiased in dense media
  int depth = 0;
  int diffuse_depth = 0, glossy_depth = 0, transmission_depth = 0;
  bool specular_bounce = false;  // last event was a delta lobe (no MIS on the emitter hit)
  bool any_non_specular = false;
  // A bounce budget ran out at the last scattering event: the ray it sampled is still
  // traced, for the emission it finds (the BSDF half of that vertex's MIS-weighted direct
  // light, as Cycles' "terminate on next surface"), and the path ends at its next hit.
  bool last_segment = false;
  Float prev_pdf = 0;          // BSDF pdf of the last bounce, for MIS on hit emitters
  Point3 prev_p;               // where the last bounce happened
  Normal3 prev_n;              // its shading normal (the light tree's receiver factor)
  uint32_t lpe_state = 0;      // reserved for the LPE automaton

  /// Counts an event against the bounce budgets; false when this event exceeds one (the
  /// caller then traces its ray for emission only: `last_segment`).
  KAURI_HOST_DEVICE bool record_scatter(const BSDFSample& s, const IntegratorSettings& cfg) {
    if (s.transmission) ++transmission_depth;
    else if (s.scattering == Scattering::Diffuse) ++diffuse_depth;
    else ++glossy_depth;
    if (s.transmission && s.scattering == Scattering::Diffuse) ++diffuse_depth;
    specular_bounce = s.is_specular();
    any_non_specular = any_non_specular || !specular_bounce;
    return diffuse_depth <= cfg.max_diffuse && glossy_depth <= cfg.max_glossy &&
           transmission_depth <= cfg.max_transmission;
  }
};

/// What one camera sample produces: beauty plus the first-hit data AOVs.
struct PathOutput {
  SampledSpectrum L{0};
  SampledSpectrum L_direct_first{0};  // contributions before any indirect bounce (clamp exempt)
  Vec3 rgb_exact;                     // output-space colour added as is (lights seen directly; clamp exempt)
  bool hit = false;                   // camera ray hit geometry (alpha)
  bool albedo_set = false;
  SampledSpectrum albedo{0};
  Normal3 normal;
  Float depth = kInfinity;
  uint32_t rays = 0;

  /// `st.depth` is the number of bounces before this contribution: light seen
  /// directly or via one bounce (emitter hit after the first BSDF sample, or
  /// next-event estimation at the first hit) is direct and never clamped.
  KAURI_HOST_DEVICE void add(const SampledSpectrum& c, const PathState& st, ContributionKind kind) {
    bool direct = kind == ContributionKind::DirectLight ? st.depth == 0 : st.depth <= 1;
    if (direct) L_direct_first += c;
    else L += c;
  }
};

/// A batch of up to kBatchColumns camera samples as columns, entry k for sample k: the
/// camera stage's rays and wavelengths, which the path lanes load as vectors, and the
/// paths' radiance sums (PathOutput::L, L_direct_first), which the film stage loads as
/// vectors. Through the per-sample structures (Ray, SampledWavelengths, PathOutput) each
/// vector stage transposed them again, lane by lane (the rays alone 1.5% of the environment
/// scene's render, the wavelengths 1.2% of the glossy scene's).
inline constexpr int kBatchColumns = 16;
struct alignas(64) BatchColumns {
  float o[3][kBatchColumns] = {}, d[3][kBatchColumns] = {}, tmax[kBatchColumns] = {};
  float lambda[kSpectrumSamples][kBatchColumns] = {};  // SampledWavelengths::lambda
  float L[kSpectrumSamples][kBatchColumns] = {}, L_direct[kSpectrumSamples][kBatchColumns] = {};

  KAURI_HOST_DEVICE Ray ray(int k) const {
    return Ray{Point3{o[0][k], o[1][k], o[2][k]}, Vec3{d[0][k], d[1][k], d[2][k]}, tmax[k]};
  }
  KAURI_HOST_DEVICE void set_ray(int k, const Ray& r) {
    for (int a = 0; a < 3; ++a) o[a][k] = r.o[a], d[a][k] = r.d[a];
    tmax[k] = r.tmax;
  }
  KAURI_HOST_DEVICE void set_wavelengths(int k, const SampledWavelengths& w) {
    for (int i = 0; i < kSpectrumSamples; ++i) lambda[i][k] = w.lambda[i];
  }
  /// Sample k's radiance sums from its path's output.
  KAURI_HOST_DEVICE void set_radiance(int k, const PathOutput& out) {
    for (int i = 0; i < kSpectrumSamples; ++i) L[i][k] = out.L[i], L_direct[i][k] = out.L_direct_first[i];
  }
};

}  // namespace kauri
