// Writing render results: multi-channel OpenEXR with metadata and an sRGB PNG
// preview. Both are written to a temporary file and renamed, so a killed render
// never leaves a half-written image behind.
#pragma once

#include <string>

#include "kauri/render/renderer.h"
#include "kauri/spectral/color_space.h"

namespace kauri {

struct ExrMetadata {
  ColorSpaceId color_space = ColorSpaceId::ACEScg;
  uint64_t seed = 0;
  std::string scene_name;
};

/// Channels: R, G, B, A, albedo.R/G/B, N.X/Y/Z, Z (32-bit float).
void write_exr(const std::string& path, const RenderResult& r, const ExrMetadata& meta);
/// 8-bit sRGB preview (working space → linear sRGB → sRGB transfer, clamped).
void write_png_preview(const std::string& path, const RenderResult& r, ColorSpaceId cs, float exposure = 0);
/// Reads an RGB(A) image (EXR, HDR, PNG, ...) as linear float RGB through OpenImageIO.
void read_rgb_image(const std::string& path, std::vector<float>* rgb, int* width, int* height);

}  // namespace kauri
