#include "report/photo_statistics.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/error.h"
#include "core/statistics.h"

namespace ibrdf {

std::map<uint32_t, PhotoStats> CollectPhotoStats(const std::vector<BrdfSample>& samples) {
  std::map<uint32_t, PhotoStats> photos;
  for (const BrdfSample& s : samples) {
    PhotoStats& p = photos[s.image];
    ++p.count;
    p.x0 = std::min<int>(p.x0, s.pixel[0]);
    p.y0 = std::min<int>(p.y0, s.pixel[1]);
    p.x1 = std::max<int>(p.x1, s.pixel[0]);
    p.y1 = std::max<int>(p.y1, s.pixel[1]);
    const double c = s.wi[0] * s.wo[0] + s.wi[1] * s.wo[1] + s.wi[2] * s.wo[2];
    if (p.phase.size() < 4096 || (p.count % 64) == 0) p.phase.push_back(float(std::acos(std::clamp(c, -1.0, 1.0))));
  }
  return photos;
}

ChosenPhoto ChoosePhoto(const std::map<uint32_t, PhotoStats>& photos, int requested) {
  IBRDF_CHECK(!photos.empty());
  std::vector<std::pair<double, uint32_t>> by_phase;
  for (const auto& [image, p] : photos) {
    std::vector<double> phase(p.phase.begin(), p.phase.end());
    by_phase.emplace_back(Percentile(phase, 0.5), image);
  }
  std::sort(by_phase.begin(), by_phase.end());
  ChosenPhoto chosen{by_phase[by_phase.size() / 2].second, by_phase[by_phase.size() / 2].first};
  if (requested >= 0) {
    const auto found =
        std::find_if(by_phase.begin(), by_phase.end(), [&](const auto& e) { return e.second == uint32_t(requested); });
    if (found == by_phase.end()) ThrowError("--photo", "photo " + std::to_string(requested) + " has no samples");
    chosen = {found->second, found->first};
  }
  return chosen;
}

}  // namespace ibrdf
