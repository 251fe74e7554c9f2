// A MERL table as synth's material: its lookups (the reader's nearest cell, or linear between cell
// centres) and what synth does with the pixels that look up cells without data (--no-data).
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "core/file_util.h"
#include "core/json_reader.h"
#include "core/merl_brdf.h"
#include "core/merl_format.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "synth/synthetic.h"
#include "tests/scratch_dir.h"
#include "tests/synth/holey_merl_table.h"

namespace ibrdf {
namespace {

using testing::HoleyMerlTable;
using testing::ScratchDir;

// A table linear in the three cell indices (so that linear interpolation between centres is exact).
Eigen::Vector3d LinearCell(int i, int j, int k) {
  const double v = 0.1 + 0.001 * i + 0.002 * j + 0.0001 * k;
  return {v, 1.5 * v, 2.0 * v};
}

MerlTable LinearTable() {
  MerlTable table;
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) table.SetCell(MerlFlatIndex(i, j, k), LinearCell(i, j, k));
    }
  }
  return table;
}

// The directions of half/difference angles (degrees; phi_h 0).
void Directions(double theta_h_deg, double theta_d_deg, double phi_d_deg, Eigen::Vector3d* wi, Eigen::Vector3d* wo) {
  HalfDiffAngles angles;
  angles.theta_h = theta_h_deg * M_PI / 180.0;
  angles.theta_d = theta_d_deg * M_PI / 180.0;
  angles.phi_d = phi_d_deg * M_PI / 180.0;
  FromHalfDiff(angles, wi, wo);
}

TEST(SynthMerl, LinearLookupInterpolatesBetweenCentresAndNeverBeyondTheData) {
  MerlTable table = LinearTable();
  const MerlBrdf nearest(table, "t.binary");
  // Cell (40, 20, 50): theta_h centre ((40.5 / 90)^2 x 90) degrees, theta_d 20.5, phi_d 50.5.
  const double theta_h = std::pow(40.5 / 90.0, 2) * 90.0;
  Eigen::Vector3d wi, wo;
  Directions(theta_h, 20.5, 50.5, &wi, &wo);
  {
    const MerlBrdf linear(table, "t.binary", MerlLookup::kLinear);
    EXPECT_LT((linear.Eval(wi, wo) - LinearCell(40, 20, 50)).norm(), 1e-9);  // a centre: the cell
    EXPECT_LT((nearest.Eval(wi, wo) - LinearCell(40, 20, 50)).norm(), 1e-12);
    // Between the centres of theta_d cells 20 and 21: their mean; the reader's nearest cell is 21.
    Directions(theta_h, 21.0, 50.5, &wi, &wo);
    EXPECT_LT((linear.Eval(wi, wo) - 0.5 * (LinearCell(40, 20, 50) + LinearCell(40, 21, 50))).norm(), 1e-9);
    EXPECT_LT((nearest.Eval(wi, wo) - LinearCell(40, 21, 50)).norm(), 1e-12);
    // phi_d is periodic over 180 degrees (reciprocity): half-way between cells 179 and 0.
    Directions(theta_h, 20.5, 180.0, &wi, &wo);
    EXPECT_LT((linear.Eval(wi, wo) - 0.5 * (LinearCell(40, 20, 179) + LinearCell(40, 20, 0))).norm(), 1e-9);
  }
  // Cell (40, 21, 50) without data: a point in cell 20 leaves it out of the interpolation (the value of
  // its other neighbours), a point in cell 21 has no data, as the reader's lookup.
  table.SetUnmeasured(MerlFlatIndex(40, 21, 50));
  const MerlBrdf linear(table, "t.binary", MerlLookup::kLinear);
  Directions(theta_h, 20.75, 50.5, &wi, &wo);
  EXPECT_LT((linear.Eval(wi, wo) - LinearCell(40, 20, 50)).norm(), 1e-9);
  Directions(theta_h, 21.25, 50.5, &wi, &wo);
  EXPECT_TRUE((linear.Lookup(wi, wo).array() < 0.0).all());
  EXPECT_EQ(linear.Eval(wi, wo), Eigen::Vector3d::Zero());
  EXPECT_EQ(linear.no_data_lookups(), 1u);
  // The lookup travels with the material's JSON (truth.json), so compare scores what synth rendered.
  EXPECT_EQ(linear.ToJson().at("lookup"), "linear");
  EXPECT_FALSE(nearest.ToJson().contains("lookup"));
}

TEST(SynthMerl, MaterialFileNamesTheLookup) {
  ScratchDir dir;
  WriteMerl(dir / "t.binary", LinearTable());
  WriteJsonFile(dir / "m.json", {{"model", "merl"}, {"file", "t.binary"}, {"lookup", "linear"}});
  const auto material = LoadMaterial(dir / "m.json");
  ASSERT_NE(dynamic_cast<const MerlBrdf*>(material.get()), nullptr);
  EXPECT_EQ(dynamic_cast<const MerlBrdf&>(*material).lookup(), MerlLookup::kLinear);
  WriteJsonFile(dir / "bad.json", {{"model", "merl"}, {"file", "t.binary"}, {"lookup", "cubic"}});
  try {
    LoadMaterial(dir / "bad.json");
    FAIL() << "an unknown lookup was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cubic"), std::string::npos) << e.what();
  }
}

// A small noise-free session of a table with data only below theta_d 30 degrees.
SynthOptions SmallSession(SynthNoData no_data) {
  SynthOptions options;
  options.rig.width = 200;
  options.rig.height = 150;
  options.rig.num_photos = 6;
  options.effects = CameraEffects::None();
  options.no_data = no_data;
  return options;
}

// The default, skip: every pixel that looked up a cell without data is left out of the samples by its
// photo's mask and counted the same in synth's summary, truth.json and derender's `masked`; no sample
// is zero-valued and none lies beyond the table's data.
TEST(SynthMerl, NoDataPixelsAreLeftOutByMasksAndCounted) {
  ScratchDir dir;
  const MerlBrdf material(HoleyMerlTable(dir));
  const SynthSummary summary =
      WriteSyntheticSession(SmallSession(SynthNoData::kSkip), material, "holey", dir / "s", false);
  EXPECT_TRUE(summary.tabulated);
  EXPECT_GT(summary.no_data_pixels, 1000u);
  // The photos that see theta_d beyond 30 degrees (cameras far enough from the light) carry a mask.
  EXPECT_GE(summary.masked_photos, 2);
  EXPECT_NE(summary.NoDataReport().find("left out of the samples"), std::string::npos) << summary.NoDataReport();
  const nlohmann::json truth = ReadJsonFile(dir / "s/truth.json");
  EXPECT_EQ(truth.at("generator").at("material_no_data").at("pixels"), summary.no_data_pixels);
  EXPECT_EQ(truth.at("generator").at("material_no_data").at("policy"), "skip");

  const Session session = Session::Load(dir / "s/session.json");
  int masks = 0;
  for (const PhotoSpec& photo : session.photos) masks += !photo.mask.empty();
  EXPECT_EQ(masks, summary.masked_photos);
  const DerenderResult result = Derender(session, DerenderOptions());
  EXPECT_EQ(result.summary.rejected.at("masked"), summary.no_data_pixels);
  ASSERT_GT(result.samples.size(), 10000u);
  for (const BrdfSample& s : result.samples) {
    ASSERT_GT(s.brdf[1], 0.0f) << "a zero-valued sample from a cell without data";
    const Eigen::Vector3d wi(s.wi[0], s.wi[1], s.wi[2]), wo(s.wo[0], s.wo[1], s.wo[2]);
    HalfDiffAngles angles;
    ToHalfDiff(wi.normalized(), wo.normalized(), &angles);
    ASSERT_LT(angles.theta_d * 180.0 / M_PI, 30.01);
  }
}

// zero renders them black and leaves them in the samples' reach (no mask: derender masks nothing and
// sees them as dark pixels; in the demo-sized round trip 942 of 211241 passed the signal floor as
// near-zero samples); error refuses the material and leaves no folder behind.
TEST(SynthMerl, NoDataZeroRendersBlackAndErrorRefuses) {
  ScratchDir dir;
  const MerlBrdf material(HoleyMerlTable(dir));
  SynthOptions noisy = SmallSession(SynthNoData::kZero);
  noisy.effects = CameraEffects();
  const SynthSummary zero = WriteSyntheticSession(noisy, material, "holey", dir / "z", false);
  EXPECT_GT(zero.no_data_pixels, 1000u);
  EXPECT_EQ(zero.masked_photos, 0);
  EXPECT_NE(zero.NoDataReport().find("rendered as 0"), std::string::npos) << zero.NoDataReport();
  const DerenderResult result = Derender(Session::Load(dir / "z/session.json"), DerenderOptions());
  EXPECT_EQ(result.summary.rejected.count("masked") ? result.summary.rejected.at("masked") : 0u, 0u);
  EXPECT_GT(result.summary.rejected.at("below_signal"), 0u);

  try {
    WriteSyntheticSession(SmallSession(SynthNoData::kError), material, "holey.binary", dir / "e", false);
    FAIL() << "--no-data error rendered a table with holes";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("holey.binary"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("without data"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "e"));
}

}  // namespace
}  // namespace ibrdf
