#include "extwrench/estimation/contact_estimate.hpp"

namespace extwrench {

std::string_view to_string(ContactModel m) noexcept {
  switch (m) {
    case ContactModel::kPureForce:
      return "pure_force";
    case ContactModel::kKnownPoint:
      return "known_point";
  }
  return "unknown";
}

std::string_view to_string(AccelerationRoute a) noexcept {
  switch (a) {
    case AccelerationRoute::kResidual:
      return "residual";
    case AccelerationRoute::kDifferentiation:
      return "differentiation";
  }
  return "unknown";
}

std::string describe_flags(std::uint32_t flags) {
  static constexpr struct {
    std::uint32_t bit;
    const char* name;
  } kNames[] = {
      {EstimateFlag::kContact, "contact"},
      {EstimateFlag::kPending, "pending"},
      {EstimateFlag::kForce, "force"},
      {EstimateFlag::kMoment, "moment"},
      {EstimateFlag::kLineOfAction, "line"},
      {EstimateFlag::kSurfacePoint, "surface_point"},
      {EstimateFlag::kSurfaceMissed, "surface_missed"},
      {EstimateFlag::kKnownPoint, "known_point"},
      {EstimateFlag::kNoGeometry, "no_geometry"},
      {EstimateFlag::kIllConditioned, "ill_conditioned"},
      {EstimateFlag::kUnobservable, "unobservable"},
      {EstimateFlag::kDisagreement, "disagreement"},
      {EstimateFlag::kBaseOnly, "base_only"},
      {EstimateFlag::kTaring, "taring"},
      {EstimateFlag::kLinkMismatch, "link_mismatch"},
      {EstimateFlag::kAmbiguous, "ambiguous"},
      {EstimateFlag::kResidualIsolation, "residual_isolation"},
      {EstimateFlag::kPartial, "partial"},
      {EstimateFlag::kUncertain, "uncertain"},
  };
  std::string out;
  for (const auto& e : kNames) {
    if ((flags & e.bit) == 0) continue;
    if (!out.empty()) out += '|';
    out += e.name;
  }
  return out.empty() ? "free" : out;
}

}  // namespace extwrench
