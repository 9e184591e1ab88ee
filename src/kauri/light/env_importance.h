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

}  // namespace kauri
