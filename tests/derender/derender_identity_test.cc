// The derenderer's samples are byte-identical to those of the plain photo-by-photo loop
// (commit 60d9575: every pixel of every photo linearized into a fresh buffer, photos merged
// after a parallel loop). Small synthetic sessions, rendered by `ibrdf synth` (seeded, so their bytes
// do not depend on the machine or the thread count), are derendered through the CLI and the .npy
// files' FNV-1a hashes compared with the ones that commit wrote: an analytic sphere (also at stride
// 2), a cylinder with 3-exposure brackets, the sRGB response and vignetting (flat field), and the
// dent mesh (Embree, shadow rays on, off and auto). A deliberate change of the samples (or of synth's
// photos) must re-record these hashes, saying why in the commit. The hashes are of 76-byte rows with
// per-channel validity and the floor on the expected signal, derendered from photos whose sensor noise
// is drawn by a ziggurat on a counter-based stream (synth/noise_random.h).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/run_ibrdf.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::RunIbrdf;
using testing::RunResult;
using testing::ScratchDir;

std::string Fnv1a64(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << path;
  uint64_t hash = 14695981039346656037ull;
  char c;
  while (in.get(c)) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

std::string Material(const std::string& name) { return std::string(IBRDF_SAMPLES_DIR) + "/materials/" + name; }

// Derenders `session` with `options` and returns the sample file's hash.
std::string DerenderHash(const ScratchDir& dir, const std::string& session, const std::string& name,
                         const std::string& options = "") {
  const std::string out = dir / (name + ".npy");
  const RunResult result = RunIbrdf("derender " + session + " --out " + out + " " + options);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  return Fnv1a64(out);
}

TEST(DerenderIdentity, AnalyticSphereAndBracketedCylinder) {
  ScratchDir dir;
  const std::string sphere = dir / "sphere", cylinder = dir / "cyl";
  RunResult result = RunIbrdf("synth --out " + sphere + " --material " + Material("bluepaint.json") +
                              " --width 200 --height 150 --photos 4");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result = RunIbrdf("synth --out " + cylinder + " --material " + Material("bluepaint.json") +
                    " --sample cylinder --width 200 --height 150 --photos 4 --brackets 3 --srgb --vignetting 0.3");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(DerenderHash(dir, sphere, "sphere"), "2b59e861ae5097a7");
  EXPECT_EQ(DerenderHash(dir, sphere, "sphere-s2", "--stride 2"), "c716049d7f514a76");
  EXPECT_EQ(DerenderHash(dir, cylinder, "cylinder"), "a172db723ee6856b");
  // The thread count changes nothing.
  const RunResult one = RunIbrdf("--threads 1 derender " + sphere + " --out " + (dir / "t1.npy"));
  ASSERT_EQ(one.exit_code, 0) << one.output;
  EXPECT_EQ(Fnv1a64(dir / "t1.npy"), "2b59e861ae5097a7");
}

TEST(DerenderIdentity, DentMesh) {
  ScratchDir dir;
  const std::string dent = dir / "dent";
  const RunResult result = RunIbrdf("synth --out " + dent + " --material " + Material("bluepaint.json") +
                                    " --shape dent --width 200 --height 150 --photos 4");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // The true mesh (world frame, exact normals) in place of the scan, so no scan or align stage runs.
  nlohmann::json session;
  std::ifstream(dent + "/session.json") >> session;
  session["sample"] = {{"kind", "mesh"}, {"file", "truth-mesh.ply"}};
  std::ofstream(dent + "/session.json") << session.dump(1);
  EXPECT_EQ(DerenderHash(dir, dent, "auto"), "73e0a11fb9b88198");
  EXPECT_EQ(DerenderHash(dir, dent, "on", "--visibility on"), "73e0a11fb9b88198");
  EXPECT_EQ(DerenderHash(dir, dent, "off", "--visibility off"), "a23fd80b6348aa63");
}

}  // namespace
}  // namespace ibrdf
