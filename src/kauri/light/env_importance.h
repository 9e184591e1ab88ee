// Host side of environment maps: the piecewise-constant importance image that
// Distribution2D samples. Render-time lookups (light.h) interpolate radiance
// bilinearly, so the importance of a texel must cover every texel its radiance mixes.
#pragma once

#include <vector>

#include "kauri/core/math.h"

namespace kauri {

/// Sampling weights of a width × height lat-long image from its luminance: the maximum
/// over each texel's 3 × 3 neighbourhood (u wraps around, v clamps at the poles), times
/// sinθ at the texel centre (the lat-long area element), so the solid-angle density is
/// positive wherever bilinearly interpolated radiance is.
std::vector<Float> env_importance(const std::vector<Float>& luminance, int width, int height);

/// The same weights MIS-compensated (Karlík et al. 2019, "MIS compensation: optimizing
/// sampling techniques in multiple importance sampling", sec. 4): max(0, m − m̄) × sinθ,
/// m the dilated luminance above and m̄ its mean over the sphere (solid-angle weighted).
/// Next-event estimation combined by MIS with BSDF sampling then spends its samples on
/// what stands out (a sun, a window) and leaves the smooth rest to BSDF sampling, which
/// already covers it. All zero for a constant image: NEE then has nothing to add.
std::vector<Float> env_importance_compensated(const std::vector<Float>& luminance, int width, int height);

}  // namespace kauri
