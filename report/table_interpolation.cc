#include "report/table_interpolation.h"

#include <algorithm>
#include <cmath>

#include "core/brdf_coords.h"

namespace ibrdf {

Eigen::Vector3d InterpolateMerl(const MerlTable& table, const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  const Eigen::Vector3d none(-1.0, -1.0, -1.0);
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return none;
  HalfDiffAngles a;
  if (!ToHalfDiff(wi, wo, &a)) return none;
  double phi_d = a.phi_d;
  if (phi_d < 0.0) phi_d += M_PI;  // the reader's reciprocity fold
  // Continuous index coordinates; cell i covers [i, i + 1), its centre at i + 0.5.
  const double u = std::sqrt(std::max(0.0, a.theta_h) / (M_PI / 2.0)) * kMerlThetaH - 0.5;
  const double v = a.theta_d / (M_PI / 2.0) * kMerlThetaD - 0.5;
  const double w = phi_d / M_PI * kMerlPhiD - 0.5;
  const double fu = std::floor(u), fv = std::floor(v), fw = std::floor(w);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  for (int du = 0; du <= 1; ++du) {
    const int i = std::clamp(int(fu) + du, 0, kMerlThetaH - 1);
    const double wu = du ? u - fu : 1.0 - (u - fu);
    for (int dv = 0; dv <= 1; ++dv) {
      const int j = std::clamp(int(fv) + dv, 0, kMerlThetaD - 1);
      const double wv = dv ? v - fv : 1.0 - (v - fv);
      for (int dw = 0; dw <= 1; ++dw) {
        const int k = ((int(fw) + dw) % kMerlPhiD + kMerlPhiD) % kMerlPhiD;  // periodic over pi
        const double ww = dw ? w - fw : 1.0 - (w - fw);
        const double weight = wu * wv * ww;
        const size_t flat = MerlFlatIndex(i, j, k);
        if (weight <= 0.0 || !table.Measured(flat)) continue;
        sum += weight * table.Cell(flat);
        weight_sum += weight;
      }
    }
  }
  return weight_sum > 1e-9 ? Eigen::Vector3d(sum / weight_sum) : none;
}

}  // namespace ibrdf
