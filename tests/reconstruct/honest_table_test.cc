// Honest tables and MERL tables as materials, on a real-style session
// whose cameras stay within 45 degrees of the light (theta_d under 25 degrees): no cell beyond the
// samples' theta_d is written as measured, domain.npy and the summary agree, --fill model fills the
// unmeasured cells and says so; a MERL table reads back as a material that looks up as the MERL reader,
// and a material evaluates at points without a regression.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/logging.h"
#include "core/merl_brdf.h"
#include "core/npy.h"
#include "core/session.h"
#include "derender/derenderer.h"
#include "reconstruct/reconstruction_error.h"
#include "reconstruct/reconstruction_stage.h"
#include "tests/error_of.h"
#include "tests/scratch_dir.h"
#include "tests/test_util.h"

namespace ibrdf {
namespace {

namespace fs = std::filesystem;
using testing::ErrorOf;
using testing::MaterialPath;
using testing::ScratchDir;

// Bluepaint, 6 photos of 200 x 150 on an arc from 8 to 45 degrees: theta_d from about 4 to 23 degrees.
class RealStyleSession : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (fs::temp_directory_path() / ("ibrdf-RealStyleSession-" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    SetVerbosity(0);
    SynthOptions synth;
    synth.rig.num_photos = 6;
    synth.rig.width = 200;
    synth.rig.height = 150;
    synth.rig.arc_end_deg = 45.0;
    const std::string session = dir_ + "/session";
    testing::MakeSession(session, synth, *LoadMaterial(MaterialPath("bluepaint")));
    samples_ = new std::vector<BrdfSample>(Derender(Session::Load(session), DerenderOptions()).samples);
    truth_ = session + "/truth.json";
  }
  static void TearDownTestSuite() {
    delete samples_;
    fs::remove_all(dir_);
  }
  static ReconstructOptions Options() {
    ReconstructOptions options;
    options.truth_file = truth_;
    options.fit.lafortune_lobes = 1;
    options.fit.max_samples = 2000;
    return options;
  }
  static std::vector<uint8_t> ReadDomain(const std::string& path) {
    std::vector<size_t> shape;
    const std::vector<uint8_t> domain = ReadNpy<uint8_t>(path, "'|u1'", &shape);
    EXPECT_EQ(shape, (std::vector<size_t>{90, 90, 180}));
    return domain;
  }
  ScratchDir out_dir_;
  static std::string dir_, truth_;
  static std::vector<BrdfSample>* samples_;
};
std::string RealStyleSession::dir_, RealStyleSession::truth_;
std::vector<BrdfSample>* RealStyleSession::samples_ = nullptr;

TEST_F(RealStyleSession, NoCellBeyondTheSamplesThetaDIsMeasuredAndTheMaskAgreesWithTheSummary) {
  const std::string out = out_dir_ / "rec";
  const ReconstructResult result = Reconstruct(*samples_, Options(), out, "samples.npy");
  ASSERT_TRUE(result.success);
  const nlohmann::json& table = result.summary.at("table");
  const double theta_d_max = table.at("samples_theta_d_deg")[1].get<double>() * M_PI / 180.0;
  EXPECT_LT(theta_d_max, 25.0 * M_PI / 180.0);
  EXPECT_GT(theta_d_max, 15.0 * M_PI / 180.0);
  const std::vector<uint8_t> domain = ReadDomain(out + "/domain.npy");
  const MerlTable merl = ReadMerl(out + "/brdf.binary");
  uint64_t counts[3] = {0, 0, 0}, beyond = 0, unmeasured_with_value = 0;
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        const size_t flat = MerlFlatIndex(i, j, k);
        const HalfDiffAngles angles = MerlCellCentre(i, j, k);
        Eigen::Vector3d wi, wo;
        FromHalfDiff(angles, &wi, &wo);
        if (!(wi.z() > 0.0 && wo.z() > 0.0)) {
          EXPECT_EQ(domain[flat], 0);
          EXPECT_FALSE(merl.Measured(flat));
          continue;
        }
        ASSERT_LE(domain[flat], 2);
        ++counts[domain[flat]];
        if (angles.theta_d > theta_d_max) {
          ++beyond;
          EXPECT_EQ(domain[flat], 0) << i << " " << j << " " << k;
        }
        if (domain[flat] == 0 && merl.Measured(flat)) ++unmeasured_with_value;
      }
    }
  }
  EXPECT_GT(beyond, 500000u);            // most of the table lies beyond theta_d = 25 degrees
  EXPECT_EQ(unmeasured_with_value, 0u);  // no fill: unmeasured cells hold MERL's "no data"
  EXPECT_EQ(table.at("cells_unmeasured").get<uint64_t>(), counts[0]);
  EXPECT_EQ(table.at("cells_interpolated").get<uint64_t>(), counts[1]);
  EXPECT_EQ(table.at("cells_measured").get<uint64_t>(), counts[2]);
  EXPECT_EQ(table.at("cells_unmeasured_filled").get<uint64_t>(), 0u);
  EXPECT_EQ(table.at("fill"), "none");
  EXPECT_GT(counts[2], 100000u);
  // The valid cells are accurate: what a MERL reader gets where the table has data.
  const nlohmann::json& lookups = result.summary.at("merl_lookups_against_truth");
  EXPECT_GT(lookups.at("hits").get<uint64_t>(), 10000u);
  EXPECT_LT(lookups.at("p95_abs_rel_error_all").get<double>(), 0.05);
  std::ifstream in(out + "/brdf.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_EQ(sidecar.at("table"), table);
}

TEST_F(RealStyleSession, FillModelFillsTheUnmeasuredCellsAndSaysSo) {
  const std::string out = out_dir_ / "rec";
  ReconstructOptions options = Options();
  options.tabulate.fill = FillMode::kModel;
  SetVerbosity(1);
  ::testing::internal::CaptureStderr();
  const ReconstructResult result = Reconstruct(*samples_, options, out, "samples.npy");
  const std::string log = ::testing::internal::GetCapturedStderr();
  SetVerbosity(0);
  ASSERT_TRUE(result.success);
  const nlohmann::json& table = result.summary.at("table");
  EXPECT_EQ(table.at("fill"), "model");
  EXPECT_EQ(table.at("fill_model"), result.chosen_model);
  EXPECT_EQ(table.at("cells_unmeasured_filled").get<uint64_t>(), table.at("cells_unmeasured").get<uint64_t>());
  EXPECT_NE(log.find("filled by --fill model"), std::string::npos) << log;
  const std::vector<uint8_t> domain = ReadDomain(out + "/domain.npy");
  const MerlTable merl = ReadMerl(out + "/brdf.binary");
  const std::unique_ptr<BrdfModel> chosen = LoadMaterial(out + "/" + result.chosen_model + ".json");
  uint64_t filled = 0;
  for (int i = 0; i < kMerlThetaH; i += 3) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; k += 7) {
        const size_t flat = MerlFlatIndex(i, j, k);
        Eigen::Vector3d wi, wo;
        FromHalfDiff(MerlCellCentre(i, j, k), &wi, &wo);
        if (!(wi.z() > 0.0 && wo.z() > 0.0) || domain[flat] != 0) continue;
        ASSERT_TRUE(merl.Measured(flat));
        const Eigen::Vector3d expected = chosen->Eval(wi, wo);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(merl.Cell(flat)[c], expected[c], 1e-9 + 1e-6 * expected[c]);
        ++filled;
      }
    }
  }
  EXPECT_GT(filled, 1000u);
  std::ifstream in(out + "/brdf.json");
  const nlohmann::json sidecar = nlohmann::json::parse(in);
  EXPECT_NE(sidecar.at("unmeasured_value").get<std::string>().find("model"), std::string::npos);
}

TEST_F(RealStyleSession, EvalReturnsTheClassPerPoint) {
  const std::string out = out_dir_ / "rec";
  const std::string points = out_dir_ / "points.npy";
  // theta_d of (theta_i, theta_e, dphi) = (0.3, 0.4, pi) is 0.35 rad (20 degrees): inside; (0.1, 1.2, pi)
  // has theta_d 0.65 rad (37 degrees): beyond the samples.
  WriteNpyArray(points, std::vector<double>{0.3, 0.4, M_PI, 0.1, 1.2, M_PI}, {2, 3});
  ReconstructOptions options = Options();
  options.eval_file = points;
  options.eval_only = true;
  const ReconstructResult result = Reconstruct(*samples_, options, out);
  ASSERT_TRUE(result.success);
  std::vector<size_t> shape;
  const std::vector<uint8_t> classes = ReadNpy<uint8_t>(out + "/eval_domain.npy", "'|u1'", &shape);
  ASSERT_EQ(shape, (std::vector<size_t>{2}));
  EXPECT_EQ(classes[0], uint8_t(DomainClass::kMeasured));
  EXPECT_EQ(classes[1], uint8_t(DomainClass::kUnmeasured));
  const std::vector<double> values = ReadNpyArray(out + "/eval.npy", &shape);
  EXPECT_GT(values[0], 0.0);
  EXPECT_EQ(values[3], -1.0);
  EXPECT_EQ(result.summary.at("eval").at("domain").at("unmeasured"), 1);
}

TEST(MerlMaterial, LooksUpAsTheMerlReaderAndCountsCellsWithoutData) {
  ScratchDir dir;
  const std::unique_ptr<BrdfModel> truth = LoadMaterial(MaterialPath("bluepaint"));
  MerlTable table;
  for (int i = 0; i < kMerlThetaH; ++i) {
    for (int j = 0; j < kMerlThetaD; ++j) {
      for (int k = 0; k < kMerlPhiD; ++k) {
        Eigen::Vector3d wi, wo;
        FromHalfDiff(MerlCellCentre(i, j, k), &wi, &wo);
        if (j < 60) table.SetCell(MerlFlatIndex(i, j, k), truth->Eval(wi, wo));
      }
    }
  }
  const std::string path = dir / "t.binary";
  WriteMerl(path, table);
  const std::unique_ptr<BrdfModel> merl = LoadMaterial(path);
  ASSERT_EQ(merl->ModelName(), "merl");
  const Eigen::Vector3d wi = FromSpherical(0.3, 0.0), wo = FromSpherical(0.5, 2.0);
  EXPECT_EQ(merl->Eval(wi, wo), table.Lookup(wi, wo));
  const auto& typed = dynamic_cast<const MerlBrdf&>(*merl);
  EXPECT_EQ(typed.cells_without_data(), kMerlCells / 3);
  // theta_d = 70 degrees: no data, evaluates to 0 and is counted.
  HalfDiffAngles angles{0.1, 0.0, 70.0 * M_PI / 180.0, 1.0};
  Eigen::Vector3d wi2, wo2;
  FromHalfDiff(angles, &wi2, &wo2);
  EXPECT_EQ(merl->Eval(wi2, wo2), Eigen::Vector3d::Zero());
  EXPECT_EQ(typed.no_data_lookups(), 1u);
  // As a material file (relative path) and as a truth for the lookup check.
  {
    std::ofstream out(dir / "m.json");
    out << R"({"model": "merl", "file": "t.binary"})";
  }
  EXPECT_EQ(LoadMaterial(dir / "m.json")->Eval(wi, wo), table.Lookup(wi, wo));
  const MerlLookupCheck check = CheckMerlLookups(table, *truth, 20000);
  EXPECT_GT(check.hit_fraction(), 0.3);
  EXPECT_LT(check.hit_fraction(), 1.0);
  EXPECT_LT(check.p95_all, 0.5);  // nearest-cell lookups of a smooth table
  EXPECT_NE(ErrorOf([&] { LoadMaterial(dir / "missing.binary"); }).find("missing.binary"), std::string::npos);
}

TEST(EvaluateMaterial, EvaluatesAMaterialAtPointsWithoutSamples) {
  ScratchDir dir;
  const std::string points = dir / "points.npy";
  std::vector<double> p;
  for (int i = 0; i < 1000; ++i) p.insert(p.end(), {0.001 * i, 0.0012 * i, 0.003 * i});
  WriteNpyArray(points, p, {1000, 3});
  ReconstructOptions options;
  options.eval_file = points;
  const ReconstructResult result = EvaluateMaterial(MaterialPath("glossy-ggx"), options, dir / "out");
  ASSERT_TRUE(result.success);
  std::vector<size_t> shape;
  const std::vector<double> values = ReadNpyArray(dir / "out/eval.npy", &shape);
  ASSERT_EQ(shape, (std::vector<size_t>{1000, 3}));
  const std::unique_ptr<BrdfModel> material = LoadMaterial(MaterialPath("glossy-ggx"));
  for (int i = 0; i < 1000; i += 37) {
    const Eigen::Vector3d f = material->Eval(FromSpherical(p[3 * i], 0.0), FromSpherical(p[3 * i + 1], p[3 * i + 2]));
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(values[3 * i + c], f[c]);
  }
  options.eval_file.clear();
  EXPECT_NE(ErrorOf([&] { EvaluateMaterial(MaterialPath("glossy-ggx"), options, dir / "out2"); }).find("--eval"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "out2"));
}

}  // namespace
}  // namespace ibrdf
