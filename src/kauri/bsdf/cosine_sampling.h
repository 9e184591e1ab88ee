// Cosine-weighted reflection sampling shared by lobes whose shape is close to cos θ_i
// (rough diffuse, sheen): ω_i on ω_o's side with pdf cos θ_i / π, f from the lobe.
#pragma once

#include "kauri/bsdf/bsdf_types.h"
#include "kauri/sampler/sampling.h"

namespace kauri {

template <class Lobe>
KAURI_HOST_DEVICE BSDFSample sample_cosine_reflection(const Lobe& lobe, Vec3 wo, Vec2 u, TransportMode mode) {
  BSDFSample s;
  if (wo.z == 0) return s;
  s.wi = sample_cosine_hemisphere(u);
  if (wo.z < 0) s.wi.z = -s.wi.z;
  if (s.wi.z == 0) return s;
  s.pdf = cosine_hemisphere_pdf(abs_cos_theta(s.wi));
  s.f = lobe.eval(wo, s.wi, mode);
  s.scattering = Scattering::Diffuse;
  return s;
}

}  // namespace kauri
