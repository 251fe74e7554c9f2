#include "core/sample_file.h"

#include "core/error.h"
#include "core/npy.h"

namespace ibrdf {

const char* BrdfSampleDtype() {
  return "[('wi', '<f4', (3,)), ('wo', '<f4', (3,)), ('theta_i', '<f4'), ('theta_e', '<f4'), "
         "('delta_phi', '<f4'), ('brdf', '<f4', (3,)), ('sigma', '<f4', (3,)), ('image', '<u4'), "
         "('pixel', '<u4', (2,))]";
}

std::string SidecarPath(const std::string& samples_path) { return samples_path + ".json"; }

void WriteSamples(const std::string& path, const std::vector<BrdfSample>& samples) {
  WriteNpy(path, BrdfSampleDtype(), {samples.size()}, sizeof(BrdfSample), samples.data(),
           samples.size() * sizeof(BrdfSample));
}

std::vector<BrdfSample> ReadSamples(const std::string& path) {
  std::vector<size_t> shape;
  std::vector<BrdfSample> samples = ReadNpy<BrdfSample>(path, BrdfSampleDtype(), &shape);
  if (shape.size() != 1) ThrowError(path, "sample files are one-dimensional arrays");
  return samples;
}

}  // namespace ibrdf
