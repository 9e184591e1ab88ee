// Embeds the fitted Jakob-Hanika tables (rgb2spec_fit output, built by CMake) into the
// library's read-only data with the assembler's .incbin, so no runtime file I/O is
// needed. GCC/Clang on ELF targets. The .bin paths come from compile definitions
// KAURI_RGB2SPEC_SRGB_BIN / KAURI_RGB2SPEC_ACESCG_BIN.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "kauri/spectral/color_space.h"

#if !defined(KAURI_RGB2SPEC_SRGB_BIN) || !defined(KAURI_RGB2SPEC_ACESCG_BIN)
#error "KAURI_RGB2SPEC_SRGB_BIN and KAURI_RGB2SPEC_ACESCG_BIN must name the fitted tables"
#endif

#define KAURI_INCBIN(sym, path)                                      \
  asm(".pushsection .rodata\n"                                       \
      ".balign 16\n"                                                 \
      ".globl " #sym "_begin\n.hidden " #sym "_begin\n" #sym "_begin:\n" \
      ".incbin \"" path "\"\n"                                       \
      ".globl " #sym "_end\n.hidden " #sym "_end\n" #sym "_end:\n"     \
      ".popsection\n")

KAURI_INCBIN(kauri_rgb2spec_srgb, KAURI_RGB2SPEC_SRGB_BIN);
KAURI_INCBIN(kauri_rgb2spec_acescg, KAURI_RGB2SPEC_ACESCG_BIN);

extern "C" {
extern const unsigned char kauri_rgb2spec_srgb_begin[], kauri_rgb2spec_srgb_end[];
extern const unsigned char kauri_rgb2spec_acescg_begin[], kauri_rgb2spec_acescg_end[];
}

namespace kauri {
namespace {

/// Checks "KSPC" + uint32 res + float scale[res] + float data[3*res^3*3] and builds the
/// view; a mismatch means a broken build, so it is fatal.
RGBToSpectrumTable parse(const unsigned char* begin, const unsigned char* end, const char* name) {
  size_t size = size_t(end - begin);
  uint32_t res = 0;
  if (size >= 8) std::memcpy(&res, begin + 4, 4);
  size_t expected = 8 + 4 * (size_t(res) + size_t(9) * res * res * res);
  if (size < 8 || std::memcmp(begin, "KSPC", 4) != 0 || res < 2 || res > 1024 || size != expected) {
    std::fprintf(stderr, "kauri: embedded RGB->spectrum table '%s' is corrupt (%zu bytes)\n", name, size);
    std::abort();
  }
  const float* scale = reinterpret_cast<const float*>(begin + 8);  // 16-byte aligned blob
  return {int(res), scale, scale + res};
}

}  // namespace

const RGBToSpectrumTable& rgb_to_spectrum_table(ColorSpaceId id) {
  static const RGBToSpectrumTable srgb = parse(kauri_rgb2spec_srgb_begin, kauri_rgb2spec_srgb_end, "srgb");
  static const RGBToSpectrumTable aces =
      parse(kauri_rgb2spec_acescg_begin, kauri_rgb2spec_acescg_end, "acescg");
  return id == ColorSpaceId::ACEScg ? aces : srgb;
}

}  // namespace kauri
