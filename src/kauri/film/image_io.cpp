#include "kauri/film/image_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticities.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace kauri {

namespace {

std::string temp_path_for(const std::string& path) {
  return path + ".tmp-" + std::to_string(getpid());
}

void commit(const std::string& tmp, const std::string& path) {
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("could not move " + tmp + " to " + path);
  }
}

Imf::Chromaticities chromaticities_of(ColorSpaceId id) {
  const ColorSpaceDefinition& d = color_space_definition(id);
  return Imf::Chromaticities(Imath::V2f(float(d.r[0]), float(d.r[1])), Imath::V2f(float(d.g[0]), float(d.g[1])),
                             Imath::V2f(float(d.b[0]), float(d.b[1])), Imath::V2f(float(d.white[0]), float(d.white[1])));
}

float srgb_encode(float c) {
  c = std::min(std::max(c, 0.0f), 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1 / 2.4f) - 0.055f;
}

}  // namespace

void write_exr(const std::string& path, const RenderResult& r, const ExrMetadata& meta) {
  const int w = r.width, h = r.height;
  Imf::Header header(w, h);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::addChromaticities(header, chromaticities_of(meta.color_space));
  header.insert("colorSpace", Imf::StringAttribute(color_space_name(meta.color_space)));
  header.insert("kauri:version", Imf::StringAttribute(KAURI_VERSION));
  header.insert("kauri:spp", Imf::IntAttribute(r.stats.spp));
  header.insert("kauri:renderTime", Imf::FloatAttribute(float(r.stats.seconds)));
  header.insert("kauri:seed", Imf::StringAttribute(std::to_string(meta.seed)));
  header.insert("kauri:nanSamples", Imf::StringAttribute(std::to_string(r.stats.nan_samples)));
  if (!meta.scene_name.empty()) header.insert("kauri:scene", Imf::StringAttribute(meta.scene_name));

  struct Channel {
    const char* name;
    const float* base;
    size_t stride;  // floats per pixel
  };
  const Channel channels[] = {
      {"R", r.rgba.data() + 0, 4},       {"G", r.rgba.data() + 1, 4},       {"B", r.rgba.data() + 2, 4},
      {"A", r.rgba.data() + 3, 4},       {"albedo.R", r.albedo.data() + 0, 3}, {"albedo.G", r.albedo.data() + 1, 3},
      {"albedo.B", r.albedo.data() + 2, 3}, {"N.X", r.normal.data() + 0, 3}, {"N.Y", r.normal.data() + 1, 3},
      {"N.Z", r.normal.data() + 2, 3},   {"Z", r.depth.data(), 1}};
  const bool aovs = !r.albedo.empty();  // a beauty-only render (aovs = false) writes RGBA
  Imf::FrameBuffer fb;
  for (const Channel& c : channels) {
    if (!aovs && c.stride != 4) continue;
    header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
    fb.insert(c.name, Imf::Slice(Imf::FLOAT, (char*)c.base, sizeof(float) * c.stride, sizeof(float) * c.stride * size_t(w)));
  }
  const std::string tmp = temp_path_for(path);
  try {
    Imf::OutputFile file(tmp.c_str(), header);
    file.setFrameBuffer(fb);
    file.writePixels(h);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("could not write " + path + ": " + e.what());
  }
  commit(tmp, path);
}

void write_png_preview(const std::string& path, const RenderResult& r, ColorSpaceId cs, float exposure) {
  const int w = r.width, h = r.height;
  const float scale = std::exp2(exposure);
  std::vector<unsigned char> px(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < size_t(w) * size_t(h); ++i) {
    Vec3 rgb = working_to_linear_srgb(cs, Vec3{r.rgba[4 * i], r.rgba[4 * i + 1], r.rgba[4 * i + 2]} * scale);
    for (int k = 0; k < 3; ++k) px[3 * i + size_t(k)] = (unsigned char)std::lround(255 * srgb_encode(rgb[k]));
  }
  const std::string tmp = temp_path_for(path);
  auto out = OIIO::ImageOutput::create("png");
  if (!out) throw std::runtime_error("OpenImageIO cannot write PNG");
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  if (!out->open(tmp, spec) || !out->write_image(OIIO::TypeDesc::UINT8, px.data()) || !out->close()) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("could not write " + path + ": " + out->geterror());
  }
  commit(tmp, path);
}

void read_rgb_image(const std::string& path, std::vector<float>* rgb, int* width, int* height) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw std::invalid_argument(path + ": cannot open image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 3) throw std::invalid_argument(path + ": expected an RGB image, found " + std::to_string(spec.nchannels) + " channel(s)");
  *width = spec.width;
  *height = spec.height;
  std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw std::invalid_argument(path + ": cannot read pixels: " + in->geterror());
  // 8-bit PNG / JPEG files store sRGB-encoded values: decode them to linear
  // (IEC 61966-2-1), as every texture and environment lookup expects linear RGB.
  std::string encoding = spec.get_string_attribute("oiio:ColorSpace");
  bool srgb = encoding == "sRGB" || encoding == "srgb_rec709_scene" || encoding == "srgb";
  auto decode = [srgb](float v) {
    if (!srgb) return v;
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
  };
  rgb->resize(size_t(spec.width) * size_t(spec.height) * 3);
  for (size_t i = 0; i < size_t(spec.width) * size_t(spec.height); ++i)
    for (int k = 0; k < 3; ++k) (*rgb)[3 * i + size_t(k)] = decode(all[i * size_t(spec.nchannels) + size_t(k)]);
}

}  // namespace kauri
