// Lobe: the closed set of BSDF lobes as a tagged union with switch dispatch
// (no virtual calls, so the same code compiles for CUDA). New lobes add an enum
// value, a union member and one line per dispatch case.
#pragma once

#include "kauri/bsdf/conductor.h"
#include "kauri/bsdf/dielectric.h"
#include "kauri/bsdf/diffuse_transmission.h"
#include "kauri/bsdf/lambert.h"
#include "kauri/bsdf/oren_nayar.h"
#include "kauri/bsdf/rough_dielectric.h"
#include "kauri/bsdf/sheen.h"
#include "kauri/bsdf/thin_dielectric.h"

#include <type_traits>
#include <utility>

namespace kauri {

namespace lobe_detail {
/// Whether lobe type L has eval_pdf(wo, wi, mode, &pdf).
template <class L, class = void>
struct HasEvalPdf : std::false_type {};
template <class L>
struct HasEvalPdf<L, std::void_t<decltype(std::declval<const L&>().eval_pdf(Vec3{}, Vec3{}, TransportMode::Radiance,
                                                                             static_cast<Float*>(nullptr)))>>
    : std::true_type {};
}  // namespace lobe_detail

enum class LobeType : uint8_t { Lambert, SmoothDielectric, GGXConductor, DiffuseTransmission, RoughDielectric, ThinDielectric, Sheen,
                               OrenNayar };

struct Lobe {
  LobeType type = LobeType::Lambert;
  union {
    LambertLobe lambert;
    SmoothDielectricLobe dielectric;
    GGXConductorLobe conductor;
    DiffuseTransmissionLobe diffuse_transmission;
    RoughDielectricLobe rough_dielectric;
    ThinDielectricLobe thin_dielectric;
    SheenLobe sheen;
    OrenNayarLobe oren_nayar;
  };

  /// Storage only: no union member is initialised (BSDF and material evaluation keep
  /// arrays of kMaxLobes / kMaxLayerNodes lobes per hit, and zeroing ~1.5 KB each time
  /// cost ~5% of a glossy render). Assign a concrete lobe before use.
  KAURI_HOST_DEVICE Lobe() {}
  KAURI_HOST_DEVICE Lobe(const LambertLobe& l) : type(LobeType::Lambert), lambert(l) {}
  KAURI_HOST_DEVICE Lobe(const SmoothDielectricLobe& l) : type(LobeType::SmoothDielectric), dielectric(l) {}
  KAURI_HOST_DEVICE Lobe(const GGXConductorLobe& l) : type(LobeType::GGXConductor), conductor(l) {}
  KAURI_HOST_DEVICE Lobe(const DiffuseTransmissionLobe& l)
      : type(LobeType::DiffuseTransmission), diffuse_transmission(l) {}
  KAURI_HOST_DEVICE Lobe(const RoughDielectricLobe& l) : type(LobeType::RoughDielectric), rough_dielectric(l) {}
  KAURI_HOST_DEVICE Lobe(const ThinDielectricLobe& l) : type(LobeType::ThinDielectric), thin_dielectric(l) {}
  KAURI_HOST_DEVICE Lobe(const SheenLobe& l) : type(LobeType::Sheen), sheen(l) {}
  KAURI_HOST_DEVICE Lobe(const OrenNayarLobe& l) : type(LobeType::OrenNayar), oren_nayar(l) {}

  /// Calls f(concrete_lobe) for the active member.
  template <class F>
  KAURI_HOST_DEVICE auto dispatch(F&& f) const {
    switch (type) {
      case LobeType::SmoothDielectric: return f(dielectric);
      case LobeType::GGXConductor: return f(conductor);
      case LobeType::DiffuseTransmission: return f(diffuse_transmission);
      case LobeType::RoughDielectric: return f(rough_dielectric);
      case LobeType::ThinDielectric: return f(thin_dielectric);
      case LobeType::Sheen: return f(sheen);
      case LobeType::OrenNayar: return f(oren_nayar);
      case LobeType::Lambert:
      default: return f(lambert);
    }
  }

  KAURI_HOST_DEVICE SampledSpectrum eval(Vec3 wo, Vec3 wi, TransportMode m) const {
    return dispatch([&](const auto& l) { return l.eval(wo, wi, m); });
  }
  KAURI_HOST_DEVICE Float pdf(Vec3 wo, Vec3 wi) const {
    return dispatch([&](const auto& l) { return l.pdf(wo, wi); });
  }
  /// eval() and pdf() of one pair: lobes with shared terms (microfacets) define
  /// eval_pdf(); the others are evaluated twice.
  KAURI_HOST_DEVICE SampledSpectrum eval_pdf(Vec3 wo, Vec3 wi, TransportMode m, Float* pdf_out) const {
    return dispatch([&](const auto& l) -> SampledSpectrum {
      if constexpr (lobe_detail::HasEvalPdf<std::decay_t<decltype(l)>>::value) {
        return l.eval_pdf(wo, wi, m, pdf_out);
      } else {
        *pdf_out = l.pdf(wo, wi);
        return l.eval(wo, wi, m);
      }
    });
  }
  KAURI_HOST_DEVICE BSDFSample sample(Vec3 wo, Float uc, Vec2 u, SampledWavelengths& lambda, TransportMode m) const {
    return dispatch([&](const auto& l) { return l.sample(wo, uc, u, lambda, m); });
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_r(Vec3 wo) const {
    return dispatch([&](const auto& l) { return l.albedo_r(wo); });
  }
  KAURI_HOST_DEVICE SampledSpectrum albedo_t(Vec3 wo) const {
    return dispatch([&](const auto& l) { return l.albedo_t(wo); });
  }
  KAURI_HOST_DEVICE Float ior(int i) const { return dispatch([&](const auto& l) { return l.ior(i); }); }
  KAURI_HOST_DEVICE Float roughness() const { return dispatch([&](const auto& l) { return l.roughness(); }); }
  KAURI_HOST_DEVICE Vec3 mean_direction(Vec3 wo) const {
    return dispatch([&](const auto& l) { return l.mean_direction(wo); });
  }
  KAURI_HOST_DEVICE LobeClass lobe_class() const { return dispatch([](const auto& l) { return l.kClass; }); }
  KAURI_HOST_DEVICE Scattering scattering() const {
    switch (type) {
      case LobeType::GGXConductor: return conductor.scattering();
      case LobeType::RoughDielectric: return rough_dielectric.scattering();
      case LobeType::DiffuseTransmission: return DiffuseTransmissionLobe::kScattering;
      case LobeType::ThinDielectric: return ThinDielectricLobe::kScattering;
      case LobeType::Sheen: return SheenLobe::kScattering;
      case LobeType::OrenNayar: return OrenNayarLobe::kScattering;
      case LobeType::SmoothDielectric: return SmoothDielectricLobe::kScattering;
      case LobeType::Lambert:
      default: return LambertLobe::kScattering;
    }
  }
  KAURI_HOST_DEVICE const char* name() const {
    if (type == LobeType::GGXConductor) return conductor.name();  // @1 or @2 (compensated)
    if (type == LobeType::RoughDielectric) return rough_dielectric.name();
    return dispatch([](const auto& l) { return l.kName; });
  }
};

}  // namespace kauri
