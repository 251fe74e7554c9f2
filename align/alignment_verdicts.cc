#include "align/alignment_verdicts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace ibrdf {
namespace {

std::string Format(const char* format, double a, double b = 0.0, double c = 0.0) {
  char text[256];
  std::snprintf(text, sizeof(text), format, a, b, c);
  return text;
}

}  // namespace

std::vector<Verdict> AlignmentVerdicts(const Session& input, const AlignResult& result,
                                       const std::optional<MeshRegistration>& registration,
                                       const AlignmentVerdictBounds& bounds) {
  std::vector<Verdict> verdicts;
  int measurement = 0, posed = 0;
  for (const ImageAlignment& image : result.images) {
    if (input.photos[image.photo].role != PhotoRole::kMeasurement) continue;
    ++measurement;
    posed += image.used;
  }
  if (measurement > 0) {
    Verdict v;
    v.check = "align.photos_posed";
    v.value = double(posed) / measurement;
    v.measured = std::to_string(posed) + " of " + std::to_string(measurement) + " measurement photos posed";
    v.bound = Format("warn below %.0f %%, fail below %.0f %%", 100.0 * bounds.warn_photos_posed,
                     100.0 * bounds.fail_photos_posed);
    v.level = VerdictLevel::kOk;
    if (v.value < bounds.warn_photos_posed) v.level = VerdictLevel::kWarn;
    if (v.value < bounds.fail_photos_posed) v.level = VerdictLevel::kFail;
    v.remedy = "the dropped photos' reasons are in alignment.json (images); photograph more markers per view, "
               "closer, or at a higher resolution";
    verdicts.push_back(v);
  }
  {
    Verdict v;
    v.check = "align.reprojection_rms";
    v.value = result.rms_px;
    v.measured = Format("marker corner RMS %.3f px", result.rms_px);
    v.bound = Format("warn over %.2f px, fail over %.2f px", bounds.warn_rms_px, bounds.fail_rms_px);
    v.level = VerdictAbove(v.value, bounds.warn_rms_px, bounds.fail_rms_px);
    v.remedy = "check the camera's intrinsics (align --calibrate with ChArUco photos) and the targets' layout";
    verdicts.push_back(v);
  }
  const SphereFit& sphere = result.sphere;
  if (sphere.fitted) {
    const double stated = input.sample.radius;
    if (!sphere.radius_fixed && stated > 0.0) {
      Verdict v;
      v.check = "sphere.radius";
      v.value = sphere.radius / stated;
      const double off = std::max(v.value, 1.0 / v.value);
      v.measured = Format("fitted radius %.6g m, %.3gx the stated %.6g m", sphere.radius, v.value, stated);
      v.bound = Format("fitted / stated radius within %.3g-%.3g (warn), ", 1.0 / bounds.warn_radius_ratio,
                       bounds.warn_radius_ratio) +
                Format("%.3g-%.3g (fail)", 1.0 / bounds.fail_radius_ratio, bounds.fail_radius_ratio);
      v.level = VerdictAbove(off, bounds.warn_radius_ratio, bounds.fail_radius_ratio);  // a zero radius: inf, fails
      v.remedy = "state the radius and mark it known (session init --sample-radius-m R --radius-known; sample.radius_known), or add "
                 "photos whose silhouettes see the sphere's limb all around";
      verdicts.push_back(v);
    }
    if (stated > 0.0) {
      Verdict v;
      v.check = "sphere.center";
      v.value = (sphere.center - input.sample.center).norm() / stated;
      v.measured = Format("fitted centre %.4g m (%.3g stated radii) from the stated centre",
                          (sphere.center - input.sample.center).norm(), v.value);
      v.bound = Format("warn over %.3g radii, fail over %.3g radii", bounds.warn_center_shift_radii,
                       bounds.fail_center_shift_radii);
      v.level = VerdictAbove(v.value, bounds.warn_center_shift_radii, bounds.fail_center_shift_radii);
      v.remedy = "state the sphere's centre on the platform (sample.center) and check the photos see the sphere";
      verdicts.push_back(v);
    }
    {
      Verdict v;
      v.check = "sphere.limb_balance";
      v.value = sphere.limb_balance;
      v.measured = Format("limb balance %.3f, radius amplification %.3g", sphere.limb_balance,
                          sphere.radius_amplification);
      v.bound = "one-sided limb evidence (SphereFitOptions) warns";
      v.level = sphere.one_sided ? VerdictLevel::kWarn : VerdictLevel::kOk;
      v.remedy = "state the known radius (sample.radius with \"radius_known\": true), or photograph the unlit limb "
                 "against a brighter background, or add photos from the other side";
      verdicts.push_back(v);
    }
  }
  if (result.light.fitted) {
    Verdict v;
    v.check = "light.position";
    v.value = result.light.spread_m;
    v.measured = Format("light markers' estimates within %.3g mm of their mean", 1e3 * result.light.spread_m);
    v.bound = Format("warn over %.3g mm, fail over %.3g mm", 1e3 * bounds.warn_light_spread_m,
                     1e3 * bounds.fail_light_spread_m);
    v.level = VerdictAbove(v.value, bounds.warn_light_spread_m, bounds.fail_light_spread_m);
    v.remedy = "photograph the light's card from more directions, or check its markers' layout (targets.light)";
    verdicts.push_back(v);
  }
  // A cylinder whose session names markers on it: align was to place it from them.
  const bool cylinder_markers = input.sample.kind == SampleSpec::Kind::kCylinder && input.targets &&
                                input.targets->sample;
  if (cylinder_markers && !result.cylinder.fitted && !result.cylinder.reason.empty()) {
    Verdict v;
    v.check = "cylinder.fitted";
    v.value = 0.0;
    v.measured = "not fitted: " + result.cylinder.reason;
    v.bound = "the cylinder's markers (targets.sample) must place it";
    v.level = VerdictLevel::kFail;
    v.remedy = "photograph the cylinder's markers from more views, or state its pose (sample.center, sample.axis) "
               "as measured and accept cylinder.fitted";
    verdicts.push_back(v);
  }
  if (result.cylinder.fitted) {
    Verdict v;
    v.check = "cylinder.marker_rms";
    v.value = result.cylinder.rms_m;
    v.measured = Format("corner RMS %.3g mm over %.0f markers (%.0f left out)", 1e3 * result.cylinder.rms_m,
                        double(result.cylinder.markers), double(result.cylinder.rejected_markers));
    v.bound = Format("warn over %.3g mm, fail over %.3g mm", 1e3 * bounds.warn_cylinder_rms_m,
                     1e3 * bounds.fail_cylinder_rms_m);
    v.level = VerdictAbove(v.value, bounds.warn_cylinder_rms_m, bounds.fail_cylinder_rms_m);
    if (v.level == VerdictLevel::kOk && result.cylinder.rejected_markers > 0) v.level = VerdictLevel::kWarn;
    v.remedy = "check the cylinder's marker corners (targets.sample) against the cylinder's radius and the "
               "markers' placement; markers left out disagreed with the others";
    verdicts.push_back(v);
  }
  if (registration) {
    Verdict v;
    v.check = "mesh.registration_rms";
    v.value = registration->rms_m;
    v.measured = Format("corner RMS %.3g mm over %.0f markers", 1e3 * registration->rms_m,
                        double(registration->used_markers));
    v.bound = Format("warn over %.3g mm, fail over %.3g mm", 1e3 * bounds.warn_mesh_rms_m, 1e3 * bounds.fail_mesh_rms_m);
    v.level = VerdictAbove(v.value, bounds.warn_mesh_rms_m, bounds.fail_mesh_rms_m);
    v.remedy = "check the scan's marker corners (sample.scan_targets) against the platform's layout";
    verdicts.push_back(v);
  }
  return verdicts;
}

}  // namespace ibrdf
