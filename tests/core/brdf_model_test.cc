// Tests of core/brdf_model.h: the analytic BRDFs (physics: reciprocity, energy, the Lambertian
// constant) and the strict reading of material JSON.
#include "core/brdf_model.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tests/error_of.h"

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/brdf_coords.h"
#include "core/error.h"
#include "tests/scratch_dir.h"

namespace ibrdf {
namespace {

using nlohmann::json;

Eigen::Vector3d RandomUpperDirection(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
  v.normalize();
  v.z() = std::abs(v.z());
  return v;
}

// The pbrt "bluepaint" Lafortune fit, copied from ../shared/data/materials/cornell-lafortune.json.
const Eigen::Vector3d kBluepaintDiffuse(0.3094, 0.39667, 0.70837);
const LafortuneLobe kBluepaintLobes[] = {
    {{0.870567, 0.857255, 0.670982}, {0.803624, 0.774290, 0.586674}, {21.820103, 18.597755, 7.472717}},
    {{-0.451218, -0.406681, -0.477976}, {0.023123, 0.017625, 0.227295}, {2.774499, 2.581499, 3.677653}},
    {{-1.031545, -1.029426, -1.026588}, {0.706734, 0.696530, 0.687715}, {66.899060, 63.767912, 57.489181}},
};

LafortuneBrdf Bluepaint() {
  return LafortuneBrdf(kBluepaintDiffuse,
                       std::vector<LafortuneLobe>(std::begin(kBluepaintLobes), std::end(kBluepaintLobes)));
}

// The formula of cornell-lafortune.json, written out independently:
// f = diffuse/pi + sum_k max(0, Cxy_k (wi.x wo.x + wi.y wo.y) + Cz_k wi.z wo.z)^n_k per channel.
Eigen::Vector3d BluepaintByHand(const Eigen::Vector3d& wi, const Eigen::Vector3d& wo) {
  Eigen::Vector3d f;
  for (int c = 0; c < 3; ++c) {
    double value = kBluepaintDiffuse[c] / M_PI;
    for (const LafortuneLobe& lobe : kBluepaintLobes) {
      const double base = lobe.cxy[c] * (wi.x() * wo.x() + wi.y() * wo.y()) + lobe.cz[c] * wi.z() * wo.z();
      value += std::pow(std::max(0.0, base), lobe.n[c]);
    }
    f[c] = value;
  }
  return f;
}

// The directional albedo rho(wo) = integral over the upper hemisphere of f(wi, wo) cos(theta_i) dwi,
// by the midpoint rule on the half vector h (wi = reflect(wo, h), dwi = 4 (wo.h) dh), which resolves
// a narrow specular peak at any incidence. Deterministic.
Eigen::Vector3d DirectionalAlbedo(const BrdfModel& brdf, const Eigen::Vector3d& wo, int n_theta) {
  const int n_phi = 2 * n_theta;
  const double d_theta = 0.5 * M_PI / n_theta, d_phi = 2.0 * M_PI / n_phi;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < n_theta; ++i) {
    const double theta = (i + 0.5) * d_theta;
    for (int j = 0; j < n_phi; ++j) {
      const Eigen::Vector3d h = FromSpherical(theta, (j + 0.5) * d_phi);
      const double wo_dot_h = wo.dot(h);
      if (wo_dot_h <= 0.0) continue;
      const Eigen::Vector3d wi = 2.0 * wo_dot_h * h - wo;
      if (wi.z() <= 0.0) continue;
      sum += brdf.Eval(wi, wo) * (wi.z() * 4.0 * wo_dot_h * std::sin(theta) * d_theta * d_phi);
    }
  }
  return sum;
}

// Lambertian: f = albedo / pi for every pair of directions above the horizon.
TEST(LambertianBrdf, IsAlbedoOverPi) {
  const LambertianBrdf brdf(Eigen::Vector3d(0.2, 0.5, 0.8));
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d f = brdf.Eval(RandomUpperDirection(rng), RandomUpperDirection(rng));
    EXPECT_LT((f - Eigen::Vector3d(0.2, 0.5, 0.8) / M_PI).norm(), 1e-16);
  }
  EXPECT_EQ(brdf.ModelName(), "lambertian");
}

// Every model is zero when either direction is below (or exactly on) the horizon.
TEST(BrdfModel, ZeroBelowHorizon) {
  const LambertianBrdf lambertian(Eigen::Vector3d(0.5, 0.5, 0.5));
  const LafortuneBrdf lafortune = Bluepaint();
  const GgxBrdf ggx(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.04, 0.04, 0.04), 0.3);
  const BrdfModel* models[] = {&lambertian, &lafortune, &ggx};
  const Eigen::Vector3d above = FromSpherical(0.5, 0.2);
  const Eigen::Vector3d below = FromSpherical(2.0, 0.7);
  const Eigen::Vector3d horizon = FromSpherical(M_PI / 2, 1.0);
  const Eigen::Vector3d mirror_below(-above.x(), -above.y(), -above.z());
  for (const BrdfModel* model : models) {
    EXPECT_EQ(model->Eval(above, below), Eigen::Vector3d::Zero()) << model->ModelName();
    EXPECT_EQ(model->Eval(below, above), Eigen::Vector3d::Zero()) << model->ModelName();
    EXPECT_EQ(model->Eval(below, below), Eigen::Vector3d::Zero()) << model->ModelName();
    EXPECT_EQ(model->Eval(above, mirror_below), Eigen::Vector3d::Zero()) << model->ModelName();
    EXPECT_EQ(model->Eval(Eigen::Vector3d(1, 0, 0), above), Eigen::Vector3d::Zero()) << model->ModelName();
    EXPECT_EQ(model->Eval(above, Eigen::Vector3d(0, 1, -0.0)), Eigen::Vector3d::Zero()) << model->ModelName();
    EXPECT_TRUE(model->Eval(horizon, above).allFinite()) << model->ModelName();
    EXPECT_TRUE((model->Eval(above, above).array() > 0.0).all()) << model->ModelName();
  }
}

// Helmholtz reciprocity f(wi, wo) = f(wo, wi), over random pairs, for each model.
void ExpectReciprocal(const BrdfModel& brdf) {
  std::mt19937 rng(2);
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector3d wi = RandomUpperDirection(rng), wo = RandomUpperDirection(rng);
    const Eigen::Vector3d forward = brdf.Eval(wi, wo), backward = brdf.Eval(wo, wi);
    ASSERT_TRUE(forward.allFinite());
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(forward[c], backward[c], 1e-12 * std::max(1.0, std::abs(forward[c])))
          << brdf.ModelName() << " wi " << wi.transpose() << " wo " << wo.transpose();
    }
  }
}

TEST(LafortuneBrdf, Reciprocity) { ExpectReciprocal(Bluepaint()); }

TEST(GgxBrdf, Reciprocity) {
  ExpectReciprocal(GgxBrdf(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.04, 0.5, 0.9), 0.2));
  ExpectReciprocal(GgxBrdf(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.7));
}

// Energy: a Lambertian surface of albedo 0.5 reflects exactly half of the incident light at every
// incidence (the quadrature is checked at 1%).
TEST(LambertianBrdf, DirectionalAlbedoEqualsAlbedo) {
  const LambertianBrdf brdf(Eigen::Vector3d(0.5, 0.5, 0.5));
  for (double theta_o_deg : {0.0, 30.0, 60.0, 85.0}) {
    const Eigen::Vector3d rho = DirectionalAlbedo(brdf, FromSpherical(theta_o_deg * M_PI / 180, 0.3), 200);
    EXPECT_NEAR(rho.x(), 0.5, 0.005) << theta_o_deg;
  }
}

// Energy: a white, purely specular GGX (diffuse 0, F0 = 1) never reflects more than it receives.
// Single-scattering GGX loses energy to masking, more at higher roughness: at alpha = 1 and normal
// incidence D = 1/pi and G1(mu) = 2 mu / (mu + 1), so the albedo is exactly 1 - ln 2.
TEST(GgxBrdf, WhiteFurnaceAlbedoAtMostOne) {
  for (double alpha : {0.1, 0.3, 0.6, 1.0}) {
    const GgxBrdf brdf(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), alpha);
    for (double theta_o_deg : {0.0, 30.0, 60.0, 80.0}) {
      const Eigen::Vector3d rho = DirectionalAlbedo(brdf, FromSpherical(theta_o_deg * M_PI / 180, 0.0), 300);
      EXPECT_LE(rho.maxCoeff(), 1.0) << "alpha " << alpha << " theta_o " << theta_o_deg;
      EXPECT_GT(rho.minCoeff(), 0.25) << "alpha " << alpha << " theta_o " << theta_o_deg;
    }
  }
  // A smooth surface at normal incidence loses little (0.989 by an independent integration).
  const GgxBrdf smooth(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.1);
  EXPECT_NEAR(DirectionalAlbedo(smooth, Eigen::Vector3d(0, 0, 1), 300).x(), 0.9888, 0.005);
  const GgxBrdf rough(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 1.0);
  EXPECT_NEAR(DirectionalAlbedo(rough, Eigen::Vector3d(0, 0, 1), 300).x(), 1.0 - std::log(2.0), 0.002);
}

// The diffuse term of GGX is Lambertian: with F0 = 0 only Schlick's (1 - cos)^5 term remains, which
// vanishes for wi = wo = h.
TEST(GgxBrdf, DiffuseTermIsLambertian) {
  const GgxBrdf brdf(Eigen::Vector3d(0.3, 0.6, 0.9), Eigen::Vector3d::Zero(), 0.5);
  const Eigen::Vector3d w = FromSpherical(0.4, 1.0);
  // At wi = wo, wi.h = 1, so the Fresnel factor is F0 = 0 and only diffuse/pi remains.
  EXPECT_LT((brdf.Eval(w, w) - Eigen::Vector3d(0.3, 0.6, 0.9) / M_PI).norm(), 1e-15);
}

// GGX at one configuration against the formulas of brdf_model.h computed by hand: normal incidence
// and exitance, so h = n, D = 1 / (pi alpha^2), G = 1, F = F0 and f = diffuse/pi + F0 / (4 pi alpha^2).
TEST(GgxBrdf, NormalIncidenceByHand) {
  const double alpha = 0.25;
  const GgxBrdf brdf(Eigen::Vector3d(0.1, 0.1, 0.1), Eigen::Vector3d(0.04, 0.5, 1.0), alpha);
  const Eigen::Vector3d n(0, 0, 1);
  const Eigen::Vector3d expected =
      Eigen::Vector3d(0.1, 0.1, 0.1) / M_PI + Eigen::Vector3d(0.04, 0.5, 1.0) / (4 * M_PI * alpha * alpha);
  EXPECT_LT((brdf.Eval(n, n) - expected).norm(), 1e-12);
  EXPECT_EQ(brdf.ModelName(), "ggx");
}

// The pbrt bluepaint material evaluates per the formula of cornell-lafortune.json, at values computed
// independently (NumPy) and at random pairs against the formula written out here.
TEST(LafortuneBrdf, BluepaintMatchesPublishedFormula) {
  const LafortuneBrdf brdf = Bluepaint();
  const double deg = M_PI / 180;
  struct Case {
    Eigen::Vector3d wi, wo, f;
  };
  const Case cases[] = {
      {FromSpherical(30 * deg, 0),
       FromSpherical(30 * deg, M_PI),
       {0.10197657086616373, 0.13001479704811958, 0.2360779485969836}},
      {FromSpherical(45 * deg, 0),
       FromSpherical(45 * deg, 0),
       {0.11913615572664356, 0.14893040934652677, 0.25670496933731657}},
      {FromSpherical(0, 0), FromSpherical(0, 0), {0.10699103296563059, 0.13488097049596426, 0.24837474482344285}},
      {FromSpherical(60 * deg, 0),
       FromSpherical(20 * deg, 100 * deg),
       {0.09856983085128881, 0.12637320895015197, 0.22607847695748076}},
      {FromSpherical(60 * deg, 0),
       FromSpherical(60 * deg, M_PI),
       {0.18347661578265229, 0.204076530965779, 0.2969423348816829}},
      {FromSpherical(80 * deg, 0),
       FromSpherical(80 * deg, M_PI),
       {4.4185145316651395, 3.6196000917199007, 2.8312280720072707}},
  };
  for (const Case& c : cases) {
    const Eigen::Vector3d f = brdf.Eval(c.wi, c.wo);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], c.f[k], 1e-12 * c.f[k]) << c.wi.transpose();
  }
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d wi = RandomUpperDirection(rng), wo = RandomUpperDirection(rng);
    const Eigen::Vector3d f = brdf.Eval(wi, wo), expected = BluepaintByHand(wi, wo);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], expected[k], 1e-12 * expected[k]);
  }
  EXPECT_EQ(brdf.ModelName(), "lafortune");
}

// ToJson round-trips through MaterialFromJson for each model: the same JSON and the same values.
TEST(MaterialFromJson, RoundTripsThroughToJson) {
  const LambertianBrdf lambertian(Eigen::Vector3d(0.25, 0.5, 0.125));
  const LafortuneBrdf lafortune = Bluepaint();
  const GgxBrdf ggx(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.04, 0.05, 0.06), 0.35);
  const BrdfModel* models[] = {&lambertian, &lafortune, &ggx};
  std::mt19937 rng(4);
  for (const BrdfModel* model : models) {
    const json text = model->ToJson();
    EXPECT_EQ(text.at("model"), model->ModelName());
    const std::unique_ptr<BrdfModel> read = MaterialFromJson(text, "material.json");
    ASSERT_NE(read, nullptr);
    EXPECT_EQ(read->ModelName(), model->ModelName());
    EXPECT_EQ(read->ToJson(), text);
    // Through a serialized string too (what a material file holds).
    const std::unique_ptr<BrdfModel> reparsed = MaterialFromJson(json::parse(text.dump()), "material.json");
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector3d wi = RandomUpperDirection(rng), wo = RandomUpperDirection(rng);
      EXPECT_EQ(read->Eval(wi, wo), model->Eval(wi, wo)) << model->ModelName();
      EXPECT_EQ(reparsed->Eval(wi, wo), model->Eval(wi, wo)) << model->ModelName();
    }
  }
}

// The optional "name", "description" and "source" strings are accepted.
TEST(MaterialFromJson, AcceptsOptionalStrings) {
  const json value = {{"model", "lambertian"},
                      {"albedo", {0.5, 0.5, 0.5}},
                      {"name", "grey"},
                      {"description", "a test"},
                      {"source", "hand"}};
  EXPECT_NO_THROW(MaterialFromJson(value, "grey.json"));
}

// Expects MaterialFromJson to throw an Error naming the file and containing `field`.
void ExpectErrorNaming(const json& value, const std::string& field, const std::string& pointer = "") {
  try {
    MaterialFromJson(value, "materials/test.json", pointer);
    ADD_FAILURE() << "expected an Error naming " << field << " for " << value.dump();
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("materials/test.json"), std::string::npos) << message;
    EXPECT_NE(message.find(field), std::string::npos) << message;
  }
}

json BluepaintJson() { return Bluepaint().ToJson(); }

TEST(MaterialFromJson, UnknownKeyIsAnErrorNamingIt) {
  json top = BluepaintJson();
  top["difuse"] = {0.1, 0.1, 0.1};
  ExpectErrorNaming(top, "/difuse");
  json nested = BluepaintJson();
  nested["lobes"][1]["Cxz"] = {0.1, 0.1, 0.1};
  ExpectErrorNaming(nested, "/lobes/1/Cxz");
  json ggx = GgxBrdf(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.3).ToJson();
  ggx["roughness"] = 0.3;
  ExpectErrorNaming(ggx, "/roughness");
}

TEST(MaterialFromJson, UnknownModelIsAnError) {
  ExpectErrorNaming({{"model", "phong"}, {"albedo", {0.5, 0.5, 0.5}}}, "/model");
  ExpectErrorNaming({{"albedo", {0.5, 0.5, 0.5}}}, "/model");                // missing
  ExpectErrorNaming({{"model", 3}, {"albedo", {0.5, 0.5, 0.5}}}, "/model");  // not a string
}

TEST(MaterialFromJson, NegativeAlbedoIsAnError) {
  ExpectErrorNaming({{"model", "lambertian"}, {"albedo", {0.5, -0.1, 0.5}}}, "/albedo");
  json lafortune = BluepaintJson();
  lafortune["diffuse"][2] = -0.5;
  ExpectErrorNaming(lafortune, "/diffuse");
  json ggx = GgxBrdf(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.3).ToJson();
  ggx["specular_f0"][0] = -0.01;
  ExpectErrorNaming(ggx, "/specular_f0");
}

TEST(MaterialFromJson, WrongLengthVectorIsAnError) {
  ExpectErrorNaming({{"model", "lambertian"}, {"albedo", {0.5, 0.5}}}, "/albedo");
  ExpectErrorNaming({{"model", "lambertian"}, {"albedo", {0.5, 0.5, 0.5, 0.5}}}, "/albedo");
  ExpectErrorNaming({{"model", "lambertian"}, {"albedo", 0.5}}, "/albedo");
  json lafortune = BluepaintJson();
  lafortune["lobes"][0]["n"] = {2.0, 3.0};
  ExpectErrorNaming(lafortune, "/lobes/0/n");
  json element = BluepaintJson();
  element["lobes"][2]["Cz"][1] = "x";
  ExpectErrorNaming(element, "/lobes/2/Cz/1");
}

// Exponents must be positive and alpha in (0, 1].
TEST(MaterialFromJson, ImpossibleParametersAreErrors) {
  json lafortune = BluepaintJson();
  lafortune["lobes"][0]["n"][1] = 0.0;
  ExpectErrorNaming(lafortune, "/lobes/0/n");
  json ggx = GgxBrdf(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 0.3).ToJson();
  for (double alpha : {0.0, -0.2, 1.5}) {
    ggx["alpha"] = alpha;
    ExpectErrorNaming(ggx, "/alpha");
  }
  ExpectErrorNaming(json::array({1, 2, 3}), "expected an object");
}

// A material embedded in another file reports its own pointer prefix.
TEST(MaterialFromJson, ErrorsCarryThePointerPrefix) {
  ExpectErrorNaming({{"model", "lambertian"}, {"albedo", {0.5, -0.5, 0.5}}}, "/material/albedo", "/material");
}

// LoadMaterial reads a file; its errors name the file.
TEST(LoadMaterial, ReadsFileAndNamesItInErrors) {
  const testing::ScratchDir scratch;
  const std::string dir = scratch.str();
  const std::string good = dir + "/bluepaint.json", bad = dir + "/bad.json";
  std::ofstream(good) << BluepaintJson().dump(2);
  json broken = BluepaintJson();
  broken["lobes"][0]["n"] = {1.0};
  std::ofstream(bad) << broken.dump(2);
  const std::unique_ptr<BrdfModel> read = LoadMaterial(good);
  EXPECT_EQ(read->ToJson(), BluepaintJson());
  try {
    LoadMaterial(bad);
    ADD_FAILURE() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/lobes/0/n"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadMaterial(dir + "/missing.json"), Error);
  std::filesystem::remove_all(dir);
}

// A material with Cz 1e300 once made `synth` write exposure_s 0. Values are validated where read:
// each message names the file and the field.
TEST(MaterialFromJson, ImplausibleValuesAreErrors) {
  json lafortune = Bluepaint().ToJson();
  lafortune["lobes"][0]["Cz"] = {1e300, 0.5, 0.5};
  std::string message = testing::ErrorOf([&] { MaterialFromJson(lafortune, "m.json"); });
  EXPECT_NE(message.find("m.json: /lobes/0/Cz"), std::string::npos) << message;
  lafortune = Bluepaint().ToJson();
  lafortune["lobes"][0]["Cz"] = {1.5, 0.5, 0.5};
  lafortune["lobes"][0]["n"] = {200, 20, 20};  // 1.5^200 = 1.6e35 /sr at the peak
  message = testing::ErrorOf([&] { MaterialFromJson(lafortune, "m.json"); });
  EXPECT_NE(message.find("m.json: /lobes/0"), std::string::npos) << message;
  EXPECT_NE(message.find("physically plausible"), std::string::npos) << message;
  const json lambertian = {{"model", "lambertian"}, {"albedo", {1.5, 0.5, 0.5}}};
  message = testing::ErrorOf([&] { MaterialFromJson(lambertian, "l.json"); });
  EXPECT_NE(message.find("l.json: /albedo"), std::string::npos) << message;
  const json ggx = {
      {"model", "ggx"}, {"diffuse_albedo", {0.5, 0.5, 0.5}}, {"specular_f0", {0.04, 2, 0.04}}, {"alpha", 0.3}};
  message = testing::ErrorOf([&] { MaterialFromJson(ggx, "g.json"); });
  EXPECT_NE(message.find("g.json: /specular_f0"), std::string::npos) << message;
}

// Every material of samples/materials still loads under these bounds.
TEST(MaterialFromJson, SampleMaterialsLoad) {
  for (const auto& entry : std::filesystem::directory_iterator(std::string(IBRDF_SAMPLES_DIR) + "/materials")) {
    EXPECT_NO_THROW(LoadMaterial(entry.path().string())) << entry.path();
  }
}

// The dielectric GGX's specular term vanishes with F0 = 0: a pure Lambertian is representable (the
// Schlick term stays at (1 - cos)^5 D G / (4 cos cos) there).
TEST(GgxBrdf, DielectricWithZeroF0IsLambertian) {
  const Eigen::Vector3d albedo(0.6, 0.3, 0.1);
  const GgxBrdf dielectric(albedo, Eigen::Vector3d::Zero(), 0.3, GgxFresnel::kDielectric);
  const GgxBrdf schlick(albedo, Eigen::Vector3d::Zero(), 0.3);
  const LambertianBrdf lambert(albedo);
  const Eigen::Vector3d wi = FromSpherical(80.0 * M_PI / 180, 0.0), wo = FromSpherical(80.0 * M_PI / 180, M_PI);
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(dielectric.Eval(wi, wo)[c], lambert.Eval(wi, wo)[c]);
    EXPECT_DOUBLE_EQ(dielectric.Eval(wo, wo)[c], lambert.Eval(wo, wo)[c]);
  }
  EXPECT_GT(schlick.Eval(FromSpherical(85.0 * M_PI / 180, 0.0), FromSpherical(85.0 * M_PI / 180, M_PI))[0],
            1.05 * lambert.Eval(wi, wo)[0]);
  ExpectReciprocal(GgxBrdf(albedo, Eigen::Vector3d(0.04, 0.05, 0.06), 0.2, GgxFresnel::kDielectric));
}

TEST(GgxBrdf, DielectricFresnelMatchesItsLimits) {
  // Normal incidence: ((eta - 1) / (eta + 1))^2 = F0; grazing: 1; eta 1.5 at 45 degrees: 0.0502
  // (the textbook value of the unpolarized average).
  EXPECT_NEAR(DielectricFresnel(1.0, IorFromF0(0.04)), 0.04, 1e-12);
  EXPECT_NEAR(IorFromF0(0.04), 1.5, 1e-12);
  EXPECT_NEAR(DielectricFresnel(1e-9, 1.5), 1.0, 1e-6);
  EXPECT_NEAR(DielectricFresnel(std::cos(M_PI / 4), 1.5), 0.0502, 2e-4);
  EXPECT_EQ(DielectricFresnel(0.3, 1.0), 0.0);
  // Round trip through the material format.
  const GgxBrdf ggx(Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.04, 0.04, 0.04), 0.2, GgxFresnel::kDielectric);
  const nlohmann::json material = ggx.ToJson();
  EXPECT_EQ(material["fresnel"], "dielectric");
  const auto again = MaterialFromJson(material, "x.json");
  const Eigen::Vector3d wi = FromSpherical(0.4, 0.0), wo = FromSpherical(0.9, 2.5);
  EXPECT_EQ(again->Eval(wi, wo), ggx.Eval(wi, wo));
  nlohmann::json bad = material;
  bad["fresnel"] = "fancy";
  EXPECT_NE(testing::ErrorOf([&] { MaterialFromJson(bad, "x.json"); }).find("x.json: /fresnel"), std::string::npos);
}

}  // namespace
}  // namespace ibrdf
